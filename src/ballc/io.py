"""Results on disk: ``.npz`` (numpy, always) and ``.nc`` (netCDF via xarray, optional).

Both hold everything needed to rebuild the :class:`ballc.Result`: the time grid and
states (bit for bit), the per-sample flags and latched values, the contacts, the
solver's status, the scene (as JSON) and provenance (ballc version, generator version
of the compiled kernels, numpy/Python versions, creation time in UTC).

>>> result.save("seed.npz");  again = ballc.load("seed.npz")
"""
from __future__ import annotations

import dataclasses
import datetime
import json
import platform
import warnings
from pathlib import Path

import numpy as np

from . import _core
from .result import Contact, Result
from .scene import Scene

FORMAT = "ballc-result-1"
_CONTACT_FIELDS = [f.name for f in dataclasses.fields(Contact)]


def provenance() -> dict:
    """Who made a file: ballc and kernel generator versions, numpy, Python, UTC time."""
    from . import __version__
    return {"format": FORMAT, "ballc_version": __version__,
            "generator_version": _core.GENERATOR_VERSION, "numpy_version": np.__version__,
            "python_version": platform.python_version(),
            "created_utc": datetime.datetime.now(datetime.timezone.utc).isoformat()}


def _contact_arrays(contacts) -> dict:
    """contact_<field> -> array over contacts ((k,) or (k, 3))."""
    arrays = {}
    for name in _CONTACT_FIELDS:
        values = [getattr(c, name) for c in contacts]
        if name == "plane":
            arrays[name] = np.array(values, dtype=str)
        elif name == "transitions":   # variable length: one JSON text per contact
            arrays[name] = np.array([json.dumps(v) for v in values], dtype=str)
        elif values and np.ndim(values[0]) == 1:
            arrays[name] = np.array(values, dtype=float).reshape(len(values), -1)
        else:
            arrays[name] = np.array(values, dtype=float)
    return arrays


def _contacts_from(arrays: dict) -> list:
    count = len(arrays["plane"])
    contacts = []
    for i in range(count):
        values = {}
        for name in _CONTACT_FIELDS:
            value = arrays[name][i]
            if name == "plane":
                values[name] = str(value)
            elif name == "transitions":
                values[name] = [(float(t), str(mode)) for t, mode in json.loads(str(value))]
            elif np.ndim(value) == 1:
                values[name] = np.array(value, dtype=float)
            else:
                values[name] = float(value)
        contacts.append(Contact(**values))
    return contacts


def _header(result) -> dict:
    return {"scene": json.dumps(result.scene.to_dict()), "provenance": json.dumps(provenance()),
            "status": int(result.status), "message": str(result.message),
            "nfev": int(result.nfev), "njev": int(result.njev), "nlu": int(result.nlu)}


def _check_provenance(path, stored: dict, state_names) -> None:
    if tuple(state_names) != tuple(_core.STATE_NAMES):
        warnings.warn(f"{path}: its states {tuple(state_names)} differ from this ballc's "
                      f"{_core.STATE_NAMES}; outputs that evaluate the model will fail",
                      stacklevel=3)
    elif stored.get("generator_version") != _core.GENERATOR_VERSION:
        warnings.warn(f"{path}: made with kernels {stored.get('generator_version')!r}, "
                      f"this ballc has {_core.GENERATOR_VERSION!r}", stacklevel=3)


#: File name suffixes save and load understand.
SUFFIXES = (".npz", ".nc")


def _checked_suffix(path, action: str) -> Path:
    """``path`` as a Path; ValueError unless it ends in .npz or .nc (numpy would quietly
    write "x.h5" as "x.h5.npz", which load("x.h5") then cannot find)."""
    path = Path(path)
    if path.suffix not in SUFFIXES:
        found = f"not {path.suffix!r}" if path.suffix else "it has no suffix"
        raise ValueError(f"cannot {action} {str(path)!r}: the file name must end in .npz "
                         f"(numpy) or .nc (netCDF, needs xarray); {found}")
    return path


