"""Results on disk: npz (and netCDF when xarray is installed) round-trip exactly."""
import dataclasses
import json

import numpy as np
import pytest

import ballc


@pytest.fixture(scope="module")
def result():
    return ballc.simulate(ballc.Scene(mixture=0.5, velocity=(-3.0, 1.0, -20.0)), 0.8)


def assert_same(a, b):
    assert np.array_equal(a.t, b.t) and np.array_equal(a.y, b.y)
    assert np.array_equal(a.flags, b.flags) and np.array_equal(a.latch, b.latch)
    assert a.scene == b.scene
    assert (a.status, a.message, a.nfev, a.njev, a.nlu) == (b.status, b.message, b.nfev,
                                                              b.njev, b.nlu)
    assert a.state_names == b.state_names
    assert len(a.contacts) == len(b.contacts) > 0
    for ca, cb in zip(a.contacts, b.contacts):
        for key, value in ca.as_dict().items():
            assert value == cb.as_dict()[key] or (value != value and cb.as_dict()[key] != cb.as_dict()[key])
        assert np.array_equal(ca.digin_direction, cb.digin_direction)


def test_npz_round_trip_is_exact(result, tmp_path):
    result.save(tmp_path / "r.npz")
    again = ballc.load(tmp_path / "r.npz")
    assert_same(result, again)
    assert np.array_equal(again.observer_specific_force, result.observer_specific_force)


def test_npz_carries_provenance(result, tmp_path):
    result.save(tmp_path / "r.npz")
    with np.load(tmp_path / "r.npz") as data:
        stored = json.loads(json.loads(str(data["header"]))["provenance"])
    assert stored["ballc_version"] == ballc.__version__
    assert stored["generator_version"] == ballc._core.GENERATOR_VERSION


def test_netcdf_round_trip_is_exact(result, tmp_path):
    pytest.importorskip("xarray", reason="netCDF output is the optional 'netcdf' extra")
    result.save(tmp_path / "r.nc")
    assert_same(result, ballc.load(tmp_path / "r.nc"))


def test_a_result_without_contacts_round_trips(tmp_path):
    quiet = ballc.simulate(ballc.Scene(velocity=(0.0, 0.0, 1.0)), 0.2)
    quiet.save(tmp_path / "q.npz")
    again = ballc.load(tmp_path / "q.npz")
    assert again.contacts == [] and np.array_equal(again.y, quiet.y)


def test_scene_toml_round_trip(tmp_path):
    scene = ballc.Scene(mixture=0.123456789, velocity=(-1.0, 2.5e-3, -7.0), mass=2,
                        tangential_model="friction", c_tau=1.0)
    scene.to_toml(tmp_path / "s.toml")
    assert ballc.Scene.from_toml(tmp_path / "s.toml") == scene


@pytest.mark.parametrize("name", ["seed.toml", "superball.toml"])
def test_example_scene_files_load(name):
    """Each field the file gives is the scene's, value for value (the file read here
    with tomllib itself); the others are the defaults, the inertia a solid sphere's."""
    from pathlib import Path
    tomllib = pytest.importorskip("tomllib")
    path = Path(__file__).parents[1] / "examples" / name
    scene = ballc.Scene.from_toml(path)
    with open(path, "rb") as stream:
        given = tomllib.load(stream)
    given.pop("simulate", None)
    assert given, "the example gives no field"
    for field, value in given.items():
        expected = tuple(value) if isinstance(value, list) else value
        assert getattr(scene, field) == expected, field
    default = ballc.Scene()
    derived = {"inertia", "tangential_damping_ratio", "tangential_stiffness_ratio", "c_tau",
               "planes"}   # planes: the ceiling_height shorthand's
    for field in set(default.to_dict()) - set(given) - derived:
        assert getattr(scene, field) == getattr(default, field), field
    if "inertia" not in given:
        assert scene.inertia == pytest.approx([0.4 * scene.mass * scene.radius ** 2] * 3,
                                              rel=1e-15)
    if name == "seed.toml":
        assert scene == default


def test_invalid_toml_names_the_file(tmp_path):
    (tmp_path / "x.toml").write_text("mixture = [\n")
    with pytest.raises(ballc.SceneError, match="x.toml: not valid TOML"):
        ballc.Scene.from_toml(tmp_path / "x.toml")


@pytest.mark.parametrize("name", ["x.h5", "x", "x.npz.bak", "x.NPZ"])
def test_save_refuses_other_suffixes(result, tmp_path, name):
    with pytest.raises(ValueError, match=r"must end in \.npz .*or \.nc") as caught:
        result.save(tmp_path / name)
    assert name in str(caught.value)
    assert list(tmp_path.iterdir()) == []          # not x.h5.npz, nothing at all


def test_load_refuses_other_suffixes(result, tmp_path):
    result.save(tmp_path / "r.npz")
    (tmp_path / "r.npz").rename(tmp_path / "r.h5")    # even an npz under another name
    with pytest.raises(ValueError, match=r"r\.h5.*must end in \.npz .*or \.nc"):
        ballc.load(tmp_path / "r.h5")


