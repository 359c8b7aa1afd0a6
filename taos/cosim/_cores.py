"""The two engines' compiled kernels stepped in chunks (no second copy of any dynamics).

* :class:`PlanarCore`: the simplex model's Lur'e plants (:func:`taos.planar.simplex.simplex_plant`,
  one per axis) through :func:`taos.planar.dynamics.integrate_samples`, the kernel of
  ``taos simulate --engine simplex``. That kernel starts from a given state and records
  ``Cy x``: with ``Cy = [I; C]`` its last record is the final state itself (exact: the identity
  rows add zeros to one state) followed by the plant's outputs, so a run cut into chunks is the
  uncut run bit for bit.
* :class:`TaosCore`: the 3-D model (:func:`taos.taos3d.simulate.pack`) through
  :func:`taos.taos3d.dynamics.integrate`, the kernel of ``taos simulate --engine taos``, which
  advances its state and bearing state in place.

Both take the pre-avionics command samples ``r`` (n + 1, 2) [rad] (pitch, yaw) every ``dt`` [s],
linearly interpolated between samples as ``taos simulate`` does, and return the signals at the
chunk's end (:class:`EndValues`, SI).

Engine rate of the 3-D model: the engine angles are the pitch/yaw components of the rotation
vector r = log(R) (:mod:`taos.taos3d.model`), so their rates are those components of
dr/dt = Jr(r)^-1 omega_b (omega_b the body angular velocity, Jr the SO(3) right Jacobian;
Jr^-1 = Jl^-T, the map :func:`taos.taos3d.dynamics._world_torque` applies). Thrust direction:
the engine axis +z of the gimbal frame (from the engine towards the thrust structure, the
direction of the thrust on the vehicle) rotated with the engine, d = R e_z; for the planar
model R = exp([r]) with r = theta_p e_y - theta_y e_x (pitch about +y, yaw about -x), i.e.
d = (theta_p s, theta_y s, cos a), a = |r|, s = sin(a) / a.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import SimulationUnstable

AXES = ("pitch", "yaw")


@dataclass(frozen=True)
class EndValues:
    """Per-axis signals at the end of a chunk, each a (pitch, yaw) pair [SI], and the thrust
    direction (3,) [-] in the gimbal frame."""

    engine_rad: tuple[float, float]
    engine_rate_rad_s: tuple[float, float]
    piston_m: tuple[float, float]
    load_force_N: tuple[float, float]
    load_pressure_Pa: tuple[float, float]
    friction_torque_Nm: tuple[float, float]
    command_avionics_rad: tuple[float, float]
    thrust_direction: tuple[float, float, float]


def planar_thrust_direction(pitch_rad: float, yaw_rad: float) -> tuple[float, float, float]:
    """d = exp([r]) e_z for r = theta_p e_y - theta_y e_x (module docstring) [-]."""
    a = math.hypot(pitch_rad, yaw_rad)
    s = 1.0 - a * a / 6.0 if a < 1e-6 else math.sin(a) / a
    return (pitch_rad * s, yaw_rad * s, math.cos(a))


def _pair(a, b) -> tuple[float, float]:
    return (float(a), float(b))


def compiled_entry(disp, args):
    """The compiled entry point of the numba kernel ``disp`` for the types of ``args`` (loaded
    from numba's cache or compiled, as a call would), without running it. Calling it skips
    numba's typing of every argument at every call, which for these kernels (the friction law's
    first-class functions, the 3-D model's named tuple) costs several times the work of a short
    chunk; the machine code is the one a call through ``disp`` runs."""
    return disp.compile(tuple(disp.typeof_pyval(a) for a in args))


class PlanarCore:
    """Both axes of the simplex model (each axis its own planar plant, as ``taos simulate``)."""

    def __init__(self, model, dt_s: float):
        from ..planar import dynamics as dyn
        from ..planar.simplex import simplex_plant
        from ..planar.simulate import check_friction_step, kernel_args

        self._dyn = dyn
        self._plants = []
        for ax in AXES:
            plant = simplex_plant(model, ax)
            check_friction_step(model, plant.inertia_kgm2, dt_s)
            n = plant.ss.A.shape[0]
            cy = np.ascontiguousarray(np.vstack([np.eye(n), plant.ss.C]))
            col = {k: n + plant.ss.output_index(k) for k in
                   ("theta_rad", "omega_rad_s", "x_p_m", "load_force_N", "p_load_Pa")}
            self._plants.append((kernel_args(plant, model), cy, n, col))
        self._fid = model.friction.entry.rates
        self._fp = model.friction.pack()
        self._avp = model.avionics.pack()
        self._label = f"{model.friction.name} friction, dt = {dt_s} s"
        self._entry = None
        self.reset()

    def reset(self) -> None:
        """Rest: every state and the friction states zero."""
        self._x = [np.zeros(n) for _, _, n, _ in self._plants]
        self._z = [0.0, 0.0]

    def advance(self, r: np.ndarray, dt_s: float, t0_s: float) -> EndValues:
        """Integrate the samples ``r`` (n + 1, 2) [rad] (n = 0: no step, the values now);
        ``t0_s`` the chunk's start time [s] (for the error message)."""
        dyn = self._dyn
        nsteps = r.shape[0] - 1
        every = max(nsteps, 1)
        nrec = nsteps // every + 1
        vals = []
        for i, (args, cy, n, col) in enumerate(self._plants):
            y = np.empty((nrec, cy.shape[0]))
            aux = np.empty((nrec, dyn.N_AUX))
            ri = np.ascontiguousarray(r[:, i:i + 1])
            call = (*args, cy, self._fid, self._fp, self._avp, self._x[i], float(self._z[i]), ri, float(dt_s), int(every),
                    y, aux)
            if self._entry is None:
                self._entry = compiled_entry(dyn.integrate_samples, call)
            status = self._entry(*call)
            if status >= 0:
                raise SimulationUnstable(t0_s + status * dt_s, f"{AXES[i]}: {self._label}")
            self._x[i] = y[-1, :n].copy()
            self._z[i] = float(aux[-1, dyn.AUX_Z])
            vals.append((y[-1], aux[-1], col))
        (yp, ap, c), (yy, ay, _) = vals
        g = lambda k: _pair(yp[c[k]], yy[c[k]])  # noqa: E731
        th = g("theta_rad")
        return EndValues(engine_rad=th, engine_rate_rad_s=g("omega_rad_s"), piston_m=g("x_p_m"),
                         load_force_N=g("load_force_N"), load_pressure_Pa=g("p_load_Pa"),
                         friction_torque_Nm=_pair(ap[dyn.AUX_TF], ay[dyn.AUX_TF]),
                         command_avionics_rad=_pair(ap[dyn.AUX_U], ay[dyn.AUX_U]),
                         thrust_direction=planar_thrust_direction(*th))


class TaosCore:
    """The 3-D TAOS model (one engine, two actuators) as ``taos simulate --engine taos`` runs it."""

    def __init__(self, tm, dt_s: float):
        from ..taos3d import dynamics as dy
        from ..taos3d.simulate import pack

        self._dy = dy
        self._pk = pack(tm)
        self._col = {k: i for i, k in enumerate(dy.REC)}
        self._label = f"TAOS, {tm.base.friction.name} friction, dt = {dt_s} s"
        self._entry = None
        self.reset()

    def reset(self) -> None:
        """Rest: identity attitude, every other state and the bearing state zero."""
        from ..taos3d.simulate import rest_state

        self._x = rest_state(self._pk)
        self._bs = np.zeros(self._dy.N_BEARING)

    def advance(self, r: np.ndarray, dt_s: float, t0_s: float) -> EndValues:
        """As :meth:`PlanarCore.advance`."""
        dy, pk = self._dy, self._pk
        nsteps = r.shape[0] - 1
        every = max(nsteps, 1)
        out = np.empty((nsteps // every + 1, len(dy.REC)))
        call = (pk.P, pk.fid, pk.fp, pk.avp, self._x, self._bs, np.ascontiguousarray(r, dtype=np.float64), float(dt_s),
                int(every), out)
        if self._entry is None:
            self._entry = compiled_entry(dy.integrate, call)
        status = self._entry(*call)
        if status >= 0:
            raise SimulationUnstable(t0_s + status * dt_s, self._label)
        rec = out[-1]
        c = self._col
        g = lambda k: _pair(rec[c[f"{k}_pitch"]], rec[c[f"{k}_yaw"]])  # noqa: E731
        x = self._x
        qx, qy, qz, qw = (float(v) for v in x[dy.X_Q:dy.X_Q + 4])
        r0, r1, r2, th = dy._logq4(qx, qy, qz, qw)
        rd = np.array(dy._world_torque(r0, r1, r2, th, *(float(v) for v in x[dy.X_W:dy.X_W + 3])))
        axes = pk.P.bearing_axes
        R = dy._rotation(qx, qy, qz, qw)
        return EndValues(engine_rad=g("theta"), engine_rate_rad_s=_pair(axes[0] @ rd, axes[1] @ rd),
                         piston_m=g("xp"), load_force_N=g("fl"), load_pressure_Pa=g("pl"),
                         friction_torque_Nm=g("tf"), command_avionics_rad=g("u"),
                         thrust_direction=(float(R[2]), float(R[5]), float(R[8])))
