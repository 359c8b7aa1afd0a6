"""TAOS simulation, linearisation and frequency responses.

* :func:`simulate_taos` runs a command profile (one or two axes) -> :class:`TaosTimeHistory`
  (the arrays of :class:`taos.planar.simulate.TimeHistory` for pitch and yaw, plus ``extra``: bearing
  slip, chain wrench, gimbal-half deflections, engine-point translation); HDF5 adds a
  ``/taos`` group.
* :func:`taos_freqresp` gives command -> piston / engine responses per axis (and cross-axis):
  exact linear (friction off: Jacobian of the compiled right-hand side, central differences
  in tangent coordinates) or amplitude-dependent by sine dwell (compiled, parallel).
* :func:`two_axis_dwell` measures one axis' response while the other runs its own sine
  (the Green Run dither of paper sec. 5.1).
"""

from __future__ import annotations

import math
import weakref
from dataclasses import dataclass, field

import numpy as np

from ..planar.actuator import actuator_state_space
from ..bounds import check_flag
from ..errors import InputError, SimulationUnstable
from ..planar._parallel import run_each
from ..planar.freqresp import LINEAR_SOLVER, FrequencyResponse, settle_time_s
from ..linear import StateSpace
from ..profiles import Profile, is_two_axis
from ..planar.simulate import SolverSettings, TimeHistory, provenance
from . import _args
from . import dynamics as _dy
from .model import AXES, PITCH_AXIS, YAW_AXIS, TaosModel, spatial_inertia
from taos.results import model_provenance

#: the 3-D time run's default step [s] (:func:`simulate_taos`, ``taos simulate --engine taos``): the
#: engine angle over the 60 s two-axis Green Run within 1e-4 deg of a 2.5e-5 s run (7.6e-5 deg;
#: tests/test_taos3d_step.py, benchmarks/RESULTS.md); the explicit step's rule allows it because the
#: step integrates the supply-pressure limit's stiff rate exactly (:func:`taos.taos3d.dynamics._etd_rk4`).
#: 4e-4 s until issue 44 (whose bearing coupling is second order: 1.8e-5 deg there)
DEFAULT_DT_S = 8e-4
#: the largest step [s] of the 3-D sine dwells (``dt_max_s``), and the verdict's and the
#: co-simulation block's (the FMU's internal) default step (:func:`taos.planar.envelope.default_dt_s`):
#: kept by issue 44, so the dwells, the verdict and the FMU's communication-step grid are as before
DWELL_DT_S = 4e-4
#: the integrator of every 3-D run and dwell (:func:`taos.taos3d.dynamics.step`), as results name it
INTEGRATOR = "rk4, trapezoidal bearing torque + BDF2 bearing substeps"


@dataclass(frozen=True, eq=False)
class Packed:
    """Arrays the compiled kernels take (see :func:`pack`): the model ``P`` (a record with the
    fields of :class:`taos.taos3d.dynamics.TaosParams`, :func:`taos.taos3d._layout.as_record`), the friction law's kernels
    ``fid`` = (``bearing_step``, ``zdot3``, ``torque3``) (its registry entry's) and packed parameters ``fp`` (scaled by the normal load), the
    packed avionics ``avp``, the state length and the actuator's state length."""

    P: np.record
    fid: object
    fp: np.ndarray
    avp: np.ndarray
    n_state: int
    n_act: int


def actuator_limits(tm: TaosModel) -> np.ndarray:
    """The actuator and gimbal limits (:mod:`taos.planar.saturation`) packed over one actuator's state:
    valve flow saturation, supply-pressure limit (square-root law, relief valve) per actuator, hard stops per axis (the
    stop damping from the pitch inertia; the 3-D engine is axisymmetric about its axis). With every limit off, the
    same layout all zeros (the kernels act on a limit only where its head slot is positive, so this is the same as no
    limits), so that every model of one actuator size is one record type: one compiled kernel family."""
    from ..planar.saturation import N_HEAD, N_ROWS, limit_rows_for_actuator, pack_model_limits
    rows, _ = limit_rows_for_actuator(tm.base.actuator)
    lim = pack_model_limits(tm.base.actuator, tm.base.engine, "pitch", rows)
    if lim.size == 0:
        lim = np.zeros(N_HEAD + N_ROWS * len(next(iter(rows.values()))))
    return lim