def save(result, path) -> None:
    """Write ``result`` to ``path``: ``.npz`` (numpy) or ``.nc`` (netCDF, needs xarray);
    any other suffix raises ValueError."""
    path = _checked_suffix(path, "save a Result as")
    if path.suffix == ".nc":
        _to_dataset(result).to_netcdf(path)
        return
    header = _header(result)
    contacts = {f"contact_{k}": v for k, v in _contact_arrays(result.contacts).items()}
    np.savez_compressed(
        path, t=result.t, y=result.y, state_names=np.array(result.state_names, dtype=str),
        flags=_or_empty(result.flags, np.int32), latch=_or_empty(result.latch, float),
        latch_names=np.array(_core.LATCH_NAMES, dtype=str),
        header=np.array(json.dumps(header)), **contacts)


def _or_empty(array, dtype):
    return np.zeros(0, dtype=dtype) if array is None else np.asarray(array, dtype=dtype)


def load(path) -> Result:
    """Read a Result written by :meth:`Result.save`.

    Parameters
    ----------
    path : str or Path
        A ``.npz`` file, or ``.nc`` (netCDF, needs xarray); any other suffix raises
        ValueError.

    Returns
    -------
    Result
        The saved run: times (s), states (SI units), contacts and scene.
    """
    path = _checked_suffix(path, "load a Result from")
    if path.suffix == ".nc":
        return _from_dataset(path)
    with np.load(path, allow_pickle=False) as data:
        header = json.loads(str(data["header"]))
        contacts = {k[len("contact_"):]: data[k] for k in data.files if k.startswith("contact_")}
        arrays = {k: data[k] for k in ("t", "y", "state_names", "flags", "latch")}
    return _result(path, header, arrays, contacts)


def _result(path, header, arrays, contacts) -> Result:
    stored = json.loads(header["provenance"])
    _check_provenance(path, stored, arrays["state_names"])
    flags, latch = arrays["flags"], arrays["latch"]
    return Result(t=arrays["t"], y=arrays["y"], scene=Scene.from_dict(json.loads(header["scene"])),
                  status=int(header["status"]), message=str(header["message"]),
                  nfev=int(header["nfev"]), njev=int(header["njev"]), nlu=int(header["nlu"]),
                  contacts=_contacts_from(contacts),
                  state_names=tuple(str(s) for s in arrays["state_names"]),
                  flags=flags if flags.size else None, latch=latch if latch.size else None)


def _to_dataset(result):
    try:
        import xarray as xr
    except ModuleNotFoundError:
        raise ModuleNotFoundError("saving a Result as netCDF needs xarray: "
                                  "pip install 'ballc[netcdf]' (or save as .npz)") from None
    variables = {"y": (("state", "time"), result.y, {"long_name": "state (SI units)"})}
    if result.flags is not None:
        variables["flags"] = (("time",), np.asarray(result.flags, dtype=np.int32))
        variables["latch"] = (("latch_name", "time"), result.latch)
    for name, values in _contact_arrays(result.contacts).items():
        dims = ("contact", f"{name}_component") if values.ndim == 2 else ("contact",)
        variables[f"contact_{name}"] = (dims, values)
    coords = {"time": ("time", result.t, {"units": "s"}),
              "state": list(result.state_names), "latch_name": list(_core.LATCH_NAMES)}
    return xr.Dataset(variables, coords=coords, attrs=_header(result))


def _from_dataset(path) -> Result:
    import xarray as xr
    with xr.open_dataset(path) as ds:
        ds.load()
        arrays = {"t": ds["time"].values.astype(float), "y": ds["y"].values.astype(float),
                  "state_names": ds["state"].values.astype(str),
                  "flags": ds["flags"].values.astype(np.int32) if "flags" in ds else np.zeros(0),
                  "latch": ds["latch"].values.astype(float) if "latch" in ds else np.zeros(0)}
        contacts = {k[len("contact_"):]: ds[k].values for k in ds.data_vars
                    if k.startswith("contact_")}
        header = dict(ds.attrs)
    contacts["plane"] = contacts["plane"].astype(str)
    return _result(path, header, arrays, contacts)
