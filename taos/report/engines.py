"""The engine a spec verdict is evaluated on, and the factors a shortfall is attributed to.

A verdict (:mod:`taos.report.verdict`) asks an **engine** for responses at mask points and for
the same engine with factors removed. Two engines, each judging with its own physics:

* :class:`PlanarEngine` (``"simplex"``): the planar simplex model, one axis at a time: exact
  linear response (:func:`taos.planar.freqresp.linear_freqresp`), sine dwells
  (:func:`taos.planar.freqresp.sine_dwell_points`, one batched call), steps
  (:mod:`taos.report.merit`); phases on the branch of
  :func:`taos.planar.freqresp.linear_phase_reference`.
* :class:`TaosEngine` (``"taos"``): the 3-D TAOS model (:mod:`taos.taos3d`): exact linear
  response (:func:`taos.taos3d.taos_freqresp`), and dwells **run as the Green Run profile runs
  them**: the measured axis' sine at the mask frequency and amplitude while the other axis runs
  the dwell the profile commands at the same time (its cross-axis dither, paper sec. 5.1), one
  parallel call of the 3-D dwell kernel (:func:`taos.taos3d.simulate._dwell`, the kernel of
  :func:`taos.taos3d.two_axis_dwell`); steps by :func:`taos.taos3d.simulate_taos` with the other
  axis at rest. Phases on the branch of the 3-D linear response, continuous from 1e-3 Hz.

Factors (:data:`CAUSES`), each removed through the model-file loader (a variant,
:meth:`taos.model.TvcModel.with_values`; 3-D: :func:`taos.taos3d.with_values`, which rebuilds the
3-D model and derives its line stiffness for the new total):

* ``friction``: ``friction.model = "none"``;
* ``load_stiffness``: the laboratory ("rigid") load, ``structure.load_stiffness`` ->
  max(K_L, :data:`LAB_LOAD_STIFFNESS_N_PER_M`), the condition an actuator is specified against;
* ``avionics``: a unity command path (``avionics.quantization_bits = 0``, no crossover table);
* ``pressure_limit``: ``actuator.pressure_limited = false``: the servovalve's square-root law
  Q = A q sqrt((P_s - sgn(q) P_L) / P_s) and the relief valve off (an ideal valve on an
  unlimited supply). Near the load resonance the Green Run amplitudes ask for P_L near or
  beyond P_s; the square-root law then takes flow gain ("valve pressure saturation").

The **servo alone** (:data:`SERVO_ALONE`) removes friction, load path and avionics and keeps the
servo whole, its valve included: a point that still fails is the servo's own.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Sequence

import numpy as np

if TYPE_CHECKING:
    from taos.model import TvcModel
    from taos.taos3d import TaosModel

#: the factors a shortfall is attributed to, in the order they are tried
CAUSES = ("friction", "load_stiffness", "avionics", "pressure_limit")
#: removed together to leave the servo alone (its valve and supply kept: they are the servo)
SERVO_ALONE = ("friction", "load_stiffness", "avionics")
#: the laboratory ("rigid") load stiffness [N/m]: 1e9 N/m = 5.7e6 lbf/in, 28 x the hot-fire and
#: 50 x the ambient K_L and 4 x the oil column (2.4e8 N/m), so the load resonance (36 Hz with the
#: shipped J_n and R) is far above the servo's band: the shipped servo's engine response is then
#: within 0.2 dB and 0.8 deg of a truly rigid load (K_L = 1e12 N/m) at 5 Hz and within 0.03 dB /
#: 0.1 deg up to 2 Hz, while the fastest mode (sqrt((K_L + oil column) / M_p), 5,200 rad/s)
#: stays integrable by the explicit step (dt |lambda|max = 1.05 at 2e-4 s; a truly rigid 1e12
#: would need a 100 x smaller step)
LAB_LOAD_STIFFNESS_N_PER_M = 1e9
#: the model-file values that remove each factor but the laboratory load (which depends on K_L)
REMOVAL_VALUES = {
    "friction": {"friction.model": "none"},
    "avionics": {"avionics.quantization_bits": 0, "avionics.crossover_command": [], "avionics.crossover_gain": []},
    "pressure_limit": {"actuator.pressure_limited": False},
}
#: a 3-D dwell measures whole cycles of both sines when n f_other / f is whole for some n up to this
MAX_MEASURE_CYCLES = 12


def removal_values(model: TvcModel, causes: Sequence[str]) -> dict:
    """The variant (model-file keys and values) removing ``causes`` from ``model`` (module
    docstring); :class:`ValueError` for a name not in :data:`CAUSES`."""
    bad = set(causes) - set(CAUSES)
    if bad:
        raise ValueError(f"unknown cause {sorted(bad)[0]!r}; expected one of {CAUSES}")
    out: dict = {}
    for c in CAUSES:
        if c not in causes:
            continue
        if c == "load_stiffness":
            out["structure.load_stiffness"] = max(model.structure.load_stiffness_N_per_m, LAB_LOAD_STIFFNESS_N_PER_M)
        else:
            out.update(REMOVAL_VALUES[c])
    return out


def laboratory_model(model: TvcModel) -> TvcModel:
    """``model`` on the laboratory load: K_L = max(K_L, :data:`LAB_LOAD_STIFFNESS_N_PER_M`)."""
    import dataclasses

    k = max(model.structure.load_stiffness_N_per_m, LAB_LOAD_STIFFNESS_N_PER_M)
    return model.replace(structure=dataclasses.replace(model.structure, load_stiffness_N_per_m=k))


def remove_causes(model: TvcModel, causes: Sequence[str]) -> TvcModel:
    """The planar ``model`` with each factor in ``causes`` removed (module docstring). Friction
    and the pressure limit are variants (``with_values``); the laboratory load and the unity
    avionics are set on the dataclasses, so that they hold on a model changed in code too (a
    variant re-applies the model's code changes over its own values)."""
    import dataclasses

    removal_values(model, causes)   # the names checked
    m = model
    if "friction" in causes:
        m = m.with_friction("none")
    if "pressure_limit" in causes:
        m = (m.with_values(REMOVAL_VALUES["pressure_limit"]) if not _code_changed(m, "actuator")
             else m.replace(actuator=dataclasses.replace(m.actuator, pressure_limited=False)))
    if "load_stiffness" in causes:
        m = laboratory_model(m)
    if "avionics" in causes:
        m = m.replace(avionics=m.avionics.ideal())
    return m


def _code_changed(model: TvcModel, part: str) -> bool:
    return any(k == f"code.{part}" for k, _ in model.overrides)


def _axis_index(axis: str) -> int:
    return ("pitch", "yaw").index(axis)


# -- the planar engine ------------------------------------------------------------------------

@dataclass(frozen=True, eq=False)
class PlanarEngine:
    """The planar simplex model as a verdict's engine (module docstring); ``dt_s`` the dwell
    and step integration step [s] (smaller where a stiffened variant's fastest mode asks)."""

    model: TvcModel
    dt_s: float = 2e-4
    name: str = field(default="simplex", init=False)

    def without(self, causes: Sequence[str]) -> PlanarEngine:
        return PlanarEngine(remove_causes(self.model, causes), self.dt_s)

    def responses(self, axis: str, freq_hz, amplitudes_rad=None, dithers=None) -> dict:
        """{"piston": (h, phase ref [deg]), "engine": (h, phase ref)} at paired points: linear
        when ``amplitudes_rad`` is None, else sine dwells (one batched call); ``dithers`` unused
        (one axis at a time)."""
        from taos.planar.freqresp import (
            linear_freqresp,
            linear_phase_reference,
            sine_dwell_points,
        )

        f = np.asarray(freq_hz, float)
        if amplitudes_rad is None:
            fr = linear_freqresp(self.model, f, axis)
            p, e = fr.piston, fr.engine
        else:
            d = sine_dwell_points(self.model, np.asarray(amplitudes_rad, float), f, axis,
                                  dt_max_s=_planar_dt(self.model, self.dt_s))
            p, e = d.piston, d.engine
        fu, inv = np.unique(f, return_inverse=True)
        rp, re = linear_phase_reference(self.model, fu, axis)
        return {"piston": (p, rp[inv]), "engine": (e, re[inv])}

    def phase_reference(self, axis: str, freq_hz) -> tuple[np.ndarray, np.ndarray]:
        from taos.planar.freqresp import linear_phase_reference

        return linear_phase_reference(self.model, freq_hz, axis)

    def step_values(self, axis: str, reqs, threads=None) -> dict:
        """The step figures the requirements name (:func:`taos.report.merit.step_response_figures`
        / :func:`taos.report.merit.step_merit`, nonlinear simplex model)."""
        from .merit import step_merit, step_response_figures

        amp = reqs[0].amplitude_rad
        if {r.figure for r in reqs} <= {"rise_time_s", "overshoot_pct"}:
            rise, over = step_response_figures(self.model, axis, amp, dt_s=self.dt_s)
            return {"rise_time_s": rise, "overshoot_pct": over}
        return step_merit(self.model, axis, step_amplitude_rad=amp, dt_s=self.dt_s, threads=threads).to_dict()

    def step_engine(self, reqs) -> str:
        return self.name


def _planar_dt(model: TvcModel, dt_s: float) -> float:
    """``dt_s``, or smaller where the (stiffened) model's fastest mode asks for it (RK4 limit,
    with a factor 2 of margin)."""
    from taos.bounds import RK4_STEP_LIMIT
    from taos.planar.envelope import fastest_mode_rad_s

    lam = fastest_mode_rad_s(model)
    return min(dt_s, 0.5 * RK4_STEP_LIMIT / lam) if dt_s * lam > 0.5 * RK4_STEP_LIMIT else dt_s


# -- the 3-D engine ---------------------------------------------------------------------------

class _AxisBlock:
    """The 3-D linear block seen from one axis, as :func:`taos.planar.freqresp._phase_reference`
    reads a simplex block: command -> (x_p [m/rad], theta [-]) of ``axis``."""

    def __init__(self, ss, axis: str):
        self.ss, self.axis = ss, axis

    def freqresp(self, f, _inp, _outs):
        a = self.axis
        return self.ss.freqresp(f, f"command_{a}_rad", [f"x_p_{a}_m", f"theta_{a}_rad"])


def measure_cycles(freq_hz: float, other_hz: float, least: int = 2) -> int:
    """The fewest whole cycles n >= ``least`` of ``freq_hz`` [Hz] holding whole cycles of
    ``other_hz`` too (n f_o / f within 1e-6 of a whole number; up to :data:`MAX_MEASURE_CYCLES`,
    else ``least``), so that the other axis' sine is orthogonal to the measured one's over the
    window."""
    if other_hz <= 0:
        return least
    for n in range(least, MAX_MEASURE_CYCLES + 1):
        r = n * other_hz / freq_hz
        if abs(r - round(r)) < 1e-6:
            return n
    return least


@dataclass(frozen=True, eq=False)
class TaosEngine:
    """The 3-D TAOS model as a verdict's engine (module docstring); ``dt_s`` the dwell and step
    integration step [s] (smaller where a stiffened variant's fastest mode asks)."""

    tm: TaosModel
    dt_s: float = 4e-4
    name: str = field(default="taos", init=False)
    #: the variants made so far, by removed factors (each 3-D rebuild once per verdict)
    _variants: dict = field(default_factory=dict, init=False, repr=False, compare=False)

    @property
    def model(self) -> TvcModel:
        return self.tm.base

    def without(self, causes: Sequence[str]) -> TaosEngine:
        """This engine's 3-D model with ``causes`` removed (module docstring), rebuilt through
        the loader (:func:`taos.taos3d.with_values`) once and kept for the other groups."""
        from taos.taos3d import with_values

        key = tuple(sorted(causes))
        if key not in self._variants:
            self._variants[key] = TaosEngine(with_values(self.tm, removal_values(self.tm.base, causes)), self.dt_s)
        return self._variants[key]

    def phase_reference(self, axis: str, freq_hz) -> tuple[np.ndarray, np.ndarray]:
        """Continuous phase [deg] of the 3-D linear command -> piston and -> engine responses of
        ``axis`` (the planar reference's method on the 3-D linear block)."""
        from taos.planar.freqresp import _phase_reference
        from taos.taos3d import linear_state_space

        ph, _ = _phase_reference(_AxisBlock(linear_state_space(self.tm), axis), freq_hz)
        return ph[:, 0], ph[:, 1]

    def dt_max_s(self) -> float:
        """``dt_s``, unless the model's fastest mode (the larger of the 3-D linear block's
        largest |eigenvalue| and the planar estimate with the relief's stall rate,
        :func:`taos.planar.envelope.fastest_mode_rad_s`) puts dt |lambda| above 0.8 x the RK4
        limit: then 0.5 x the limit / |lambda| (the shipped models' relief valve sits at 1.6 at
        4e-4 s by design; a laboratory load at 1e9 N/m, 5,850 rad/s, needs 1.7e-4 s)."""
        from taos.bounds import RK4_STEP_LIMIT
        from taos.planar.envelope import fastest_mode_rad_s
        from taos.taos3d import linear_state_space

        lam = max(float(np.abs(np.linalg.eigvals(linear_state_space(self.tm).A)).max()),
                  fastest_mode_rad_s(self.tm.base))
        return self.dt_s if self.dt_s * lam <= 0.8 * RK4_STEP_LIMIT else 0.5 * RK4_STEP_LIMIT / lam

    def responses(self, axis: str, freq_hz, amplitudes_rad=None, dithers=None) -> dict:
        """As :meth:`PlanarEngine.responses`, on the 3-D model: linear when ``amplitudes_rad``
        is None; else two-axis dwells, ``dithers`` per point the other axis' (amplitude [rad],
        frequency [Hz]) or None (at rest); identical points run once."""
        from taos.taos3d import taos_freqresp

        f = np.asarray(freq_hz, float)
        if amplitudes_rad is None:
            fr = taos_freqresp(self.tm, f, None, axis)
            p, e = fr.piston, fr.engine
        else:
            p, e = self._dwells(axis, f, np.asarray(amplitudes_rad, float),
                                [None] * f.size if dithers is None else list(dithers))
        fu, inv = np.unique(f, return_inverse=True)
        rp, re = self.phase_reference(axis, fu)
        return {"piston": (p, rp[inv]), "engine": (e, re[inv])}

    def _dwells(self, axis, f, a, dithers):
        from taos.taos3d import _args
        from taos.taos3d.simulate import _dwell

        i = _axis_index(axis)
        rows, index = [], []
        for k in range(f.size):
            ao, fo = dithers[k] if dithers[k] is not None else (0.0, 0.0)
            row = (float(a[k]), float(f[k]), float(ao), float(fo))
            if row not in rows:
                rows.append(row)
            index.append(rows.index(row))
        amps = np.zeros((len(rows), 2))
        freqs = np.zeros((len(rows), 2))
        for r, (ak, fk, ao, fo) in enumerate(rows):
            amps[r, i], freqs[r, i], amps[r, 1 - i], freqs[r, 1 - i] = ak, fk, ao, fo
        amps, freqs = _args.check_two_axis(amps, freqs, axis)
        ncyc = np.array([measure_cycles(r[1], r[3]) for r in rows], np.int64)
        res = _dwell(self.tm, amps, freqs, freqs[:, i], self.dt_max_s(), 2, ncyc, None, 64)
        h = (res[:, :, 0] + 1j * res[:, :, 1]) / amps[:, i][:, None]
        idx = np.array(index)
        return h[idx, i] / self.tm.base.actuator.moment_arm_m, h[idx, 2 + i]

    def step_values(self, axis: str, reqs, threads=None) -> dict:
        """Rise time and overshoot (:func:`taos.report.merit.rise_and_overshoot`) of a command
        step on ``axis`` (the other at rest), on the 3-D model; other step figures on the
        planar model (:meth:`step_engine` says which)."""
        from taos.profiles import Step, TwoAxis
        from taos.taos3d import simulate_taos

        from .merit import STEP_HOLD_S, STEP_T0_S, rise_and_overshoot

        if self.step_engine(reqs) != self.name:
            return PlanarEngine(self.tm.base).step_values(axis, reqs, threads)
        amp = reqs[0].amplitude_rad
        steps = [Step(0.0, STEP_T0_S, STEP_HOLD_S), Step(0.0, STEP_T0_S, STEP_HOLD_S)]
        steps[_axis_index(axis)] = Step(amp, STEP_T0_S, STEP_HOLD_S)
        th = simulate_taos(self.tm, TwoAxis(*steps, "step"), dt_s=self.dt_max_s(), record_every=1,
                           duration_s=STEP_T0_S + STEP_HOLD_S)
        rise, over = rise_and_overshoot(th.t_s, th.engine_rad[_axis_index(axis)])
        return {"rise_time_s": rise, "overshoot_pct": over}

    def step_engine(self, reqs) -> str:
        """``"taos"`` for rise time and overshoot; ``"simplex"`` when a requirement names the
        threshold or hysteresis (planar step figures, :func:`taos.report.merit.step_merit`)."""
        return self.name if {r.figure for r in reqs} <= {"rise_time_s", "overshoot_pct"} else "simplex"


# -- the profile's cross-axis dither ----------------------------------------------------------

def concurrent_dwells(profile) -> dict[str, list[tuple[float, float, float, float]]]:
    """Per axis of a two-axis profile, each dwell segment as (frequency [Hz], amplitude [rad],
    the other axis' frequency [Hz], amplitude [rad]): the other axis' dwell segment overlapping
    it longest in time, (0, 0) when the other axis runs none meanwhile."""
    from taos.profiles import dwell_segments

    spans = {}
    for ax in ("pitch", "yaw"):
        spans[ax] = [(t0, t0 + s.duration_s, s) for t0, s in dwell_segments(getattr(profile, ax))]
    out = {}
    for ax, other in (("pitch", "yaw"), ("yaw", "pitch")):
        rows = []
        for t0, t1, s in spans[ax]:
            best, over = None, 0.0
            for u0, u1, o in spans[other]:
                ov = min(t1, u1) - max(t0, u0)
                if ov > over + 1e-12:
                    best, over = o, ov
            rows.append((s.frequency_hz, s.amplitude_rad) + ((best.frequency_hz, best.amplitude_rad)
                                                               if best is not None else (0.0, 0.0)))
        out[ax] = rows
    return out


def engine_for(model: TvcModel, engine: str = "simplex", dt_s: float | None = None,
               tm: TaosModel | None = None):
    """The verdict engine ``engine`` ("simplex" or "taos") of ``model`` (3-D: ``tm``, else built
    by :func:`taos.taos3d.taos_model`); ``dt_s`` default the engine's own step."""
    from taos.planar.envelope import default_dt_s

    dt = default_dt_s(engine) if dt_s is None else dt_s
    if engine == "taos":
        from taos.taos3d import taos_model

        return TaosEngine(tm if tm is not None else taos_model(model), dt)
    return PlanarEngine(model, dt)
