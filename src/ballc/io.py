"""Results on disk: ``.npz`` (numpy, always) and ``.nc`` (netCDF via xarray, optional).

Both hold everything needed to rebuild the :class:`ballc.Result`: the time grid and
states (bit for bit), the per-sample flags and latched values, the contacts, the user
events' times and states (``t_events``, ``y_events``), the solver's status, the scene (as JSON) and provenance (ballc version, generator version
of the compiled kernels, numpy/Python versions, creation time in UTC).

>>> result.save("seed.npz");  again = ballc.load("seed.npz")

This module knows the file formats only; how a Result becomes arrays and back is
result.py's (so result.py uses io.py, never the other way round).
"""
from __future__ import annotations

import datetime
import json
import platform
import warnings
import zipfile
import zlib
from pathlib import Path

import numpy as np

from . import _core

FORMAT = "ballc-result-1"


def provenance() -> dict:
    """Who made a file: ballc and kernel generator versions, numpy, Python, UTC time."""
    from . import __version__
    return {"format": FORMAT, "ballc_version": __version__,
            "generator_version": _core.GENERATOR_VERSION, "numpy_version": np.__version__,
            "python_version": platform.python_version(),
            "created_utc": datetime.datetime.now(datetime.timezone.utc).isoformat()}


def _header(result) -> dict:
    return {"scene": json.dumps(result.scene.to_dict()), "provenance": json.dumps(provenance()),
            "status": int(result.status), "message": str(result.message),
            "nfev": int(result.nfev), "njev": int(result.njev), "nlu": int(result.nlu),
            # method="auto"'s switches, [(t, method)], or null (JSON: a netCDF attribute
            # is a string or a number)
            "method_switches": json.dumps(None if result.method_switches is None else
                                          [[float(t), str(m)] for t, m in
                                           result.method_switches]),
            # how many user events the run was given (their occurrences are the
            # event_* arrays), or null: none given
            "event_count": json.dumps(None if result.t_events is None else
                                      len(result.t_events))}


def _expected_states(scene: dict) -> tuple:
    """The state names this ballc gives the scene stored in a file (its planes' names)."""
    planes = scene.get("planes")
    if not planes:
        return _core.STATE_NAMES
    return _core.state_names(tuple(p.get("name") or f"plane{i}" for i, p in enumerate(planes)))


def _check_provenance(path, stored: dict, state_names, scene: dict) -> None:
    expected = _expected_states(scene)
    if tuple(state_names) != tuple(expected):
        warnings.warn(f"{path}: its states {tuple(state_names)} differ from this ballc's "
                      f"{expected}; outputs that evaluate the model will fail",
                      stacklevel=3)
    elif stored.get("generator_version") != _core.GENERATOR_VERSION:
        warnings.warn(f"{path}: made with kernels {stored.get('generator_version')!r}, "
                      f"this ballc has {_core.GENERATOR_VERSION!r}", stacklevel=3)


#: The right-hand side's flags of kernels "1" (two planes, before planes of any
#: orientation): (bit, kind, plane); files written then are read with today's flags.
_FLAGS_1 = ((1, "observer", 0), (2, "friction", 0), (4, "digin", 0), (8, "friction", 1),
            (16, "digin", 1), (32, "compliant", 0), (64, "compliant", 1), (128, "slip", 0),
            (256, "slip", 1), (512, "stick", 0), (1024, "stick", 1), (2048, "slip_fixed", 0),
            (4096, "slip_fixed", 1), (8192, "compliant_sliding", 0),
            (16384, "compliant_sliding", 1), (32768, "compliant_elastic", 0),
            (65536, "compliant_elastic", 1))


def _flags_of(flags, stored: dict) -> np.ndarray:
    """A file's per-sample flags in this ballc's layout (int64; kernels "1" converted)."""
    flags = np.asarray(flags, dtype=np.int64)
    if stored.get("generator_version") != "1" or not flags.size:
        return flags
    converted = np.zeros_like(flags)
    for bit, kind, plane in _FLAGS_1:
        converted |= np.where(flags & bit, _core.flag(kind, plane), 0)
    return converted


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
    contacts = {f"contact_{k}": v for k, v in result.contact_arrays().items()}
    events = {f"event_{k}": v for k, v in result.event_arrays().items()}
    np.savez_compressed(
        path, t=result.t, y=result.y, state_names=np.array(result.state_names, dtype=str),
        flags=_or_empty(result.flags, np.int64), latch=_or_empty(result.latch, float),
        latch_names=np.array(result.scene.latch_names, dtype=str),
        header=np.array(json.dumps(header)), **contacts, **events)


def _or_empty(array, dtype):
    return np.zeros(0, dtype=dtype) if array is None else np.asarray(array, dtype=dtype)


def read(path) -> tuple[dict, dict, dict]:
    """The parts of a file written by ``Result.save``; ``ballc.load`` turns them into a
    Result.

    Parameters
    ----------
    path : str or Path
        A ``.npz`` file, or ``.nc`` (netCDF, needs xarray); any other suffix raises
        ValueError.

    Returns
    -------
    tuple of dict
        (header, arrays, contact arrays); warns when the file was made by another
        state layout or kernel version.
    """
    path = _checked_suffix(path, "load a Result from")
    if path.suffix == ".nc":
        header, arrays, contacts = _read_dataset(path)
    else:
        header, arrays, contacts = _read_npz(path)
    stored = json.loads(header["provenance"])
    _check_provenance(path, stored, arrays["state_names"], json.loads(header["scene"]))
    arrays["flags"] = _flags_of(arrays["flags"], stored)
    return header, arrays, contacts


