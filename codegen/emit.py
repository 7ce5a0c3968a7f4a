"""C emission: one joint CSE per kernel, sympy's C99 printer, provenance header.

Every kernel has the same signature::

    void ballc_<name>(const double *restrict state, const double *restrict params,
                      const double *restrict constants, const double *restrict extra,
                      double *restrict out);

``state`` is the state (STATE_NAMES order), ``params`` the parameters (PARAMETER_NAMES order),
``constants`` the parameter constants (``ballc_parameter_constants(params, constants)``),
``extra`` a kernel-specific input vector (latched contact values, or a vector to
multiply with), ``out`` the kernel's outputs, written (never accumulated).

Parameter constants: after each kernel's CSE, every subexpression whose free symbols
are parameters only (a CSE temporary, a subtree, or the parameter factors and terms of
a product or sum) is replaced by a constant ``pc<i>``, shared by all kernels; one more
function, ``ballc_parameter_constants``, computes them from the parameter vector, so a
caller computes them once per parameter vector instead of once per kernel call.
"""
from __future__ import annotations

import hashlib
from dataclasses import dataclass, field
from pathlib import Path

import sympy as sm
from sympy.core.function import AppliedUndef
from sympy.printing.c import C99CodePrinter

GENERATOR_VERSION = "2"
SIGNATURE = ("void ballc_{name}(const double *restrict state, const double *restrict params,\n"
             "        const double *restrict constants, const double *restrict extra,\n"
             "        double *restrict out)")
CONSTANTS_SIGNATURE = ("void ballc_parameter_constants(const double *restrict params, "
                       "double *restrict constants)")
CODEGEN_DIR = Path(__file__).resolve().parent


@dataclass
class Kernel:
    """One C function: outputs as flat sympy expressions of x, p and extra."""

    name: str
    doc: str
    outputs: list          # flat list of sympy expressions
    extra: list            # symbols read from ``extra`` (may be empty)
    extra_doc: str = ""
    definitions: list = field(default_factory=list)  # [(symbol, expr)] emitted first, in order
    #: the symbols the ``state`` argument holds, in order: None for the model's state
    #: (STATE_NAMES), a plane kernel's contact state otherwise (CONTACT_STATE_NAMES)
    state: list | None = None


def forward_jacobian(outputs, variables, prefix="j"):
    """Jacobian of ``outputs`` by the chain rule over their CSE (symbolic forward mode).

    Differentiating the expanded trees repeats every shared subexpression in every
    derivative; instead each CSE temporary gets its gradient as new temporaries.
    Returns (definitions [(symbol, expr)] in dependency order, flat row-major Jacobian).
    """
    temps, reduced = sm.cse(list(outputs), symbols=sm.numbered_symbols(f"{prefix}c"),
                            order="canonical")
    names = sm.numbered_symbols(f"{prefix}d")
    definitions, gradients = [], {}

    def gradient(expr):
        result = {}
        inner = [s for s in expr.free_symbols if s in gradients]
        for k, var in enumerate(variables):
            d = expr.diff(var) if expr.has(var) else sm.S.Zero
            for s in inner:
                if k in gradients[s]:
                    d += expr.diff(s) * gradients[s][k]
            if d != 0:
                result[k] = d
        return result

    for symbol, expr in temps:
        definitions.append((symbol, expr))
        gradients[symbol] = {}
        for k, d in gradient(expr).items():
            if not d.is_Atom:
                name = next(names)
                definitions.append((name, d))
                d = name
            gradients[symbol][k] = d
    jac = []
    for expr in reduced:
        g = gradient(expr)
        jac += [g.get(k, sm.S.Zero) for k in range(len(variables))]
    return definitions, jac


