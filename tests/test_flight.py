"""Exact free flight (ballc.flight), each against an independent oracle: the compiled
right-hand side, radau5 at rtol = atol = 1e-12, exact rational arithmetic, the energy,
and whole runs with the exact path off."""
from fractions import Fraction

import numpy as np
import pytest

import ballc
from ballc import _core, events as ev, flight, layout, outcome
from ballc.scene import SceneError

TIGHT = dict(rtol=1e-12, atol=1e-12)
LATCH = np.zeros(_core.N_LATCH)


def flying_scene(**changes):
    values = dict(observer_mass=0.0, angular_velocity=(3.0, -2.0, 5.0),
                  velocity=(-1.5, 0.7, 4.0), angles=(0.3, -0.2, 1.1))
    values.update(changes)
    return ballc.Scene(**values)


def flown(scene, t_end=5.0, exact=True, **kw):
    """The run up to its first contact start (a terminal user event there: the contact
    start's own event is the C loop's), at 1e-12, exact flight on or off."""
    return ballc.simulate(scene, t_end, exact_flight=exact, progress=False, **TIGHT, **kw)


def first_contact(run):
    """(t, state) where the run's first contact started."""
    k = int(np.flatnonzero(run.t == run.contacts[0].t_start)[0])
    return run.t[k], run.y[:, k]


def test_exact_solution_satisfies_the_compiled_rhs():
    """d/dt of the closed form (central differences) is the C right-hand side."""
    scene = flying_scene()
    y0 = scene.initial_state()
    sol = flight.FreeFlight(0.0, y0, scene.gravity)
    params = scene.parameter_vector()
    h = 1e-5
    for t in (0.0, 0.37, 1.9):
        derivative = (sol(t + h) - sol(t - h)) / (2 * h)
        expected = _core.rhs(np.ascontiguousarray(sol(t)), params, LATCH, 0)
        np.testing.assert_allclose(derivative, expected, rtol=0, atol=1e-7)
    np.testing.assert_array_equal(sol(0.0), y0)
    assert np.linalg.norm(sol(123.4)[layout.QUATERNION]) == pytest.approx(1.0, abs=1e-15)


@pytest.mark.parametrize("changes", [
    {},                                                         # floor, spinning
    dict(velocity=(2.0, -1.0, 11.0)),                           # up to the ceiling
    dict(velocity=(0.0, 0.0, -25.0), angular_velocity=(0, 0, 0)),   # straight down
    dict(angular_velocity=(40.0, 10.0, -20.0), gravity=0.0,
         velocity=(0.1, 0.0, -3.0)),                            # no gravity: linear z
])
def test_exact_flight_equals_radau5(changes):
    """The C loop's closed-form flight (no right-hand-side call) and its contact start,
    the root of the start's own event, against radau5 at 1e-12 on the same flight."""
    scene = flying_scene(**changes)
    t_end = 5.0
    exact, integrated = flown(scene, t_end), flown(scene, t_end, exact=False)
    first = exact.segments[0]
    assert (first["method"], first["nfev"], first["end"]) == ("flight", 0, "enter")
    assert integrated.segments[0]["nfev"] > 0
    (t_a, y_a), (t_b, y_b) = first_contact(exact), first_contact(integrated)
    assert abs(t_a - t_b) <= 1e-9
    np.testing.assert_allclose(y_a[:13], y_b[:13], rtol=0, atol=1e-9)
    # the contact start is the root of rho - threshold, threshold 4 ulp of the plane's
    # height: rho there is that threshold, to rounding
    plane = exact.contacts[0].plane
    rho = ev.penetration(plane, scene)(0.0, y_a)
    assert abs(rho - ev.threshold_base(scene, plane)) < 1e-14
    # samples at given times within the flight
    t_eval = np.linspace(0, t_a, 17)[1:-1]
    on = ballc.simulate(scene, t_a, t_eval=t_eval, progress=False, **TIGHT)
    off = ballc.simulate(scene, t_a, t_eval=t_eval, exact_flight=False, progress=False,
                         **TIGHT)
    np.testing.assert_array_equal(on.t, t_eval)
    assert on.nfev == 0
    np.testing.assert_allclose(on.y, off.y, rtol=0, atol=1e-9)


def test_no_event_reaches_t_end():
    scene = flying_scene(velocity=(1.0, 2.0, 0.5), position=(0, 0, 4.0))
    exact, integrated = flown(scene, 0.2), flown(scene, 0.2, exact=False)
    assert exact.status == integrated.status == 0 and exact.nfev == 0
    assert exact.t[0] == 0.0 and exact.t[-1] == 0.2 and exact.t.size >= 33
    assert not exact.contacts
    np.testing.assert_allclose(exact.y[:, -1], integrated.y[:, -1], rtol=0, atol=1e-10)