#: The arrays every ballc .npz holds (besides contact_* and latch_names).
NPZ_ARRAYS = ("header", "t", "y", "state_names", "flags", "latch")
#: The user events' arrays (files of earlier versions lack them).
EVENT_ARRAYS = ("event_index", "event_times", "event_states")
#: The keys of a file's header (files of earlier versions lack "method_switches").
HEADER_KEYS = ("scene", "provenance", "status", "message", "nfev", "njev", "nlu")


def _not_a_result(path, why: str) -> ValueError:
    return ValueError(f"cannot load {str(path)!r}: it is not a ballc result file ({why}); "
                      "ballc.load reads the .npz or .nc files that Result.save and `ballc run` "
                      f"(result.npz) write, with the arrays {', '.join(NPZ_ARRAYS)}")


#: What numpy and zipfile raise for a file that is no .npz, or a damaged or truncated
#: one (zipfile.BadZipFile is none of the others).
_UNREADABLE = (OSError, ValueError, EOFError, zipfile.BadZipFile, zlib.error)


def _read_npz(path):
    try:
        data = np.load(path, allow_pickle=False)
    except FileNotFoundError:
        raise
    except _UNREADABLE as error:    # not a .npz (pickle, text, empty), or truncated
        raise _not_a_result(path, f"not an .npz archive, or a damaged or truncated one: "
                            f"{error}") from None
    if not isinstance(data, np.lib.npyio.NpzFile):      # a single .npy array
        raise _not_a_result(path, "it holds one array, not an .npz archive")
    with data:
        missing = [name for name in NPZ_ARRAYS if name not in data.files]
        if missing:
            found = ", ".join(data.files[:8]) + (", ..." if len(data.files) > 8 else "")
            raise _not_a_result(path, f"it has no {', '.join(missing)}; it holds: "
                                f"{found or 'nothing'}")
        try:
            text = str(data["header"])
            contacts = {k[len("contact_"):]: data[k] for k in data.files
                        if k.startswith("contact_")}
            arrays = {k: data[k] for k in NPZ_ARRAYS[1:] + EVENT_ARRAYS if k in data.files}
        except _UNREADABLE as error:      # an archive member damaged or cut short
            raise _not_a_result(path, f"a damaged or truncated .npz archive: {error}") \
                from None
    return _header_of(path, text), arrays, contacts


def _header_of(path, text: str) -> dict:
    try:
        header = json.loads(text)
    except ValueError:
        header = None
    if not isinstance(header, dict) or any(key not in header for key in HEADER_KEYS):
        raise _not_a_result(path, f"its header is not ballc's: {text[:60]!r}")
    return header


def _to_dataset(result):
    try:
        import xarray as xr
    except ModuleNotFoundError:
        raise ModuleNotFoundError("saving a Result as netCDF needs xarray: "
                                  "pip install 'ballc[netcdf]' (or save as .npz)") from None
    variables = {"y": (("state", "time"), result.y, {"long_name": "state (SI units)"})}
    if result.flags is not None:
        # netCDF3 has no 64-bit integers: the flags' low and high 32 bits, as int32
        flags = np.asarray(result.flags, dtype=np.int64)
        variables["flags"] = (("time",), (flags & 0xFFFFFFFF).astype(np.uint32).view(np.int32))
        variables["flags_high"] = (("time",), (flags >> 32).astype(np.int32))
        variables["latch"] = (("latch_name", "time"), result.latch)
    for name, values in result.contact_arrays().items():
        dims = ("contact", f"{name}_component") if values.ndim == 2 else ("contact",)
        variables[f"contact_{name}"] = (dims, values)
    events = result.event_arrays()
    variables["event_index"] = (("event",), events["index"])
    variables["event_times"] = (("event",), events["times"], {"units": "s"})
    variables["event_states"] = (("event", "state"), events["states"])
    coords = {"time": ("time", result.t, {"units": "s"}),
              "state": list(result.state_names), "latch_name": list(result.scene.latch_names)}
    return xr.Dataset(variables, coords=coords, attrs=_header(result))


def _flags_read(ds) -> np.ndarray:
    """A netCDF file's flags (int64): its low 32 bits and, if written, its high ones."""
    if "flags" not in ds:
        return np.zeros(0)
    low = ds["flags"].values.astype(np.int32).view(np.uint32).astype(np.int64)
    if "flags_high" not in ds:
        return ds["flags"].values.astype(np.int64)   # a file from before 64-bit flags
    return low | (ds["flags_high"].values.astype(np.int64) << 32)


def _read_dataset(path):
    import xarray as xr
    with xr.open_dataset(path) as ds:
        ds.load()
        missing = [k for k in ("y", "time", "state") if k not in ds.variables] + [
            k for k in HEADER_KEYS if k not in ds.attrs]
        if missing:
            raise _not_a_result(path, f"it has no {', '.join(missing)}")
        arrays = {"t": ds["time"].values.astype(float), "y": ds["y"].values.astype(float),
                  "state_names": ds["state"].values.astype(str),
                  "flags": _flags_read(ds),
                  "latch": ds["latch"].values.astype(float) if "latch" in ds else np.zeros(0)}
        arrays.update({name: ds[name].values for name in EVENT_ARRAYS if name in ds})
        contacts = {k[len("contact_"):]: ds[k].values for k in ds.data_vars
                    if k.startswith("contact_")}
        header = dict(ds.attrs)
    contacts["plane"] = contacts["plane"].astype(str)
    return header, arrays, contacts
