"""A flight record for the PTI reconstruction (:mod:`taos.flight.pti`): what telemetry must hold.

Per axis (``pitch``, ``yaw``), sampled on one uniform time base ``t_s`` [s]:

* ``pti_rad``      the programmed test input r [rad], as injected (known exactly: the PTI table);
* ``command_rad``  the TVC engine-angle command u = u_fcs + r [rad]: the flight-control output
  with the PTI added, i.e. what the TVC (its avionics, then the actuators) receives;
* ``piston_m``     the actuator piston position x_p [m];
* ``engine_rad``   the engine angle theta [rad] (optional);
* ``rate_rad_s``   the vehicle attitude rate [rad/s] (optional; kept, not needed by the loop).

Two files are read (:func:`load_flight_record`):

* HDF5 in the layout :meth:`taos.flight.ascent_sim.AscentHistory.to_hdf5` writes (the output of
  ``taos ascent``): ``/t_s``, ``/<axis>/<signal>``, root attributes ``axes``, ``friction_model``
  and the run's provenance (a user's HDF5 in this layout is read alike);
* CSV with a header row ``t_s,<axis>_pti_rad,<axis>_command_rad,<axis>_piston_m[,<axis>_engine_rad]
  [,<axis>_rate_rad_s]`` for one or both axes, SI numbers (a telemetry export converted to SI).

Bad input raises :class:`~taos.errors.InputError` naming the file, the field and the expectation.
"""

from __future__ import annotations

import json
import math
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from taos.errors import InputError

REQUIRED = ("pti_rad", "command_rad", "piston_m")
OPTIONAL = ("engine_rad", "rate_rad_s")
MAX_SAMPLES = 20_000_000


@dataclass(frozen=True, eq=False)
class FlightRecord:
    """Telemetry of one flight (module docstring): ``t_s`` (n,) [s]; ``axes``; ``signals`` name ->
    (n_axes, n) SI arrays (the :data:`REQUIRED` ones always, the :data:`OPTIONAL` ones when
    recorded); ``friction_model`` of a simulated record ('' for telemetry); ``source``;
    ``provenance`` (a simulated record's run provenance)."""

    t_s: np.ndarray
    axes: tuple[str, ...]
    signals: dict
    friction_model: str = ""
    source: str = "<code>"
    provenance: dict = field(default_factory=dict)

    def signal(self, name: str, axis: str) -> np.ndarray | None:
        """One signal of one axis (SI), None when not recorded."""
        s = self.signals.get(name)
        return None if s is None else s[self.axes.index(axis)]

    @property
    def dt_s(self) -> float:
        """The sample interval [s]."""
        return float(self.t_s[1] - self.t_s[0])

    @classmethod
    def from_history(cls, h, source: str = "<simulation>") -> "FlightRecord":
        """The record of a simulated ascent (:class:`taos.flight.ascent_sim.AscentHistory`)."""
        sig = {k: np.asarray(h.signals[k], float) for k in REQUIRED + ("engine_rad", "rate_rad_s")}
        return cls(np.asarray(h.t_s, float), tuple(h.axes), sig, h.friction_model, source, dict(h.provenance))


#: the record's signals held to the record magnitudes (taos.planar.runfile.SIGNAL_LIMITS) -> unit kind
SIGNAL_KINDS = {"pti_rad": "angle", "command_rad": "angle", "engine_rad": "angle", "piston_m": "length"}


def _check(src: str, t: np.ndarray, sig: dict, axes: tuple) -> None:
    from taos.planar.runfile import check_limits

    if t.ndim != 1 or t.size < 16 or t.size > MAX_SAMPLES:
        raise InputError(src, "t_s", f"16 to {MAX_SAMPLES} samples", got=str(t.size))
    with np.errstate(over="ignore", invalid="ignore"):   # times beyond reason are refused here, not warned about
        d = np.diff(t)
        bad = not np.all(np.isfinite(t)) or not np.all(np.isfinite(d)) or not np.all(d > 0) \
            or np.ptp(d) > 1e-6 * max(float(d.mean()), 1e-12) + 1e-9
    if bad:
        raise InputError(src, "t_s", "strictly increasing, uniformly spaced finite times in s")
    for name, a in sig.items():
        if a.shape != (len(axes), t.size):
            raise InputError(src, name, f"{t.size} samples per axis", got=str(a.shape[-1]))
        if not np.all(np.isfinite(a)):
            raise InputError(src, name, "finite numbers", got="NaN or infinite values")
        if name in SIGNAL_KINDS:
            check_limits(a, SIGNAL_KINDS[name], src, name)


