"""Flight-control limit cycles from gimbal friction: describing-function prediction and
time-domain confirmation (seed paper sections 3.1-3.2, figures 6-8).

Prediction (harmonic balance, Gelb & Vander Velde 1968, ch. 2): with the loop L0(j w) broken
at the TVC command (:func:`taos.flight.vehicle.loop_freqresp`) and the TVC's describing function
N(A, w) (:class:`taos.flight.describing.DescribingFunctionMap`), a limit cycle of command amplitude A
and frequency w satisfies

    L0(j w) N(A, w) = -1,  i.e.  20 log10|L0 N| = 0 dB  and  arg(L0 N) = -180 deg (mod 360).

The two real equations are searched on a fine (log A, log f) grid over the map (cells where
both change sign), then refined with a root finder. Stability by Loeb's criterion: with
U + j V = 1 + L0 N, the cycle is stable if dU/dA dV/dw - dU/dw dV/dA > 0 (derivatives by
central differences on the interpolated map). Without a cycle the remaining margin is the
smallest gain margin of L0 N(A, .) over the map's amplitudes.

Time domain: the closed flight loop (:func:`taos.flight.vehicle.flight_plant`) with the nonlinear
simplex TVC, from a small initial attitude error, integrated by the compiled RK4 kernel;
the settled oscillation of the FCS command (the describing function's input) and of the
engine angle is measured over the final window by a least-squares fit of the fundamental at
the spectral peak frequency.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field

import numpy as np

from taos.errors import InputError
from taos.harmonics import harmonic_amplitudes as _fit
from taos.flight.describing import DescribingFunctionMap, describing_function_map
from taos.flight.vehicle import FlightModel, Margins, flight_plant, loop_freqresp, margins
from taos.linear import StateSpace, gain_db, phase_deg
from taos.model import TvcModel
from taos.results import atomic_write, model_provenance, package_version, write_provenance
from taos.planar.avionics import Avionics
from taos.planar.simulate import DEFAULT_DT_S, integrate_plant

DEG = math.pi / 180.0
#: default describing-function grid for the flight loop: command amplitudes [deg], frequencies [Hz]
DEFAULT_AMPLITUDES_DEG = tuple(np.round(np.logspace(np.log10(0.01), 0.0, 11), 5))
DEFAULT_FREQ_HZ = tuple(np.round(np.logspace(np.log10(0.03), np.log10(2.0), 10), 5))


#: the paper's bounding avionics gain for the flight LCO analysis [dB] (sec. 2.3: "at most ... a -1 dB
#: decrease in flight control loop gain ... and such a gain was applied during the bounding model assessment")
BOUNDING_AVIONICS_GAIN_DB = -1.0


def with_bounding_avionics(model: TvcModel, gain_db: float = BOUNDING_AVIONICS_GAIN_DB) -> TvcModel:
    """The model with its command avionics replaced by the paper's bounding assessment: a
    constant gain of ``gain_db`` [dB] and no quantisation. The flown 12-bit truncation makes the
    describing function vanish below one LSB, so in a conditionally stable loop it alone
    sustains a cycle of one to three LSB (~0.01 deg) whatever the friction; the bounding
    analysis replaced it by this gain, valid "for reasonable TVC motions above base
    quantization level" (paper sec. 2.3)."""
    g = 10.0 ** (gain_db / 20.0)
    # an analysis choice made in code (recorded as code.avionics in the model's overrides and hash)
    return model.replace(avionics=Avionics(gain_table_rad=(0.0,), gain_table=(g,)))


@dataclass(frozen=True)
class LimitCycle:
    """One harmonic-balance solution: command amplitude A [rad], frequency [Hz], Loeb
    stability, and the engine-angle amplitude |N(A, w)| A [rad]."""

    amplitude_rad: float
    freq_hz: float
    stable: bool
    engine_amplitude_rad: float
    loeb: float

    def to_dict(self) -> dict:
        return {"amplitude_deg": math.degrees(self.amplitude_rad), "frequency_hz": self.freq_hz,
                "stable": self.stable, "engine_amplitude_deg": math.degrees(self.engine_amplitude_rad),
                "loeb": self.loeb}


