"""Coefficients of restitution of ballc's two compliant normal damping laws, and their inverses.

Standalone: imports only math, functools, numpy and scipy (no other ballc module), so it can
be run as a script (``python src/ballc/restitution.py`` runs a self-check).

Notation as in docs/contact_laws.md: rho the penetration (m), rhodot its rate (> 0 while
moving into the plane), rhodot^- the rate at contact start (m/s), k0 the Hertz constant
(N/m^{3/2}), m the (equivalent) mass (kg).  The restitution e = (exit normal speed) /
(entry normal speed) (dimensionless) of one free impact (no gravity, no other force).

* Hunt-Crossley: F = max(0, k0 rho^{3/2} (1 + chi rhodot / rhodot^-)), chi >= 0 (1).
  e(chi) solves chi (1 + e) = ln((1 + chi) / (1 - chi e)) (closed form of the impact;
  the clamp is never active for this law), e in (0, 1] for chi in [0, inf).
  :func:`hunt_crossley_restitution_of_chi`, :func:`hunt_crossley_chi_for_restitution`.
* Viscoelastic ("Hertz viscous", Tsuji): F = max(0, k0 rho^{3/2} + c_n rhodot),
  c_n = 2 gamma sqrt(m k_n), k_n = 3/2 k0 sqrt(rho), gamma >= 0 (1).  e depends on gamma
  only; e(0) = 1, e decreases monotonically and tends to 0 only as gamma -> inf
  (e ~ 5 / (24 gamma^2)), so every e in (0, 1] has a finite gamma.
  :func:`viscoelastic_restitution`, :func:`viscoelastic_gamma_for_restitution`.

Ranges: :func:`restitution_limits`.
"""

from __future__ import annotations

import functools
import math

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

__all__ = ["hunt_crossley_restitution_of_chi", "hunt_crossley_chi_for_restitution",
           "viscoelastic_restitution", "viscoelastic_gamma_for_restitution",
           "restitution_limits", "RESTITUTION_RANGE", "CHI_RANGE", "GAMMA_RANGE",
           "VISCOELASTIC_LARGE_GAMMA_COEFFICIENT"]

#: Restitution e accepted by both inverses: 0 < e <= 1 (open at 0: chi, gamma -> inf).
RESTITUTION_RANGE = (0.0, 1.0)
#: Hunt-Crossley chi accepted by the forward map: 0 <= chi < inf.
CHI_RANGE = (0.0, math.inf)
#: Viscoelastic gamma accepted by the forward map: 0 <= gamma < inf.
GAMMA_RANGE = (0.0, math.inf)
#: Viscoelastic law for large gamma: e ~ VISCOELASTIC_LARGE_GAMMA_COEFFICIENT / gamma^2.
VISCOELASTIC_LARGE_GAMMA_COEFFICIENT = 5.0 / 24.0

_EPS = np.finfo(float).eps

# ---------------------------------------------------------------------------------------
# Hunt-Crossley
# ---------------------------------------------------------------------------------------

#: e(chi) = 1 + sum_k _E_SERIES[k-1] chi^k (exact rationals of the root's Taylor series,
#: radius of convergence ~1.07; truncation error at chi = 0.1 ~ 1e-19).
_E_SERIES = (-2 / 3, 4 / 9, -44 / 135, 104 / 405, -40 / 189, 7648 / 42525, -2848 / 18225,
             31712 / 229635, -23429344 / 189448875, 89072576 / 795685275,
             -1441952704 / 14105329875, 893393408 / 9499507875,
             -9352282112 / 107417512125, 11547336704 / 142492618125,
             -314833934543872 / 4154372281434375, 886909037097472 / 12463116844303125)
#: chi(d) = sum_k _CHI_SERIES[k-1] d^k, d = 1 - e: the reversion of _E_SERIES (exact
#: rationals, radius ~1; truncation error at d = 0.1 ~ 1e-17 relative).
_CHI_SERIES = (3 / 2, 3 / 2, 27 / 20, 6 / 5, 759 / 700, 351 / 350, 6639 / 7000, 1599 / 1750,
               192537 / 215600, 190221 / 215600, 10993971 / 12512500,
               308346453 / 350350000, 6203405379 / 7007000000, 894162999 / 1001000000,
               41382469053 / 45815000000, 136200425703 / 148898750000)
_SERIES_LIMIT = 0.1


def _poly(coefficients, x):
    """sum_k coefficients[k-1] x^k (Horner)."""
    acc = 0.0
    for c in reversed(coefficients):
        acc = acc * x + c
    return acc * x


