"""Time-domain confirmation of a predicted limit cycle, started ON the predicted cycle.

The from-rest confirmation (:func:`taos.flight.lco.simulate_flight`: a 0.2 deg attitude error,
300 s, the last 120 s measured) spends most of its time on the settling transient. Here the run
starts from the describing function's periodic solution instead, so a few cycles decide.

**The start** (harmonic balance, Gelb & Vander Velde 1968, ch. 2). On the predicted cycle of
command amplitude A and frequency w the FCS command is c = A sin(w t + phi), the engine angle's
fundamental is Theta = N(A, w) A and the piston's is P = R N_p(A, w) A (the describing-function
map's engine and piston responses, :class:`taos.flight.describing.DescribingFunctionMap`, R the
moment arm). The closed flight plant (:func:`taos.flight.vehicle.flight_plant`) is linear but for
its two scalar inputs, the avionics output u and the friction torque T_f::

    x' = A x + b_u u + b_f T_f   ->   X = (j w I - A)^-1 (b_u U + b_f T)

with phasors U, T of their fundamentals. The engine and piston rows of X must equal Theta and P:
two complex equations for U and T (a 2 x 2 solve), and then X gives every state of the loop -
servo, oil column, engine, vehicle and FCS - on the cycle. The FCS command row of X is then
-L0 N A, i.e. A again up to the harmonic-balance residual (reported: ``command_residual``).
The start is x0 = Im(X e^{j phi}) at the phase phi where the gimbal's friction rate
w_f = c_w . X peaks (sliding, away from a reversal), and the friction state is made
consistent by running the law over three cycles of that prescribed rate up to phi
(:meth:`taos.friction.FrictionLaw.response`): z0 is on the law's periodic hysteresis loop.

Without a predicted stable cycle the run starts the same way at the point where the loop
comes closest to one (the nearest margin of :func:`taos.flight.lco_verdict.nearest_margin`; a
threshold-only case at its unstable cycle; a loop still unstable at the map's largest amplitude
at that amplitude), so a cycle the describing function missed still has its best chance to
show.

**The decision** (the time domain still decides). The run goes on in pieces of
``CHUNK_CYCLES`` cycles; after each, the command's fundamental is fitted over every whole cycle
(up-crossing to up-crossing) and the sequence a_k of cycle amplitudes is read:

* ``sustained``: the last ``SETTLED_CYCLES`` ratios a_k / a_(k-1) within ``SETTLED_TOL`` of 1 and
  the drift still to come, were the last changes to go on geometrically, within it too
  (|d_k| rho / (1 - rho) / a_k, d_k = a_k - a_(k-1), rho = d_k / d_(k-1)), above the threshold (0.004 deg, just under one avionics LSB, as
  :func:`taos.flight.lco.measure_oscillation`): a limit cycle, measured over those cycles;
* ``decays``: a_k below the threshold, or a geometric decay whose Aitken limit
  a_k - (a_k - a_(k-1))^2 / (a_k - 2 a_(k-1) + a_(k-2)) lies below it with a steady ratio
  rho = (a_k - a_(k-1)) / (a_(k-1) - a_(k-2)) in (0, ``RHO_MAX``]: no limit cycle;
* otherwise it runs on, up to ``duration_s`` (the from-rest run's length); a run that reaches
  it undecided is measured as the from-rest run is (:func:`taos.flight.lco.measure_oscillation`
  over the last ``window_s``), ``grows`` when its growth over that window exceeds
  ``1 + SETTLED_TOL``, ``undecided`` otherwise.

Runs of several points are independent; :func:`confirm_many` runs them on a thread pool, each
run's integration in a compiled kernel that releases the GIL, so both cores work and every
result is bit-identical to a serial run.
"""

from __future__ import annotations

import math
import threading
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

import numpy as np

from taos.harmonics import harmonic_amplitudes
from taos.planar import dynamics as _dyn
from taos.planar.simulate import DEFAULT_DT_S, check_friction_step, kernel_args

DEG = math.pi / 180.0
#: cycles integrated per piece between decisions
CHUNK_CYCLES = 2
#: cycle-to-cycle amplitude ratios within this of 1 count as settled
SETTLED_TOL = 0.01
#: that many consecutive settled ratios make a sustained cycle
SETTLED_CYCLES = 2
#: the largest ratio of successive amplitude changes accepted as a geometric decay
RHO_MAX = 0.95
#: the amplitude below which there is no cycle [rad] (as taos.flight.lco.measure_oscillation)
THRESHOLD_RAD = 0.004 * DEG
#: friction pre-roll: cycles of the prescribed rate and steps per cycle
PREROLL_CYCLES, PREROLL_STEPS = 3, 4000
#: recorded every this many integration steps
RECORD_EVERY = 25
OUTCOMES = ("sustained", "decays", "grows", "undecided")


