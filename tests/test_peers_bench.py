"""benchmarks/peers.py: the segment recording and replay it rests on.

The recording must not change what ballc.simulate computes, the segments must chain
from 0 to t_end, and radau5 replaying each segment from its recorded start state must
reproduce the recorded end state to the order of the tolerance.  The peers' part runs
only when the optional peers are installed (``pip install ".[bench]"``).  No timings.
"""
import numpy as np
import pytest

import ballc
from benchmarks import peers

T_END = 1.2   # the first floor and ceiling contacts of the seed throw


@pytest.fixture(scope="module")
def recorded():
    result, segments = peers.record_segments(t_end=T_END, rtol=1e-12, atol=1e-12)
    return result, segments


def test_recording_changes_nothing(recorded):
    result, _ = recorded
    plain = ballc.simulate(ballc.Scene(), T_END, rtol=1e-12, atol=1e-12)
    assert np.array_equal(plain.t, result.t)
    assert np.array_equal(plain.y, result.y)
    assert plain.nfev == result.nfev


def test_segments_chain_from_start_to_end(recorded):
    result, segments = recorded
    assert result.status == 0
    assert segments[0].t0 == 0.0 and segments[-1].t1 == T_END
    for before, after in zip(segments, segments[1:]):
        assert after.t0 == before.t1
    kinds = {s.flags for s in segments}
    assert len(kinds) >= 3    # free flight, floor contact, ceiling contact at least
    assert sum(s.nfev for s in segments) == result.nfev


@pytest.mark.parametrize("tol, bound", [(1e-8, 1e-6), (1e-10, 1e-8), (1e-12, 1e-10)])
def test_radau5_replay_reproduces_the_reference(recorded, tol, bound):
    _, segments = recorded
    worst = 0.0
    for seg in peers.replayable(segments):
        y, counts = peers.run_radau5(seg, None, tol)
        assert counts["nfev"] > 0
        worst = max(worst, max(peers.errors(y, seg.y1)))
    assert worst < bound


@pytest.mark.parametrize("tol, bound", [(1e-8, 1e-5), (1e-10, 1e-7), (1e-12, 1e-9)])
def test_dop853_replay_reproduces_the_reference(recorded, tol, bound):
    """ballc's compiled DOP853 (a contender of the replay) reaches every segment's
    recorded end to the order of the tolerance, without a Jacobian or an LU."""
    _, segments = recorded
    worst = 0.0
    for seg in peers.replayable(segments):
        y, counts = peers.run_dop853(seg, None, tol)
        assert counts["nfev"] > 0 and counts["njev"] == 0 and counts["nlu"] == 0
        worst = max(worst, max(peers.errors(y, seg.y1)))
    assert worst < bound


def test_rotation_error():
    q = np.array([1.0, 0.0, 0.0, 0.0])
    assert np.allclose(peers._rotation_error(q, q), 0)
    half = 0.5e-3                                   # a 1e-3 rad turn about y
    turned = np.array([np.cos(half), 0.0, np.sin(half), 0.0])
    assert np.allclose(peers._rotation_error(turned, q), [0, 1e-3, 0], atol=1e-15)
    assert np.allclose(peers._rotation_error(-turned, q), [0, 1e-3, 0], atol=1e-15)


def test_peers_replay_a_contact(recorded):
    pytest.importorskip("sksundae")
    pytest.importorskip("assimulo")
    _, segments = recorded
    segments = [s for s in peers.replayable(segments) if not peers.near_singular(s)][:4]
    for name, run in peers.contenders().items():
        for seg in segments:
            y, counts = run(seg, seg.system(), 1e-8)
            assert peers.errors(y, seg.y1)[0] < 1e-4, name
            assert counts["nfev"] > 0, name
            assert counts["njev"] > 0 or name == "dop853", name   # explicit: no Jacobian


def test_missing_peer_message():
    assert 'pip install ".[bench]"' in peers.MISSING


def test_cvode_c_harness_replays_a_contact(recorded, tmp_path):
    """benchmarks/cvode_c.py: the segment file round-trips exactly, and the C harness
    (radau5, dop853 and CVODE driven from C) reaches every segment's end with finite CPU,
    radau5 and dop853 as ballc's own radau5 and dop853 do it.  Skipped without
    scikit-sundae's bundled SUNDIALS or a C compiler."""
    from benchmarks import cvode_c
    try:
        cvode_c.sundials_libraries()
        cvode_c.compiler()
    except cvode_c.Unavailable as exc:
        pytest.skip(str(exc))
    _, segments = recorded
    segments = peers.replayable(segments)
    cvode_c.write_segments(segments, tmp_path / "segments.txt")
    for seg, (flags, t0, t1, params, latch, y0) in zip(
            segments, cvode_c.read_segments(tmp_path / "segments.txt")):
        assert (flags, t0, t1) == (seg.flags, seg.t0, seg.t1)
        assert np.array_equal(params, seg.params) and np.array_equal(latch, seg.latch)
        assert np.array_equal(y0, seg.y0)
    exe = cvode_c.build_harness(tmp_path)
    out = cvode_c.run_harness(exe, segments, (1e-8,), 1, tmp_path)
    assert out["sundials"].startswith("7.")
    assert {name for name, _ in out["runs"]} == {"radau5", "dop853", "CVODE BDF",
                                                  "CVODE Adams"}
    rows = cvode_c.rows_from_runs(out["runs"], segments)
    for name in cvode_c.CONTENDERS.values():
        row = rows[(name, 1e-8)]
        assert row["failed"] == 0 and np.isfinite(row["cpu"]) and row["cpu"] > 0, name
        assert row["nfev"] > 0 and row["nstep"] > 0, name
        if name == "dop853":      # explicit: no Jacobian, no LU
            assert row["njev"] == 0 and row["nlu"] == 0
        else:
            assert row["njev"] > 0, name
        assert row["err6_regular"] < 1e-4, name
    for method in ("radau5", "dop853"):
        ends = out["runs"][(method, 1e-8)]["y_end"]
        for k, seg in enumerate(segments):
            y, _ = peers.run_radau5(seg, None, 1e-8, method)
            assert np.allclose(ends[k], y, rtol=1e-10, atol=1e-12), method