def _number(name, value, allowed):
    """float(value), or ValueError naming the value and the allowed range."""
    message = f"{name} = {value!r} is not allowed: must be a number in {allowed}"
    if isinstance(value, (bool, np.bool_)):
        raise ValueError(message)
    try:
        return float(value)
    except (TypeError, ValueError):
        raise ValueError(message) from None


def _restitution_input(e, parameter):
    """e as a float in (0, 1], or ValueError naming it (e -> 0 needs ``parameter`` -> inf)."""
    v = _number("restitution", e, "(0, 1]")
    if not 0.0 < v <= 1.0:
        raise ValueError(f"restitution = {e!r} is not allowed: must be a number in (0, 1] "
                         f"(e -> 0 would need {parameter} -> infinity)")
    return v


def hunt_crossley_restitution_of_chi(chi: float) -> float:
    """Restitution e (1) of one Hunt-Crossley impact with damping factor ``chi`` (1).

    Force F = max(0, k0 rho^{3/2} (1 + chi rhodot / rhodot^-)) (N): rho (m) the
    penetration, rhodot (m/s) its rate, rhodot^- > 0 the rate at contact start.  With
    v = rhodot / rhodot^-, m v dv/drho = -k0 rho^{3/2} (1 + chi v) / rhodot^- integrates to
    the exit/entry speed ratio e, the root in (0, min(1, 1/chi)) of

        chi (1 + e) = ln((1 + chi) / (1 - chi e)),

    independent of m, k0 and rhodot^- (the bracket 1 + chi v stays > 0 because
    e < 1/chi, so the clamp is never active).  e(0) = 1, e falls monotonically, e -> 0
    as chi -> inf (e ~ 1/chi: chi e = 1 - y with y = (1 + chi) e^{-(1+chi)} e^{y}).

    Computed with the root's Taylor series (16 exact terms) for chi < 0.1; otherwise with
    u = ln(1 - chi e), which turns the equation into

        u - expm1(u) + (chi - log1p(chi)) = 0,   u in (c, min(c + 1, 0)),
        c = log1p(chi) - chi - 1,

    solved by brentq, then e = -expm1(u) / chi.  Relative error <~ 3e-15 for every chi
    in [0, 1e6] and beyond (chi = 1e6 gives e = 1e-6).

    Parameters
    ----------
    chi : float
        Hunt-Crossley damping factor, >= 0 (dimensionless).

    Returns
    -------
    float
        e in (0, 1] (dimensionless).
    """
    x = _number("chi", chi, "[0, inf)")
    if not (x >= 0 and math.isfinite(x)):
        raise ValueError(f"chi = {chi!r} is not allowed: must be a finite number >= 0")
    if x < _SERIES_LIMIT:
        return 1.0 + _poly(_E_SERIES, x)
    s = x - math.log1p(x)                  # > 0
    c = math.log1p(x) - x - 1.0            # < -1

    def residual(u):
        return u - math.expm1(u) + s       # increasing in u < 0

    hi = min(c + 1.0, 0.0)
    u = brentq(residual, c, hi, xtol=1e-300, rtol=4 * _EPS, maxiter=200)
    return -math.expm1(u) / x


def hunt_crossley_chi_for_restitution(e: float) -> float:
    """The Hunt-Crossley damping factor chi (1) whose impact has restitution ``e`` (1).

    Exact inverse of :func:`hunt_crossley_restitution_of_chi`: solves
    chi (1 + e) = ln((1 + chi) / (1 - chi e)) for chi > 0.  e = 1 gives 0; e -> 0 needs
    chi -> inf (chi ~ 1/e), so e must be in (0, 1].

    For d = 1 - e < 0.1 the reverted Taylor series chi = 3/2 d + 3/2 d^2 + 27/20 d^3 + ...
    (16 exact terms) is used (no cancellation: d is exact in floating point); otherwise
    brentq on u = ln(1 - chi e) with chi = -expm1(u) / e:

        u - expm1(u) + (chi - log1p(chi)) = 0,

    on u in (log1p(1/e) - 1/e - 2, log(1 - e chi_lo)), which is accurate also when
    chi e rounds to 1 (tiny e).  The forward map applied to the result reproduces e to a
    relative ~1e-15.

    Parameters
    ----------
    e : float
        Coefficient of restitution, in (0, 1] (dimensionless).

    Returns
    -------
    float
        chi >= 0 (dimensionless).
    """
    v = _restitution_input(e, "chi")
    d = 1.0 - v
    if d < _SERIES_LIMIT:
        return _poly(_CHI_SERIES, d)

    def chi_of(u):
        return -math.expm1(u) / v

    def residual(u):
        x = chi_of(u)
        return u - math.expm1(u) + (x - math.log1p(x))

    lo = math.log1p(1.0 / v) - 1.0 / v - 2.0     # residual(lo) <= -1
    # chi >= 3/2 d (e(chi) >= 1 - 2 chi / 3); a third of it is safely below the root,
    # where residual > 0 (residual ~ u^2 (1/e^2 - 1) / 2 near u = 0).
    hi = math.log1p(-v * 0.5 * d)
    u = brentq(residual, lo, hi, xtol=1e-300, rtol=4 * _EPS, maxiter=200)
    return chi_of(u)