def test_default_samples_resolve_the_rotation():
    scene = flying_scene(angular_velocity=(0.0, 0.0, 200.0))
    run = flown(scene, 0.5)
    flight_end = run.contacts[0].t_start if run.contacts else run.t[-1]
    t = run.t[run.t <= flight_end]
    turn = 200.0 * np.diff(t)
    assert turn.max() <= flight.MAX_TURN * (1 + 1e-12)
    assert np.all(np.diff(t) > 0)


def test_energy_constant_in_flight():
    scene = flying_scene()
    y0 = scene.initial_state()
    y0[13:] = [0.25, 0.5, 1e-6, -2e-6, 3e-6, 4e-6]    # dissipated work, deflections
    run = ballc.simulate(scene, 0.3, y0=y0, progress=False)
    assert not run.contacts and run.nfev == 0
    energy = _core.energies(np.ascontiguousarray(run.y.T), scene.parameter_vector())
    total = energy[:, 0] + energy[:, 1]
    assert np.ptp(total) <= 1e-13 * total[0]
    np.testing.assert_array_equal(run.y[13:], np.repeat(y0[13:, None], run.t.size, axis=1))
    omega = run.y[layout.ANGULAR_VELOCITY]
    np.testing.assert_array_equal(omega, np.repeat(y0[7:10, None], run.t.size, axis=1))


def _exact_polynomial(c0, c1, c2, s):
    s = Fraction(s)
    return Fraction(c0) + Fraction(c1) * s + Fraction(c2) * s * s


@pytest.mark.parametrize("c0, c1, c2", [
    (-1e-13, -30.0, 4.905),          # leaving the floor fast, back much later
    (-1e-13, 30.0, -4.905),          # the small root next to a large one
    (-2.0, 1e8, 4.905),              # naive formula: catastrophic cancellation
    (-3.0, 0.0, 4.905),
    (-3.0, 2.5, 0.0),                # no gravity
])
def test_roots_are_correct_to_rounding(c0, c1, c2):
    """Oracle: the sign of the quadratic in exact rational arithmetic two ulps either side."""
    roots = _core.flight_crossings(c0, c1, c2, 0, np.inf)
    assert roots
    for s in roots:
        below, above = s - 2 * np.spacing(s), s + 2 * np.spacing(s)
        assert _exact_polynomial(c0, c1, c2, below) * _exact_polynomial(c0, c1, c2, above) < 0


def test_crossing_directions_and_tangency():
    crossings = _core.flight_crossings   # the C loop's, which locates flight's events
    # opening upwards, roots 1 and 3: falls through 1, rises through 3
    assert crossings(3.0, -4.0, 1.0, 0, 10) == [1.0, 3.0]
    assert crossings(3.0, -4.0, 1.0, 1, 10) == [3.0]
    assert crossings(3.0, -4.0, 1.0, -1, 10) == [1.0]
    assert crossings(3.0, -4.0, 1.0, 0, 2) == [1.0]
    assert crossings(4.0, -4.0, 1.0, 0, 10) == []      # tangent at 2: no sign change
    assert crossings(1.0, 0.0, 1.0, 0, 10) == []


def test_user_linear_event_located_exactly():
    """A user's LinearEvent (the apex, vz = 0, falling) is located in closed form."""
    scene = flying_scene()
    apex = ev.LinearEvent.of_state("vz", 1.0, 0.0, False, -1)
    t_apex = scene.velocity[2] / scene.gravity
    exact = flown(scene, 0.8, events=[apex])
    integrated = flown(scene, 0.8, events=[apex], exact=False)
    assert exact.nfev == 0 and integrated.nfev > 0
    np.testing.assert_allclose(exact.t_events[0], [t_apex], rtol=1e-15)
    np.testing.assert_allclose(integrated.t_events[0], [t_apex], rtol=1e-9)


def test_dense_output_is_the_exact_solution():
    scene = flying_scene()
    run = flown(scene, 0.3, dense_output=True)
    assert run.nfev == 0 and not run.contacts
    (_, _, piece), = run.sol.pieces
    assert isinstance(piece, flight.FreeFlight) and piece.t_max == run.t[-1]
    np.testing.assert_array_equal(run.sol(run.t), run.y)


@pytest.mark.parametrize("why", ["callable event", "quaternion event", "anisotropic",
                                 "observer", "off"])
