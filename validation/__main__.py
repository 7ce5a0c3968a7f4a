"""Run the Chung & Ooi (2011) sphere-on-plane benchmark tests with ballc.

    python -m validation [--out DIR] [--only 2,4]

Prints one line per compared curve: the error 100 sum|sim - ref| / sum|ref| and the
threshold the DEM codes (Kratos) use; draws one figure per test into DIR (default
ballc-output/validation/); exits 1 if any comparison fails.  "LIMIT" rows are inputs
ballc's contact law cannot represent (reported, not counted as failures).
"""
import argparse
import math
import sys
import time
from pathlib import Path


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", type=Path, default=Path("ballc-output/validation"),
                        help="output folder (default: %(default)s)")
    parser.add_argument("--only", default="", help="comma-separated test numbers (2..7)")
    args = parser.parse_args(argv)
    from .cases import TESTS
    chosen = [t.strip() for t in args.only.split(",") if t.strip()] or list(TESTS)
    unknown = [t for t in chosen if t not in TESTS]
    if unknown:
        parser.error(f"--only: unknown test(s) {unknown}; choose from {list(TESTS)}")
    args.out.mkdir(parents=True, exist_ok=True)
    rows = []
    header = (f"{'test':22s} {'curve':44s} {'model':13s} {'error %':>9s} {'threshold %':>11s}"
              f"  status  threshold source / note")
    print(header)
    print("-" * len(header))
    for key in chosen:
        t0 = time.perf_counter()
        test_rows, fig = TESTS[key]()
        path = args.out / f"test{key}.png"
        fig.savefig(path, dpi=90)
        import matplotlib.pyplot as plt
        plt.close(fig)
        for r in test_rows:
            err = "-" if math.isnan(r.error) else f"{r.error:.3g}"
            thr = "-" if math.isnan(r.threshold) else f"{r.threshold:g}"
            note = r.source + (f"; {r.note}" if r.note else "")
            print(f"{r.test:22s} {r.curve:44s} {r.model:13s} {err:>9s} {thr:>11s}  "
                  f"{r.status:6s}  {note}")
        print(f"{'':22s} ({path}, {time.perf_counter() - t0:.1f} s)")
        rows += test_rows
    failed = [r for r in rows if r.status == "FAIL"]
    limits = [r for r in rows if r.status == "LIMIT"]
    reported = [r for r in rows if r.status == "REPORT"]
    print(f"\n{len(rows) - len(failed) - len(limits) - len(reported)} passed, "
          f"{len(failed)} failed, {len(limits)} not representable (LIMIT), "
          f"{len(reported)} reported, not scored (REPORT)")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