def pack(tm: TaosModel, ideal_avionics: bool = False) -> Packed:
    """Pack a TAOS model for :mod:`taos.taos3d.dynamics` (SI arrays)."""
    f64 = lambda a: np.ascontiguousarray(a, dtype=np.float64)  # noqa: E731
    Y = spatial_inertia(tm)
    Ks = tm.chain_stiffness
    S = tm.bearing_selection
    Kphi = S.T @ Ks @ S
    Kc = np.linalg.inv(Kphi)
    G = Kc @ S.T @ Ks
    act = actuator_state_space(tm.base.actuator)
    geo = tm.geometry
    R = tm.base.actuator.moment_arm_m
    P = _dy.TaosParams(   # the named tuple names every field; the kernels take it as a record
        spatial_inertia=f64(Y), spatial_inertia_inv=f64(np.linalg.inv(Y)), chain_stiffness=f64(Ks),
        slip_gain=f64(G), bearing_compliance=f64(Kc), bearing_selection=f64(S),
        structure_attach_m=f64(geo.structure_attach_m), engine_attach_m=f64(geo.engine_attach_m),
        act_A=f64(act.A), act_b_xc=f64(act.B[:, act.input_index("x_c_m")]),
        act_b_fl=f64(act.B[:, act.input_index("f_load_N")]), act_c_xp=f64(act.C[act.output_index("x_p_m")]),
        bearing_axes=f64(np.vstack([PITCH_AXIS, YAW_AXIS])),
        line_stiffness_N_per_m=f64(tm.line_load_stiffnesses_N_per_m), moment_arm_m=float(R),
        engine_stiffness_Nm_per_rad=float(tm.base.engine.rotational_stiffness_Nm_per_rad),
        line_length0_m=f64([np.linalg.norm(geo.engine_attach_m[i] - geo.structure_attach_m[i]) for i in range(2)]),
        line_damping_Ns_per_m=f64([tm.base.structure.load_damping_Ns_per_m(R, tm.base.engine.inertia("pitch"), ax)
                                   for ax in AXES]),
        act_vp_index=act.states.index("v_p_m_s"), limits=f64(actuator_limits(tm)),
        torque_wrench=f64(Ks @ S @ Kc), act_pl_index=act.states.index("p_load_Pa"),
        act_q_index=act.states.index("q_m_s"))
    law = tm.bearing_friction   # the model's own law and levels: one friction for every summary
    fp = law.pack()
    av = tm.base.avionics.ideal() if ideal_avionics else tm.base.avionics
    na = act.A.shape[0]
    return Packed(_dy.as_record(P), (law.entry.bearing_step, law.entry.zdot3, law.entry.torque3), fp, av.pack(), _dy.N_BODY + 2 * na, na)


def rest_state(pk: Packed) -> np.ndarray:
    """The state at rest (:mod:`taos.taos3d.dynamics` layout): identity quaternion, all else 0."""
    x = np.zeros(pk.n_state)
    x[_dy.X_Q + 3] = 1.0  # quaternion w
    return x


