"""A C compiler wrapper that reuses object files (what ccache does, for plant_defects).

    CC="python /path/to/benchmarks/compile_cache.py gcc" python setup.py build_ext --inplace

setuptools recompiles every source of an extension when any of them changed; this
wrapper makes a recompile of an unchanged source a copy.  A compile (``-c SRC -o OBJ``)
is keyed by the sha256 of the compiler (its path, size and mtime), the arguments but
the output path, and the preprocessed source (``-E``: every header it includes, as
included) with the working directory's path taken out, so that two copies of the tree
at different paths share objects.  A hit copies the cached object to OBJ; a miss
compiles and stores it (written to a temporary name, then renamed: concurrent builds
never see half a file).  Anything else (the link) runs the compiler as given.

The cache is the directory ``BALLC_COMPILE_CACHE`` (required).
"""
from __future__ import annotations

import hashlib
import os
import shutil
import subprocess
import sys
import tempfile


def _compile_parts(args):
    """(source, output index) of a single-source compile ``... -c SRC -o OBJ``, else None."""
    if "-c" not in args or "-o" not in args or "-E" in args:
        return None
    out = args.index("-o") + 1
    sources = [a for a in args[1:] if a.endswith((".c", ".cc", ".cpp"))]
    if out >= len(args) or len(sources) != 1:
        return None
    return sources[0], out


def _key(args, out):
    compiler = shutil.which(args[0]) or args[0]
    stat = os.stat(compiler)
    preprocess = [a for i, a in enumerate(args) if i not in (out - 1, out) and a != "-c"]
    text = subprocess.run(preprocess + ["-E", "-o", "-"], stdout=subprocess.PIPE,
                          check=True).stdout
    text = text.replace(os.getcwd().encode(), b"@CWD@")
    digest = hashlib.sha256()
    digest.update(repr((compiler, stat.st_size, stat.st_mtime_ns)).encode())
    digest.update("\0".join(preprocess).encode())
    digest.update(b"\0" + text)
    return digest.hexdigest()


def main(args):
    parts = _compile_parts(args)
    cache = os.environ.get("BALLC_COMPILE_CACHE")
    if parts is None or not cache:
        return subprocess.call(args)
    _, out = parts
    try:
        key = _key(args, out)
    except (OSError, subprocess.CalledProcessError):
        return subprocess.call(args)   # the compiler will report the error itself
    stored = os.path.join(cache, key[:2], key + ".o")
    target = args[out]
    if os.path.isfile(stored):
        shutil.copyfile(stored, target)
        return 0
    rc = subprocess.call(args)
    if rc == 0:
        os.makedirs(os.path.dirname(stored), exist_ok=True)
        fd, temporary = tempfile.mkstemp(dir=os.path.dirname(stored), suffix=".part")
        os.close(fd)
        shutil.copyfile(target, temporary)
        os.replace(temporary, stored)
    return rc


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