@pytest.mark.parametrize("suffix", [".npz", ".nc"])
def test_method_switches_round_trip(tmp_path, suffix):
    """method="auto"'s switches are saved (they were dropped before); a run of another
    method saves None."""
    if suffix == ".nc":
        pytest.importorskip("xarray", reason="netCDF output is the optional 'netcdf' extra")
    run = ballc.simulate(ballc.Scene(velocity=(0.0, 0.0, 1.0)), 0.2, method="dop853")
    run.save(tmp_path / f"plain{suffix}")
    assert ballc.load(tmp_path / f"plain{suffix}").method_switches is None
    run.method_switches = [(0.015625, "radau5"), (0.1, "dop853")]
    run.save(tmp_path / f"switched{suffix}")
    assert ballc.load(tmp_path / f"switched{suffix}").method_switches == run.method_switches


def test_a_file_saved_before_switches_were_kept_loads(result, tmp_path):
    result.save(tmp_path / "r.npz")
    with np.load(tmp_path / "r.npz") as data:
        arrays = dict(data)
    header = json.loads(str(arrays["header"]))
    del header["method_switches"]
    arrays["header"] = np.array(json.dumps(header))
    np.savez(tmp_path / "old.npz", **arrays)
    again = ballc.load(tmp_path / "old.npz")
    assert again.method_switches is None and np.array_equal(again.y, result.y)


def _height(level, terminal=False):
    """An event: the centre's height z crosses ``level`` (m)."""
    def event(t, y):
        return y[ballc.STATE_NAMES.index("z")] - level
    event.terminal = terminal
    return event


#: The heights (m) of each run's events (with_events)
LEVELS = {"None": [], "no events": [], "none fire": [-50.0], "several": [2.0, -50.0],
          "terminal": [1.5, 0.9]}


@pytest.fixture(scope="module")
def with_events():
    """Runs with user events: none given (t_events None), none that fire, one firing
    several times beside one that never fires, and a terminal one that stops the run."""
    scene = ballc.Scene(velocity=(0.0, 0.0, -8.0), position=(0.0, 0.0, 3.0))
    t_end = {"no events": 0.3, "none fire": 0.3, "several": 1.2, "terminal": 1.2}
    runs = {name: ballc.simulate(scene, t_end[name], events=[
        _height(level, terminal=(name == "terminal" and k == 1))
        for k, level in enumerate(levels)]) for name, levels in LEVELS.items()
        if name not in ("None", "no events")}
    runs["no events"] = ballc.simulate(scene, 0.3)
    runs["None"] = dataclasses.replace(runs["no events"], t_events=None, y_events=None)
    return runs


def test_the_event_runs_are_what_their_names_say(with_events):
    assert with_events["no events"].t_events == [] and with_events["None"].t_events is None
    assert [len(t) for t in with_events["none fire"].t_events] == [0]
    several = with_events["several"]
    assert len(several.t_events[0]) >= 2 and len(several.t_events[1]) == 0
    terminal = with_events["terminal"]
    assert terminal.status == 1 and len(terminal.t_events[1]) == 1
    assert terminal.t_events[1][0] == terminal.t[-1]


@pytest.mark.parametrize("suffix", [".npz", ".nc"])
@pytest.mark.parametrize("name", ["None", "no events", "none fire", "several", "terminal"])
def test_user_events_round_trip(with_events, tmp_path, suffix, name):
    """save/load keep t_events and y_events (they were dropped), value for value, with
    the empty arrays of events that never fired (issue 28, item 5)."""
    if suffix == ".nc":
        pytest.importorskip("xarray", reason="netCDF output is the optional 'netcdf' extra")
    run = with_events[name]
    run.save(tmp_path / f"r{suffix}")
    again = ballc.load(tmp_path / f"r{suffix}")
    if run.t_events is None:
        assert again.t_events is None and again.y_events is None
        return
    assert len(again.t_events) == len(run.t_events) == len(again.y_events)
    for saved, loaded in zip(run.t_events + run.y_events, again.t_events + again.y_events):
        assert loaded.shape == saved.shape and loaded.dtype == saved.dtype
        assert np.array_equal(loaded, saved)
    z = ballc.STATE_NAMES.index("z")
    for states, level in zip(again.y_events, LEVELS[name]):
        assert states.shape[1:] == (len(ballc.STATE_NAMES),)
        assert np.allclose(states[:, z], level, rtol=0, atol=1e-9)   # where each fired


def test_a_file_saved_before_events_were_kept_loads(with_events, tmp_path):
    run = with_events["several"]
    run.save(tmp_path / "r.npz")
    with np.load(tmp_path / "r.npz") as data:
        arrays = {k: v for k, v in dict(data).items() if not k.startswith("event")}
    header = json.loads(str(arrays["header"]))
    header.pop("event_count", None)
    arrays["header"] = np.array(json.dumps(header))
    np.savez(tmp_path / "old.npz", **arrays)
    again = ballc.load(tmp_path / "old.npz")
    assert again.t_events is None and np.array_equal(again.y, run.y)
