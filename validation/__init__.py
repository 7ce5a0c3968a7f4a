"""ballc against the Chung & Ooi (2011) DEM benchmark tests: ``python -m validation``.

See validation/README.md for the reference curves' provenance and docs/validation.md
for what each test shows about each tangential model.
"""