@dataclass(frozen=True, eq=False)
class LcoPrediction:
    """Describing-function LCO prediction for one flight loop and TVC map."""

    df: DescribingFunctionMap
    cycles: tuple[LimitCycle, ...]
    margin_db: float
    margins_by_amplitude: tuple[Margins, ...]
    flight: FlightModel = field(repr=False)
    axis: str = "yaw"
    #: why a cycle may lie outside the map's amplitudes (:func:`grid_edge_warnings`); empty: none
    grid_warnings: tuple[str, ...] = ()

    @property
    def grid_may_miss_cycle(self) -> bool:
        """True when the harmonic-balance condition is still unmet and moving towards a cycle at
        an edge of the map's amplitudes: a cycle may lie beyond it (:func:`grid_edge_warnings`)."""
        return bool(self.grid_warnings)

    @property
    def stable_cycle(self) -> LimitCycle | None:
        """The stable limit cycle of largest amplitude, if any."""
        st = [c for c in self.cycles if c.stable]
        return max(st, key=lambda c: c.amplitude_rad) if st else None

    def loop(self, freq_hz) -> np.ndarray:
        """L0(j w) [-] of the flight loop without the TVC."""
        return loop_freqresp(self.flight, freq_hz, self.axis)

    def open_loop(self, amplitude_rad: float, freq_hz) -> np.ndarray:
        """L0(j w) N(A, w) [-] at command amplitude ``amplitude_rad`` [rad]."""
        f = np.asarray(freq_hz, float)
        return self.loop(f) * self.df(amplitude_rad, f)

    def margins_at(self, amplitude_rad: float, n: int = 400) -> Margins:
        """Margins of L0 N(A, .) over the map's frequency range."""
        f = np.logspace(np.log10(self.df.freq_hz[0]), np.log10(self.df.freq_hz[-1]), n)
        return margins(f, self.open_loop(amplitude_rad, f))

    def to_dict(self) -> dict:
        c = self.stable_cycle
        return {"lco": c is not None,
                "amplitude_deg": None if c is None else math.degrees(c.amplitude_rad),
                "engine_amplitude_deg": None if c is None else math.degrees(c.engine_amplitude_rad),
                "frequency_hz": None if c is None else c.freq_hz,
                "stable": None if c is None else c.stable,
                # no margin is stated when a cycle may lie outside the map: it would be the map's, not the loop's
                "margin_db": (self.margin_db if math.isfinite(self.margin_db) and not self.grid_may_miss_cycle
                              else None),
                "grid_may_miss_cycle": self.grid_may_miss_cycle, "grid_warnings": list(self.grid_warnings),
                "cycles": [x.to_dict() for x in self.cycles]}


def _wrap180(x):
    return (np.asarray(x) + 180.0) % 360.0 - 180.0