@dataclass(frozen=True, eq=False)
class TaosTimeHistory(TimeHistory):
    """:class:`~taos.planar.simulate.TimeHistory` (axes pitch and yaw) plus ``extra`` arrays:
    ``bearing_slip_rad`` (2, n), ``chain_wrench`` (6, n) [N, N m] at O, ``upper_deflection``
    and ``lower_deflection`` (6, n) = K^-1 W [m, rad], ``engine_point_m`` (3, n)."""

    extra: dict = field(default_factory=dict)

    def _write_extra(self, h5) -> None:
        """The ``/taos`` group with ``extra`` (the rest as the planar history)."""
        g = h5.create_group("taos")
        for k, v in self.extra.items():
            g.create_dataset(k, data=v, compression="gzip", track_times=False)

    #: the /taos arrays held to the record magnitudes (taos.planar.runfile.SIGNAL_LIMITS): rows -> unit kind
    EXTRA_KINDS = {"bearing_slip_rad": ((0, 2), "angle"), "upper_deflection": ((0, 3), "length"),
                   "lower_deflection": ((0, 3), "length")}

    @classmethod
    def _read_extra(cls, h5, src: str, n: int) -> dict:
        """The ``/taos`` arrays, each a real finite ``(k, n)`` table (:mod:`taos.planar.runfile`);
        the slips and the deflections' translations within the record magnitudes, the
        deflections' rotations within the angle bound."""
        import h5py

        from ..planar.runfile import check_limits, dataset, node

        g = node(h5, "taos", src)
        if not isinstance(g, h5py.Group):
            raise InputError(src, "/taos", "the 3-D run's group of arrays", got="missing" if g is None else "a dataset")
        extra = {k: dataset(h5, f"taos/{k}", src, n=n, ndim=2) for k in g}
        for k, ((r0, r1), kind) in cls.EXTRA_KINDS.items():
            if k in extra:
                check_limits(extra[k][r0:r1], kind, src, f"/taos/{k}")
                if k.endswith("deflection"):
                    check_limits(extra[k][3:], "angle", src, f"/taos/{k}")
        return {"extra": extra}


def run_samples(tm: TaosModel, cmd: np.ndarray, dt_s: float, record_every: int = 1,
                pk: Packed | None = None) -> np.ndarray:
    """Integrate the two-axis command samples ``cmd`` (n + 1, 2) [rad] every ``dt_s`` [s]
    from rest; returns the records (n_rec, len(dynamics.REC))."""
    cmd = np.ascontiguousarray(_args.check_samples(cmd, dt_s, record_every), dtype=np.float64)
    pk = pack(tm) if pk is None else pk
    nrec = (cmd.shape[0] - 1) // record_every + 1
    out = np.empty((nrec, len(_dy.REC)))
    n = pk.n_state   # integrate's loop, called with its scratch (one compiled kernel less to load)
    status = _dy._steps(pk.P, pk.fid, pk.fp, pk.avp, rest_state(pk), np.zeros(_dy.N_BEARING), cmd, dt_s,
                        record_every, out, np.empty((5, n)), np.empty(_dy.N_AUX), np.empty((4, 2)), np.empty((2, 2)))
    if status >= 0:
        raise SimulationUnstable(status * dt_s, f"TAOS, {tm.base.friction.name} friction, dt = {dt_s} s")
    return out


def simulate_taos(tm: TaosModel, profile: Profile, *, dt_s: float = DEFAULT_DT_S, record_every: int = 5,
                  duration_s: float | None = None) -> TaosTimeHistory:
    """Run ``profile`` (a single-axis profile drives pitch; two-axis drives both) through the
    TAOS model from rest; ``dt_s`` integration step [s]; ``duration_s`` default the profile's
    duration plus 1 s."""
    _args.check_tm(tm)
    _args.check_simulate_args(profile, dt_s, record_every, duration_s)
    _args.check_rk4_step(float(dt_s), tm.base, "dt_s", pressure_limit=False)   # the explicit step's rule, as --dt
    T = (profile.duration_s + 1.0) if duration_s is None else duration_s
    n = int(math.ceil(T / dt_s))
    t = np.arange(n + 1) * dt_s
    c = np.atleast_2d(profile(t))
    cmd = np.zeros((n + 1, 2))
    cmd[:, : c.shape[0]] = c.T if is_two_axis(profile) else c[:1].T
    out = run_samples(tm, cmd, dt_s, record_every)
    col = {k: i for i, k in enumerate(_dy.REC)}
    two = lambda a, b: np.vstack([out[:, col[a]], out[:, col[b]]])  # noqa: E731
    W = out[:, [col[k] for k in ("w_fx", "w_fy", "w_fz", "w_mx", "w_my", "w_mz")]].T
    extra = {"bearing_slip_rad": two("phi_pitch", "phi_yaw"), "chain_wrench": W,
             "upper_deflection": np.linalg.solve(tm.K_upper, W), "lower_deflection": np.linalg.solve(tm.K_lower, W),
             "engine_point_m": out[:, [col["px"], col["py"], col["pz"]]].T}
    solver = SolverSettings(method=INTEGRATOR, dt_s=dt_s, record_every=record_every)
    prov = provenance(tm.base, solver, engine="taos", profile=getattr(profile, "name", type(profile).__name__),
                      stiffness_source=tm.stiffness_source, friction_scale=tm.friction_scale,
                      bearing_coulomb_torque_Nm=tm.bearing_friction.coulomb_torque_Nm,
                      line_load_stiffness_N_per_m=tm.line_load_stiffness_N_per_m)
    return TaosTimeHistory(
        t_s=t[::record_every], axes=AXES, moment_arm_m=tm.base.actuator.moment_arm_m, provenance=prov,
        command_rad=cmd[::record_every].T.copy(), command_avionics_rad=two("u_pitch", "u_yaw"),
        piston_m=two("xp_pitch", "xp_yaw"), engine_rad=two("theta_pitch", "theta_yaw"),
        friction_torque_Nm=two("tf_pitch", "tf_yaw"), friction_state_rad=two("z_pitch", "z_yaw"),
        load_force_N=two("fl_pitch", "fl_yaw"), load_pressure_Pa=two("pl_pitch", "pl_yaw"),
        spool_flow_m_s=two("q_pitch", "q_yaw"),
        supply_pressure_Pa=np.full((2, out.shape[0]), tm.base.actuator.supply_pressure_Pa), extra=extra)