@dataclass(frozen=True)
class CycleStart:
    """A start on a (predicted) periodic solution: ``x0`` (n,) the plant state [SI], ``z0`` the
    friction state [rad], the command amplitude [rad] and frequency [Hz] it was made for, the
    start phase [rad] of the command, the relative harmonic-balance residual of the command
    |c_w X - A| / A [-], and what the start is (``source``)."""

    x0: np.ndarray
    z0: float
    amplitude_rad: float
    freq_hz: float
    phase_rad: float
    command_residual: float
    source: str


def periodic_start(plant, model, df, amplitude_rad: float, freq_hz: float, source: str) -> CycleStart:
    """The loop's state on the periodic solution of command amplitude ``amplitude_rad`` [rad] and
    frequency ``freq_hz`` [Hz] with the describing-function map ``df`` (module docstring).
    ``plant``: :func:`taos.flight.vehicle.flight_plant` of ``model`` (its avionics as flown)."""
    ss = plant.ss
    n = ss.A.shape[0]
    w = 2.0 * math.pi * freq_hz
    bu = ss.B[:, ss.input_index("command_rad")]
    bf = ss.B[:, ss.input_index("friction_torque_Nm")]
    X2 = np.linalg.solve(1j * w * np.eye(n) - ss.A, np.column_stack([bu, bf]).astype(complex))
    o = ss.output_index
    rows = ss.C[[o("theta_rad"), o("x_p_m")]]
    R = model.actuator.moment_arm_m
    target = np.array([df(amplitude_rad, freq_hz), R * df(amplitude_rad, freq_hz, "piston")]) * amplitude_rad
    ut = np.linalg.solve(rows @ X2, target)
    X = X2 @ ut
    resid = abs(plant.cmd_c @ X - amplitude_rad) / amplitude_rad
    W = plant.rate_c @ X
    phi = 0.5 * math.pi - float(np.angle(W))
    x0 = (X * np.exp(1j * phi)).imag
    z0 = 0.0
    if model.friction.has_state:
        k = PREROLL_CYCLES * PREROLL_STEPS
        t = (np.arange(k + 1) - k) / (PREROLL_STEPS * freq_hz)
        v = np.abs(W) * np.sin(w * t + 0.5 * math.pi)
        _, zs = model.friction.response(v, 1.0 / (PREROLL_STEPS * freq_hz), 0.0)
        z0 = float(zs[-1])
    cphase = float(np.angle(plant.cmd_c @ X)) + phi
    return CycleStart(x0, z0, float(amplitude_rad), float(freq_hz), cphase, float(resid), source)


@dataclass(frozen=True)
class Confirmation:
    """The outcome of a confirmation run (SI): ``outcome`` (:data:`OUTCOMES`), whether it is a
    limit cycle, the command and engine fundamentals [rad] and frequency [Hz] over the cycles
    measured, the cycle amplitudes a_k [rad], the simulated time [s], the start."""

    outcome: str
    lco: bool
    amplitude_rad: float
    engine_amplitude_rad: float
    freq_hz: float
    cycle_amplitudes_rad: tuple[float, ...]
    simulated_s: float
    start: CycleStart

    def to_dict(self) -> dict:
        return {"outcome": self.outcome, "lco": self.lco,
                "amplitude_deg": math.degrees(self.amplitude_rad) if self.lco else None,
                "engine_amplitude_deg": math.degrees(self.engine_amplitude_rad) if self.lco else None,
                "frequency_hz": self.freq_hz if self.lco else None,
                "final_amplitude_deg": math.degrees(self.amplitude_rad),
                "cycles": len(self.cycle_amplitudes_rad), "simulated_s": self.simulated_s,
                "start": {"source": self.start.source, "amplitude_deg": math.degrees(self.start.amplitude_rad),
                          "frequency_hz": self.start.freq_hz, "command_residual": self.start.command_residual}}