def predict_lco(flight: FlightModel, df: DescribingFunctionMap, axis: str | None = None,
                n_grid: int = 160) -> LcoPrediction:
    """Solve L0(j w) N(A, w) = -1 over the map (see the module docstring)."""
    import scipy.optimize

    from ._args import check_predict_args

    check_predict_args(flight, df, axis, n_grid)

    axis = axis or flight.axis
    la = np.linspace(np.log(df.amplitude_rad[0]), np.log(df.amplitude_rad[-1]), n_grid)
    lf = np.linspace(np.log(df.freq_hz[0]), np.log(df.freq_hz[-1]), n_grid)
    f = np.exp(lf)
    L0 = loop_freqresp(flight, f, axis)
    l0db = gain_db(L0)
    l0ph = phase_deg(L0)

    def nichols(lA, lF):
        """(gain dB, phase error to -180 mod 360) of L0 N at scalar log A, log f."""
        ff = math.exp(lF)
        L = complex(loop_freqresp(flight, [ff], axis)[0])
        h = L * df(math.exp(lA), ff)
        return np.array([float(gain_db(h)), float(_wrap180(math.degrees(math.atan2(h.imag, h.real)) + 180.0))])

    A, F = np.meshgrid(la, lf, indexing="ij")
    N = df(np.exp(A), np.exp(F))
    G = l0db[None, :] + gain_db(N)
    E = _wrap180(l0ph[None, :] + np.degrees(np.angle(N)) + 180.0)
    found: list[tuple[float, float]] = []
    # the grid cells whose corners bracket both 0 dB and -180 deg (phase error within 90 deg),
    # in row-major order (amplitude, then frequency); each one starts a root search
    g4 = np.stack((G[:-1, :-1], G[1:, :-1], G[:-1, 1:], G[1:, 1:]))
    e4 = np.stack((E[:-1, :-1], E[1:, :-1], E[:-1, 1:], E[1:, 1:]))
    skip = ((g4.min(0) > 0) | (g4.max(0) < 0) | (e4.min(0) > 0) | (e4.max(0) < 0)
            | (np.abs(e4).max(0) > 90))
    for i, j in zip(*np.nonzero(~skip)):
        x0 = np.array([0.5 * (la[i] + la[i + 1]), 0.5 * (lf[j] + lf[j + 1])])
        sol = scipy.optimize.root(lambda x: nichols(*x), x0, method="hybr", options={"xtol": 1e-10})
        x = sol.x if sol.success else x0
        if not (la[0] - 1e-9 <= x[0] <= la[-1] + 1e-9 and lf[0] - 1e-9 <= x[1] <= lf[-1] + 1e-9):
            x = x0
        if np.abs(nichols(*x)).max() > 0.5:
            x = x0
        if all(abs(x[0] - a) > 0.05 or abs(x[1] - b) > 0.05 for a, b in found):
            found.append((float(x[0]), float(x[1])))
    cycles = []
    for lA, lF in sorted(found):
        Ar, fr = math.exp(lA), math.exp(lF)
        w = 2 * math.pi * fr

        def uv(Ax, wx):
            h = 1.0 + complex(loop_freqresp(flight, [wx / (2 * math.pi)], axis)[0]) * df(Ax, wx / (2 * math.pi))
            return h.real, h.imag

        dA, dw = 0.02 * Ar, 0.02 * w
        Up, Vp = uv(Ar + dA, w)
        Um, Vm = uv(Ar - dA, w)
        Uq, Vq = uv(Ar, w + dw)
        Un, Vn = uv(Ar, w - dw)
        loeb = ((Up - Um) / (2 * dA)) * ((Vq - Vn) / (2 * dw)) - ((Uq - Un) / (2 * dw)) * ((Vp - Vm) / (2 * dA))
        loeb *= Ar * w  # dimensionless (log derivatives)
        cycles.append(LimitCycle(Ar, fr, bool(loeb > 0), abs(df(Ar, fr)) * Ar, float(loeb)))
    # remaining margin: the smallest gain distance [dB] of the L0 N(A, .) curves from 0 dB at
    # their -180 deg crossings, over the fine amplitude grid (0 when a cycle exists)
    dist = []
    for i in range(n_grid):
        e = E[i]
        k = np.flatnonzero((np.sign(e[:-1]) != np.sign(e[1:])) & (np.abs(e[:-1]) < 90) & (np.abs(e[1:]) < 90))
        for j in k:
            t = e[j] / (e[j] - e[j + 1])
            dist.append(abs(G[i, j] + t * (G[i, j + 1] - G[i, j])))
    margin = 0.0 if cycles else (float(min(dist)) if dist else float("inf"))
    per_amp = tuple(margins(f, L0 * df(a, f)) for a in df.amplitude_rad)
    pred = LcoPrediction(df=df, cycles=tuple(cycles), margin_db=margin,
                         margins_by_amplitude=per_amp, flight=flight, axis=axis)
    return dataclasses.replace(pred, grid_warnings=grid_edge_warnings(pred))