# -- linearisation -----------------------------------------------------------------------
def _state_from_tangent(pk: Packed, y: np.ndarray) -> np.ndarray:
    """Full state from tangent coordinates y = (dp (3), dr (3), v (6), actuators)."""
    x = np.empty(pk.n_state)
    x[_dy.X_P:_dy.X_P + 3] = y[:3]
    r = y[3:6]
    a = np.linalg.norm(r)
    s = 0.5 if a < 1e-12 else math.sin(a / 2) / a
    x[_dy.X_Q:_dy.X_Q + 3] = s * r
    x[_dy.X_Q + 3] = math.cos(a / 2)
    x[_dy.X_V:] = y[6:]  # the twist (linear, angular) and the actuators
    return x


#: the linearisation of each model object (models are frozen: one linearisation serves every
#: axis, frequency and notch search of that object; entries go with their model)
_LINEARISED: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def linear_state_space(tm: TaosModel) -> StateSpace:
    """Linearisation about rest with friction off (T = 0, bearing free): states (dp, dr, v,
    actuators) in tangent coordinates; inputs ``command_pitch_rad``, ``command_yaw_rad``
    (after the avionics, unity here); outputs x_p and theta per axis.

    Computed once per model object (a frozen :class:`TaosModel`; its matrices read-only), so the
    responses of both axes and the notch searches (:func:`taos_freqresp`, tens of calls) share
    one linearisation and its balancing: the same numbers as a fresh one every call."""
    ss = _LINEARISED.get(tm)
    if ss is None:
        ss = _linearise(tm)
        for a in (ss.A, ss.B, ss.C, ss.D):
            a.flags.writeable = False
        _LINEARISED[tm] = ss
    return ss