def _up_crossings(t: np.ndarray, c: np.ndarray) -> np.ndarray:
    """Times [s] where ``c`` crosses zero upwards (linear interpolation)."""
    k = np.flatnonzero((c[:-1] < 0.0) & (c[1:] >= 0.0))
    return t[k] - c[k] * (t[k + 1] - t[k]) / (c[k + 1] - c[k])


def cycle_amplitudes(t: np.ndarray, c: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(start times [s], amplitudes) of the fundamental of ``c`` over each whole cycle between
    successive up-crossings, fitted at that cycle's own frequency (offset included)."""
    tc = _up_crossings(t, c)
    out_t, out_a = [], []
    for a, b in zip(tc[:-1], tc[1:]):
        m = (t >= a) & (t < b)
        if m.sum() < 16:
            continue
        out_t.append(a)
        out_a.append(harmonic_amplitudes(t[m], c[m], 1.0 / (b - a))[0])
    return np.asarray(out_t), np.asarray(out_a)


def _drift_left(a: np.ndarray) -> float:
    """The relative change still to come of the cycle amplitudes ``a`` if their last changes
    go on geometrically, |d_k| rho / (1 - rho) / a_k with rho = d_k / d_(k-1) (0 when the last
    change is below 0.1 %; inf while the changes do not shrink)."""
    d = np.diff(a[-3:])
    if abs(d[-1]) < 1e-3 * a[-1]:
        return 0.0
    rho = d[-1] / d[-2] if d[-2] != 0 else math.inf
    if rho >= 1.0:
        return math.inf
    return abs(d[-1]) * max(rho, 0.0) / (1.0 - max(rho, 0.0)) / a[-1]


def _decide(a: np.ndarray) -> str | None:
    """``sustained``, ``decays`` or None (run on) from the cycle amplitudes ``a`` (module docstring)."""
    if a.size and a[-1] < THRESHOLD_RAD:
        return "decays"
    if a.size >= SETTLED_CYCLES + 1:
        r = a[-SETTLED_CYCLES:] / a[-SETTLED_CYCLES - 1:-1]
        if np.all(np.abs(r - 1.0) < SETTLED_TOL) and _drift_left(a) < SETTLED_TOL:
            return "sustained"
    if a.size >= 4:
        d = np.diff(a[-4:])
        rho = d[1:] / d[:-1]
        if np.all(d < 0) and np.all((rho > 0) & (rho <= RHO_MAX)) and abs(rho[1] / rho[0] - 1) < 0.1:
            den = d[-1] - d[-2]
            lim = a[-1] - d[-1] ** 2 / den if den != 0 else a[-1]
            if lim < THRESHOLD_RAD:
                return "decays"
    return None


def confirm(plant, model, start: CycleStart, *, duration_s: float = 300.0, window_s: float = 120.0,
            dt_s: float = DEFAULT_DT_S, cancel: threading.Event | None = None) -> Confirmation:
    """Run the closed loop ``plant`` (with ``model``'s friction and avionics) from ``start`` and
    decide (module docstring). ``duration_s`` [s] the longest run, ``window_s`` [s] the window of
    the final measurement when undecided, ``dt_s`` [s] the RK4 step; ``cancel``: when set, the
    run stops after its current piece (raises :class:`RuntimeError`)."""
    from taos.errors import SimulationUnstable
    from taos.flight.lco import FlightHistory, measure_oscillation

    check_friction_step(model, plant.inertia_kgm2, dt_s)
    ss = plant.ss
    n = ss.A.shape[0]
    o = ss.output_index
    Cy = np.ascontiguousarray(np.vstack([plant.cmd_c, ss.C[o("theta_rad")], np.eye(n)]))
    args = kernel_args(plant, model)
    kern = (model.friction.entry.rates, model.friction.pack(), model.avionics.pack())
    period_steps = 1.0 / (start.freq_hz * dt_s)
    chunk = max(RECORD_EVERY, int(math.ceil(CHUNK_CYCLES * period_steps / RECORD_EVERY)) * RECORD_EVERY)
    n_max = int(math.ceil(duration_s / dt_s / RECORD_EVERY)) * RECORD_EVERY
    x, z = np.ascontiguousarray(start.x0, float), float(start.z0)
    ts, cs, es = [np.zeros(1)], [np.array([float(plant.cmd_c @ x)])], [np.array([float(ss.C[o("theta_rad")] @ x)])]
    done, outcome = 0, None
    while done < n_max and outcome is None:
        if cancel is not None and cancel.is_set():
            raise RuntimeError("confirmation cancelled")
        k = min(chunk, n_max - done)
        nrec = k // RECORD_EVERY + 1
        y = np.empty((nrec, Cy.shape[0]))
        aux = np.empty((nrec, _dyn.N_AUX))
        # integrate_samples runs without the GIL: the confirmations proceed on several threads
        st = _dyn.integrate_samples(*args, Cy, *kern, x, z, np.zeros((k + 1, 1)), dt_s, RECORD_EVERY, y, aux)
        if st >= 0:
            raise SimulationUnstable((done + st) * dt_s, f"{model.friction.name} friction, confirmation run")
        x, z = np.ascontiguousarray(y[-1, 2:]), float(aux[-1, _dyn.AUX_Z])
        ts.append((done + RECORD_EVERY * np.arange(1, nrec)) * dt_s)
        cs.append(y[1:, 0])
        es.append(y[1:, 1])
        done += k
        t, c = np.concatenate(ts), np.concatenate(cs)
        _, a = cycle_amplitudes(t, c)
        outcome = _decide(a)
    t, c, e = np.concatenate(ts), np.concatenate(cs), np.concatenate(es)
    tc, a = cycle_amplitudes(t, c)
    if outcome == "sustained":
        t0, t1 = tc[-SETTLED_CYCLES - 1], tc[-1] + (tc[-1] - tc[-2])
        m = (t >= t0) & (t < t1)
        f = SETTLED_CYCLES / (tc[-1] - tc[-SETTLED_CYCLES - 1]) if tc.size > SETTLED_CYCLES else 1.0 / (tc[-1] - tc[-2])
        amp, _ = harmonic_amplitudes(t[m], c[m], f)
        eamp, _ = harmonic_amplitudes(t[m], e[m], f)
        return Confirmation("sustained", True, amp, eamp, float(f), tuple(map(float, a)), done * dt_s, start)
    if outcome == "decays":
        last = float(a[-1]) if a.size else 0.0
        return Confirmation("decays", False, last, 0.0, start.freq_hz, tuple(map(float, a)), done * dt_s, start)
    z_ = np.zeros_like(t)
    h = FlightHistory(t, z_, c, e, z_, z_, z_, model.friction.name, model.structure.load_stiffness_N_per_m)
    meas = measure_oscillation(h, min(window_s, 0.5 * t[-1]))
    kind = "grows" if meas.growth > 1.0 + SETTLED_TOL else "undecided"
    return Confirmation(kind, meas.lco, meas.amplitude_rad, meas.engine_amplitude_rad, meas.freq_hz,
                        tuple(map(float, a)), done * dt_s, start)


def confirm_many(jobs, threads: int | None = None, **kw) -> list[Confirmation]:
    """:func:`confirm` for every ``(plant, model, start)`` of ``jobs``, on ``threads`` threads
    (default numba's thread count; 1: in this thread, one after the other). The results are in
    the order of ``jobs`` and the same, bit for bit, for any thread count."""
    import numba

    jobs = list(jobs)
    threads = numba.get_num_threads() if threads is None else threads
    if threads <= 1 or len(jobs) <= 1:
        return [confirm(p, m, s, **kw) for p, m, s in jobs]
    cancel = threading.Event()   # an interrupt (or a failed run) stops the other runs after their piece
    ex = ThreadPoolExecutor(max_workers=min(threads, len(jobs)), thread_name_prefix="taos-confirm")
    try:
        futs = [ex.submit(confirm, *j, cancel=cancel, **kw) for j in jobs]
        return [f.result() for f in futs]
    except BaseException:
        cancel.set()
        raise
    finally:
        ex.shutdown(wait=True, cancel_futures=True)


def compile_kernel(model) -> None:
    """Compile (or load from the cache) the confirmation's kernel (the simulation's own
    :func:`taos.planar.dynamics.integrate_samples`, the same specialisation) with ``model``'s plant types:
    a run of no step on its simplex plant (``python -m taos.cli.warmup`` calls it)."""
    from taos.planar.simplex import simplex_plant

    plant = simplex_plant(model, "pitch")
    n = plant.ss.A.shape[0]
    y, aux = np.empty((1, n)), np.empty((1, _dyn.N_AUX))
    _dyn.integrate_samples(*kernel_args(plant, model), np.eye(n), model.friction.entry.rates, model.friction.pack(),
                     model.avionics.pack(), np.zeros(n), 0.0, np.zeros((1, plant.n_ext)), 1e-4, 1, y, aux)
