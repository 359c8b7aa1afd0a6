"""Flight runs: disperse, fly the segment, measure the limit cycle.

The LCO of a run is measured as ``taos lco`` measures it (:func:`taos.flight.lco.measure_oscillation`)
over the campaign's analysis window at the end of the segment: the FCS command fundamental,
its frequency, and whether it is sustained (growth over the window > 0.8) above just under one
avionics LSB (0.004 deg). Peaks of engine angle, engine rate and attitude error are taken over
the whole segment.

Physical sanity: the engine is held inside its gimbal range (``model.engine.gimbal_range_rad``)
by hard stops, so a run whose engine reaches them (peak or oscillation amplitude at or above
``STOP_FRACTION`` of the range) has left the small-amplitude regime a limit-cycle verdict is
about: it is stored as **diverged**, apart from the runs that failed (non-finite state, refused
value), and never counted as a limit cycle. A model without hard stops has no such bound. The
measured oscillation must be physical too: the fundamental of a signal bounded by its peak P is
at most 4P/pi (a square wave's), at a positive frequency; a run whose measurement breaks that
(a fit of a window without an oscillation) is stored as failed, with the reason.

:class:`FlightRuns` is the engine's run kind (:class:`taos.montecarlo.engine.RunKind`): it
carries the parsed campaign, ascent and TVC model (no file is opened by a worker) and the content
hash of every input file they came from.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from taos.errors import InputError, SimulationUnstable
from taos.flight.ascent import Ascent
from taos.flight.ascent_sim import simulate_ascents
from taos.flight.lco import measure_oscillation
from taos.model import TvcModel
from taos.montecarlo.campaign import Campaign, apply_factors
from taos.montecarlo.store import STATUS

RECORD_INTERVAL_S = 0.02
#: measured cost of one RK4 step of a flight run in the lockstep kernel, for sizing batches [s]
#: (CPU time under load, benchmarks/RESULTS.md issue 26: 0.11 s per 200,000-step run)
STEP_COST_S = 5.5e-7
#: the same for one ETDRK4 step (``integrator = "etdrk4"``; benchmarks/RESULTS.md, mcexp: 0.025 CPU-s a
#: 40,000-step run in-process, load 1-4)
EXP_STEP_COST_S = 6.5e-7
STOP_FRACTION = 0.98
#: the largest fundamental of a signal bounded by its peak: a square wave's, 4/pi (1 % margin)
FUNDAMENTAL_BOUND = 4 / math.pi * 1.01
SCALARS = ("amplitude_deg", "engine_amplitude_deg", "frequency_hz", "growth", "peak_engine_deg",
           "peak_engine_rate_deg_s", "peak_attitude_deg")
FLAGS = ("lco",)


@dataclass(frozen=True, eq=False)
class FlightRuns:
    """Runs of case ``case`` of campaign ``campaign`` on the loaded ``ascent`` and ``model``;
    ``inputs_sha256`` the content hash of every file they were read from."""

    campaign: Campaign
    case: str
    ascent: Ascent
    model: TvcModel
    inputs_sha256: str
    scalars: tuple[str, ...] = SCALARS
    flags: tuple[str, ...] = FLAGS

    def _grid(self) -> tuple[int, int, int]:
        """(record step in dt, trace step in records, trace length) as simulate_ascent records."""
        c = self.campaign
        rec = max(1, int(round(max(RECORD_INTERVAL_S, c.dt_s) / c.dt_s)))
        nsteps = int(math.ceil(c.duration_s / c.dt_s / rec)) * rec
        step = max(1, int(round(c.trace_interval_s / (rec * c.dt_s))))
        return rec, step, (nsteps // rec) // step + 1

    @property
    def trace_t_s(self) -> np.ndarray:
        rec, step, m = self._grid()
        return self.campaign.start_s + np.arange(m) * step * rec * self.campaign.dt_s

    @property
    def run_cost_s(self) -> float:
        step = EXP_STEP_COST_S if self.campaign.integrator == "etdrk4" else STEP_COST_S
        return step * self.campaign.duration_s / self.campaign.dt_s

    @property
    def gimbal_range_deg(self) -> float:
        """The sanity bound on engine angles [deg]: ``STOP_FRACTION`` of the gimbal range (inf when
        the model has no hard stops)."""
        r = self.model.engine.gimbal_range_rad
        return math.degrees(r) * STOP_FRACTION if r > 0 else math.inf

    def run_batch(self, names: tuple[str, ...], factors: np.ndarray, seeds: np.ndarray) -> dict:
        n, m = len(seeds), len(self.trace_t_s)
        out = {"status": np.zeros(n, np.int8), "error": [""] * n, "trace": np.full((n, m), np.nan),
               "engine_trace": np.full((n, m), np.nan),
               **{k: np.full(n, np.nan) for k in self.scalars}, **{k: np.zeros(n, bool) for k in self.flags}}
        c = self.campaign
        runs, rows = [], []
        for i in range(n):
            try:
                a2, m2, _ = apply_factors(self.ascent, self.model, c.cases[self.case],
                                          dict(zip(names, (float(v) for v in factors[i]))))
            except (InputError, ValueError, ArithmeticError) as e:
                self._failed(out, i, e)
                continue
            runs.append((a2, m2, int(seeds[i])))
            rows.append(i)
        # the batch's runs in lockstep (taos.flight.ascent_sim.simulate_ascents): each run's
        # numbers are its own, whatever else is in the batch
        flown = simulate_ascents(runs, axis=c.axis, start_s=c.start_s, end_s=c.start_s + c.duration_s, dt_s=c.dt_s,
                                 record_interval_s=max(RECORD_INTERVAL_S, c.dt_s),
                                 friction_follows_thrust=c.friction_follows_thrust, integrator=c.integrator)
        for i, h in zip(rows, flown):
            if isinstance(h, (SimulationUnstable, InputError, ValueError, ArithmeticError)):
                self._failed(out, i, h)
            else:
                self._measure(h, out, i)
        return out

    @staticmethod
    def _failed(out: dict, i: int, e: Exception) -> None:
        out["status"][i], out["error"][i] = STATUS["failed"], str(e).splitlines()[0][:300]

    def _measure(self, h, out: dict, i: int) -> None:
        c = self.campaign
        t_end = float(h.t_s[-1])
        osc = measure_oscillation(h.flight_history(c.axis, t_end - c.analysis_window_s, t_end),
                                  window_s=c.analysis_window_s)
        deg = math.degrees
        vals = {"amplitude_deg": deg(osc.amplitude_rad), "engine_amplitude_deg": deg(osc.engine_amplitude_rad),
                "frequency_hz": osc.freq_hz, "growth": osc.growth,
                "peak_engine_deg": deg(float(np.max(np.abs(h.signal("engine_rad", c.axis))))),
                "peak_engine_rate_deg_s": deg(float(np.max(np.abs(h.signal("engine_rate_rad_s", c.axis))))),
                "peak_attitude_deg": deg(float(np.max(np.abs(h.signal("attitude_rad", c.axis)))))}
        for k, v in vals.items():
            out[k][i] = v
        _, step, _ = self._grid()
        for k, sig in (("trace", "command_rad"), ("engine_trace", "engine_rad")):   # at the trace interval
            tr = h.signal(sig, c.axis)[::step]
            mm = min(len(tr), out[k].shape[1])
            out[k][i, :mm] = tr[:mm]
        bound = self.gimbal_range_deg
        worst = vals["peak_engine_deg"]
        if not math.isfinite(worst) or worst >= bound:
            out["status"][i] = STATUS["diverged"]
            out["error"][i] = f"engine reached its hard stops ({worst:.4g} deg, bound {bound:.4g} deg)"
            return
        peak_cmd = deg(float(np.max(np.abs(h.signal("command_rad", c.axis)))))
        if not (vals["engine_amplitude_deg"] <= FUNDAMENTAL_BOUND * worst
                and vals["amplitude_deg"] <= FUNDAMENTAL_BOUND * peak_cmd and vals["frequency_hz"] > 0):
            out["status"][i] = STATUS["failed"]
            out["error"][i] = (f"oscillation measurement not physical: fundamental {vals['engine_amplitude_deg']:.4g} "
                               f"deg at {vals['frequency_hz']:.3g} Hz from an engine peaking at {worst:.4g} deg")
            return
        out["status"][i] = STATUS["ok"]
        out["lco"][i] = bool(osc.lco)