def _linearise(tm: TaosModel) -> StateSpace:
    """:func:`linear_state_space`, computed (central differences of the compiled right-hand side)."""
    pk = pack(tm, ideal_avionics=True)
    n = pk.n_state - 1
    aux = np.empty(_dy.N_AUX)
    dx = np.empty(pk.n_state)

    def f(y, u):
        x = _state_from_tangent(pk, y)
        _dy.rhs(x, 0.0, 0.0, u[0], u[1], pk.P, dx, aux)
        out = np.empty(n)
        out[:3] = y[6:9]          # dp/dt = v_lin at rest
        out[3:6] = y[9:12]        # dr/dt = omega at rest
        out[6:] = dx[7:]
        return out, np.array([aux[_dy.AUX_THETA], aux[_dy.AUX_THETA + 1]])

    y0 = np.zeros(n)
    u0 = np.zeros(2)
    A = np.empty((n, n))
    C = np.zeros((4, n))
    h = np.full(n, 1e-6)
    na = pk.n_act
    act = actuator_state_space(tm.base.actuator)
    scale = np.array([1e6 if s.endswith("Pa") else 1.0 for s in act.states])
    h[12:] = np.tile(scale * 1e-6, 2)
    for j in range(n):
        yp, ym = y0.copy(), y0.copy()
        yp[j] += h[j]
        ym[j] -= h[j]
        fp, gp = f(yp, u0)
        fm, gm = f(ym, u0)
        A[:, j] = (fp - fm) / (2 * h[j])
        C[2:, j] = (gp - gm) / (2 * h[j])
    B = np.empty((n, 2))
    for j in range(2):
        up, um = u0.copy(), u0.copy()
        up[j] += 1e-6
        um[j] -= 1e-6
        B[:, j] = (f(y0, up)[0] - f(y0, um)[0]) / 2e-6
    cxp = pk.P.act_c_xp
    C[0, 12:12 + na] = cxp
    C[1, 12 + na:12 + 2 * na] = cxp
    states = tuple(f"{k}" for k in ("px", "py", "pz", "rx", "ry", "rz", "vx", "vy", "vz", "wx", "wy", "wz")) + \
        tuple(f"pitch_{s}" for s in act.states) + tuple(f"yaw_{s}" for s in act.states)
    return StateSpace(A, B, C, np.zeros((4, 2)), states, ("command_pitch_rad", "command_yaw_rad"),
                      ("x_p_pitch_m", "x_p_yaw_m", "theta_pitch_rad", "theta_yaw_rad"))


def taos_freqresp(tm: TaosModel, freq_hz: np.typing.ArrayLike, amplitude_rad: float | None = None, axis: str = "pitch",
                  cross: bool = False, *, dt_max_s: float = DWELL_DT_S, settle_cycles: int = 2,
                  measure_cycles: int = 2, settle_s: float | None = None,
                  min_steps_per_cycle: int = 64) -> FrequencyResponse:
    """Command -> piston (x_p / (R theta_c)) and command -> engine (theta / theta_c) of the
    TAOS model, commanding ``axis``; ``cross=True`` reports the other axis' outputs (the
    kinematic and friction cross-coupling). ``amplitude_rad`` None: exact linear response
    (friction off, unity avionics); else sine dwell from rest with friction and avionics.
    Raises :class:`~taos.errors.InputError` for an empty grid, a frequency outside (0, 1e4] Hz,
    an amplitude outside (0, 90] deg, an unknown axis or a non-positive step."""
    f, _ = _args.check_dwell_args(tm, freq_hz, amplitude_rad, axis, "amplitude_rad", dt_max_s, settle_cycles,
                                  measure_cycles, settle_s, min_steps_per_cycle)
    check_flag(cross, "cross")
    i = AXES.index(axis)
    o = 1 - i if cross else i
    R = tm.base.actuator.moment_arm_m
    label = f"{axis}->{AXES[o]}" if cross else axis
    if amplitude_rad is None:
        ss = linear_state_space(tm)
        h = ss.freqresp(f, ss.inputs[i], [ss.outputs[o], ss.outputs[2 + o]])
        return FrequencyResponse(f, h[:, 0] / R, h[:, 1], None, label, engine_model="taos", friction_model="none",
                                 provenance={**model_provenance(tm.base), "seeds": "none (deterministic)",
                                             "solver": {**LINEAR_SOLVER, "method": "linear (exact, the 3-D model "
                                                        "linearised about rest)", "engine": "taos"}})
    return taos_freqresp_family(tm, f, [amplitude_rad], axis, cross, dt_max_s=dt_max_s, settle_cycles=settle_cycles,
                                measure_cycles=measure_cycles, settle_s=settle_s,
                                min_steps_per_cycle=min_steps_per_cycle)[0]


