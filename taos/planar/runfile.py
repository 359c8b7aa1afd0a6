"""Reading a run file (HDF5) without trusting it: the one validation every reader of a
``taos simulate`` run (:meth:`taos.planar.simulate.TimeHistory.from_hdf5`, ``taos view``) and of
an HDF5 record (:func:`taos.identify.data.load_test_data`, ``taos estimate``) goes through.

A dataset is read only when it is one: stored in the file itself (an external link to another
file is refused, whatever that file is), reached without a link loop, of a real numeric type
(integers or floats: text, compound and complex data are refused, never cast), one-dimensional
(or ``(k, n)`` where a table is expected), of the expected length, no larger than
:data:`taos.bounds.MAX_DATA_SAMPLES`, and finite. A run's physical signals are held to the same
magnitudes as a measured record's (:data:`SIGNAL_LIMITS`, the ``data`` group of
docs/reference/bounds.md), its moment arm to the model bound ``actuator.moment_arm``, its engine
name to :data:`ENGINES`. Each refusal is one line,
``InputError(file, dataset or attribute, expected, got)``; nothing is written by reading.
"""

from __future__ import annotations

import math

import numpy as np

from ..bounds import MAX_DATA_SAMPLES, MODEL_BOUNDS
from ..errors import InputError

#: largest magnitude of a signal, by unit kind (SI), and why: beyond it the column is in the
#: wrong unit or corrupt, and anything computed from it (a response, a drawn pose) would be absurd
SIGNAL_LIMITS = {
    "angle": (math.radians(45.0), "45 deg: no TVC gimbal swings further (RS-25: 10.5 deg)"),
    "length": (1.0, "1 m: a piston stroke is centimetres (RS-25 actuator: +-5 in)"),
    "pressure": (1e9, "1 GPa (145000 psi): hydraulic supplies are 3000-5000 psi"),
    "velocity": (100.0, "100 m/s: servo-actuator piston rates are below 1 m/s"),
}
#: a run file's per-axis arrays held to :data:`SIGNAL_LIMITS` (name -> unit kind)
RUN_SIGNAL_KINDS = {"command_rad": "angle", "command_avionics_rad": "angle", "engine_rad": "angle",
                    "piston_m": "length", "load_pressure_Pa": "pressure", "supply_pressure_Pa": "pressure",
                    "spool_flow_m_s": "velocity"}
#: SI unit of each kind of :data:`SIGNAL_LIMITS`
KIND_SI = {"angle": "rad", "length": "m", "pressure": "Pa", "velocity": "m/s"}
AXES = ("pitch", "yaw")
#: the engine models a run can use: the planar simplex model (:mod:`taos.planar`) and the 3-D
#: TAOS model (:mod:`taos.taos3d`)
ENGINES = ("simplex", "taos")


def open_hdf5(path, src: str, what: str):
    """``h5py.File(path, "r")`` of a regular, readable input, else InputError (one line)."""
    import h5py

    from ..errors import check_input_file

    check_input_file(path, what)
    try:
        return h5py.File(path, "r")
    except (OSError, ValueError, RuntimeError) as e:
        raise InputError(src, "(file)", what, got=" ".join(str(e).split())[:120]) from None


def node(h5, key: str, src: str):
    """The object at ``key``, following soft links inside the file only; None when absent."""
    import h5py

    g, parts = h5, [p for p in key.split("/") if p]
    for i, part in enumerate(parts):
        here = "/" + "/".join(parts[:i + 1])
        try:
            link = g.get(part, getlink=True) if isinstance(g, h5py.Group) else None
        except (RuntimeError, KeyError, OSError, ValueError) as e:
            raise InputError(src, here, "an object stored in this file", got=" ".join(str(e).split())[:100]) from None
        if link is None:
            return None
        if isinstance(link, h5py.ExternalLink):
            raise InputError(src, here, "an object stored in this file (not an external link to another file)",
                             got=f"a link to {link.filename}:{link.path}"[:120])
        try:
            g = g[part]
        except (RuntimeError, KeyError, OSError, ValueError) as e:   # a dangling link or a link loop
            raise InputError(src, here, "an object stored in this file (a link that resolves)",
                             got=" ".join(str(e).split())[:100]) from None
    return g


def has(h5, key: str, src: str) -> bool:
    """Whether ``key`` names an object of the file (external links and link loops refused)."""
    return node(h5, key, src) is not None