# ---------------------------------------------------------------------------------------
# Viscoelastic (Hertz + viscous, clamped at 0)
# ---------------------------------------------------------------------------------------

_SQRT6 = math.sqrt(6.0)
_RTOL = 1e-13
_P_SWITCH = 0.5


def _viscoelastic_impact(gamma: float):
    """(e, q) of the dimensionless viscoelastic impact, q = 1 - e^2 computed without
    cancellation (for gamma -> 0).  See :func:`viscoelastic_restitution`."""
    b = _SQRT6 * gamma
    # expected scales (for absolute tolerances): velocity at the clamp ~ e, depth r_max
    e_scale = min(1.0, 0.25 / (gamma * gamma))
    r_scale = min(1.0, (1.25 / b) ** 0.8)

    # Phase 1: compression, independent variable s = r^{1/4}, state (p = r', W/gamma)
    # with W = int sqrt6 gamma r^{1/4} r'^2 dt the dissipated energy.
    def rhs_s(s, y):
        p = y[0]
        s4 = s ** 4
        return [-4.0 * s4 * s4 * s / p - 4.0 * b * s4, 4.0 * _SQRT6 * s4 * p]

    def p_low(s, y):
        return y[0] - _P_SWITCH
    p_low.terminal = True
    p_low.direction = -1
    s_end = 2.0 * max(1.0, (1.25 / b) ** 0.2) if b > 0 else 2.0
    sol = solve_ivp(rhs_s, (0.0, s_end), [1.0, 0.0], method="DOP853", rtol=_RTOL,
                    atol=[1e-3 * _RTOL, 1e-3 * _RTOL], events=p_low)
    if sol.status != 1:
        raise RuntimeError(f"viscoelastic impact, gamma = {gamma!r}: compression did not "
                           "reach p = 1/2")
    s1 = sol.t_events[0][0]
    p1, w1 = sol.y_events[0][0]

    # Phase 2: time domain through the turning point, state (r, v, W/gamma); stops at the
    # clamp (r^{5/4} + sqrt6 gamma v = 0: the force would turn negative) or at
    # v = -1/2 (back to the s-domain).
    def rhs_t(t, y):
        r, v, _ = y
        r4 = r ** 0.25
        return [v, -(r * math.sqrt(r) + b * r4 * v), _SQRT6 * r4 * v * v]

    def clamp(t, y):
        return y[0] ** 1.25 + b * y[1]
    clamp.terminal = True
    clamp.direction = -1

    def v_low(t, y):
        return y[1] + _P_SWITCH
    v_low.terminal = True
    v_low.direction = -1
    t_end = 50.0 * max(1.0, 1.0 / (b * s1 + 1e-300)) + 50.0
    sol = solve_ivp(rhs_t, (0.0, t_end), [s1 ** 4, p1, w1], method="DOP853", rtol=_RTOL,
                    atol=[1e-3 * _RTOL * r_scale, 1e-3 * _RTOL * e_scale, 1e-3 * _RTOL],
                    events=[clamp, v_low])
    if sol.status != 1:
        raise RuntimeError(f"viscoelastic impact, gamma = {gamma!r}: no turning point")
    if sol.t_events[0].size:                     # clamped before v = -1/2: e < 1/2
        r_c, v_c, _ = sol.y_events[0][0]
        e = -v_c
        return e, (1.0 - e) * (1.0 + e)
    r2, v2, w2 = sol.y_events[1][0]

    # Phase 3: restitution in the s-domain again (s decreasing), until the clamp
    # s^5 + sqrt6 gamma p = 0 (for gamma = 0: s = 0).
    def clamp_s(s, y):
        return s ** 5 + b * y[0]
    clamp_s.terminal = True
    clamp_s.direction = -1
    sol = solve_ivp(rhs_s, (r2 ** 0.25, 0.0), [v2, w2], method="DOP853", rtol=_RTOL,
                    atol=[1e-3 * _RTOL, 1e-3 * _RTOL], events=clamp_s)
    if sol.t_events[0].size:
        s_c = sol.t_events[0][0]
        v_c, w_c = sol.y_events[0][0]
    else:                                        # gamma = 0 (or clamp at s ~ 0)
        s_c, (v_c, w_c) = 0.0, sol.y[:, -1]
    # energy: v_c^2 / 2 + 2/5 r_c^{5/2} = 1/2 - gamma W_hat
    q = 2.0 * gamma * w_c + 0.8 * s_c ** 10
    # for e > 1/2, sqrt(1 - q) is the more accurate (q is accurate relative to itself)
    return (math.sqrt(1.0 - q) if q < 0.75 else -v_c), q