def taos_freqresp_family(tm: TaosModel, freq_hz: np.typing.ArrayLike, amplitudes_rad: np.typing.ArrayLike,
                         axis: str = "pitch", cross: bool = False, *,
                         dt_max_s: float = DWELL_DT_S, settle_cycles: int = 2, measure_cycles: int = 2,
                         settle_s: float | None = None, min_steps_per_cycle: int = 64) -> list[FrequencyResponse]:
    """Sine-dwell responses of the TAOS model at every command amplitude [rad] x frequency
    [Hz], all dwells in one parallel call (as :func:`taos_freqresp`, whose single-amplitude
    result is the family's row bit for bit: each dwell is independent). Arguments checked as
    :func:`taos_freqresp`'s."""
    return taos_freqresp_axes(tm, {axis: (freq_hz, amplitudes_rad)}, cross, dt_max_s=dt_max_s,
                              settle_cycles=settle_cycles, measure_cycles=measure_cycles, settle_s=settle_s,
                              min_steps_per_cycle=min_steps_per_cycle)[axis]


def taos_freqresp_axes(tm: TaosModel, grids: dict[str, tuple], cross: bool = False, *, dt_max_s: float = DWELL_DT_S,
                       settle_cycles: int = 2, measure_cycles: int = 2, settle_s: float | None = None,
                       min_steps_per_cycle: int = 64) -> dict[str, list[FrequencyResponse]]:
    """:func:`taos_freqresp_family` of several axes, ``grids`` = {axis: (freq_hz [Hz],
    amplitudes_rad [rad])}, with the dwells of every axis in ONE parallel call (both cores busy
    to the end; each dwell independent, so every row is the family's, bit for bit). Every
    axis' arguments are checked (as :func:`taos_freqresp`'s, the step budget per axis) before
    any dwell runs; an unstable dwell raises for the first in (axis, amplitude, frequency) order."""
    from ..errors import InputError

    check_flag(cross, "cross")
    parts = []
    for axis, (freq_hz, amplitudes_rad) in grids.items():
        if amplitudes_rad is None:
            raise InputError("argument", "amplitudes_rad", "dwell amplitudes in rad (taos_freqresp gives the linear "
                             "response)", got="None")
        f, a = _args.check_dwell_args(tm, freq_hz, amplitudes_rad, axis, "amplitudes_rad", dt_max_s, settle_cycles,
                                      measure_cycles, settle_s, min_steps_per_cycle)
        i = AXES.index(axis)
        A, F = (g.ravel() for g in np.meshgrid(a, f, indexing="ij"))
        amps = np.zeros((A.size, 2))
        amps[:, i] = A
        freqs = np.zeros((A.size, 2))
        freqs[:, i] = F
        parts.append((axis, f, a, i, A, amps, freqs, F))
    if not parts:
        return {}
    res = _dwell(tm, np.vstack([p[5] for p in parts]), np.vstack([p[6] for p in parts]),
                 np.concatenate([p[7] for p in parts]), dt_max_s, settle_cycles, measure_cycles, settle_s,
                 min_steps_per_cycle, groups=[p[4].size for p in parts])
    R = tm.base.actuator.moment_arm_m
    solver = {"method": "sine dwell, settled from rest", "integrator": INTEGRATOR,
              "step": "dt_max_s or less, a whole number of steps per cycle", "dt_max_s": float(dt_max_s),
              "min_steps_per_cycle": int(min_steps_per_cycle), "settle_cycles": int(settle_cycles),
              "settle_s": _settle_s(tm, settle_s), "measure_cycles": int(measure_cycles), "engine": "taos"}
    out, k0 = {}, 0
    for axis, f, a, i, A, _, _, _ in parts:
        o = 1 - i if cross else i
        label = f"{axis}->{AXES[o]}" if cross else axis
        h = ((res[k0:k0 + A.size, :, 0] + 1j * res[k0:k0 + A.size, :, 1]) / A[:, None]).reshape(a.size, f.size, 4)
        k0 += A.size
        out[axis] = [FrequencyResponse(f, h[k, :, o] / R, h[k, :, 2 + o], float(ak), label, engine_model="taos",
                                       friction_model=tm.base.friction.name,
                                       provenance={**model_provenance(tm.base), "seeds": "none (deterministic)",
                                                   "solver": dict(solver), "friction_scale": tm.friction_scale})
                     for k, ak in enumerate(a)]
    return out


