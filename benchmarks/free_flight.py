"""Exact free flight (ballc.flight): what it saves, and whether the seed scene's flight
would pay for an explicit method.

Part 1: an observer-free isotropic scene (the seed scene with observer_mass = 0; its
default inertia is a solid sphere's, isotropic): simulate with exact_flight on and off
at several tolerances, CPU time (best of N, process time, same process), right-hand-side
calls, and with the exact path off the share of radau5's steps and calls that the flight
segments take (the C loop's segment log, ``result.segments``).

Part 2: the seed scene (observer present, so no exact flight): its flight segments are
read from a run (its segment log, samples and dense output, as benchmarks.peers
records segments), then replayed from the same start states, with the contact starts'
events (ballc.events.penetration past its threshold), with radau5 and with
scipy's DOP853 over a range of tolerances; the error is the end state (at the contact
start event) against a reference (radau5 at rtol = atol = 1e-13, checked against DOP853
at 1e-13).  Work is counted in right-hand-side calls and steps, radau5's Jacobians and
LU factorisations, and radau5's CPU time (DOP853's CPU in scipy is Python overhead, so
its cost in C is estimated as calls x the C right-hand side's cost).

    python -m benchmarks.free_flight [--repeat 5] [--t-end 5]
"""
from __future__ import annotations

import argparse
import time

import numpy as np
from scipy.integrate import solve_ivp

import ballc
from ballc import _core, _radau5
from ballc import events as ev

TOLERANCES = (1e-3, 1e-6, 1e-8, 1e-10)
REPLAY_TOLERANCES = (1e-4, 1e-6, 1e-8, 1e-10, 1e-12)


def flight_segments(result, scene, t_end):
    """The flight segments of ``result`` (a run of the C loop to ``t_end`` with dense
    output) that ended in a contact start: [dict(inputs=(params, latch, flags, t0, t1,
    y0, events), nstep, nfev)], from its segment log, as the loop integrated them: from
    t0 towards t1 = t_end (a flight has no rest check to stop at) with the contact
    starts' events past their thresholds (max(base, base + rho0), base
    events.threshold_base, as the C loop's segment_events makes them); y0 is the
    segment's piece of result.sol at t0 (its first step's start state, exactly), the
    latch and flags its samples'."""
    log = result.segments
    if log is None:
        raise SystemExit("the run did not take the C loop: it has no segment log")
    params = scene.parameter_vector()
    found = []
    for row, (_, _, interpolant) in zip(log, result.sol.pieces):
        if list(row["before"]) != ["flight", "flight"] or row["end"] != "enter":
            continue
        t0 = float(row["t_start"])
        first = np.flatnonzero(result.t > t0)[0]
        y0 = np.asarray(interpolant(t0), dtype=float)
        events = []
        for plane in ("floor", "ceiling"):
            rho = ev.penetration(plane, scene)
            base = ev.threshold_base(scene, plane)
            threshold = max(base, float(rho(t0, y0)) + base)
            events.append(ev.LinearEvent(rho.coefficients, rho.offset - threshold,
                                         terminal=True, direction=1))
        found.append(dict(inputs=(params, np.array(result.latch[:, first]),
                                  int(result.flags[first]), t0, t_end, y0, events),
                          nstep=int(row["nstep"]), nfev=int(row["nfev"])))
    return found


def best_cpu(function, repeat):
    best, value = np.inf, None
    for _ in range(repeat):
        start = time.process_time()
        value = function()
        best = min(best, time.process_time() - start)
    return best, value


def part1(t_end, repeat):
    scene = ballc.Scene(observer_mass=0.0)
    rows = []
    for rtol in TOLERANCES:
        run = {}
        for exact in (True, False):
            cpu, result = best_cpu(lambda: ballc.simulate(
                scene, t_end, rtol=rtol, atol=rtol, exact_flight=exact, progress=False),
                repeat)
            run[exact] = (cpu, result)
        on, off = run[True][1], run[False][1]
        log = off.segments
        flight = log[(log["before"] == "flight").all(axis=1)]
        share = lambda key: flight[key].sum() / max(log[key].sum(), 1e-300)  # noqa: E731
        rows.append(dict(
            rtol=rtol, cpu_on=run[True][0], cpu_off=run[False][0], nfev_on=on.nfev,
            nfev_off=off.nfev, contacts_on=len(on.contacts), contacts_off=len(off.contacts),
            came_back_on=ballc.outcome.came_back(on), came_back_off=ballc.outcome.came_back(off),
            flight_segments=len(flight), step_share=share("nstep"), nfev_share=share("nfev"),
            state_difference=float(np.abs(on.y[:13, -1] - off.y[:13, -1]).max())))
    return scene, rows


def replay(inputs, method, rtol, atol):
    params, latch, flags, t0, t1, y0, events = inputs
    start = time.process_time()
    if method == "radau5":
        sol = _radau5.solve_system(params, latch, flags, (t0, t1), y0, rtol=rtol, atol=atol,
                                   events=events)
        cpu = time.process_time() - start
        return dict(t=sol.t[-1], y=sol.y[:, -1], nfev=sol.nfev, nstep=sol.nstep,
                    njev=sol.njev, nlu=sol.nlu, cpu=cpu)
    system = _core.System(params, latch, flags)
    sol = solve_ivp(system, (t0, t1), y0, method=method, rtol=rtol, atol=atol,
                    events=events)
    cpu = time.process_time() - start
    return dict(t=sol.t[-1], y=sol.y[:, -1], nfev=sol.nfev, nstep=sol.t.size - 1,
                njev=0, nlu=0, cpu=cpu)