def grid_edge_warnings(pred: LcoPrediction) -> tuple[str, ...]:
    """Why a cycle may lie outside the map's command amplitudes (empty: no sign of one).

    * largest amplitude: the loop with the TVC there is still unstable (a negative phase margin
      or a negative signed low-frequency gain margin, :func:`taos.flight.lco_verdict.grows_beyond_map`):
      motion grows past the map, so a stable cycle (or divergence) lies above it;
    * smallest amplitude: the loop there is stable, no cycle is found in the map, and the signed
      gain distance from harmonic balance shrinks towards the smallest amplitude: extrapolated, it
      reaches 0 dB below the map, where a cycle may lie."""
    from taos.flight.lco_verdict import grows_beyond_map, low_frequency_crossing_hz, signed_low_gain_margin
    out = []
    top = grows_beyond_map(pred)
    if top:
        out.append(top)
    a = pred.df.amplitude_rad
    if not pred.cycles and a.size >= 2:
        f0 = low_frequency_crossing_hz(pred)
        g0 = signed_low_gain_margin(pred, float(a[0]), f0)[0] if f0 is not None else None
        g1 = signed_low_gain_margin(pred, float(a[1]), f0)[0] if f0 is not None else None
        pm0 = pred.margins_by_amplitude[0].phase_margin_deg
        if g0 is not None and g1 is not None and 0 <= g0 < g1 and (pm0 is None or pm0 >= 0):
            out.append(f"the loop's low-frequency gain margin falls towards the map's smallest amplitude "
                       f"{math.degrees(a[0]):.3g} deg ({g1:.3g} dB at {math.degrees(a[1]):.3g} deg, {g0:.3g} dB "
                       f"there): a cycle may lie below it")
    return tuple(out)


#: automatic extension of a describing-function map whose edges may hide a cycle: rounds per edge
#: and the factor of each round (the largest amplitude times 2, the smallest divided by 3)
EXTEND_ROUNDS = 3
EXTEND_UP, EXTEND_DOWN = 2.0, 3.0


def extend_to_cover(flight: FlightModel, flown: TvcModel, df: DescribingFunctionMap, axis: str,
                    rounds: int = EXTEND_ROUNDS) -> LcoPrediction:
    """:func:`predict_lco`, with the map's amplitudes extended (at most ``rounds`` rows per edge,
    the dwells of the map's own settings on the flown model ``flown``) while its edge warnings say
    a cycle may lie beyond. The prediction returned carries the map as extended and, when the
    bounded extension did not settle it, its warnings."""
    pred = predict_lco(flight, df, axis)
    lsb = flown.avionics.lsb_rad
    for _ in range(max(int(rounds), 0)):
        if not pred.grid_warnings:
            break
        a = df.amplitude_rad
        new = []
        if any("largest" in w for w in pred.grid_warnings):
            new.append(float(a[-1]) * EXTEND_UP)
        if any("smallest" in w for w in pred.grid_warnings) and float(a[0]) / EXTEND_DOWN >= 0.5 * lsb:
            new.append(float(a[0]) / EXTEND_DOWN)
        if not new:
            break
        pv = df.provenance
        rows = describing_function_map(flown, new, df.freq_hz, axis, settle_cycles=pv.get("settle_cycles", 1),
                                       measure_cycles=pv.get("measure_cycles", 1),
                                       settle_s=pv.get("settle_s"), dt_max_s=pv.get("dt_max_s", DEFAULT_DT_S),
                                       method=pv.get("steady_state", "settle"))
        amps = np.concatenate([a, rows.amplitude_rad])
        k = np.argsort(amps)
        df = dataclasses.replace(df, amplitude_rad=amps[k], engine=np.concatenate([df.engine, rows.engine])[k],
                                 piston=np.concatenate([df.piston, rows.piston])[k],
                                 provenance={**df.provenance, "extended_amplitudes_deg":
                                             [*df.provenance.get("extended_amplitudes_deg", []),
                                              *np.degrees(new).tolist()]})
        pred = predict_lco(flight, df, axis)
    return pred


