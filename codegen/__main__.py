"""``python -m codegen`` writes generated/; ``python -m codegen --check`` verifies it.

The check regenerates everything in memory and fails (exit 1) if any file in
generated/ would change, naming the files.
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from .emit import (CONSTANTS_SIGNATURE, GENERATOR_VERSION, SIGNATURE, BallcPrinter,
                   ParameterConstants, c_string_array, constants_c, header_comment, kernel_c)
from .contact import TANGENTIAL_LAWS
from .kernels import MASS_LAYOUT, build_kernels, contact_law_offsets, describe_contact_law_layout
from .model import (BALL_STATE_NAMES, CONTACT_STATE_NAMES, LATCH_FIELDS, MAX_PLANES,
                    MECHANICAL_STATE_NAMES, PARAMETER_NAMES, PARAMETERS, PLANE_FIELDS,
                    PLANE_INPUT_NAMES, PLANE_STATE_FIELDS, ROLLING_BALL_STATE_NAMES,
                    ROLLING_MODE_CODES, ROLLING_SPRING_FIELDS)

GENERATED = Path(__file__).resolve().parent.parent / "generated"


def render(verbose=False) -> dict[str, str]:
    """File name -> contents of everything in generated/."""
    started = time.perf_counter()
    model, kernels = build_kernels()
    derived = time.perf_counter()
    header = header_comment()
    printer = BallcPrinter()
    bodies, prototypes, sizes = [], [], []
    total_ops = 0
    constants = ParameterConstants(model.parameters)
    for kernel in kernels:
        source, ops = kernel_c(kernel, model.states, model.parameters, printer, constants)
        total_ops += ops
        bodies.append(source)
        prototypes.append(SIGNATURE.format(name=kernel.name) + ";")
        sizes.append(f"#define BALLC_{kernel.name.upper()}_NOUT {len(kernel.outputs)}")
        if verbose:
            print(f"  {kernel.name:28s} {len(kernel.outputs):4d} outputs {ops:6d} ops",
                  file=sys.stderr)

    source, ops = constants_c(constants, model.parameters, printer)
    total_ops += ops
    bodies.insert(0, source)
    prototypes.insert(0, CONSTANTS_SIGNATURE + ";")
    if verbose:
        print(f"  {'parameter_constants':28s} {len(constants):4d} outputs {ops:6d} ops",
              file=sys.stderr)

    law_names = {f"plane_{law}" for law in TANGENTIAL_LAWS}
    if PARAMETER_NAMES[-1] != "plane_count":
        raise ValueError("the plane table must close the parameters: plane_count last")
    (contact_law_nout,) = {len(k.outputs) for k in kernels if k.name in law_names}
    units = [p[2] for p in PARAMETERS]
    n_ball, n_plane_states = len(BALL_STATE_NAMES), len(PLANE_STATE_FIELDS)
    n_fixed, n_fields = len(PARAMETER_NAMES), len(PLANE_FIELDS)
    h = [header, "#ifndef BALLC_KERNELS_H", "#define BALLC_KERNELS_H", "",
         "/* Argument layout: the one source of truth for state and parameter order.  A run",
         "   with n planes has BALLC_N_BALL_STATES + n BALLC_N_PLANE_STATES states (the",
         "   ball's, then each plane's own from BALLC_STATE_PLANES on), BALLC_PARAMETER_PLANES",
         "   + n BALLC_N_PLANE_FIELDS parameters (the plane table closes them, its count at",
         "   BALLC_PARAMETER_PLANE_COUNT) and n BALLC_N_LATCH_PER_PLANE latched values. */",
         f"#define BALLC_GENERATOR_VERSION \"{GENERATOR_VERSION}\"",
         f"#define BALLC_MAX_PLANES {MAX_PLANES}",
         f"#define BALLC_N_BALL_STATES {n_ball}",
         f"#define BALLC_N_PLANE_STATES {n_plane_states}",
         *[f"#define BALLC_PLANE_STATE_{name.upper()} {i}"
           for i, name in enumerate(PLANE_STATE_FIELDS)],
         f"#define BALLC_STATE_PLANES {n_ball}",
         "/* with rolling resistance (and only then), after every plane's states: the",
         "   rolling block, dissipated_rolling then BALLC_N_ROLLING_PLANE_STATES per plane */",
         f"#define BALLC_N_ROLLING_BALL_STATES {len(ROLLING_BALL_STATE_NAMES)}",
         f"#define BALLC_N_ROLLING_PLANE_STATES {len(ROLLING_SPRING_FIELDS)}",
         "#define BALLC_MAX_STATES " + str(n_ball + MAX_PLANES * n_plane_states
                                            + len(ROLLING_BALL_STATE_NAMES)
                                            + MAX_PLANES * len(ROLLING_SPRING_FIELDS)),
         "/* parameter constants: ballc_parameter_constants(params, constants) */",
         f"#define BALLC_N_PARAMETER_CONSTANTS {len(constants)}",
         f"#define BALLC_N_LATCH_PER_PLANE {len(LATCH_FIELDS)}",
         f"#define BALLC_MAX_LATCH {MAX_PLANES * len(LATCH_FIELDS)}",
         "/* the plane table, in the parameters: its count, then BALLC_N_PLANE_FIELDS per "
         "plane from BALLC_PARAMETER_PLANES on */",
         f"#define BALLC_PARAMETER_PLANES {n_fixed}",
         f"#define BALLC_N_PLANE_FIELDS {n_fields}",
         f"#define BALLC_MAX_PARAMETERS {n_fixed + MAX_PLANES * n_fields}",
         *[f"#define BALLC_PLANE_{name.upper()} {i}" for i, (name, *_) in enumerate(PLANE_FIELDS)],
         "/* a plane kernel's state: one contact in its plane's own frame */",
         f"#define BALLC_N_CONTACT_STATES {len(CONTACT_STATE_NAMES)}",
         *[f"#define BALLC_CONTACT_STATE_{name.upper()} {i}"
           for i, name in enumerate(CONTACT_STATE_NAMES)],
         "/* a plane kernel's extra: the plane's latch (its frame), gravity into the plane */",
         f"#define BALLC_N_PLANE_INPUTS {len(PLANE_INPUT_NAMES)}",
         f"#define BALLC_PLANE_INPUT_GRAVITY {PLANE_INPUT_NAMES.index('gravity_into_plane')}",
         f"#define BALLC_MASS_SIZE {len(MASS_LAYOUT)}",
         *[f"#define BALLC_STATE_{name.upper()} {i}" for i, name in enumerate(BALL_STATE_NAMES)],
         *[f"#define BALLC_PARAMETER_{name.upper()} {i}"
           for i, name in enumerate(PARAMETER_NAMES)],
         *[f"#define BALLC_LATCH_{field[0].upper()} {i}" for i, field in enumerate(LATCH_FIELDS)],
         "/* a plane's rolling and twisting modes, as its latch holds them */",
         *[f"#define BALLC_ROLLING_MODE_{name.upper()} {code}"
           for name, code in ROLLING_MODE_CODES],
         f"#define BALLC_N_MECHANICAL_STATES {len(MECHANICAL_STATE_NAMES)}",
         f"#define BALLC_CONTACT_LAW_NOUT {contact_law_nout}",
         "/* contact-law kernel outputs: " + describe_contact_law_layout() + " */",
         *[f"#define BALLC_LAW_{suffix} {offset}" for suffix, offset in contact_law_offsets()],
         *sizes, "",
         c_string_array("BALLC_STATE_NAMES", BALL_STATE_NAMES).rstrip(),
         c_string_array("BALLC_PLANE_STATE_NAMES", PLANE_STATE_FIELDS).rstrip(),
         c_string_array("BALLC_ROLLING_BALL_STATE_NAMES", ROLLING_BALL_STATE_NAMES).rstrip(),
         c_string_array("BALLC_ROLLING_PLANE_STATE_NAMES", ROLLING_SPRING_FIELDS).rstrip(),
         c_string_array("BALLC_PARAMETER_NAMES", PARAMETER_NAMES).rstrip(),
         c_string_array("BALLC_PARAMETER_UNITS", units).rstrip(),
         c_string_array("BALLC_PLANE_FIELD_NAMES", [f[0] for f in PLANE_FIELDS]).rstrip(),
         c_string_array("BALLC_PLANE_FIELD_UNITS", [f[1] for f in PLANE_FIELDS]).rstrip(),
         c_string_array("BALLC_LATCH_FIELD_NAMES", [f[0] for f in LATCH_FIELDS]).rstrip(),
         c_string_array("BALLC_CONTACT_STATE_NAMES", CONTACT_STATE_NAMES).rstrip(),
         c_string_array("BALLC_PARAMETER_CONSTANT_NAMES", map(str, constants.values)).rstrip(),
         c_string_array("BALLC_MASS_LAYOUT", MASS_LAYOUT).rstrip(),
         "", *prototypes, "", "#endif", ""]
    c = [header, "#include <math.h>", "#include \"ballc_kernels.h\"", "", *bodies]
    if verbose:
        print(f"derivation {derived - started:.1f} s, CSE + printing "
              f"{time.perf_counter() - derived:.1f} s, {total_ops} operations in "
              f"{len(kernels)} kernels", file=sys.stderr)
    return {"ballc_kernels.h": "\n".join(h), "ballc_kernels.c": "\n".join(c)}


HEADER_END = "Do not edit: change codegen/ and regenerate. */\n"


def split_header(text: str) -> tuple[str, str]:
    """(provenance header, body) of a generated file."""
    head, sep, body = text.partition(HEADER_END)
    return (head + sep, body) if sep else ("", text)


def check(files: dict[str, str], out: Path) -> int:
    """Compare generated/ with what codegen/ produces now: the C first, then the header.

    A difference in the code is stale (exit 1).  A difference in the provenance header
    only (another sympy version, an edited comment in codegen/ -- the inputs hash) with
    byte-identical code is reported but passes (exit 0): the compiled result is the same.
    """
    stale, header_only = [], []
    for name, text in files.items():
        path = out / name
        if not path.is_file():
            stale.append(name)
            continue
        committed = path.read_text()
        if committed == text:
            continue
        if split_header(committed)[1] == split_header(text)[1]:
            header_only.append(name)
        else:
            stale.append(name)
    if stale:
        print(f"generated/ is stale: the code of {', '.join(stale)} differs from what "
              "codegen/ produces; run `python -m codegen` and commit", file=sys.stderr)
        return 1
    if header_only:
        print(f"generated/ is current: the code is identical; only the provenance header of "
              f"{', '.join(header_only)} differs (sympy version or codegen/ inputs hash); "
              "run `python -m codegen` to refresh it")
        return 0
    print(f"generated/ is current ({len(files)} files)")
    return 0


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python -m codegen", description=__doc__)
    parser.add_argument("--check", action="store_true",
                        help="fail if generated/ is not what codegen/ produces")
    parser.add_argument("--out", type=Path, default=GENERATED, help="output directory")
    parser.add_argument("-v", "--verbose", action="store_true")
    args = parser.parse_args(argv)

    files = render(verbose=args.verbose)
    if args.check:
        return check(files, args.out)
    args.out.mkdir(parents=True, exist_ok=True)
    for name, text in files.items():
        (args.out / name).write_text(text)
    print(f"wrote {', '.join(files)} to {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