def test_fallbacks_integrate(why):
    """Exact flight only where it is exact: a callable user event, a LinearEvent of the
    quaternion (not polynomial in flight), anisotropic inertia, a massive observer, or
    exact_flight=False integrate the flight (the log names the integrator)."""
    scene = flying_scene(inertia=(0.4, 0.4, 0.41) if why == "anisotropic" else None,
                         observer_mass=1e-4 if why == "observer" else 0.0)
    extra = {"callable event": [lambda t, y: y[layout.INDEX["vz"]]],
             "quaternion event": [ev.LinearEvent.of_state("qx", 1.0, 2.0)]}.get(why)
    result = ballc.simulate(scene, 0.3, events=extra, exact_flight=why != "off",
                            progress=False)
    assert result.nfev > 0
    assert "flight" not in set(result.segments["method"])
    if why in ("callable event", "off"):   # the same scene flies where nothing stops it
        assert ballc.simulate(scene, 0.3, progress=False).segments[0]["method"] == "flight"


def test_simulate_flight_only_costs_nothing_for_any_method():
    scene = flying_scene(velocity=(1.0, 2.0, 0.5), position=(0, 0, 4.0))
    for method in ("radau5", "DOP853", "Radau"):
        result = ballc.simulate(scene, 0.2, method=method, progress=False)
        assert result.nfev == 0 and result.status == 0 and result.t[-1] == 0.2


def test_option_is_validated():
    with pytest.raises(SceneError, match="exact_flight"):
        ballc.simulate(flying_scene(), 1.0, exact_flight="yes")


@pytest.mark.parametrize("changes, rtol", [
    (dict(observer_mass=0.0), 1e-10),
    (dict(observer_mass=0.0, tangential_model="compliant"), 1e-10),
    (dict(observer_mass=0.0, friction_coefficient=0.5, mixture=0.0,
          angular_velocity=(0.0, 20.0, 0.0)), 1e-8),
])
def test_whole_run_agrees_with_the_integrated_flight(changes, rtol):
    scene = ballc.Scene(**changes)
    on = ballc.simulate(scene, 3.0, rtol=rtol, atol=rtol, progress=False, dense_output=True)
    off = ballc.simulate(scene, 3.0, rtol=rtol, atol=rtol, progress=False,
                         exact_flight=False, dense_output=True)
    assert on.status == off.status == 0
    assert on.nfev < off.nfev
    assert len(on.contacts) == len(off.contacts) >= 2
    assert outcome.came_back(on) == outcome.came_back(off)
    for a, b in zip(on.contacts, off.contacts):
        assert a.plane == b.plane
        assert a.t_start == pytest.approx(b.t_start, abs=1e-6)
    # These runs' own error is dominated by the contacts, not the flight: the mixture
    # scene's stick-slip, and in the compliant scene a jump while unloading (most likely
    # where the tangential spring reaches its Coulomb cap, a kink that is integrated
    # through), give 1e-6 .. 3e-5 in state at rtol 1e-10, exact flight on or off alike;
    # which of the two is closer to the truth moves with rounding (a start state 1e-10
    # apart takes different steps through the kink).
    # So both runs must be accurate against a tight reference, at a bound 10x above that
    # (a defect of the closed form -- a sign, the spin, the root -- gives O(1) errors).
    reference = ballc.simulate(scene, 3.0, rtol=1e-12, atol=1e-12, progress=False,
                               exact_flight=False, dense_output=True)
    times = np.linspace(0, 3.0, 50)
    for quantity in (lambda r: np.array([c.velocity_after for c in r.contacts]),
                     lambda r: r.sol(times)[:13]):
        for run in (on, off):
            assert np.max(np.abs(quantity(run) - quantity(reference))) <= 3e-4
    balance = on.energy["balance"]
    assert abs(balance[-1] - balance[0]) <= 1e-6 * abs(balance[0])


def test_a_flight_too_long_to_sample_stops_honestly():
    """A ball floating without gravity, spinning, for 1e9 s: its exact flight would store
    ~5e10 samples (pi/16 of turn each).  The run stops at once with status -1 and says
    why and what to do, keeping what was computed (the start); with t_eval it runs."""
    scene = ballc.Scene(gravity=0.0, observer_mass=0.0, velocity=(0.0, 0.0, 0.0),
                        angular_velocity=(0.0, 0.0, 10.0))
    run = ballc.simulate(scene, 1e9, progress=False)
    assert run.status == -1 and "more than 1e8 samples" in run.message
    assert "t_eval" in run.message and run.t.tolist() == [0.0]
    sampled = ballc.simulate(scene, 1e9, t_eval=[0.0, 5e8, 1e9], progress=False)
    assert sampled.status == 0 and sampled.nfev == 0
    np.testing.assert_allclose(sampled.angular_velocity[:, -1], (0.0, 0.0, 10.0), rtol=0)