def viscoelastic_restitution(gamma: float) -> float:
    """Restitution e (1) of one Hertz viscoelastic impact with damping ratio ``gamma`` (1).

    Dimensional impact (no gravity), rho (m) the penetration, t (s):

        m rho'' = -max(0, k0 rho^{3/2} + 2 gamma sqrt(m k_n) rho'),  k_n = 3/2 k0 sqrt(rho),
        rho(0) = 0, rho'(0) = v0 > 0,

    m (kg), k0 (N/m^{3/2}), gamma >= 0 (1).  With the scales T = (m / (k0 sqrt(v0)))^{2/5}
    (s) and L = v0 T (m) -- chosen so that m L / T^2 = k0 L^{3/2} -- and r = rho / L,
    tau = t / T, the damping term becomes 2 gamma sqrt(3/2 m k0 L^{1/2}) L r' / T divided
    by m L / T^2 = 2 gamma sqrt(3/2) sqrt(k0 L^{1/2} T^2 / m) r^{1/4} r' = sqrt(6) gamma
    r^{1/4} r', so

        r'' = -max(0, r^{3/2} + sqrt(6) gamma r^{1/4} r'),  r(0) = 0, r'(0) = 1,

    and e = -r'(exit) depends on gamma only (not on m, k0, v0).  The force is > 0 while
    r' > 0; after the turning point it reaches 0 at the clamp point r^{5/4} =
    -sqrt(6) gamma r' (for gamma > 0, always at r > 0), from where the ball flies free
    (the force stays 0: r' is constant, r^{5/4} shrinks), so e = -r' at the clamp point.

    e(0) = 1; e decreases monotonically with gamma; e ~ 1 - 3.4414 gamma for small gamma
    and e ~ 5 / (24 gamma^2) for large gamma (the overdamped ball creeps to
    r_max^{5/4} = 5 / (4 sqrt6 gamma) and is released at once with r' = -r_max^{5/4} /
    (sqrt6 gamma)), so e -> 0 only as gamma -> inf.

    Numerics: the start r^{1/4} singularity is avoided by integrating with s = r^{1/4}
    as the independent variable (p = r': dp/ds = -4 s^9 / p - 4 sqrt6 gamma s^4, smooth)
    while |p| >= 1/2, and in time only around the turning point (p = 0); scipy's DOP853
    with rtol = 1e-13 and the clamp as an event.  The dissipated energy W is integrated
    along so that 1 - e^2 = 2 W + 4/5 r_c^{5/2} has no cancellation for small gamma
    (e = sqrt(1 - (1 - e^2)) for e > 1/2, e = -r'(clamp) below).  Relative error of e
    and of 1 - e^2 ~1e-12 (against rtol = 1e-14 runs and a plain time integration of the
    dimensional ODE); ~5-15 ms per call.

    Parameters
    ----------
    gamma : float
        Damping ratio, >= 0 (dimensionless).

    Returns
    -------
    float
        e in (0, 1] (dimensionless).
    """
    g = _number("gamma", gamma, "[0, inf)")
    if not (g >= 0 and math.isfinite(g)):
        raise ValueError(f"gamma = {gamma!r} is not allowed: must be a finite number >= 0")
    if g == 0:
        return 1.0
    return float(_viscoelastic_impact(g)[0])