# -- time domain ---------------------------------------------------------------------------
@dataclass(frozen=True, eq=False)
class FlightHistory:
    """Closed flight loop time history (SI): attitude, FCS command (before the avionics),
    engine angle, friction torque, programmed test input."""

    t_s: np.ndarray
    attitude_rad: np.ndarray
    command_rad: np.ndarray
    engine_rad: np.ndarray
    piston_m: np.ndarray
    friction_torque_Nm: np.ndarray
    pti_rad: np.ndarray
    friction_model: str
    load_stiffness_N_per_m: float
    provenance: dict = field(default_factory=dict)
    #: the loop's axis, and the hydraulic signals (None when not recorded): piston rate v_p [m/s],
    #: load pressure P_L [Pa], valve no-load flow over piston area q [m/s] (as
    #: :data:`taos.flight.ascent_sim.HYDRAULIC`), for the duty cycle (:mod:`taos.flight.duty`)
    axis: str = ""
    piston_rate_m_s: np.ndarray | None = None
    load_pressure_Pa: np.ndarray | None = None
    valve_flow_m_s: np.ndarray | None = None

    ARRAYS = ("t_s", "attitude_rad", "command_rad", "engine_rad", "piston_m", "friction_torque_Nm", "pti_rad")
    HYDRAULIC = ("piston_rate_m_s", "load_pressure_Pa", "valve_flow_m_s")

    @property
    def axes(self) -> tuple[str, ...]:
        """The one axis, so the duty cycle (:func:`taos.flight.duty.duty_summary`) reads this run
        as it reads an ascent's."""
        return (self.axis,)

    @property
    def has_hydraulics(self) -> bool:
        return all(getattr(self, k) is not None for k in self.HYDRAULIC)

    def signal(self, name: str, axis: str) -> np.ndarray:
        """The recorded signal ``name`` (an array field) of ``axis`` (this run's)."""
        if axis != self.axis or getattr(self, name, None) is None:
            raise KeyError(f"{name} of the {axis} axis is not recorded")
        return getattr(self, name)

    def to_hdf5(self, path) -> None:
        def write(tmp):
            import h5py
            with h5py.File(tmp, "w") as h5:
                for k in self.ARRAYS + (self.HYDRAULIC if self.has_hydraulics else ()):
                    h5.create_dataset(k, data=getattr(self, k), compression="gzip")
                h5.attrs["friction_model"] = self.friction_model
                h5.attrs["load_stiffness_N_per_m"] = self.load_stiffness_N_per_m
                write_provenance(h5, {"provenance": self.provenance})
        atomic_write(path, write)


def simulate_flight(flight: FlightModel, model: TvcModel, duration_s: float = 300.0, *,
                    attitude0_rad: float = 0.2 * DEG, axis: str | None = None, dt_s: float = DEFAULT_DT_S,
                    record_every: int = 50, pti=None) -> FlightHistory:
    """Integrate the closed flight loop with the nonlinear simplex TVC.

    Parameters
    ----------
    duration_s : simulated time [s]; attitude0_rad : initial attitude error [rad] (the seed);
    dt_s : RK4 step [s]; record_every : keep every n-th step;
    pti : optional callable t [s] -> programmed test input [rad] added to the FCS command.
    """
    axis = axis or flight.axis
    plant = flight_plant(flight, model, axis)
    n = int(math.ceil(duration_s / dt_s))
    t = np.arange(n + 1) * dt_s
    r = np.zeros((n + 1, 1)) if pti is None else np.asarray(pti(t), float).reshape(-1, 1)
    x0 = np.zeros(plant.ss.A.shape[0])
    x0[plant.ss.state_index("xi_rad")] = attitude0_rad
    ss = plant.ss   # recorded besides the outputs: the actuator states of the duty cycle (rows of C only)
    hyd = ("v_p_m_s", "p_load_Pa", "q_m_s")
    C = np.vstack([ss.C, np.eye(ss.A.shape[0])[[ss.state_index(k) for k in hyd]]])
    rec_plant = dataclasses.replace(plant, ss=StateSpace(ss.A, ss.B, C, np.vstack([ss.D, np.zeros((3, ss.D.shape[1]))]),
                                                         ss.states, ss.inputs, ss.outputs + hyd))
    y, aux = integrate_plant(rec_plant, model, r, dt_s, record_every, x0)
    o = rec_plant.ss.output_index
    prov = {**model_provenance(model), "flight_file": flight.source,
            "flight_sha256": flight.sha256, "package_version": package_version(), "dt_s": dt_s,
            "record_every": record_every, "attitude0_rad": attitude0_rad, "axis": axis}
    return FlightHistory(t_s=t[::record_every], attitude_rad=y[:, o("attitude_rad")],
                         command_rad=y[:, o("delta_cmd_rad")] + r[::record_every, 0],
                         engine_rad=y[:, o("theta_rad")], piston_m=y[:, o("x_p_m")],
                         friction_torque_Nm=aux[:, 0], pti_rad=r[::record_every, 0],
                         friction_model=model.friction.name,
                         load_stiffness_N_per_m=model.structure.load_stiffness_N_per_m, provenance=prov,
                         axis=axis, piston_rate_m_s=y[:, o("v_p_m_s")], load_pressure_Pa=y[:, o("p_load_Pa")],
                         valve_flow_m_s=y[:, o("q_m_s")])