def _read_hdf5(p: Path, src: str) -> FlightRecord:
    """Every dataset read through the run-file reader (:mod:`taos.planar.runfile`: stored in the
    file itself, real, 1-D, finite, as long as ``/t_s``)."""
    from taos.planar.runfile import dataset, has, open_hdf5

    with open_hdf5(p, src, "a readable HDF5 flight record") as h5:
        if not has(h5, "t_s", src):
            raise InputError(src, "/t_s", "the time base in s (the layout of taos ascent)", got="nothing")
        t = dataset(h5, "t_s", src)
        axes = tuple(a for a in ("pitch", "yaw") if has(h5, a, src))
        if not axes:
            raise InputError(src, "/pitch or /yaw", "a group per axis", got="none")
        sig = {}
        for name in REQUIRED + OPTIONAL:
            have = [has(h5, f"{a}/{name}", src) for a in axes]
            if name in REQUIRED and not all(have):
                ax = axes[have.index(False)]
                raise InputError(src, f"/{ax}/{name}", "this signal (module taos.flight.pti_record)", got="nothing")
            if all(have):
                sig[name] = np.vstack([dataset(h5, f"{a}/{name}", src, n=t.size) for a in axes])
        prov = {}
        for k, v in h5.attrs.items():
            v = v.decode("utf-8", "replace") if isinstance(v, bytes) else v
            if isinstance(v, str) and v[:1] in "{[":
                try:
                    v = json.loads(v)
                except ValueError:
                    pass
            prov[k] = v.item() if hasattr(v, "item") and getattr(v, "size", 2) == 1 else v
        fm = str(h5.attrs.get("friction_model", ""))
    prov = {k: v for k, v in prov.items() if isinstance(v, (str, int, float, dict, list))}
    _check(src, t, sig, axes)
    return FlightRecord(t, axes, sig, fm, src, prov)


def _read_csv(p: Path, src: str) -> FlightRecord:
    from taos.errors import check_input_file

    check_input_file(p, "a readable UTF-8 CSV flight record")
    try:
        with open(p, encoding="utf-8") as fh:
            header = [h.strip() for h in fh.readline().split(",")]
    except (OSError, UnicodeDecodeError):
        raise InputError(src, "(file)", "a readable UTF-8 CSV flight record") from None
    if not header or header[0] != "t_s":
        raise InputError(src, "header", "first column t_s (then <axis>_<signal> columns in SI)",
                         got=repr(",".join(header))[:80])
    known = {f"{a}_{s}" for a in ("pitch", "yaw") for s in REQUIRED + OPTIONAL}
    for h in header[1:]:
        if h not in known:
            raise InputError(src, f"column {h!r}", "one of t_s, <pitch|yaw>_<" + "|".join(REQUIRED + OPTIONAL) + ">")
    if len(set(header)) != len(header):
        raise InputError(src, "header", "each column once")
    try:
        with warnings.catch_warnings():   # a header without rows: refused by _check's sample count
            warnings.filterwarnings("ignore", "loadtxt: input contained no data")
            data = np.loadtxt(p, delimiter=",", skiprows=1, ndmin=2, encoding="utf-8")
    except (ValueError, UnicodeDecodeError) as e:
        raise InputError(src, "(rows)", "numbers only, one per column", got=str(e).splitlines()[0][:80]) from None
    if data.size == 0:
        raise InputError(src, "(rows)", "16 or more rows of numbers after the header", got="none")
    if data.shape[1] != len(header):
        raise InputError(src, "(rows)", f"{len(header)} numbers per row", got=str(data.shape[1]))
    col = {h: data[:, i] for i, h in enumerate(header)}
    axes = tuple(a for a in ("pitch", "yaw") if any(h.startswith(a + "_") for h in header))
    if not axes:
        raise InputError(src, "header", "the columns of at least one axis")
    sig = {}
    for name in REQUIRED + OPTIONAL:
        have = [f"{a}_{name}" in col for a in axes]
        if name in REQUIRED and not all(have):
            raise InputError(src, f"{axes[have.index(False)]}_{name}", "this column", got="nothing")
        if all(have):
            sig[name] = np.vstack([col[f"{a}_{name}"] for a in axes])
    t = col["t_s"]
    _check(src, t, sig, axes)
    return FlightRecord(t, axes, sig, "", src, {})


def load_flight_record(path: str | Path) -> FlightRecord:
    """Read a flight record (module docstring): ``.h5``/``.hdf5`` or ``.csv``."""
    p = Path(path)
    src = str(p)
    if not p.is_file():
        raise InputError(src, "(file)", "an existing flight record (.h5 or .csv)", got="no such file")
    suf = p.suffix.lower()
    if suf in (".h5", ".hdf5"):
        return _read_hdf5(p, src)
    if suf == ".csv":
        return _read_csv(p, src)
    raise InputError(src, "(file)", "a .h5/.hdf5 or .csv flight record", got=repr(p.suffix))


def record_window(rec: FlightRecord, t0_s: float, t1_s: float) -> slice:
    """The sample slice of [t0, t1] [s] (clipped to the record)."""
    i0 = max(0, int(math.ceil((t0_s - rec.t_s[0]) / rec.dt_s - 1e-9)))
    i1 = min(rec.t_s.size, int(math.floor((t1_s - rec.t_s[0]) / rec.dt_s + 1e-9)) + 1)
    return slice(i0, max(i0, i1))
