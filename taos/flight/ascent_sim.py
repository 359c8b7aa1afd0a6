"""Flying an ascent (:mod:`taos.flight.ascent`): the closed flight loop with the nonlinear TVC,
time-varying vehicle, boosters until separation, PTIs and winds; and the LCO read off its windows.

Each axis (pitch, yaw) is the planar flight loop of :func:`taos.flight.vehicle.flight_plant`
(vehicle + FCS + the simplex TVC with its friction, avionics and actuator/gimbal limits,
integrated by the compiled RK4 kernel of :mod:`taos.planar.dynamics`) augmented with

* the booster TVC, a first-order servo on the FCS command (state ``booster_deflection_rad``),
  adding n_b T_b l_b / I_v delta_b to the attitude acceleration until separation;
* a disturbance input ``disturbance_rad_s2`` = M_a(t) alpha_w(t) (wind angle of attack);
* the PTI added to the FCS command (input ``pti_rad``).

The vehicle properties and the scheduled FCS gains are held constant over each update interval
(zero-order hold; the file's ``update_interval``, 1 s) and the state is carried from interval to
interval: the attitude and rate are kept continuous across a change of the tail-wags-dog
coefficient b (xi = theta - b delta is re-based), the friction state is carried as it is. At
separation the attitude rate receives the file's ``separation_rate_kick``. With
``friction_follows_thrust`` the friction level is held likewise: the law's torque-like parameters
times N(t) / N_model, the trajectory's core thrust per engine over the model's bearing load
(:func:`taos.flight.friction_env.friction_scale`, T_c = mu N r_b).

An axis is one call of :func:`taos.planar.dynamics.integrate_segments_lanes` through all its
intervals (each interval's plant as data, the re-basing and the kick as state jumps);
:func:`simulate_ascents` flies many runs (Monte Carlo batches) side by side in the same kernel,
:data:`LANES` at a time, each run's numbers its own.

:func:`fly_ascent` is the ``taos ascent`` study: the ascent flown once per friction law and once
without friction, each run's post-separation windows analysed (:class:`AscentStudy`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from taos.flight._args import check_ascent_args, check_fly_args
from taos.flight.ascent import Ascent
# the lanes (plant, grid, inputs, packing) live in taos.flight.ascent_lanes; named here as before
from taos.flight.ascent_lanes import (AXES, MAX_STEPS, _external_inputs, _grid, _lane, _Lane,  # noqa: F401
                                      ascent_plant, flight_at, flights_at)
from taos.flight.lco import FlightHistory, flown_model, measure_oscillation
from taos.harmonics import fit_sines
from taos.model import TvcModel
from taos.results import atomic_write, package_version, write_provenance
from taos.results import model_provenance

DEFAULT_DT_S = 5e-4
#: recorded signals of an ascent run, per axis (SI)
SIGNALS = ("attitude_rad", "rate_rad_s", "command_rad", "engine_rad", "engine_rate_rad_s", "piston_m",
           "friction_torque_Nm", "booster_deflection_rad", "pti_rad", "disturbance_rad_s2",
           "piston_rate_m_s", "load_pressure_Pa", "valve_flow_m_s")
#: the hydraulic signals (the actuator states v_p, P_L and q, the valve's no-load flow over the
#: piston area; :mod:`taos.planar.actuator`) -> their state names, for the duty cycle
#: (:mod:`taos.flight.duty`)
HYDRAULIC = {"piston_rate_m_s": "v_p_m_s", "load_pressure_Pa": "p_load_Pa", "valve_flow_m_s": "q_m_s"}
#: the integrator of every ascent run (the compiled RK4 kernel of :mod:`taos.planar.dynamics`), as
#: the runs' provenance names it
INTEGRATOR = "rk4-fixed-step"
#: the exponential integrator of Monte Carlo lanes (:func:`simulate_ascents` ``integrator="etdrk4"``)
EXP_INTEGRATOR = "etdrk4-lanes"
#: :func:`simulate_ascents`' integrators
INTEGRATORS = ("rk4", "etdrk4")



@dataclass(frozen=True, eq=False)
class AscentHistory:
    """An ascent run: ``t_s`` and, per axis, the :data:`SIGNALS` as (n_axes, n_samples) arrays
    (SI); separation time [s]; PTI windows per axis; provenance."""

    t_s: np.ndarray
    axes: tuple[str, ...]
    signals: dict
    separation_time_s: float
    pti_windows: dict
    friction_model: str
    load_stiffness_N_per_m: float
    provenance: dict = field(default_factory=dict)

    def signal(self, name: str, axis: str) -> np.ndarray:
        return self.signals[name][self.axes.index(axis)]

    def flight_history(self, axis: str, t0_s: float, t1_s: float) -> FlightHistory:
        """The part of one axis between t0 and t1 as a :class:`~taos.flight.lco.FlightHistory`."""
        sel = (self.t_s >= t0_s) & (self.t_s <= t1_s)
        g = lambda k: self.signal(k, axis)[sel]  # noqa: E731
        return FlightHistory(t_s=self.t_s[sel], attitude_rad=g("attitude_rad"), command_rad=g("command_rad"),
                             engine_rad=g("engine_rad"), piston_m=g("piston_m"),
                             friction_torque_Nm=g("friction_torque_Nm"), pti_rad=g("pti_rad"),
                             friction_model=self.friction_model, load_stiffness_N_per_m=self.load_stiffness_N_per_m)

    def to_hdf5(self, path) -> None:
        """Write atomically: /t_s, /<axis>/<signal>, PTI windows and provenance as attributes."""
        def write(tmp):
            import h5py
            with h5py.File(tmp, "w") as h5:
                h5.create_dataset("t_s", data=self.t_s)
                h5.attrs["axes"] = ",".join(self.axes)
                h5.attrs["separation_time_s"] = self.separation_time_s
                h5.attrs["friction_model"] = self.friction_model
                h5.attrs["load_stiffness_N_per_m"] = self.load_stiffness_N_per_m
                write_provenance(h5, self.provenance)
                for i, ax in enumerate(self.axes):
                    g = h5.create_group(ax)
                    g.attrs["pti_windows_s"] = np.asarray(self.pti_windows[ax], float).reshape(-1, 2)
                    for k in SIGNALS:
                        g.create_dataset(k, data=self.signals[k][i], compression="gzip")
        atomic_write(path, write)


#: recorded outputs of the ascent plant, in the order of SIGNALS[:8] (friction torque from aux)
_RECORDED = ("attitude_rad", "rate_rad_s", "delta_cmd_rad", "theta_rad", "omega_rad_s", "x_p_m", None,
             "booster_deflection_rad")


def _recorded(plants: list, bounds: tuple, rec: int, Xq: np.ndarray) -> np.ndarray:
    """(n_rec, 8): the :data:`_RECORDED` outputs y = C x of one lane at its records ``Xq``
    (n_rec, n), each record with the C of its segment's plant (column 6, the friction torque,
    left for the caller). y = C x term by term in the order of the state index, over all the
    records at once: a term whose coefficient is zero in a segment adds 0 x = +-0 there, which
    changes no bit of a finite sum begun at +0, so every record has the bits of its own
    segment's sum, whatever the lane's memory layout."""
    nrec = Xq.shape[0]
    seg = np.empty(nrec, np.int64)   # the segment of each record
    for s_, (k0, k1) in enumerate(zip(bounds[:-1], bounds[1:])):
        seg[k0 // rec:k1 // rec + (1 if k1 == bounds[-1] else 0)] = s_
    p0 = plants[0].ss
    if any(p.ss.outputs != p0.outputs or p.ss.states != p0.states for p in plants):
        raise ValueError("a lane's segment plants differ in their outputs or states")
    C = np.stack([p.ss.C for p in plants])   # (n_seg, n_y, n)
    Y = np.empty((nrec, 8))
    for j, name in enumerate(_RECORDED):
        if name is not None:
            rows = C[:, p0.output_index(name)]   # (n_seg, n)
            coef = rows[seg]
            y = np.zeros(nrec)
            for i in np.flatnonzero(np.any(rows != 0.0, axis=0)):
                y += coef[:, i] * Xq[:, i]
            Y[:, j] = y
    return Y


def _fly_lanes(lanes: list[_Lane], t: np.ndarray, bounds: tuple, rec: int, dt_s: float, exp: bool = False) -> list:
    """Fly ``lanes`` (equal keys) in one call of
    :func:`taos.planar.dynamics.integrate_segments_lanes` (RK4, step ``dt_s`` [s]) or, with
    ``exp``, of :func:`taos.planar._explanes.integrate_segments_lanes_exp` (ETDRK4, step 2
    ``dt_s``: ``t``, ``bounds``, ``rec`` and the lanes' inputs are then on the half-step grid);
    per lane (the first 8 :data:`SIGNALS` then the :data:`HYDRAULIC` ones at the records (n_rec,
    11), the external inputs there (n_rec, 2)) or the :class:`~taos.errors.SimulationUnstable` it
    ended with."""
    from taos.errors import SimulationUnstable
    from taos.planar import dynamics as _dy

    mats = np.stack([ln.mats for ln in lanes], axis=-1)           # (n_seg, n + 3, n + n_r + 2, R)
    if exp:   # the TVC block goes to the exact propagation: its entries leave N's matrix
        nb, co = _exp_block(lanes, mats, 2.0 * dt_s)
        mats = mats.copy()
        mats[:, :nb, :nb, :] = 0.0
    mask = np.any(mats != 0.0, axis=(0, 3))
    ip = np.concatenate([[0], np.cumsum(mask.sum(axis=1))]).astype(np.int64)
    ix = np.nonzero(mask)[1].astype(np.int64)
    mx = np.ascontiguousarray(mats[:, mask, :])                    # (n_seg, nnz, R)
    heads = np.ascontiguousarray(np.stack([ln.heads for ln in lanes], axis=1))  # (n_seg, R, N_HEAD)
    si = lanes[0].plants[0].ss.state_index
    jdst = np.array([si("xi_rad"), si("xi_rate_rad_s")], np.int64)
    jsrc = np.array([si("theta_rad"), si("omega_rad_s")], np.int64)
    jcoef = np.ascontiguousarray(np.stack([ln.jcoef for ln in lanes], axis=-1))
    kick = np.ascontiguousarray(np.stack([ln.kick for ln in lanes], axis=-1))
    x0 = np.ascontiguousarray(np.stack([ln.x0 for ln in lanes], axis=-1))
    r = np.ascontiguousarray(np.stack([ln.r for ln in lanes]), dtype=np.float64)  # (R, n_steps + 1, n_r)
    n, nl = x0.shape
    nrec = (len(t) - 1) // rec + 1
    X = np.empty((nrec, n, nl))
    aux = np.empty((nrec, _dy.N_AUX, nl))
    status = np.empty(nl, np.int64)
    m0 = lanes[0].model
    common = (ip, ix, mx, heads, m0.friction.entry.rates_lanes,
              np.ascontiguousarray(np.stack([ln.fpack for ln in lanes], axis=1)),
              np.stack([ln.model.avionics.pack() for ln in lanes]), np.asarray(bounds, np.int64), jdst, jsrc, jcoef,
              kick, x0, np.zeros(nl), r)
    if exp:
        from taos.planar._explanes import integrate_segments_lanes_exp
        integrate_segments_lanes_exp(*common, float(2.0 * dt_s), int(nb), co, int(rec), X, aux, status)
    else:
        _dy.integrate_segments_lanes(*common, dt_s, rec, X, aux, status)
    out = []
    how = f"ETDRK4 step {2.0 * dt_s} s" if exp else f"dt = {dt_s} s"
    XL = np.ascontiguousarray(X.transpose(2, 0, 1))   # (R, n_rec, n): a lane's records contiguous
    for q, ln in enumerate(lanes):
        if status[q] >= 0:
            out.append(SimulationUnstable(float(t[status[q]]), f"{ln.model.friction.name} friction, {how}"))
            continue
        Xq = XL[q]
        Y = _recorded(ln.plants, bounds, rec, Xq)
        Y[:, 2] += ln.r[::rec, 0]  # the FCS command: the PTI is added to it
        Y[:, 6] = aux[:, _dy.AUX_TF, q]
        Yh = np.column_stack([Xq[:, si(v)] for v in HYDRAULIC.values()])
        out.append((np.column_stack([Y, Yh]), ln.r[::rec]))
    return out


def _exp_block(lanes: list[_Lane], mats: np.ndarray, h: float) -> tuple[int, np.ndarray]:
    """(nb, co): the exactly propagated block, the TVC's states (those before the vehicle's
    ``xi_rad``: valve, oil column, piston, pressure feedback, engine), and its ETDRK4
    coefficients for the step ``h`` [s] per segment and lane, (n_seg, 6, nb, nb, R)
    (:func:`taos.planar._expstep.etd_coefficients`; computed once per distinct block: the TVC's
    block does not change with the vehicle's segments)."""
    from taos.planar._expstep import etd_coefficients

    nb = lanes[0].plants[0].ss.state_index("xi_rad")
    nseg, nl = mats.shape[0], mats.shape[-1]
    co = np.empty((nseg, 6, nb, nb, nl))
    for q in range(nl):
        done: dict = {}
        for s_ in range(nseg):
            blk = np.ascontiguousarray(mats[s_, :nb, :nb, q])
            key = blk.tobytes()
            if key not in done:
                done[key] = np.stack(etd_coefficients(blk, h))
            co[s_, :, :, :, q] = done[key]
    return nb, co


#: runs flown in lockstep by one kernel call (the lanes of :func:`simulate_ascents`), and the
#: memory one call may take for its inputs and records [bytes] (fewer lanes for long runs)
LANES = 32
LANE_BYTES = 1 << 30
#: kernel calls are made of a multiple of this many lanes (but the last): calls of 21-31 lanes
#: measured 1.2-1.8x the time a lane of a 32-lane call (benchmarks/RESULTS.md, section mcfast: the
#: compiled vector loops across the lanes leave a scalar rest)
LANE_VECTOR = 16


def _lane_bytes(ln: _Lane, n_t: int, rec: int) -> int:
    """Memory of one lane in a kernel call: its inputs, recorded states and matrices [bytes]."""
    return 8 * (ln.r.size + ((n_t - 1) // rec + 1) * (ln.x0.size + 3) + ln.mats.size) + 1


def simulate_ascents(runs: list[tuple[Ascent, TvcModel, int]], *, axis: str, start_s: float = 0.0,
                     end_s: float | None = None, dt_s: float = DEFAULT_DT_S, record_interval_s: float = 0.01,
                     attitude0_rad: float = 0.0, friction_follows_thrust: bool = False,
                     integrator: str = "rk4") -> list:
    """Fly many ascents on one ``axis``: ``runs`` is a list of (ascent, TVC model, seed); returns,
    per run, its :class:`AscentHistory` (as :func:`simulate_ascent` with ``axes=(axis,)``) or the
    exception it ended with (:class:`~taos.errors.SimulationUnstable`,
    :class:`~taos.errors.InputError`, ValueError, ArithmeticError).

    ``integrator``: ``"rk4"`` (classical RK4, step ``dt_s``, :data:`INTEGRATOR`) or ``"etdrk4"``
    (:data:`INTEGRATORS`: the TVC's actuator and engine propagated exactly, the rest by ETDRK4's
    stages, :mod:`taos.planar._explanes`, step ``dt_s``; the inputs sampled every dt_s / 2, and
    ``record_interval_s`` a whole even number of half steps).

    Runs with the same plant structure and segments are integrated :data:`LANES` at a time in
    lockstep (vectorised across the runs); a run's numbers do not depend on the other runs nor on
    how many there are."""
    from taos.errors import InputError, SimulationUnstable
    if integrator not in INTEGRATORS:
        raise InputError("argument", "integrator", "one of " + ", ".join(INTEGRATORS), got=repr(integrator))
    exp = integrator == "etdrk4"
    gdt = 0.5 * dt_s if exp else dt_s     # the input and record grid's spacing [s]
    if exp and int(round(record_interval_s / gdt)) % 2:
        raise InputError("argument", "record_interval_s", f"a whole number of ETDRK4 steps of {dt_s:g} s",
                         got=repr(record_interval_s))
    res: list = [None] * len(runs)
    groups, version = {}, package_version()   # read once a call (importlib.metadata: ms a read)
    grids = {}
    for i, (asc, model, seed) in enumerate(runs):
        try:
            end, rec, t, bounds = _grid(asc, start_s, end_s, gdt, record_interval_s)
            r = _external_inputs(asc, axis, t, seed, gdt)
            ln = _lane(asc, model, axis, t, bounds, rec, gdt, start_s, attitude0_rad, r, friction_follows_thrust,
                       step_s=dt_s)
        except (SimulationUnstable, InputError, ValueError, ArithmeticError) as e:
            res[i] = e
            continue
        grids[i] = (end, rec, t, bounds)
        groups.setdefault((ln.key, rec, len(t), bounds), []).append((i, ln))
    for (_, rec, _, bounds), members in groups.items():
        t = grids[members[0][0]][2]
        lanes = max(1, min(LANES, LANE_BYTES // _lane_bytes(members[0][1], len(t), rec)))
        lanes -= lanes % LANE_VECTOR if lanes > LANE_VECTOR else 0
        # as few kernel calls as allowed, all but the last of ``lanes`` runs (LANE_VECTOR)
        for chunk in (members[g:g + lanes] for g in range(0, len(members), lanes)):
            for (i, _), flown in zip(chunk, _fly_lanes([ln for _, ln in chunk], t, bounds, rec, gdt, exp)):
                if isinstance(flown, Exception):
                    res[i] = flown
                    continue
                asc, model, seed = runs[i]
                res[i] = _history(asc, model, (axis,), [flown], grids[i], dt_s, seed, start_s, attitude0_rad,
                                  friction_follows_thrust, version=version, integrator=integrator)
    return res


def _history(ascent: Ascent, model: TvcModel, axes: tuple, flown: list, grid: tuple, dt_s: float, seed: int,
             start_s: float, attitude0_rad: float, follow: bool = False, version: str | None = None,
             integrator: str = "rk4") -> AscentHistory:
    end, rec, t, _ = grid
    method, rec_steps = (INTEGRATOR, rec) if integrator == "rk4" else (EXP_INTEGRATOR, rec // 2)
    out = {k: [] for k in SIGNALS}
    for Y, Rr in flown:
        for j, k in enumerate(SIGNALS[:8]):
            out[k].append(Y[:, j])
        out["pti_rad"].append(Rr[:, 0])
        out["disturbance_rad_s2"].append(Rr[:, 1])
        for j, k in enumerate(HYDRAULIC):
            out[k].append(Y[:, 8 + j])
    prov = {**model_provenance(model), "ascent_file": ascent.source,
            "ascent_sha256": ascent.sha256, "flight_file": ascent.flight.source,
            "flight_sha256": ascent.flight.sha256, "package_version": version or package_version(),
            "solver": {"method": method, "dt_s": dt_s, "record_every": rec_steps},
            "seed": int(seed), "start_s": start_s, "end_s": end, "attitude0_rad": attitude0_rad,
            "friction_model": model.friction.name} | ({"friction_follows_thrust": True} if follow else {})
    return AscentHistory(t_s=t[::rec], axes=tuple(axes), signals={k: np.vstack(v) for k, v in out.items()},
                         separation_time_s=ascent.boosters.separation_time_s,
                         pti_windows={ax: ascent.pti_windows(ax) for ax in axes}, friction_model=model.friction.name,
                         load_stiffness_N_per_m=model.structure.load_stiffness_N_per_m, provenance=prov)


def simulate_ascent(ascent: Ascent, model: TvcModel, *, axes: tuple[str, ...] = AXES, start_s: float = 0.0,
                    end_s: float | None = None, dt_s: float = DEFAULT_DT_S, record_interval_s: float = 0.01,
                    seed: int = 0, attitude0_rad: float = 0.0, progress: bool = False,
                    friction_follows_thrust: bool = False) -> AscentHistory:
    """Fly ``ascent`` from ``start_s`` to ``end_s`` [s] (default the trajectory's end) with the
    TVC ``model`` on each of ``axes``.

    ``dt_s`` RK4 step [s]; ``record_interval_s`` output spacing [s] (a whole number of steps);
    ``seed`` draws the turbulence (axis k uses the stream SeedSequence([seed, k])), so a run is a
    pure function of its inputs; ``attitude0_rad`` initial attitude error [rad];
    ``friction_follows_thrust``: the friction level follows the trajectory's thrust (module
    docstring; recorded in the provenance). Each axis is
    one call of the compiled kernel through all the segments (:func:`simulate_ascents`' kernel,
    one lane). Raises :class:`~taos.errors.SimulationUnstable` on a non-finite state."""
    check_ascent_args(**locals())   # every argument (the parameters, nothing else yet), before any work
    grid = _grid(ascent, start_s, end_s, dt_s, record_interval_s)
    _, rec, t, bounds = grid
    it = list(axes)
    if progress:
        from tqdm import tqdm
        it = tqdm(it, desc="ascent", unit="axis")
    lanes = [_lane(ascent, model, ax, t, bounds, rec, dt_s, start_s, attitude0_rad,
                   _external_inputs(ascent, ax, t, seed, dt_s), friction_follows_thrust) for ax in it]
    if len({ln.key for ln in lanes}) == 1:  # the axes side by side in one kernel call
        flown = _fly_lanes(lanes, t, bounds, rec, dt_s)
    else:
        flown = [f for ln in lanes for f in _fly_lanes([ln], t, bounds, rec, dt_s)]
    for f in flown:
        if isinstance(f, Exception):
            raise f
    return _history(ascent, model, tuple(axes), flown, grid, dt_s, seed, start_s, attitude0_rad,
                    friction_follows_thrust)


# -- windows --------------------------------------------------------------------------------
@dataclass(frozen=True)
class WindowResult:
    """One analysis window of an ascent run: ``kind`` 'pti' or 'quiescent', [start, end] [s];
    the oscillation of the FCS command measured as ``taos lco`` does
    (:func:`~taos.flight.lco.measure_oscillation`): LCO flag, command and engine amplitudes
    [rad], frequency [Hz]; for PTI windows the command fundamental at ``lco_band_freq_hz``
    that the friction adds beyond the linear run (``friction_band_amplitude_rad``)."""

    axis: str
    kind: str
    start_s: float
    end_s: float
    lco: bool
    amplitude_rad: float
    engine_amplitude_rad: float
    freq_hz: float
    friction_band_amplitude_rad: float | None = None

    def to_dict(self) -> dict:
        """JSON form (degrees; None where a figure does not apply)."""
        num = lambda v, f=math.degrees: None if v is None or not math.isfinite(v) else f(v)  # noqa: E731
        return {"axis": self.axis, "kind": self.kind, "start_s": self.start_s, "end_s": self.end_s, "lco": self.lco,
                "amplitude_deg": num(self.amplitude_rad), "engine_amplitude_deg": num(self.engine_amplitude_rad),
                "frequency_hz": num(self.freq_hz, float),
                "friction_band_amplitude_deg": num(self.friction_band_amplitude_rad)}


def analysis_windows(h: AscentHistory, axis: str, settle_s: float = 15.0, min_quiet_s: float = 20.0
                     ) -> list[tuple[str, float, float]]:
    """(kind, start, end) of the post-separation windows: each PTI window, and each quiescent
    stretch of at least ``min_quiet_s`` between them (starting ``settle_s`` after separation or
    after a PTI ends)."""
    t0 = max(h.separation_time_s, float(h.t_s[0]))
    t_end = float(h.t_s[-1])
    out = []
    cursor = t0 + settle_s
    for a, b in sorted(h.pti_windows[axis]):
        if b <= t0 or a >= t_end:
            continue
        if a - cursor >= min_quiet_s:
            out.append(("quiescent", cursor, a))
        out.append(("pti", max(a, t0), min(b, t_end)))
        cursor = b + settle_s
    if t_end - cursor >= min_quiet_s:
        out.append(("quiescent", cursor, t_end))
    return out


def analyse_ascent(h: AscentHistory, linear: AscentHistory | None = None, axes=None,
                   threshold_rad: float = 0.004 * math.pi / 180) -> list[WindowResult]:
    """Measure each post-separation window of ``h`` (:func:`analysis_windows`). Quiescent
    windows: the command oscillation (LCO if above ``threshold_rad`` and not decaying). PTI
    windows, when the same run without friction (``linear``) is given: the friction-induced part
    of the command (h - linear) at the frequency of the preceding quiescent window's oscillation
    (the nearest one if none precedes), over the second half of the window (the first half still
    carries the decay of the cycle the PTI broke up): what a limit cycle riding on the PTI would
    show."""
    res = []
    for ax in axes or h.axes:
        wins = analysis_windows(h, ax)
        quiet = []
        for kind, a, b in wins:
            if kind != "quiescent":
                continue
            m = measure_oscillation(h.flight_history(ax, a, b), window_s=b - a, threshold_rad=threshold_rad)
            quiet.append(WindowResult(ax, kind, a, b, m.lco, m.amplitude_rad, m.engine_amplitude_rad, m.freq_hz))
        res += quiet
        for kind, a, b in wins:
            if kind != "pti":
                continue
            band = None
            f = None
            if quiet:
                before = [q for q in quiet if q.end_s <= a + 1e-9]
                near = before[-1] if before else min(quiet, key=lambda q: abs(q.start_s - b))
                f = near.freq_hz
            if linear is not None and f:
                sel = (h.t_s >= 0.5 * (a + b)) & (h.t_s <= b)
                d = h.signal("command_rad", ax)[sel] - linear.signal("command_rad", ax)[sel]
                band = float(fit_sines(h.t_s[sel], d, f, trend=True).amplitude()[0, 0])
            res.append(WindowResult(ax, kind, a, b, False, float("nan"), float("nan"), f or float("nan"), band))
    return sorted(res, key=lambda r: (r.axis, r.start_s))


# -- the study: one run per friction law, windows against the run without friction -------------
def run_file(friction_model: str) -> str:
    """The file name of the run with friction law ``friction_model`` in an ascent study's folder."""
    return f"ascent_{friction_model}.h5"


@dataclass(frozen=True, eq=False)
class AscentStudy:
    """An ascent flown once per friction law (:func:`fly_ascent`): ``runs``, one
    :class:`AscentHistory` per model in the order given; ``windows``, each run's analysed
    post-separation windows (:func:`analyse_ascent` against ``reference``, the same ascent flown
    without friction); the flown ``axes``, segment [``start_s``, ``end_s``] [s] and the
    ``avionics`` setting the runs were flown with."""

    ascent: Ascent
    runs: tuple[AscentHistory, ...]
    windows: tuple[tuple[WindowResult, ...], ...]
    reference: AscentHistory
    axes: tuple[str, ...]
    start_s: float
    end_s: float
    avionics: str
    #: the flown TVC of each run (for the duty cycle; empty: no duty cycle in the summary)
    models: tuple = ()

    @property
    def zoom_s(self) -> float:
        """The late-burn stretch the study's plot zooms on [s]: at most 60 s, a quarter of the run."""
        return min(60.0, 0.25 * (self.end_s - self.start_s))

    def summary(self) -> dict:
        """The ``summary.json`` of ``taos ascent`` (JSON-ready): the ascent file and hash, the
        avionics setting, the axes, and per run its law, its file name (:func:`run_file`), its
        windows (:meth:`WindowResult.to_dict`), its hydraulic duty cycle over the whole run
        (:func:`taos.flight.duty.duty_summary`) and provenance."""
        from taos.flight.duty import duty_summary
        duty = [duty_summary(h, m) for h, m in zip(self.runs, self.models)] or [None] * len(self.runs)
        return {"ascent_file": self.ascent.source, "ascent_sha256": self.ascent.sha256, "avionics": self.avionics,
                "axes": list(self.axes), "friction_follows_thrust": bool(self.reference.provenance.get(
                    "friction_follows_thrust", False)),
                "runs": [{"friction_model": h.friction_model, "file": run_file(h.friction_model),
                          "windows": [w.to_dict() for w in wins], "duty": d, "provenance": h.provenance}
                         for h, wins, d in zip(self.runs, self.windows, duty)]}

    to_dict = summary


def fly_ascent(ascent: Ascent, models: Sequence[TvcModel], *, reference: TvcModel, avionics: str = "bounding",
               axes: tuple[str, ...] = ("yaw",), start_s: float = 0.0, end_s: float | None = None,
               dt_s: float = DEFAULT_DT_S, seed: int = 0, progress: bool = False,
               friction_follows_thrust: bool = False) -> AscentStudy:
    """Fly ``ascent`` from ``start_s`` to ``end_s`` [s] (default the trajectory's end) on ``axes``
    with each TVC of ``models`` (typically one per friction law) and with ``reference``, the same
    TVC without friction (law ``none``; a model of law ``none`` in ``models`` is that run), and
    analyse each run's post-separation windows against the reference (:func:`analyse_ascent`).

    ``avionics``: ``"bounding"`` flies every model with the paper's bounding avionics gain,
    ``"model"`` with the models' own avionics (:func:`taos.flight.lco.flown_model`). ``dt_s``, ``seed``,
    ``friction_follows_thrust``: as :func:`simulate_ascent` (the same seed for every run, so the
    runs differ by their TVC only). ``progress``: a bar over the models. Raises
    :class:`~taos.errors.SimulationUnstable` when a run diverges."""
    check_fly_args(**locals())   # every argument (the parameters, nothing else yet), before any run
    models = [flown_model(m, avionics) for m in models]   # (ValueError for an unknown setting)
    reference = flown_model(reference, avionics)
    axes = tuple(axes)
    end = ascent.end_time_s if end_s is None else float(end_s)
    fly = {"axes": axes, "start_s": start_s, "end_s": end, "dt_s": dt_s, "seed": seed,
           "friction_follows_thrust": friction_follows_thrust}
    ref = simulate_ascent(ascent, reference, **fly)
    from tqdm import tqdm

    runs, windows = [], []
    for m in tqdm(models, desc="ascent", unit="law", disable=not progress):
        h = ref if m.friction.name == "none" else simulate_ascent(ascent, m, **fly)
        runs.append(h)
        windows.append(tuple(analyse_ascent(h, ref)))
    return AscentStudy(ascent, tuple(runs), tuple(windows), ref, axes, float(start_s), end, avionics,
                       tuple(models))