@dataclass(frozen=True)
class MeasuredOscillation:
    """Settled oscillation over the final window: fundamental amplitudes [rad] of the FCS
    command and the engine angle, frequency [Hz], the ratio of the command amplitude in the
    window's second half to its first (growth; < 1 decaying), the third-harmonic ratio of the
    engine angle (0 sine, 1/3 square wave), and whether it counts as a limit cycle."""

    lco: bool
    amplitude_rad: float
    engine_amplitude_rad: float
    freq_hz: float
    growth: float
    engine_third_harmonic: float
    window_s: float

    def to_dict(self) -> dict:
        return {"lco": self.lco, "amplitude_deg": math.degrees(self.amplitude_rad) if self.lco else None,
                "engine_amplitude_deg": math.degrees(self.engine_amplitude_rad) if self.lco else None,
                "frequency_hz": self.freq_hz if self.lco else None,
                "final_amplitude_deg": math.degrees(self.amplitude_rad),
                "final_engine_amplitude_deg": math.degrees(self.engine_amplitude_rad),
                "growth": self.growth, "engine_third_harmonic": self.engine_third_harmonic,
                "window_s": self.window_s}




def measure_oscillation(h: FlightHistory, window_s: float = 120.0, threshold_rad: float = 0.004 * DEG
                        ) -> MeasuredOscillation:
    """Measure the settled oscillation in the last ``window_s`` seconds of ``h``.

    Frequency: peak of the zero-padded spectrum of the detrended command, refined by a
    parabola through the peak bins. It is a limit cycle when the command fundamental exceeds
    ``threshold_rad`` [rad] (default just below one avionics LSB) and does not decay over the
    window (growth > 0.8)."""
    sel = h.t_s >= h.t_s[-1] - window_s
    t, c, e = h.t_s[sel], h.command_rad[sel], h.engine_rad[sel]
    dt = t[1] - t[0]
    x = (c - c.mean()) * np.hanning(c.size)
    nfft = 1 << int(math.ceil(math.log2(c.size * 8)))
    spec = np.abs(np.fft.rfft(x, nfft))
    fr = np.fft.rfftfreq(nfft, dt)
    lo = np.searchsorted(fr, 2.0 / window_s)
    k = lo + int(np.argmax(spec[lo:]))
    if 0 < k < spec.size - 1:
        a, b, cc = spec[k - 1], spec[k], spec[k + 1]
        den = a - 2 * b + cc
        shift = 0.5 * (a - cc) / den if den != 0 else 0.0
    else:
        shift = 0.0
    f = float((k + shift) * (fr[1] - fr[0]))
    amp, _ = _fit(t, c, f)
    eamp, e3 = _fit(t, e, f)
    half = t >= t[0] + 0.5 * (t[-1] - t[0])
    a1, _ = _fit(t[~half], c[~half], f)
    a2, _ = _fit(t[half], c[half], f)
    growth = a2 / a1 if a1 > 0 else 0.0
    lco = bool(amp > threshold_rad and growth > 0.8)
    return MeasuredOscillation(lco, amp, eamp, f, float(growth), float(e3 / eamp) if eamp > 0 else 0.0, window_s)


