"""Results on disk: npz (and netCDF when xarray is installed) round-trip exactly."""
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
    from pathlib import Path
    scene = ballc.Scene.from_toml(Path(__file__).parents[1] / "examples" / name)
    assert isinstance(scene, ballc.Scene)
    if name == "seed.toml":
        assert scene == ballc.Scene()


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
