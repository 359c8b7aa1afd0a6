"""Nonlinear multi-engine time domain: every engine's nonlinear TVC coupled through the modes.

Each actuator k is the taos planar simplex block of its engine's model
(:func:`taos.planar.simplex.simplex_state_space`, ``structure_inputs=True``) with the model
file's friction law, valve law and limits (:mod:`taos.planar.saturation`) and avionics
(:mod:`taos.planar.avionics`); the blocks are coupled through the structure's modes
q'' + 2 zeta w q' + w^2 q = Phi^T f exactly as in the linear MASV model
(:mod:`masv.coupled`, :mod:`masv.system`). The compiled kernel is :mod:`masv._kernel`.

Where the coupled model needs a choice the planar one does not make (stated here, and in the
results' provenance under ``coupling``):

* gimbal friction and the hard stops act between the engine and the structure: their rate
  and angle are relative to the structure's rotation at the gimbal (w = theta' - r',
  theta - r), and their torque's reaction acts on the structure (the linear model has neither;
  on a rigid structure both are the planar model's);
* the friction law's applied torque is R F_L - K_n (theta - r), without the gimbal
  acceleration's inertial torque -m_e l_e a_g (as the planar model, which has none);
* r' comes from the retained modes; the residual flexibility of truncated modes (a massless
  compliance) enters e and r but not their rates, nor the torque's direct path into the
  friction law's applied torque (``coupling.residual_flexibility`` says whether there is any).

Commands: one profile for every actuator (a two-axis profile drives the pitch actuators with
its pitch part and the yaw actuators with its yaw part), or a profile per actuator name.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from taos.errors import InputError, SimulationUnstable
from taos.profiles import is_two_axis
from taos.results import atomic_write, write_provenance

from .config import MasvConfig
from .provenance import config_provenance
from .system import build_system

#: default RK4 step [s]. 4e-4 s: on the Green Run two-axis profile (models/masv/core_stage.toml,
#: modified LuGre, limits and avionics) the engine angles differ from a 5e-5 s run by at most
#: 2.3e-4 deg of a 0.362 deg peak (2e-4 s: 1.5e-4 deg, as `taos simulate` at its default 2e-4 s
#: on rs25_hotfire; the stick-slip instants, not the step, set the difference; benchmarks/RESULTS.md),
#: at half the cost; the relief-valve step rule of the shipped servo (taos.bounds) is 1.6 of the
#: RK4 limit 2.0 at this step
DEFAULT_DT_S = 4e-4
#: default recording: every 5th step (2 ms at the default step)
DEFAULT_RECORD_EVERY = 5
#: recorded per-actuator arrays of :class:`MasvTimeHistory` (each (n_act, n_rec), SI)
ACTUATOR_ARRAYS = ("command_rad", "command_avionics_rad", "piston_m", "engine_rad", "load_force_N",
                   "gimbal_torque_Nm", "friction_state_rad", "elongation_m", "gimbal_rotation_rad")


@dataclass(frozen=True, eq=False)
class MasvTimeHistory:
    """One multi-engine run. ``t_s`` (n_rec,) [s]; per actuator (n_act, n_rec):
    ``command_rad`` theta_c, ``command_avionics_rad`` u, ``piston_m`` x_p, ``engine_rad`` theta,
    ``load_force_N`` F_L, ``gimbal_torque_Nm`` T (friction minus hard stop, on the engine as
    -T), ``friction_state_rad`` z, ``elongation_m`` e, ``gimbal_rotation_rad`` r; ``modal_q``,
    ``modal_qdot`` (n_modes, n_rec) [sqrt(kg) m, sqrt(kg) m/s]; ``provenance``."""

    t_s: np.ndarray
    actuators: tuple[str, ...]
    engines: tuple[str, ...]
    engine_of: tuple[str, ...]
    command_rad: np.ndarray
    command_avionics_rad: np.ndarray
    piston_m: np.ndarray
    engine_rad: np.ndarray
    load_force_N: np.ndarray
    gimbal_torque_Nm: np.ndarray
    friction_state_rad: np.ndarray
    elongation_m: np.ndarray
    gimbal_rotation_rad: np.ndarray
    modal_q: np.ndarray
    modal_qdot: np.ndarray
    provenance: dict = field(default_factory=dict)

    def to_hdf5(self, path) -> None:
        """Write atomically: /t_s, /actuators/<name>/<array>, /modes/q and /modes/qdot,
        provenance as root attributes (JSON for nested values)."""
        def write(tmp):
            import h5py

            with h5py.File(tmp, "w") as h5:
                h5.create_dataset("t_s", data=self.t_s, track_times=False)
                h5.attrs["actuators"] = ",".join(self.actuators)
                h5.attrs["engine_of"] = ",".join(self.engine_of)
                write_provenance(h5, self.provenance)
                for i, a in enumerate(self.actuators):
                    g = h5.create_group(f"actuators/{a}")
                    for n in ACTUATOR_ARRAYS:
                        g.create_dataset(n, data=getattr(self, n)[i], compression="gzip", track_times=False)
                m = h5.create_group("modes")
                m.create_dataset("q", data=self.modal_q, compression="gzip", track_times=False)
                m.create_dataset("qdot", data=self.modal_qdot, compression="gzip", track_times=False)
        atomic_write(path, write)


def _commands(cfg: MasvConfig, commands, t: np.ndarray) -> tuple[np.ndarray, dict]:
    """(n_steps + 1, n_act) command samples [rad] and what drove each actuator."""
    na = len(cfg.actuators)
    out = np.zeros((t.size, na))
    names = cfg.actuator_names
    if isinstance(commands, dict):
        for n in commands:
            if n not in names:
                raise InputError("commands", n, "an actuator of the configuration (" + ", ".join(names) + ")")
        per = {n: commands.get(n) for n in names}
    else:
        per = {n: commands for n in names}
    how, done = {}, {}
    for k, a in enumerate(cfg.actuators):
        p = per[a.name]
        if p is None:
            how[a.name] = "none (zero)"
            continue
        if id(p) not in done:                 # each profile evaluated once
            done[id(p)] = np.atleast_2d(p(t))
        v = done[id(p)]
        out[:, k] = v[1] if (is_two_axis(p) and a.axis == "yaw") else v[0]
        how[a.name] = getattr(p, "name", "") or type(p).__name__
    return out, how


def _duration(commands) -> float:
    ps = list(commands.values()) if isinstance(commands, dict) else [commands]
    return max(p.duration_s for p in ps if p is not None) + 1.0


def simulate(cfg: MasvConfig, commands, *, dt_s: float = DEFAULT_DT_S, record_every: int = DEFAULT_RECORD_EVERY,
             duration_s: float | None = None, friction: str | None = None, avionics: bool = True,
             limits: bool = True) -> MasvTimeHistory:
    """Run the configuration's engines, nonlinear, coupled through its modes (module docstring).

    Parameters
    ----------
    cfg : MasvConfig
    commands : a :mod:`taos.profiles` profile for every actuator, or {actuator name: profile}
        (actuators not named get zero) [rad].
    dt_s : float
        RK4 step [s] (checked against each friction law's explicit-step rule).
    record_every : int
        Keep every n-th step.
    duration_s : float, optional
        Simulated time [s]; default the longest profile's duration plus 1 s.
    friction : str, optional
        A friction law for every engine (e.g. ``"none"``: the variant ``friction.model``);
        default each model file's own.
    avionics, limits : bool
        False turns off the avionics (quantiser, crossover gain) or the valve, pressure and
        gimbal limits (for comparisons with the linear model).
    """
    if not (dt_s > 0 and math.isfinite(dt_s)) or int(record_every) < 1:
        raise InputError("simulate", "dt_s/record_every", "a positive step and record_every >= 1",
                         got=f"{dt_s}, {record_every}")
    from dataclasses import replace

    from taos.planar._avionics_slots import AV_TABLE
    from taos.planar.saturation import (
        N_HEAD,
        ROW_FLOW_IN,
        ROW_P,
        ROW_Q,
        ROW_UV,
        ROW_UV_IN,
        embed_limits,
        row_start,
    )
    from taos.planar.simplex import simplex_limits

    from ._kernel import _csr_arrays, integrate, lane_layout, lane_operator

    if friction is not None:
        cfg = replace(cfg, engines=tuple(replace(e, model=e.model.with_friction(friction)) for e in cfg.engines))
    system = build_system(cfg)
    cm = system.coupled(("command_rad", "friction_torque_Nm"), torque_reaction=True)
    na, nm, N = cm.n_act, cm.n_modes, cm.A.shape[0]
    nb = int(cm.offsets[-1])
    models = [cfg.engine(a.engine).model for a in cfg.actuators]
    rates = {m.friction.entry.rates for m in models}
    if len(rates) != 1:
        raise InputError(cfg.source, "engine.model", "one friction law for every engine (the kernel takes one)",
                         got=", ".join(sorted({m.friction.name for m in models})))
    for m, a in zip(models, cfg.actuators):
        m.friction.check_step(m.engine.inertia(a.axis), dt_s, m.source)
    lims = [embed_limits(simplex_limits(m, a.axis), cm.blocks[k].A.shape[0], 0) if limits else np.zeros(0)
            for k, (m, a) in enumerate(zip(models, cfg.actuators))]
    # the stage vector v = [x; u; T; e_v; c_q; q''] of masv._kernel: x' = M v, q'' = Q v, aux = R x
    nv = N + 4 * na + nm
    Mf, Qf = np.zeros((N, nv)), np.zeros((nm, nv))
    Mf[:, :N], Mf[:, N:N + 2 * na], Mf[:, N + 4 * na:] = cm.A_direct, cm.B_direct, cm.Gq
    Qf[:, :N], Qf[:, N:N + 2 * na] = cm.Qx, cm.Qw
    rows = np.zeros((6 * na, N))
    H = np.zeros((na, N_HEAD))
    for k in range(na):
        o, m = int(cm.offsets[k]), cm.blocks[k].A.shape[0]
        ith, iom = o + cm.blocks[k].states.index("theta_rad"), o + cm.blocks[k].states.index("omega_rad_s")
        rows[k, iom] = 1.0
        if nm:
            rows[k, nb + nm:] -= cm.Ux[na + k, nb:nb + nm]       # - r' from the retained modes
        rows[na + k] = cm.output_rows(k, "applied_torque_Nm")[0]
        rows[2 * na + k] = -cm.Ux[na + k]
        rows[2 * na + k, ith] += 1.0
        lk = lims[k]
        if lk.size:
            H[k] = lk[:N_HEAD]
            blk = {i: lk[row_start(i, m):row_start(i + 1, m)] for i in (ROW_UV, ROW_Q, ROW_P, ROW_UV_IN, ROW_FLOW_IN)}
            rows[3 * na + k, o:o + m] = blk[ROW_UV]
            rows[4 * na + k, o:o + m] = blk[ROW_Q]
            rows[5 * na + k, o:o + m] = blk[ROW_P]
            Mf[o:o + m, N + 2 * na + k] = blk[ROW_UV_IN]
            Mf[o:o + m, N + 3 * na + k] = blk[ROW_FLOW_IN]
    lay = lane_layout(cm.offsets, nm)
    off = cm.offsets

    def remap(a):
        out = np.zeros((a.shape[0], lay.nw))
        np.add.at(out, (slice(None), lay.colmap[:a.shape[1]]), a)
        return out

    blk_rows = [np.vstack([Mf[off[k] + i] if off[k] + i < off[k + 1] else np.zeros(nv) for k in range(na)])
                for i in range(lay.m)]
    ml = lane_operator(blk_rows, lay.colmap, na, lay.ws0, lay.nw)
    rl = lane_operator([rows[i * na:(i + 1) * na] for i in range(6)], lay.colmap, na, lay.ws0, lay.nw)
    mp, mx, mvv = _csr_arrays(remap(Mf[nb:]))
    fp = np.ascontiguousarray(np.vstack([m.friction.pack() for m in models]))
    packs = [m.avionics.pack() if avionics else np.zeros(AV_TABLE) for m in models]   # zeros: off
    avp = np.zeros((na, max(p.size for p in packs)))
    for k, p in enumerate(packs):
        avp[k, :p.size] = p
    T = _duration(commands) if duration_s is None else float(duration_s)
    n = int(math.ceil(T / dt_s))
    t = np.arange(n + 1) * dt_s
    r, how = _commands(cfg, commands, t)
    nrec = n // record_every + 1
    reps, amap = [], np.empty(na, dtype=np.int64)     # actuators with one command and one avionics
    for k in range(na):
        j = next((i for i, q in enumerate(reps) if np.array_equal(r[:, q], r[:, k]) and
                  np.array_equal(avp[q], avp[k])), len(reps))
        if j == len(reps):
            reps.append(k)
        amap[k] = j
    xo, vo, zo = np.empty((nrec, lay.nx)), np.empty((nrec, 2 * na)), np.empty((nrec, na))
    t0 = time.perf_counter()
    st = integrate(ml.arrays(), mp, mx, mvv, _csr_arrays(remap(Qf)), rl.arrays(), H, lay.m, lay.nw, lay.ws0,
                   models[0].friction.entry.rates_lanes, fp, avp[reps], amap, np.zeros(lay.nx), np.zeros(na),
                   np.ascontiguousarray(r[:, reps]), float(dt_s), int(record_every), xo, vo, zo)
    wall = time.perf_counter() - t0
    if st >= 0:
        raise SimulationUnstable(st * dt_s, f"masv simulate, dt = {dt_s} s")
    xo = xo[:, lay.xmap]

    def out(name):
        c = [cm.output_rows(k, name) for k in range(na)]
        return np.vstack([a for a, _ in c]) @ xo.T + np.vstack([b for _, b in c]) @ vo.T

    uc = xo @ cm.Ux.T + vo @ cm.Uw.T
    prov = {**config_provenance(cfg), "engine": "masv-nonlinear", "commands": how,
            "solver": {"method": "rk4-fixed-step", "dt_s": dt_s, "record_every": int(record_every),
                       "kernel_wall_s": wall, "real_time_factor": T / wall if wall > 0 else None},
            "nonlinear": {"friction": sorted({m.friction.name for m in models}), "avionics": bool(avionics),
                          "limits": bool(limits)},
            "coupling": {"friction_and_stops": "relative to the structure's gimbal rotation, reaction on the "
                         "structure", "residual_flexibility": bool(np.any(system.g_res)),
                         "n_states": N, "nnz": int(np.count_nonzero(Mf) + np.count_nonzero(Qf))}}
    return MasvTimeHistory(
        t_s=t[::record_every], actuators=cfg.actuator_names, engines=tuple(e.name for e in cfg.engines),
        engine_of=tuple(a.engine for a in cfg.actuators), command_rad=r[::record_every].T.copy(),
        command_avionics_rad=vo[:, :na].T.copy(), piston_m=out("x_p_m"), engine_rad=out("theta_rad"),
        load_force_N=out("load_force_N"), gimbal_torque_Nm=vo[:, na:].T.copy(), friction_state_rad=zo.T.copy(),
        elongation_m=uc[:, :na].T.copy(), gimbal_rotation_rad=uc[:, na:].T.copy(),
        modal_q=xo[:, nb:nb + nm].T.copy(), modal_qdot=xo[:, nb + nm:].T.copy(), provenance=prov)
