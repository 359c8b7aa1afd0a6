"""The TVC describing function N(A, w): amplitude- and frequency-dependent engine response.

N(A, w) = theta_1 / theta_c,1, the complex ratio of the fundamentals of the engine angle and
of the FCS command theta_c = A sin(w t), with the avionics (quantisation, crossover gain) and
the gimbal friction in the path (seed paper sections 3.1-3.2; Gelb & Vander Velde,
*Multiple-Input Describing Functions and Nonlinear System Design*, 1968, ch. 2 and 5). It is
measured by sine dwell on the nonlinear simplex model (:func:`taos.planar.freqresp.sine_dwell_grid`,
the compiled integrator) over a grid of amplitudes x frequencies and interpolated in
(log A, log f) bilinearly in gain [dB] and unwrapped phase [deg]; outside the grid the
nearest edge value is held.

:func:`rigid_engine_response` is the analytic check: with a rigid load path the engine
angle is the piston angle and friction acts on the engine rate in a linear loop; replacing it
by the law's analytic describing function N(V, w) (V the rate amplitude; Coulomb:
4 T_c / (pi V)) gives theta / theta_c = G_c / (1 + j w G_f N(w |theta|, w)), solved for
|theta| by a bracketed root search.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field

import numpy as np

from taos.bounds import check_instance, check_response_args
from taos.errors import InputError
from taos.planar.freqresp import sine_dwell_points
from taos.linear import StateSpace, gain_db, phase_deg
from taos.model import Structure, TvcModel
from taos.results import atomic_write, package_version, write_json, write_provenance
from taos.planar.simplex import simplex_state_space
from taos.planar.simulate import DEFAULT_DT_S
from taos.results import model_provenance

#: gain floor [dB] below which the engine is taken as stuck (phase is then borrowed from the
#: nearest amplitude at which it moves; the gain itself is kept, floored here)
STUCK_DB = -120.0


def _unwrap_map(h: np.ndarray) -> np.ndarray:
    """Phase [deg] of a (n_amp, n_freq) map, unwrapped along frequency from the lowest, and
    each amplitude row shifted by whole turns to lie within 180 deg of its neighbour at the
    lowest frequency (stuck rows borrow the nearest moving row's phase)."""
    g = gain_db(h)
    ph = phase_deg(h, axis=1)
    moving = (g > STUCK_DB).all(axis=1)
    if moving.any():
        idx = np.flatnonzero(moving)
        for i in range(h.shape[0]):
            if not moving[i]:
                ph[i] = ph[idx[np.argmin(np.abs(idx - i))]]
    for i in range(1, h.shape[0]):
        ph[i] -= 360.0 * np.round((ph[i, 0] - ph[i - 1, 0]) / 360.0)
    # the largest amplitude anchors the branch nearest 0 deg at low frequency
    ph -= 360.0 * np.round(ph[-1, 0] / 360.0)
    return ph


@dataclass(frozen=True, eq=False)
class DescribingFunctionMap:
    """N(A, w) of the TVC on a grid (SI): command amplitude ``amplitude_rad`` (n_a, increasing),
    ``freq_hz`` (n_f, increasing), complex ``engine`` = theta/theta_c and ``piston`` =
    x_p/(R theta_c), shape (n_a, n_f). Call it to interpolate."""

    amplitude_rad: np.ndarray
    freq_hz: np.ndarray
    engine: np.ndarray
    piston: np.ndarray
    friction_model: str
    axis: str = "pitch"
    load_stiffness_N_per_m: float = float("nan")
    provenance: dict = field(default_factory=dict)

    # -- views ------------------------------------------------------------------------------
    def gain_db(self, which: str = "engine") -> np.ndarray:
        """20 log10 |N| [dB], floored at :data:`STUCK_DB`."""
        return np.maximum(gain_db(getattr(self, which)), STUCK_DB)

    def phase_deg(self, which: str = "engine") -> np.ndarray:
        """Unwrapped phase [deg] (see :func:`_unwrap_map`)."""
        return _unwrap_map(getattr(self, which))

    def __call__(self, amplitude_rad, freq_hz, which: str = "engine"):
        """Interpolated complex gain at (A [rad], f [Hz]) (broadcast): bilinear in
        (log A, log f) on gain dB and unwrapped phase, edge values held outside the grid."""
        la = np.log(np.clip(np.asarray(amplitude_rad, float), self.amplitude_rad[0], self.amplitude_rad[-1]))
        lf = np.log(np.clip(np.asarray(freq_hz, float), self.freq_hz[0], self.freq_hz[-1]))
        la, lf = np.broadcast_arrays(la, lf)
        ga = np.log(self.amplitude_rad)
        gf = np.log(self.freq_hz)
        ia = np.clip(np.searchsorted(ga, la) - 1, 0, max(ga.size - 2, 0))
        jf = np.clip(np.searchsorted(gf, lf) - 1, 0, max(gf.size - 2, 0))
        ta = (la - ga[ia]) / (ga[ia + 1] - ga[ia]) if ga.size > 1 else np.zeros_like(la)
        tf = (lf - gf[jf]) / (gf[jf + 1] - gf[jf]) if gf.size > 1 else np.zeros_like(lf)
        ia1 = np.minimum(ia + 1, ga.size - 1)
        jf1 = np.minimum(jf + 1, gf.size - 1)
        out = []
        for M in (self.gain_db(which), self.phase_deg(which)):
            out.append((1 - ta) * (1 - tf) * M[ia, jf] + ta * (1 - tf) * M[ia1, jf]
                       + (1 - ta) * tf * M[ia, jf1] + ta * tf * M[ia1, jf1])
        g, p = out
        h = 10 ** (g / 20) * np.exp(1j * np.radians(p))
        return complex(h) if h.ndim == 0 else h

    # -- export -----------------------------------------------------------------------------
    def to_dict(self) -> dict:
        """JSON-able: SI arrays plus degrees / dB per field habit."""
        return {
            "friction_model": self.friction_model,
            "axis": self.axis,
            "load_stiffness_N_per_m": self.load_stiffness_N_per_m,
            "amplitude_deg": np.degrees(self.amplitude_rad).tolist(),
            "freq_hz": self.freq_hz.tolist(),
            "engine": {"gain_db": self.gain_db("engine").tolist(), "phase_deg": self.phase_deg("engine").tolist()},
            "piston": {"gain_db": self.gain_db("piston").tolist(), "phase_deg": self.phase_deg("piston").tolist()},
            "provenance": self.provenance,
        }

    def to_json(self, path) -> None:
        write_json(str(path), self.to_dict())

    def to_hdf5(self, path) -> None:
        """Atomically: /amplitude_rad, /freq_hz, /engine, /piston (complex), attributes."""
        import h5py

        def write(tmp):
            with h5py.File(tmp, "w") as h5:
                for k in ("amplitude_rad", "freq_hz", "engine", "piston"):
                    h5.create_dataset(k, data=getattr(self, k))
                h5.attrs["friction_model"] = self.friction_model
                h5.attrs["axis"] = self.axis
                h5.attrs["load_stiffness_N_per_m"] = self.load_stiffness_N_per_m
                write_provenance(h5, {"provenance": self.provenance})
        atomic_write(path, write)

    @classmethod
    def from_hdf5(cls, path) -> "DescribingFunctionMap":
        """Read a map written by :meth:`to_hdf5`, validated by the run-file reader
        (:mod:`taos.planar.runfile`): positive finite amplitudes and frequencies, finite complex
        responses of shape (amplitudes, frequencies), the axis pitch or yaw, a finite load
        stiffness, JSON provenance; InputError (one line) otherwise."""
        from ..planar.runfile import dataset, open_hdf5, text_attr

        src = str(path)
        with open_hdf5(path, src, "an HDF5 describing-function map written by taos") as h5:
            a, f = dataset(h5, "amplitude_rad", src), dataset(h5, "freq_hz", src)
            for name, x in (("/amplitude_rad", a), ("/freq_hz", f)):
                if not (x.size and np.all(x > 0)):
                    raise InputError(src, name, "positive values", got=f"{x.size} values, smallest "
                                     f"{x.min() if x.size else 'none'}")
            resp = {k: dataset(h5, k, src, ndim=2, rows=a.size, n=f.size, complex_ok=True) for k in ("engine", "piston")}
            axis = text_attr(h5, "axis", src)
            if axis not in ("pitch", "yaw"):
                raise InputError(src, "axis", "pitch or yaw", got=repr(axis)[:40])
            try:
                k = float(h5.attrs.get("load_stiffness_N_per_m"))
                prov = json.loads(text_attr(h5, "provenance", src))
            except (TypeError, ValueError, RecursionError):
                k, prov = -1.0, None
            if not ((math.isnan(k) or 0 <= k < math.inf) and isinstance(prov, dict)):   # NaN: not recorded
                raise InputError(src, "load_stiffness_N_per_m", "a stiffness of at least 0 N/m (NaN: not recorded) "
                                 "and JSON provenance", got=str(k))
            return cls(amplitude_rad=a, freq_hz=f, **resp, friction_model=text_attr(h5, "friction_model", src),
                       axis=axis, load_stiffness_N_per_m=k, provenance=prov)


def describing_function_map(model: TvcModel, amplitudes_rad: np.typing.ArrayLike, freq_hz: np.typing.ArrayLike,
                            axis: str = "pitch", *,
                            settle_cycles: int = 2, measure_cycles: int = 2, settle_s: float | None = None,
                            dt_max_s: float = DEFAULT_DT_S, method: str = "settle") -> DescribingFunctionMap:
    """N(A, w) by sine dwell on the nonlinear simplex model (friction and avionics in the path).

    Parameters
    ----------
    model : TvcModel
    amplitudes_rad, freq_hz : command amplitudes [rad] and frequencies [Hz] (sorted here)
    axis : 'pitch' or 'yaw'
    settle_cycles, measure_cycles, settle_s, dt_max_s : sine-dwell settings
        (:func:`taos.planar.freqresp.sine_dwell_grid`; settle at least ``settle_s`` [s], default four
        decades of the slowest linear mode).
    method : 'settle' or 'shoot'
        How each dwell reaches its periodic orbit (:func:`taos.planar.freqresp.sine_dwell_points`;
        'shoot': the periodic steady state by shooting, :mod:`taos.planar.steady`).
    """
    check_instance(model, "model", TvcModel, "a TvcModel (taos.load_model)")
    check_response_args(freq_hz, amplitudes_rad, axis)   # as given: text or booleans are refused, not converted
    amps = np.sort(np.atleast_1d(np.asarray(amplitudes_rad, float)))
    f = np.sort(np.atleast_1d(np.asarray(freq_hz, float)))
    check_response_args(f, amps, axis)   # the grid of taos.planar.freqresp.sine_dwell_grid, with its solver's account
    A, F = np.meshgrid(amps, f, indexing="ij")
    pts = sine_dwell_points(model, A.ravel(), F.ravel(), axis, dt_max_s=dt_max_s, settle_cycles=settle_cycles,
                            measure_cycles=measure_cycles, settle_s=settle_s, method=method)
    piston, engine = pts.piston.reshape(A.shape), pts.engine.reshape(A.shape)
    # the settings as asked (the lco module matches a reused map on them) and the solver's own account
    prov = {**model_provenance(model), "package_version": package_version(),
            "method": "sine-dwell", "steady_state": method, "dt_max_s": dt_max_s, "settle_cycles": settle_cycles,
            "measure_cycles": measure_cycles, "settle_s": settle_s, "solver": pts.solver}
    return DescribingFunctionMap(amps, f, engine, piston, model.friction.name, axis,
                                 model.structure.load_stiffness_N_per_m, prov)


# -- analytic check: the friction describing function in the rigid-load loop ----------------------
def rigid_limit_model(model: TvcModel, stiffness_factor: float = 1000.0) -> TvcModel:
    """The model with its load path ``stiffness_factor`` times stiffer and ideal avionics."""
    return model.replace(structure=Structure(model.structure.load_stiffness_N_per_m * stiffness_factor),
                         avionics=model.avionics.ideal())


def rigid_engine_response(model: TvcModel, amplitude_rad: float, freq_hz: float,
                          axis: str = "pitch") -> complex:
    """Analytic friction-in-loop engine response theta/theta_c [-] from the friction law's
    describing function (:meth:`taos.friction.FrictionLaw.rate_describing_function`: the
    analytic one where the law has one, else the law's own, simulated alone).

    The linear simplex block gives theta = G_c theta_c - G_f T_f (G_c, G_f exact at j w).
    Replacing T_f by its describing function on the engine rate, T_f = N(V, w) (j w theta),
    V = w |theta| (Coulomb: N = 4 T_c / (pi V)), gives theta/theta_c = G_c / (1 + j w G_f N),
    solved for |theta| by a bracketed root search (largest root). (Valid while the engine
    slides through most of the cycle; with a rigid load path the piston and engine
    coincide.) ``amplitude_rad`` command amplitude [rad], ``freq_hz`` [Hz]."""
    import scipy.optimize

    law = model.friction
    w = 2 * math.pi * freq_hz
    ss: StateSpace = simplex_state_space(model, axis)
    h = ss.freqresp([freq_hz], ["command_rad", "friction_torque_Nm"], "theta_rad")[0]
    gc, gf = complex(h[0]), -complex(h[1])

    def resp(mag):
        return gc / (1 + 1j * w * gf * law.rate_describing_function(w * mag, w))

    # |theta| = A |resp(|theta|)|: bracket from the linear amplitude downwards, take the largest root
    hi = 2 * abs(gc) * amplitude_rad
    grid = hi * np.logspace(0, -6, 241)
    res = np.array([m - amplitude_rad * abs(resp(m)) for m in grid])
    k = np.flatnonzero(np.sign(res[:-1]) != np.sign(res[1:]))
    if k.size == 0:
        return 0j  # no sliding solution: the relay holds the engine
    mag = scipy.optimize.brentq(lambda m: m - amplitude_rad * abs(resp(m)), grid[k[0] + 1], grid[k[0]],
                                xtol=1e-16, rtol=1e-13)
    return resp(mag)