# -- the whole analysis ------------------------------------------------------------------------
@dataclass(frozen=True, eq=False)
class LcoReport:
    """Prediction beside the time-domain run (the ``taos lco`` JSON)."""

    prediction: LcoPrediction
    time_domain: MeasuredOscillation | None
    history: FlightHistory | None
    model: TvcModel = field(repr=False)

    def to_dict(self) -> dict:
        d = self.prediction.to_dict()
        if d["lco"]:   # with a cycle there is no margin left to state: null, not 0.0
            d["margin_db"] = None
        fl = self.prediction.flight
        big = self.prediction.margins_by_amplitude[-1]
        d.update({
            "friction_model": self.model.friction.name,
            "load_stiffness_N_per_m": self.model.structure.load_stiffness_N_per_m,
            "axis": self.prediction.axis,
            "margins_at_largest_amplitude": {"amplitude_deg": math.degrees(self.prediction.df.amplitude_rad[-1]),
                                             **big.to_dict()},
            "time_domain": None if self.time_domain is None else {**self.time_domain.to_dict(), "duty": self.duty()},
            "verdict": {**decision(d, None if self.time_domain is None else self.time_domain.to_dict()),
                        **self.verdict().to_dict()},
            "describing_function": {"amplitude_deg": np.degrees(self.prediction.df.amplitude_rad).tolist(),
                                    "freq_hz": self.prediction.df.freq_hz.tolist()},
            "provenance": {**model_provenance(self.model),
                           "flight_file": fl.source, "flight_sha256": fl.sha256,
                           "package_version": package_version()},
        })
        return d

    def duty(self) -> dict | None:
        """The hydraulic duty cycle of the time-domain run over its measurement window (the settled
        oscillation; :func:`taos.flight.duty.duty_summary` with the flown model's limits), or None
        without a run that recorded the actuator states."""
        h = self.history
        if self.time_domain is None or h is None or not h.has_hydraulics:
            return None
        from taos.flight.duty import duty_summary
        return duty_summary(h, self.model, float(h.t_s[-1]) - self.time_domain.window_s)

    def verdict(self):
        """The verdict in plain words with its margin table (:mod:`taos.flight.lco_verdict`)."""
        from taos.flight.lco_verdict import lco_verdict
        return lco_verdict(self)

def model_avionics_amplitudes_rad(model: TvcModel, n: int = 15) -> np.ndarray:
    """Default describing-function amplitudes [rad] with the flown avionics (``--avionics
    model``): from half an LSB of the quantiser to 1 deg, so the map sees the quantiser's own
    limit cycle (one to three LSB) as well as the friction's."""
    lsb = model.avionics.lsb_rad
    return np.logspace(np.log10(0.5 * lsb), np.log10(DEG), n)


def decision(prediction: dict, time_domain: dict | None) -> dict:
    """The one LCO verdict of an analysis: the time domain decides when it was run (it carries
    every harmonic and the quantiser exactly); the describing function's verdict is reported
    beside it, with the reason when they differ."""
    if time_domain is None:
        return {"lco": prediction["lco"], "decided_by": "describing function", "agree": None, "note": None}
    agree = bool(prediction["lco"]) == bool(time_domain["lco"])
    note = None
    if not agree:
        note = ("the describing function keeps the fundamental only: near a gain-loss threshold "
                "(friction floor or quantiser step) the harmonics it drops decide; the time domain decides")
    return {"lco": bool(time_domain["lco"]), "decided_by": "time domain", "agree": agree,
            "prediction_lco": bool(prediction["lco"]), "note": note}


def flown_model(model: TvcModel, avionics: str = "bounding") -> TvcModel:
    """The TVC model with the avionics of the analysis: "bounding" (the paper's -1 dB gain,
    :func:`with_bounding_avionics`) or "model" (the file's quantiser and crossover curve)."""
    if avionics == "bounding":
        return with_bounding_avionics(model)
    if avionics != "model":
        raise ValueError(f"avionics must be 'bounding' or 'model', got {avionics!r}")
    return model