def rhs_cost(params, flags, y0, repeat=200_000):
    """Seconds per C right-hand-side call (the Python-call overhead measured with a
    no-op of the same shape and subtracted)."""
    system = _core.System(params, np.zeros(_core.N_LATCH), flags)
    y = np.ascontiguousarray(y0)
    out = []
    for function in (system, lambda t, y: None):
        best = np.inf
        for _ in range(3):
            start = time.perf_counter()
            for _ in range(repeat):
                function(0.0, y)
            best = min(best, time.perf_counter() - start)
        out.append(best / repeat)
    return max(out[0] - out[1], 0.0), out[0]


def part2(t_end, repeat):
    scene = ballc.Scene()    # the seed scene: observer of 1e-4 kg
    result = ballc.simulate(scene, t_end, progress=False, dense_output=True)
    flights = flight_segments(result, scene, t_end)
    references = [replay(c["inputs"], "radau5", 1e-13, 1e-13) for c in flights]
    cross = [replay(c["inputs"], "DOP853", 1e-13, 1e-13) for c in flights]
    reference_spread = max(float(np.abs(a["y"][:13] - b["y"][:13]).max())
                           for a, b in zip(references, cross))
    rows = []
    for method in ("radau5", "DOP853"):
        for tol in REPLAY_TOLERANCES:
            totals = dict(nfev=0, nstep=0, njev=0, nlu=0, cpu=0.0)
            error = t_error = 0.0
            for c, ref in zip(flights, references):
                best = None
                for _ in range(repeat if method == "radau5" else 1):
                    out = replay(c["inputs"], method, tol, tol)
                    best = out if best is None or out["cpu"] < best["cpu"] else best
                for key in totals:
                    totals[key] += best[key]
                error = max(error, float(np.abs(best["y"][:13] - ref["y"][:13]).max()))
                t_error = max(t_error, abs(best["t"] - ref["t"]))
            rows.append(dict(method=method, tol=tol, error=error, t_error=t_error, **totals))
    cost, called = rhs_cost(scene.parameter_vector(), flights[0]["inputs"][2],
                            flights[0]["inputs"][5])
    log = result.segments
    return dict(scene=scene, contacts=len(result.contacts), segments=len(log),
                flights=len(flights), flight_steps=sum(c["nstep"] for c in flights),
                total_steps=int(log["nstep"].sum()),
                flight_nfev=sum(c["nfev"] for c in flights), total_nfev=int(log["nfev"].sum()),
                reference_spread=reference_spread, rows=rows, rhs_cost=cost,
                rhs_call=called)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--t-end", type=float, default=5.0)
    args = parser.parse_args(argv)
    scene, rows = part1(args.t_end, args.repeat)
    print(f"Part 1: Scene(observer_mass=0) (inertia {scene.inertia[0]:g} kg m^2 each), "
          f"t_end = {args.t_end:g} s, radau5, CPU best of {args.repeat}\n")
    print("| rtol = atol | CPU on (ms) | CPU off (ms) | speed-up | RHS calls on | RHS calls "
          "off | contacts on/off | came back on/off | flight share of steps / calls (off) "
          "| max end-state difference |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r['rtol']:.0e} | {1e3 * r['cpu_on']:.1f} | {1e3 * r['cpu_off']:.1f} | "
              f"{r['cpu_off'] / r['cpu_on']:.2f} | {r['nfev_on']} | {r['nfev_off']} | "
              f"{r['contacts_on']}/{r['contacts_off']} | {r['came_back_on']}/"
              f"{r['came_back_off']} | {100 * r['step_share']:.1f} % / "
              f"{100 * r['nfev_share']:.1f} % | "
              f"{r['state_difference']:.1e} |")
    p2 = part2(args.t_end, args.repeat)
    print(f"\nPart 2: the seed scene (observer 1e-4 kg), t_end = {args.t_end:g} s, rtol = "
          f"atol = 1e-10: {p2['contacts']} contacts, {p2['segments']} segments, "
          f"{p2['flights']} flight segments ending in a contact start; flight takes "
          f"{p2['flight_steps']} of {p2['total_steps']} steps, {p2['flight_nfev']} of "
          f"{p2['total_nfev']} RHS calls.")
    print(f"Replayed flight segments; reference radau5 at 1e-13 (DOP853 at 1e-13 differs "
          f"from it by {p2['reference_spread']:.1e}); one RHS call through _core.System (flight, "
          f"observer; its Python-call overhead subtracted, its output array not: an upper "
          f"bound of the C cost) {1e9 * p2['rhs_cost']:.0f} ns\n")
    print("| method | rtol = atol | max end-state error | max event-time error (s) | RHS "
          "calls | steps | Jacobians | LUs | CPU (ms) | est. C cost (ms) |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for r in p2["rows"]:
        estimate = (f"{1e3 * r['cpu']:.2f}" if r["method"] == "radau5"
                    else f"<= {1e3 * r['nfev'] * p2['rhs_cost']:.2f} (calls x RHS)")
        print(f"| {r['method']} | {r['tol']:.0e} | {r['error']:.1e} | {r['t_error']:.1e} | "
              f"{r['nfev']} | {r['nstep']} | {r['njev']} | {r['nlu']} | "
              f"{1e3 * r['cpu']:.2f} | {estimate} |")


if __name__ == "__main__":
    main()