def _settle_s(tm: TaosModel, settle_s: float | None) -> float:
    """The settling time of a dwell [s]: ``settle_s``, default four decades of the base model's
    slowest linear pitch mode."""
    return float(settle_time_s(tm.base, "pitch")) if settle_s is None else float(settle_s)


def _dwell(tm, amps, freqs, fmeas, dt_max_s, settle_cycles, measure_cycles, settle_s, min_steps_per_cycle,
           groups=None):
    """The dwells of rows ``amps``, ``freqs`` (n, 2) [rad, Hz] measured at ``fmeas`` (n,) [Hz], in
    one parallel call: (n, 4, 3) correlation coefficients in row order. The step budget is
    checked on the whole grid, or on each group of consecutive rows of sizes ``groups``."""
    pk = pack(tm)
    ts = _settle_s(tm, settle_s)
    fmeas = np.array(fmeas, float)   # own copies (writable, C order: the kernel's compiled signature)
    npc = np.maximum(np.ceil(1.0 / (fmeas * dt_max_s)), min_steps_per_cycle).astype(np.int64)
    dts = 1.0 / (fmeas * npc)
    nset = (np.maximum(settle_cycles, np.ceil(ts * fmeas)) * npc).astype(np.int64)
    nmeas = (measure_cycles * npc).astype(np.int64)
    bounds = np.cumsum([0] + list(groups if groups is not None else [fmeas.size]))
    for g0, g1 in zip(bounds[:-1], bounds[1:]):   # before any work, as the command line's budget
        _args.check_dwell_steps(int(np.sum(nset[g0:g1] + nmeas[g0:g1])))
    amps, freqs = np.array(amps, float), np.array(freqs, float)
    out = np.zeros((fmeas.size, 4, 3))
    status = np.full(fmeas.size, -1, np.int64)
    x0 = rest_state(pk)
    # one task per dwell on the threads, the longest (most steps) first
    run_each(lambda b: _dy.dwell_batch(pk.P, pk.fid, pk.fp, pk.avp, x0, amps, freqs, fmeas, dts, nset, nmeas, out,
                                       status, b, b + 1), nset + nmeas)
    bad = np.flatnonzero(status >= 0)
    if bad.size:   # the first failing dwell in row order
        b = bad[0]
        raise SimulationUnstable(status[b] * dts[b], f"TAOS sine dwell at {fmeas[b]:.3g} Hz")
    return out


def two_axis_dwell(tm: TaosModel, amplitude_rad, freq_hz, *, measure_axis: str = "pitch",
                   dt_max_s: float = DWELL_DT_S, settle_cycles: int = 2, measure_cycles: int = 2,
                   settle_s: float | None = None, min_steps_per_cycle: int = 64):
    """Pitch and yaw sines at once (rows of ``amplitude_rad``/``freq_hz`` (n, 2) [rad, Hz]);
    returns (piston, engine) complex gains of ``measure_axis`` at its own frequency (n,).
    Whole measured cycles of both sines need commensurate frequencies. Raises
    :class:`~taos.errors.InputError` for rows not (n, 2), a non-finite, negative or too large
    value, a zero amplitude or frequency on the measured axis, an unknown axis, a bad step."""
    amps, freqs = _args.check_two_axis(amplitude_rad, freq_hz, measure_axis)
    _args.check_dwell_args(tm, freqs[:, AXES.index(measure_axis)], amps[:, AXES.index(measure_axis)], measure_axis,
                           "amplitude_rad", dt_max_s, settle_cycles, measure_cycles, settle_s, min_steps_per_cycle)
    i = AXES.index(measure_axis)
    res = _dwell(tm, amps, freqs, freqs[:, i], dt_max_s, settle_cycles, measure_cycles, settle_s,
                 min_steps_per_cycle)
    h = (res[:, :, 0] + 1j * res[:, :, 1]) / amps[:, i][:, None]
    return h[:, i] / tm.base.actuator.moment_arm_m, h[:, 2 + i]