class BallcPrinter(C99CodePrinter):
    """C99 printer with compact Heaviside, exact small integer powers and half-integer
    powers as products with one square root."""

    def __init__(self, settings=None):
        # no M_SQRT2-style macros: they are not C99 (a constant such as sqrt(2) is
        # printed as its value instead)
        super().__init__({"math_macros": {}, **(settings or {})})

    def _print_Heaviside(self, expr):
        arg = self._print(expr.args[0])
        h0 = expr.args[1] if len(expr.args) > 1 else sm.S.Half
        return f"(({arg}) > 0 ? 1.0 : (({arg}) < 0 ? 0.0 : {self._print(sm.Float(h0))}))"

    def _print_Pow(self, expr):
        base, exp = expr.as_base_exp()
        if exp.is_Integer and 2 <= abs(exp) <= 4:
            b = self._print(base)
            product = "(" + "*".join([f"({b})"] * abs(int(exp))) + ")"
            return product if exp > 0 else f"(1.0/{product})"
        if exp.is_Rational and exp.q == 2 and 3 <= abs(exp.p) <= 5:
            # x^(3/2) = x sqrt(x), x^(5/2) = x^2 sqrt(x): a multiply and a square root
            # instead of pow (the Hertz force and its derivatives)
            b = self._print(base)
            factors = "*".join([f"({b})"] * (abs(exp.p) // 2) + [f"sqrt({b})"])
            return f"({factors})" if exp > 0 else f"(1.0/({factors}))"
        return super()._print_Pow(expr)


class ParameterConstants:
    """The parameter-only subexpressions of all kernels, numbered in order of first use.

    ``hoist`` rewrites an expression with every maximal parameter-only part replaced by
    a constant symbol ``pc<i>``; the same value (after expanding nested constants) gets
    the same symbol in every kernel.
    """

    def __init__(self, param_syms):
        self.params = frozenset(param_syms)
        self.symbols, self.values = [], []   # pc<i> and its expression of parameters
        self._by_value, self._value = {}, {}

    def __len__(self):
        return len(self.symbols)

    def parameter_only(self, expr) -> bool:
        symbols = expr.free_symbols
        return bool(symbols) and all(s in self.params or s in self._value for s in symbols)

    def constant(self, expr):
        """The constant symbol of a parameter-only ``expr`` (a new one if needed)."""
        if expr.is_Symbol:
            return expr
        value = expr.xreplace(self._value)
        symbol = self._by_value.get(value)
        if symbol is None:
            symbol = sm.Symbol(f"pc{len(self.symbols)}")
            self.symbols.append(symbol)
            self.values.append(value)
            self._by_value[value] = symbol
            self._value[symbol] = value
        return symbol

    def hoist(self, expr):
        if expr.is_Atom:
            return expr
        if self.parameter_only(expr):
            return self.constant(expr)
        if isinstance(expr, (sm.Add, sm.Mul)):
            fixed = [a for a in expr.args if self.parameter_only(a) or a.is_Number]
            nontrivial = [a for a in fixed if not a.is_Number]
            if len(nontrivial) >= 2 or any(not a.is_Atom for a in nontrivial):
                rest = [self.hoist(a) for a in expr.args if a not in fixed]
                return expr.func(self.constant(expr.func(*fixed)), *rest)
        return expr.func(*[self.hoist(a) for a in expr.args])

    def hoist_all(self, definitions, outputs):
        """(definitions, outputs) with parameter-only parts replaced by constants; a
        definition that is parameter-only as a whole is dropped and its symbol replaced."""
        alias, kept = {}, []
        for symbol, expr in definitions:
            expr = expr.xreplace(alias)
            if self.parameter_only(expr):
                alias[symbol] = self.constant(expr)
            else:
                kept.append((symbol, self.hoist(expr)))
        return kept, [self.hoist(e.xreplace(alias)) for e in outputs]


def plain_symbols(states):
    """Plain symbols named like the state dynamicsymbols (qw(t) -> qw)."""
    return [sm.Symbol(s.func.__name__) for s in states]


def _plain(expr, replacements):
    """Replace dynamicsymbols by plain symbols and reject anything left over."""
    return sm.sympify(expr).xreplace(replacements)


def kernel_c(kernel: Kernel, state_syms, param_syms, printer=None,
             constants: ParameterConstants | None = None) -> tuple[str, int]:
    """C source of one kernel and its operation count after CSE; with ``constants``, the
    parameter-only subexpressions are read from the ``constants`` argument (and added to
    ``constants``)."""
    printer = printer or BallcPrinter()
    plain_states = plain_symbols(state_syms) if kernel.state is None else list(kernel.state)
    replacements = dict(zip(state_syms, plain_symbols(state_syms)))
    outputs = [_plain(e, replacements) for e in kernel.outputs]
    definitions = [(s, _plain(e, replacements)) for s, e in kernel.definitions]

    inputs = {}
    for array, syms in (("state", plain_states), ("params", param_syms), ("extra", kernel.extra)):
        for i, s in enumerate(syms):
            inputs[s] = (array, i)
    defined = {s for s, _ in definitions}
    everything = outputs + [e for _, e in definitions]
    missing = set().union(*(e.free_symbols for e in everything)) - set(inputs) - defined
    leftovers = [e for e in everything if e.has(sm.Derivative) or e.atoms(AppliedUndef)]
    if missing or leftovers:
        raise ValueError(f"kernel {kernel.name}: unknown symbols {sorted(map(str, missing))}"
                         f" or unresolved derivatives")

    temps = sm.numbered_symbols("t", start=0)
    subexpressions, reduced = sm.cse(outputs, symbols=temps, order="canonical")
    if constants is not None:
        definitions, reduced = constants.hoist_all(definitions + subexpressions, reduced)
        subexpressions = []
        for i, s in enumerate(constants.symbols):
            inputs[s] = ("constants", i)
    used = set().union(*(e.free_symbols for _, e in definitions + subexpressions),
                       *(e.free_symbols for e in reduced)) & set(inputs)
    ops = sum(sm.count_ops(e) for _, e in definitions + subexpressions)
    ops += sum(sm.count_ops(e) for e in reduced)

    lines = [f"/* {kernel.doc}"]
    if kernel.extra:
        lines.append(f"   extra: {kernel.extra_doc or ', '.join(map(str, kernel.extra))}")
    lines.append(f"   {len(outputs)} outputs, {ops} operations after CSE. */")
    lines.append(SIGNATURE.format(name=kernel.name))
    lines.append("{")
    lines.append("    (void)state; (void)params; (void)constants; (void)extra;")
    arrays = ("state", "params", "constants", "extra")
    for sym in sorted(used, key=lambda s: (arrays.index(inputs[s][0]), inputs[s][1])):
        array, i = inputs[sym]
        lines.append(f"    const double {sym} = {array}[{i}];")
    for sym, expr in definitions + subexpressions:
        lines.append(f"    const double {sym} = {printer.doprint(expr)};")
    for i, expr in enumerate(reduced):
        lines.append(f"    out[{i}] = {printer.doprint(expr)};")
    lines.append("}")
    return "\n".join(lines) + "\n", ops


def constants_c(constants: ParameterConstants, param_syms, printer=None) -> tuple[str, int]:
    """C source of ballc_parameter_constants (one joint CSE over all constants)."""
    printer = printer or BallcPrinter()
    index = {s: i for i, s in enumerate(param_syms)}
    missing = set().union(set(), *(v.free_symbols for v in constants.values)) - set(index)
    if missing:
        raise ValueError(f"parameter constants: unknown symbols {sorted(map(str, missing))}")
    subexpressions, reduced = sm.cse(constants.values, symbols=sm.numbered_symbols("t"),
                                     order="canonical")
    used = set().union(set(), *(e.free_symbols for _, e in subexpressions),
                       *(e.free_symbols for e in reduced)) & set(index)
    ops = sum(sm.count_ops(e) for _, e in subexpressions) + sum(map(sm.count_ops, reduced))
    lines = ["/* The parameter constants (BALLC_PARAMETER_CONSTANT_NAMES): the parameter-only",
             "   subexpressions of the kernels, computed once per parameter vector.",
             f"   {len(reduced)} outputs, {ops} operations after CSE. */",
             CONSTANTS_SIGNATURE, "{", "    (void)params;"]
    for sym in sorted(used, key=index.get):
        lines.append(f"    const double {sym} = params[{index[sym]}];")
    for sym, expr in subexpressions:
        lines.append(f"    const double {sym} = {printer.doprint(expr)};")
    for i, expr in enumerate(reduced):
        lines.append(f"    constants[{i}] = {printer.doprint(expr)};")
    lines.append("}")
    return "\n".join(lines) + "\n", ops


def inputs_hash(extra_files=()) -> str:
    """sha256 over the codegen sources and the sympy version (the generator's inputs)."""
    digest = hashlib.sha256()
    digest.update(f"sympy {sm.__version__}\n".encode())
    for path in sorted(CODEGEN_DIR.glob("*.py")) + [Path(f) for f in extra_files]:
        if path.name == "seed_reference.py":
            continue  # test oracle, not an input of the generated code
        digest.update(path.name.encode())
        digest.update(path.read_bytes())
    return digest.hexdigest()


def header_comment() -> str:
    return (
        "/* Generated by ballc codegen (python -m codegen), generator version "
        f"{GENERATOR_VERSION}, sympy {sm.__version__}.\n"
        f"   Inputs sha256: {inputs_hash()}\n"
        "   Do not edit: change codegen/ and regenerate. */\n"
    )


def c_string_array(name: str, values) -> str:
    items = ", ".join(f'"{v}"' for v in values)
    return f"static const char *const {name}[] = {{{items}}};\n"
