"""Time-domain simulation of the simplex TVC model (and any :class:`~taos.planar.simplex.LurePlant`).

Fixed-step classical RK4 in the compiled kernel of :mod:`taos.planar.dynamics`. The default step
(2e-4 s) resolves the fastest dynamics of the shipped models (oil column ~ 250 Hz,
servovalve 100 Hz) with a wide RK4 stability margin; halving it changes a 20 s LuGre run by
less than 1e-4 deg (``tests/test_simplex.py::test_step_refinement_lugre_20s``).
``simulate(..., integrator="exp")`` runs the exponential integrator of
:mod:`taos.planar._exptime` instead (the step set by the friction loop and the records).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from typing import TYPE_CHECKING, NamedTuple

import numpy as np

if TYPE_CHECKING:
    import h5py

from ..errors import SimulationUnstable
from ..model import TvcModel, model_inputs
from ..profiles import Profile, is_two_axis
from ..results import atomic_write, base_provenance, write_provenance
from .simplex import LurePlant, simplex_plant
from taos.results import model_provenance

DEFAULT_DT_S = 2e-4


@dataclass(frozen=True)
class SolverSettings:
    """Integrator settings recorded with every result."""

    method: str = "rk4-fixed-step"
    dt_s: float = DEFAULT_DT_S
    record_every: int = 10


def check_friction_step(model: TvcModel, inertia_kgm2: float, dt_s: float) -> None:
    """Refuse steps that the friction law cannot be integrated with (the law's own explicit-step
    rule, :meth:`taos.friction.FrictionLaw.check_step`)."""
    model.friction.check_step(inertia_kgm2, dt_s, model.source)


class PlantArrays(NamedTuple):
    """The plant's arrays the compiled planar kernels take (:mod:`taos.planar.dynamics`), named; a
    kernel call passes them in this order (``kernel(*arrays, Cy, ...)``). n states, n_r external
    inputs; [x] and [r] the SI units of the plant's states and inputs; every array C-contiguous
    float64."""

    #: (n, n) state matrix [x/s per x]
    A: np.ndarray
    #: (n, n_r) external-input columns [x/s per r]
    Br: np.ndarray
    #: (n,) post-avionics command column [x/s per rad]
    bc: np.ndarray
    #: (n,) friction-torque column [x/s per N m]
    bf: np.ndarray
    #: (n,) pre-avionics command row over x [rad per x]
    cc: np.ndarray
    #: (n_r,) pre-avionics command row over r [rad per r]
    dc: np.ndarray
    #: (n,) friction relative-rate row [rad/s per x]
    cw: np.ndarray
    #: (n,) applied (non-friction) torque row [N m per x]
    ca: np.ndarray
    #: (k,) packed actuator/gimbal limits over the state (empty: no limits;
    #: :mod:`taos.planar.saturation`, ``LIM_*``, ``ROW_*``)
    lim: np.ndarray


def kernel_args(plant: LurePlant, model: TvcModel) -> PlantArrays:
    """The arrays the compiled kernels take (:class:`PlantArrays`: A, Br, bc, bf, cc, dc, cw, ca,
    lim, in the kernels' order)."""
    ss = plant.ss
    ne = plant.n_ext
    ic = ss.input_index("command_rad")
    ifr = ss.input_index("friction_torque_Nm")
    f64 = lambda a: np.ascontiguousarray(a, dtype=np.float64)  # noqa: E731
    return PlantArrays(A=f64(ss.A), Br=f64(ss.B[:, :ne]), bc=f64(ss.B[:, ic]), bf=f64(ss.B[:, ifr]),
                       cc=f64(plant.cmd_c), dc=f64(plant.cmd_d), cw=f64(plant.rate_c), ca=f64(plant.applied_c),
                       lim=f64(plant.limits))


def integrate_plant(plant: LurePlant, model: TvcModel, r: np.ndarray, dt_s: float, record_every: int = 1,
                    x0: np.ndarray | None = None, z0: float = 0.0):
    """Integrate ``plant`` over input samples ``r`` (n_steps + 1, n_ext) every ``dt_s``, from the
    linear state ``x0`` and the friction state ``z0`` (default rest).

    Returns (y (n_rec, n_out), aux (n_rec, 3) = friction torque, friction state, avionics
    output; columns :data:`taos.planar.dynamics.AUX_TF`, ``AUX_Z``, ``AUX_U``). Raises
    :class:`SimulationUnstable` on a non-finite state."""
    from . import dynamics as _ig

    check_friction_step(model, plant.inertia_kgm2, dt_s)
    n = plant.ss.A.shape[0]
    nrec = (r.shape[0] - 1) // record_every + 1
    y = np.empty((nrec, plant.ss.C.shape[0]))
    aux = np.empty((nrec, _ig.N_AUX))
    x0 = np.zeros(n) if x0 is None else np.asarray(x0, float)

    status = _ig.integrate_samples(*kernel_args(plant, model), np.ascontiguousarray(plant.ss.C),
                                   model.friction.entry.rates, model.friction.pack(), model.avionics.pack(),
                                   x0, float(z0), np.ascontiguousarray(r, dtype=np.float64), dt_s,
                                   record_every, y, aux)
    if status >= 0:
        raise SimulationUnstable(status * dt_s, f"{model.friction.name} friction, dt = {dt_s} s")
    return y, aux


@dataclass(frozen=True, eq=False)
class TimeHistory:
    """Recorded time history of one run; arrays are (n_axes, n_samples), SI units.

    Attributes: ``t_s``; ``command_rad`` (FCS command), ``command_avionics_rad`` (after
    quantisation and crossover gain), ``piston_m``, ``engine_rad``, ``friction_torque_Nm``,
    ``friction_state_rad``, ``load_force_N``; ``provenance`` (model file hash, package
    version, solver settings, friction law, profile).

    Optional hydraulic signals (:data:`OPTIONAL_ARRAYS`, None when a model does not record
    them): ``load_pressure_Pa`` P_L (actuator state), ``spool_flow_m_s`` the servovalve's
    no-load flow over piston area q = K_q x_v / A (the spool position in piston-rate units:
    the spool stroke itself needs the valve flow gain K_q, which the model does not carry),
    ``supply_pressure_Pa`` P_s (constant in the model: an ideal supply). The chamber
    pressures of a symmetric actuator follow as (P_s +- P_L) / 2.
    """

    t_s: np.ndarray
    axes: tuple[str, ...]
    command_rad: np.ndarray
    command_avionics_rad: np.ndarray
    piston_m: np.ndarray
    engine_rad: np.ndarray
    friction_torque_Nm: np.ndarray
    friction_state_rad: np.ndarray
    load_force_N: np.ndarray
    moment_arm_m: float
    provenance: dict = field(default_factory=dict)
    load_pressure_Pa: np.ndarray | None = None
    spool_flow_m_s: np.ndarray | None = None
    supply_pressure_Pa: np.ndarray | None = None

    ARRAYS = ("command_rad", "command_avionics_rad", "piston_m", "engine_rad", "friction_torque_Nm",
              "friction_state_rad", "load_force_N")
    OPTIONAL_ARRAYS = ("load_pressure_Pa", "spool_flow_m_s", "supply_pressure_Pa")

    def to_hdf5(self, path) -> None:
        """Write atomically: /t_s, /<axis>/<array>, provenance as root attributes."""
        def write(tmp):
            import h5py

            with h5py.File(tmp, "w") as h5:
                h5.create_dataset("t_s", data=self.t_s, track_times=False)
                h5.attrs["axes"] = ",".join(self.axes)
                h5.attrs["moment_arm_m"] = self.moment_arm_m
                write_provenance(h5, self.provenance)
                for i, ax in enumerate(self.axes):
                    g = h5.create_group(ax)
                    for name in self.ARRAYS:
                        g.create_dataset(name, data=getattr(self, name)[i], compression="gzip", track_times=False)
                    for name in self.OPTIONAL_ARRAYS:
                        if getattr(self, name) is not None:
                            g.create_dataset(name, data=getattr(self, name)[i], compression="gzip", track_times=False)
                self._write_extra(h5)
        atomic_write(path, write)

    def _write_extra(self, h5: h5py.File) -> None:
        """Hook for subclasses that record more (the 3-D model's ``/taos`` group)."""

    @classmethod
    def from_hdf5(cls, path) -> "TimeHistory":
        """Read a run file written by :meth:`to_hdf5`, validated (:func:`taos.planar.runfile.read_run`:
        shapes, real finite numbers, sample times, the moment arm, the engine name); InputError
        (one line naming the dataset or attribute) otherwise."""
        from .runfile import open_hdf5, read_run

        src = str(path)
        with open_hdf5(path, src, "an HDF5 run file written by taos simulate") as h5:
            run = read_run(h5, src, cls.ARRAYS, cls.OPTIONAL_ARRAYS)
            extra = cls._read_extra(h5, src, run["t_s"].size)
        return cls(**run, **extra)

    @classmethod
    def _read_extra(cls, h5: h5py.File, src: str, n: int) -> dict:
        """Hook for subclasses: extra constructor arguments read from the file (``src`` its name
        for errors, ``n`` the number of samples)."""
        return {}


def _with_spool_output(plant: LurePlant) -> LurePlant:
    """The plant with the servovalve state ``q_m_s`` as an extra output (recorded only)."""
    import dataclasses

    from ..linear import StateSpace
    ss = plant.ss
    row = np.zeros((1, ss.A.shape[0]))
    row[0, ss.state_index("q_m_s")] = 1.0
    ext = StateSpace(ss.A, ss.B, np.vstack([ss.C, row]), np.vstack([ss.D, np.zeros((1, ss.D.shape[1]))]),
                     ss.states, ss.inputs, ss.outputs + ("q_m_s",))
    return dataclasses.replace(plant, ss=ext)


def provenance(model: TvcModel, solver: SolverSettings, **more) -> dict:
    return {**model_provenance(model),
            "model_inputs": model_inputs(model),
            **base_provenance(), "seeds": "none (deterministic)", "friction_model": model.friction.name,
            "solver": {"method": solver.method, "dt_s": solver.dt_s, "record_every": solver.record_every},
            **more}


def _axis_arrays(model: TvcModel, axis: str, cmd: np.ndarray, dt_s: float, record_every: int,
                 integrator: str = "rk4", profile: Profile | None = None, index: int = 0) -> tuple[dict, dict | None]:
    """One axis' run (its own planar model) driven by the command samples ``cmd`` (n + 1,)
    [rad]: ({array name: recorded samples} (:class:`TimeHistory` names), how the exponential
    integrator ran (``integrator="exp"``; ``profile`` and its axis ``index`` give its
    breakpoints) or None)."""
    from .dynamics import AUX_TF, AUX_U, AUX_Z

    plant = _with_spool_output(simplex_plant(model, axis))
    how = None
    if integrator == "exp":
        from functools import partial

        from ._exptime import breakpoints, integrate_plant_exp
        y, aux, how = integrate_plant_exp(plant, model, kernel_args(plant, model), cmd, dt_s, record_every,
                                          breakpoints(profile, index),
                                          partial(integrate_plant, plant, model, cmd[:, None], dt_s, record_every))
    else:
        y, aux = integrate_plant(plant, model, cmd[:, None], dt_s, record_every)
    o = plant.ss.output_index
    return {"load_pressure_Pa": y[:, o("p_load_Pa")], "spool_flow_m_s": y[:, o("q_m_s")],
            "supply_pressure_Pa": np.full(y.shape[0], model.actuator.supply_pressure_Pa),
            "command_rad": cmd[::record_every], "command_avionics_rad": aux[:, AUX_U],
            "piston_m": y[:, o("x_p_m")], "engine_rad": y[:, o("theta_rad")],
            "friction_torque_Nm": aux[:, AUX_TF], "friction_state_rad": aux[:, AUX_Z],
            "load_force_N": y[:, o("load_force_N")]}, how


def simulate(model: TvcModel, profile: Profile, *, dt_s: float = DEFAULT_DT_S, record_every: int = 10,
             duration_s: float | None = None, progress: bool = False, threads: int | None = None,
             integrator: str = "rk4") -> TimeHistory:
    """Run ``profile`` through the simplex model (each axis its own planar model; the axes are
    independent runs, in parallel on ``threads`` threads with the numbers of a serial run,
    :mod:`taos.planar._parallel`).

    Parameters
    ----------
    model : TvcModel
    profile : a profile of :mod:`taos.profiles` (single axis drives pitch; two-axis drives both)
    dt_s : float
        Integration step [s].
    record_every : int
        Keep every n-th step.
    duration_s : float, optional
        Simulated time [s]; default the profile's duration plus 1 s.
    progress : bool
        Show a progress bar per axis.
    threads : int, optional
        Threads for the axes (1: one after the other); default numba's thread count
        (``NUMBA_NUM_THREADS``, default the number of cores). The results do not depend on it.
    integrator : str
        ``"rk4"`` (the fixed-step kernel at ``dt_s``) or ``"exp"`` (ETDRK4 with the step
        chosen by the friction loop and the records, the command sampled every ``dt_s``:
        :mod:`taos.planar._exptime`; it runs RK4 where it does not apply and says why in the
        provenance's ``exp``).
    """
    from ._parallel import run_tasks

    from ..bounds import (MAX_DURATION_S, check_choice, check_count, check_flag, check_instance, check_number,
                          check_profile, check_step)
    from .simplex import check_rk4_step

    check_instance(model, "model", TvcModel, "a TvcModel (taos.load_model)")
    check_profile(profile)
    check_choice(integrator, "integrator", ("rk4", "exp"))
    check_number(duration_s, "duration_s", 0.0, MAX_DURATION_S, "s", lo_open=True, optional=True)
    T = (profile.duration_s + 1.0) if duration_s is None else float(duration_s)
    check_step(dt_s, "dt_s", duration_s=T)
    if integrator == "rk4":   # the explicit step's rule, as the command line's --dt
        check_rk4_step(float(dt_s), model, "dt_s")
    check_count(record_every, "record_every", 1)
    check_flag(progress, "progress")
    n = int(math.ceil(T / dt_s))
    t = np.arange(n + 1) * dt_s
    cmd = np.atleast_2d(profile(t))
    axes = ("pitch", "yaw") if is_two_axis(profile) else ("pitch",)
    bar = None
    if progress:
        from tqdm import tqdm
        bar = tqdm(total=len(axes), desc="simplex", unit="axis")
    try:
        runs = run_tasks([lambda i=i, ax=ax: _axis_arrays(model, ax, cmd[i], dt_s, record_every, integrator,
                                                          profile, i)
                          for i, ax in enumerate(axes)], threads, done=None if bar is None else lambda i: bar.update())
    finally:
        if bar is not None:
            bar.close()
    exp_how = [how for _, how in runs if how is not None]
    exp = any(h["method"] == "etdrk4" for h in exp_how)
    solver = SolverSettings(method="etdrk4" if exp else SolverSettings.method, dt_s=dt_s, record_every=record_every)
    prov = provenance(model, solver, engine="simplex", profile=getattr(profile, "name", type(profile).__name__),
                      **({"exp": {ax: h for ax, h in zip(axes, exp_how)}} if exp_how else {}))
    names = TimeHistory.ARRAYS + TimeHistory.OPTIONAL_ARRAYS
    return TimeHistory(t_s=t[::record_every], axes=axes, moment_arm_m=model.actuator.moment_arm_m,
                       provenance=prov, **{k: np.vstack([r[k] for r, _ in runs]) for k in names})