def dataset(h5, key: str, src: str, *, n: int | None = None, ndim: int = 1, rows: int | None = None,
            complex_ok: bool = False) -> np.ndarray:
    """The dataset at ``key`` as a float64 array, refused (InputError naming ``/key``) unless it is
    a real numeric dataset of ``ndim`` dimensions (1: ``(n,)``; 2: ``(rows, n)``), at most
    :data:`MAX_DATA_SAMPLES` samples long, every value finite. ``complex_ok``: complex data is
    read as complex128 (a frequency response), real data too."""
    import h5py

    ds = node(h5, key, src)
    name = "/" + key.strip("/")
    if ds is None:
        raise InputError(src, name, "a dataset of the layout", got="missing")
    if not isinstance(ds, h5py.Dataset):
        raise InputError(src, name, "a dataset of numbers", got="a group")
    kind = ds.dtype.kind
    if kind == "c" and not complex_ok:
        raise InputError(src, name, "real numbers", got=f"complex data ({ds.dtype})")
    if kind not in ("fiuc" if complex_ok else "fiu"):
        raise InputError(src, name, "numbers (integers or floats)", got=f"data of type {ds.dtype}")
    shape = ds.shape
    want = "(n,)" if ndim == 1 else f"({rows if rows is not None else 'k'}, n)"
    if shape is None or len(shape) != ndim or (ndim == 2 and rows is not None and shape[0] != rows):
        raise InputError(src, name, f"an array of shape {want}", got=f"shape {shape}")
    if shape[-1] > MAX_DATA_SAMPLES:
        raise InputError(src, name, f"at most {MAX_DATA_SAMPLES} samples", got=str(shape[-1]))
    if n is not None and shape[-1] != n:
        raise InputError(src, name, f"{n} samples like the time column", got=str(shape[-1]))
    try:
        x = np.asarray(ds[()], dtype=np.complex128 if complex_ok else np.float64)
    except (OSError, ValueError, TypeError, RuntimeError) as e:   # a filter missing, a corrupt chunk
        raise InputError(src, name, "readable numbers", got=" ".join(str(e).split())[:100]) from None
    bad = np.flatnonzero(~np.isfinite(x.ravel()))
    if bad.size:
        raise InputError(src, name, "finite numbers in every sample", got=f"{x.ravel()[bad[0]]} at sample {bad[0]}")
    return x


def text_attr(h5, name: str, src: str, default: str | None = None) -> str:
    """Root attribute ``name`` as text (bytes decoded as UTF-8), else InputError."""
    v = h5.attrs.get(name, default) if name in h5.attrs or default is not None else None
    if isinstance(v, bytes):
        try:
            v = v.decode("utf-8")
        except UnicodeDecodeError:
            v = None
    elif isinstance(v, np.str_):
        v = str(v)
    if not isinstance(v, str):
        raise InputError(src, name, "a text attribute", got="none" if v is None else repr(v)[:60])
    return v


def check_limits(x: np.ndarray, kind: str, src: str, field: str, si: str | None = None) -> None:
    """Magnitudes within :data:`SIGNAL_LIMITS` ``[kind]``, else InputError naming ``field``."""
    lim, why = SIGNAL_LIMITS[kind]
    si = si or KIND_SI[kind]
    if x.size:
        i = int(np.argmax(np.abs(x)))
        v = float(x.flat[i])
        if abs(v) > lim:
            raise InputError(src, field, f"magnitudes of at most {lim:g} {si} ({why})",
                             got=f"{v:.4g} {si} at sample {i % x.shape[-1]}")


def read_run(h5, src: str, arrays, optional=()) -> dict:
    """A run file's contents, validated: ``{"t_s", "axes", "moment_arm_m", "provenance", <array>:
    (n_axes, n)}`` for every name of ``arrays`` and of ``optional`` present on every axis.

    Checks: ``axes`` one or two distinct names of pitch/yaw; ``t_s`` of at least 2 finite,
    strictly increasing samples; every array real, finite, as long as ``t_s``, within
    :data:`SIGNAL_LIMITS` for its unit kind; ``moment_arm_m`` within the model bound; an
    ``engine`` attribute (when present) naming a known engine, ``taos`` exactly when the file has
    the 3-D ``/taos`` group."""
    text = text_attr(h5, "axes", src)
    axes = tuple(text.split(","))
    if not (1 <= len(axes) <= 2 and all(a in AXES for a in axes) and len(set(axes)) == len(axes)):
        raise InputError(src, "axes", "'pitch', 'yaw' or 'pitch,yaw'", got=repr(text)[:60])
    t = dataset(h5, "t_s", src)
    if t.size < 2 or np.any(np.diff(t) <= 0):
        raise InputError(src, "/t_s", "at least 2 strictly increasing sample times", got=f"{t.size} samples"
                         + ("" if t.size < 2 else " not increasing"))
    lo, hi, _, why = MODEL_BOUNDS["actuator.moment_arm"]
    arm = h5.attrs.get("moment_arm_m")
    try:
        arm_ok = arm is not None and np.ndim(arm) == 0 and not np.iscomplexobj(arm) and lo <= float(arm) <= hi
    except (TypeError, ValueError):
        arm_ok = False
    if not arm_ok:
        raise InputError(src, "moment_arm_m", f"a moment arm from {lo:g} to {hi:g} m ({why})", got=str(arm)[:60])
    three_d = has(h5, "taos", src)
    if "engine" in h5.attrs:
        engine = text_attr(h5, "engine", src)
        if engine not in ENGINES:
            raise InputError(src, "engine", "the engine that wrote the run: " + " or ".join(ENGINES), got=repr(engine)[:60])
        if (engine == "taos") != three_d:
            raise InputError(src, "engine", f"'{'taos' if three_d else 'simplex'}' (the file "
                             f"{'has' if three_d else 'has no'} /taos group)", got=repr(engine))
    out = {"t_s": t, "axes": axes, "moment_arm_m": float(arm)}
    for name in (*arrays, *[o for o in optional if all(has(h5, f"{ax}/{o}", src) for ax in axes)]):
        rows = [dataset(h5, f"{ax}/{name}", src, n=t.size) for ax in axes]
        if name in RUN_SIGNAL_KINDS:
            for ax, x in zip(axes, rows):
                check_limits(x, RUN_SIGNAL_KINDS[name], src, f"/{ax}/{name}")
        out[name] = np.vstack(rows)
    out["provenance"] = {k: v for k, v in h5.attrs.items() if k not in ("axes", "moment_arm_m")}
    return out