@functools.lru_cache(maxsize=256)
def _viscoelastic_gamma(e: float) -> float:
    if e == 1.0:
        return 0.0
    q_target = (1.0 - e) * (1.0 + e)
    if e >= 0.5:      # match ln(1 - e^2) (keeps the relative accuracy as e -> 1)
        def residual(x):
            return math.log(_viscoelastic_impact(math.exp(x))[1]) - math.log(q_target)
        guess = q_target / 2.1            # 1 - e^2 ~ 2.1 gamma for small gamma
    else:             # match ln e (keeps the relative accuracy as e -> 0)
        def residual(x):
            return math.log(e) - math.log(_viscoelastic_impact(math.exp(x))[0])
        guess = math.sqrt(VISCOELASTIC_LARGE_GAMMA_COEFFICIENT / e)
    lo = hi = math.log(guess)
    f_lo = residual(lo)                 # residual increases with ln gamma
    step = 0.5
    if f_lo > 0:
        while f_lo > 0:
            hi, lo = lo, lo - step
            step *= 2
            f_lo = residual(lo)
    else:
        f_hi = f_lo
        while f_hi <= 0:
            lo, hi = hi, hi + step
            step *= 2
            f_hi = residual(hi)
    return math.exp(brentq(residual, lo, hi, xtol=1e-13, rtol=4 * _EPS))


def viscoelastic_gamma_for_restitution(e: float) -> float:
    """The viscoelastic damping ratio gamma (1) whose Hertz impact has restitution ``e`` (1).

    Inverse of :func:`viscoelastic_restitution` (brentq on ln gamma, matching ln(1 - e^2)
    for e >= 1/2 and ln e below, so that gamma is accurate as e -> 1 and e -> 0); results
    are cached (functools.lru_cache).  e = 1 gives 0.  With the clamp at zero force e > 0
    for every finite gamma and e -> 0 only as gamma -> inf (gamma ~ sqrt(5 / (24 e))), so
    every e in (0, 1] is reachable and e must be in (0, 1].  Small e: gamma ~ 0.2906 (1 - e)
    (for comparison, the linear spring-dashpot's gamma = -ln e / sqrt(pi^2 + ln^2 e) ~
    0.3183 (1 - e)).  gamma is found to ~1e-13 in ln gamma, so the accuracy is that of
    :func:`viscoelastic_restitution` (~1e-12 in e and in 1 - e^2); ~50-70 ms per new e,
    ~10 us cached.

    Parameters
    ----------
    e : float
        Coefficient of restitution, in (0, 1] (dimensionless).

    Returns
    -------
    float
        gamma >= 0 (dimensionless).
    """
    v = _restitution_input(e, "gamma")
    return _viscoelastic_gamma(v)


def restitution_limits() -> dict:
    """The ranges of both laws: {law: {"parameter": (lo, hi), "restitution": (lo, hi)}}.

    Both laws map their parameter in [0, inf) onto e in (0, 1] (monotonically decreasing,
    e = 1 at 0); e = 0 is not reachable (open end).  The inverses accept e in (0, 1].
    """
    return {"hunt_crossley": {"parameter": ("chi", CHI_RANGE), "restitution": RESTITUTION_RANGE,
                              "large_parameter": "e ~ 1 / chi"},
            "viscoelastic": {"parameter": ("gamma", GAMMA_RANGE),
                             "restitution": RESTITUTION_RANGE,
                             "large_parameter": "e ~ 5 / (24 gamma^2)"}}


if __name__ == "__main__":   # self-check
    import time
    for chi, ref in [(9.998, 0.1), (3.087, 0.3)]:
        print(f"HC chi={chi}: e={hunt_crossley_restitution_of_chi(chi):.6f} (~{ref})")
    worst = 0.0
    for e in [0.05] + [k / 10 for k in range(1, 11)] + [1 - 1e-9, 1e-6]:
        x = hunt_crossley_chi_for_restitution(e)
        worst = max(worst, abs(hunt_crossley_restitution_of_chi(x) - e) / e)
    print(f"HC round trip worst relative error {worst:.2e}")
    worst = 0.0
    for e in [0.05] + [k / 10 for k in range(1, 11)]:
        t0 = time.perf_counter()
        g = viscoelastic_gamma_for_restitution(e)
        dt = time.perf_counter() - t0
        err = abs(viscoelastic_restitution(g) - e) / e
        worst = max(worst, err)
        print(f"VE e={e:.2f} gamma={g:.12f} ({dt * 1e3:.0f} ms)")
    print(f"VE round trip worst relative error {worst:.2e}")