def describing_function_map_for(model: TvcModel, axis: str, *, amplitudes_rad=None, freq_hz=None,
                                avionics: str = "bounding", settle_cycles: int = 1, measure_cycles: int = 1,
                                steady: str = "settle", flown: bool = False) -> DescribingFunctionMap:
    """The describing-function map :func:`analyse_lco` uses for ``model`` on ``axis`` with
    ``avionics`` (``flown=True``: ``model`` already carries them, :func:`flown_model`). Default
    grid: :data:`DEFAULT_AMPLITUDES_DEG` x :data:`DEFAULT_FREQ_HZ`; with the file's avionics the
    amplitudes reach half an LSB (:func:`model_avionics_amplitudes_rad`)."""
    if not flown:
        model = flown_model(model, avionics)
    if amplitudes_rad is None and avionics == "model" and model.avionics.lsb_rad > 0:
        amps = model_avionics_amplitudes_rad(model)  # the quantiser's own cycle lives below 0.01 deg
    else:
        amps = np.radians(DEFAULT_AMPLITUDES_DEG) if amplitudes_rad is None else np.asarray(amplitudes_rad, float)
    f = np.asarray(DEFAULT_FREQ_HZ if freq_hz is None else freq_hz, float)
    return describing_function_map(model, amps, f, axis, settle_cycles=settle_cycles, measure_cycles=measure_cycles,
                                   method=steady)


def analyse_lco(flight: FlightModel, model: TvcModel, *, axis: str | None = None,
                amplitudes_rad: np.typing.ArrayLike | None = None, freq_hz: np.typing.ArrayLike | None = None,
                duration_s: float = 300.0, window_s: float = 120.0,
                attitude0_rad: float = 0.2 * DEG, settle_cycles: int = 1, measure_cycles: int = 1,
                avionics: str = "bounding", time_domain: bool = True, steady: str = "settle",
                df: DescribingFunctionMap | None = None, extend: int = EXTEND_ROUNDS) -> LcoReport:
    """Describing-function map, harmonic-balance prediction and (optionally) the time-domain
    run for one flight file and TVC model. Defaults: :data:`DEFAULT_AMPLITUDES_DEG` x
    :data:`DEFAULT_FREQ_HZ`, one settling and one measured cycle beyond the linear settling
    time (the friction hysteresis is periodic after the first reversal). ``avionics``:
    "bounding" (the paper's -1 dB gain, :func:`with_bounding_avionics`) or "model" (the model
    file's quantisation and crossover curve, as flown; the default amplitudes then reach half an
    LSB, :func:`model_avionics_amplitudes_rad`). ``steady``: how each dwell of the map reaches
    its periodic orbit ("settle", or "shoot": the periodic steady state by shooting,
    :func:`taos.planar.freqresp.sine_dwell_points`). ``df``: a describing-function map already
    made for this TVC model, avionics and axis (:func:`describing_function_map_for`), reused
    instead of computed: the map depends on the TVC only, so a sweep over the flight loop's gains
    makes it once. ``extend``: at most this many amplitude rows added per edge of the map while
    a cycle may lie beyond it (:func:`extend_to_cover`; 0: none, the prediction then only warns)."""
    from ._args import check_lco_args

    check_lco_args(flight, model, axis=axis, amplitudes_rad=amplitudes_rad, freq_hz=freq_hz, duration_s=duration_s,
                   window_s=window_s, attitude0_rad=attitude0_rad, settle_cycles=settle_cycles,
                   measure_cycles=measure_cycles, avionics=avionics, time_domain=time_domain, steady=steady, df=df,
                   extend=extend)
    axis = axis or flight.axis
    model = flown_model(model, avionics)
    if df is None:
        df = describing_function_map_for(model, axis, amplitudes_rad=amplitudes_rad, freq_hz=freq_hz,
                                         avionics=avionics, settle_cycles=settle_cycles,
                                         measure_cycles=measure_cycles, steady=steady, flown=True)
    else:   # reused only when made from the same content: the flown model (its hash covers every
        # override and the avionics), the axis and the dwell settings
        want = {"model_sha256": model.sha256, "steady_state": steady, "settle_cycles": settle_cycles,
                "measure_cycles": measure_cycles}
        got = {k: df.provenance.get(k) for k in want}
        if df.axis != axis or got != want:
            raise InputError("describing-function map", "df", f"a map made for this flown model and settings "
                             f"({axis} axis, {want})", got=f"one for the {df.axis} axis, {got}")
    pred = extend_to_cover(flight, model, df, axis, extend)
    hist = meas = None
    if time_domain:
        hist = simulate_flight(flight, model, duration_s, attitude0_rad=attitude0_rad, axis=axis)
        meas = measure_oscillation(hist, window_s)
    return LcoReport(pred, meas, hist, model)
