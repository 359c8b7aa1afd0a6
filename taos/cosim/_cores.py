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

Both step chunks of ``n`` internal steps of ``dt`` [s]: the caller writes the chunk's
pre-avionics command samples (n + 1, 2) [rad] (pitch, yaw), linearly interpolated between
samples as ``taos simulate`` does, into the array :meth:`PlanarCore.samples` returns, then
:meth:`PlanarCore.advance` returns the signals at the chunk's end (:data:`SIGNALS`, SI).

Per-chunk cost: a host may step the block at every internal step, so a chunk's Python is kept
small. The command samples, the kernel's output arrays and its argument list are made once per
chunk length and reused; the kernel is called through its compiled entry point
(:func:`compiled_entry`), and the friction law's compiled functions are passed as
:class:`FunctionAddress` objects (numba's wrapper-address protocol: the same function pointer,
found without the signature comparison numba makes for a ``cfunc`` at every call). The simplex
core loads the friction law's compiled functions and its kernel at its first chunk, not when
built (a block built for its checks alone, as ``taos fmu`` builds one, loads no kernel).

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
from operator import itemgetter

import numpy as np

from ..errors import SimulationUnstable

AXES = ("pitch", "yaw")
#: the per-axis signals of a chunk's end [SI], each as (pitch, yaw) in :data:`SIGNALS`
AXIS_SIGNALS = ("engine_rad", "engine_rate_rad_s", "piston_m", "load_force_N", "load_pressure_Pa",
                "friction_torque_Nm", "command_avionics_rad")
#: the values :meth:`PlanarCore.advance` returns, in order: each per-axis signal for pitch then
#: yaw, then the thrust direction's x, y, z [-] in the gimbal frame
SIGNALS = tuple(f"{ax}_{s}" for s in AXIS_SIGNALS for ax in AXES) + tuple(f"thrust_direction_{c}" for c in "xyz")
#: the most chunk lengths whose buffers a core keeps (a host varying its step reallocates)
MAX_CHUNK_SHAPES = 3


def planar_thrust_direction(pitch_rad: float, yaw_rad: float) -> tuple[float, float, float]:
    """d = exp([r]) e_z for r = theta_p e_y - theta_y e_x (module docstring) [-]."""
    a = math.hypot(pitch_rad, yaw_rad)
    s = 1.0 - a * a / 6.0 if a < 1e-6 else math.sin(a) / a
    return (pitch_rad * s, yaw_rad * s, math.cos(a))


def compiled_entry(disp, args):
    """The compiled entry point of the numba kernel ``disp`` for the types of ``args`` (loaded
    from numba's cache or compiled, as a call would), without running it. Calling it skips
    numba's typing of every argument at every call, which for these kernels (the friction law's
    first-class functions, the 3-D model's named tuple) costs several times the work of a short
    chunk; the machine code is the one a call through ``disp`` runs."""
    return disp.compile(tuple(disp.typeof_pyval(a) for a in args))


class FunctionAddress:
    """A compiled numba ``cfunc`` (a friction law's kernel) as an object of numba's wrapper
    address protocol (an object with ``__wrapper_address__()``, the address of the compiled
    function; numba's ``numba.experimental.function_type._get_wrapper_address``), passed for
    the cfunc to a compiled entry point typed with the cfunc itself (:func:`compiled_entry`).
    The kernel receives the same function pointer; numba's unboxing of the argument at each call
    skips its check that the cfunc's signature equals the expected one (a comparison of numba
    types costing about 1 us a call: done once, by the typing). No numba import here: this
    module holds no compiled code (``taos/cli/warmup.py --sources``). The owner keeps the cfunc
    referenced (its compiled code lives as long as it does)."""

    __slots__ = ("_address",)

    def __init__(self, cfunc):
        self._address = int(cfunc.address)

    def __wrapper_address__(self) -> int:
        return self._address


def _chunk_shape(n: int) -> tuple[int, int]:
    """(record interval, records) of a chunk of ``n`` steps: its start and its end."""
    every = max(n, 1)
    return every, n // every + 1


class PlanarCore:
    """Both axes of the simplex model (each axis its own planar plant, as ``taos simulate``)."""

    def __init__(self, model, dt_s: float):
        from ..planar import dynamics as dyn
        from ..planar.simplex import simplex_plant
        from ..planar.simulate import check_friction_step, kernel_args

        self._dyn = dyn
        self._dt = float(dt_s)
        self._plants = []
        for ax in AXES:
            plant = simplex_plant(model, ax)
            check_friction_step(model, plant.inertia_kgm2, dt_s)
            n = plant.ss.A.shape[0]
            cy = np.ascontiguousarray(np.vstack([np.eye(n), plant.ss.C]))
            cols = [n + plant.ss.output_index(k) for k in ("theta_rad", "omega_rad_s", "x_p_m", "load_force_N",
                                                             "p_load_Pa")]
            self._plants.append((kernel_args(plant, model), cy, n, cols))
        self._friction = model.friction
        self._cfunc = self._fid = None   # the friction law's compiled rates, loaded at the first chunk
        self._fp = model.friction.pack()
        self._avp = model.avionics.pack()
        self._label = f"{model.friction.name} friction, dt = {dt_s} s"
        #: positions of the friction kernel and of the friction state z0 in the argument list
        self._ifid = len(self._plants[0][0]) + 1
        self._iz = self._ifid + 4
        #: per axis: (theta, omega, x_p, F_L, P_L) of a record of y; (T_f, z, u) of one of aux
        self._pick = [itemgetter(*cols) for _, _, _, cols in self._plants]
        self._aux = itemgetter(dyn.AUX_TF, dyn.AUX_Z, dyn.AUX_U)
        self._entry = None
        #: per axis: the linear state [x] (updated in place at the end of each chunk)
        self._x = [np.zeros(n) for _, _, n, _ in self._plants]
        self._chunks: dict = {}
        self.reset()

    def reset(self) -> None:
        """Rest: every state and the friction states zero."""
        for x in self._x:
            x[:] = 0.0
        self._z = [0.0, 0.0]

    def _chunk(self, n: int):
        """(samples (n + 1, 2), per axis (kernel argument list, last record of y, last record of
        aux, the state in that record)) of a chunk of ``n`` steps."""
        got = self._chunks.get(n)
        if got is None:
            if self._fid is None:
                self._cfunc = self._friction.entry.rates
                self._fid = FunctionAddress(self._cfunc)
            if len(self._chunks) >= MAX_CHUNK_SHAPES:
                self._chunks.clear()
            every, nrec = _chunk_shape(n)
            r = np.zeros((2, n + 1, 1))   # each axis' samples contiguous (n + 1, 1): the kernel's input
            lanes = []
            for i, (args, cy, nx, _) in enumerate(self._plants):
                y, aux = np.empty((nrec, cy.shape[0])), np.empty((nrec, self._dyn.N_AUX))
                call = [*args, cy, self._fid, self._fp, self._avp, self._x[i], 0.0, r[i], self._dt, every, y, aux]
                lanes.append((call, y[-1], aux[-1], y[-1, :nx]))
            got = self._chunks[n] = (r[:, :, 0].T, lanes)
        return got

    def samples(self, n: int) -> np.ndarray:
        """The command samples (n + 1, 2) [rad] (pitch, yaw) of the next chunk of ``n`` steps, to
        be written by the caller (a view of the axes' kernel inputs; contents undefined)."""
        return self._chunk(n)[0]

    def advance(self, n: int, t0_s: float) -> tuple[float, ...]:
        """Integrate ``n`` steps (0: no step, the values now) over the samples written into
        :meth:`samples` ``(n)``; ``t0_s`` the chunk's start time [s] (for the error message).
        Returns :data:`SIGNALS`. Raises :class:`~taos.errors.SimulationUnstable` with the state
        left at the chunk's start."""
        lanes = self._chunk(n)[1]
        if self._entry is None:
            c = list(lanes[0][0])
            c[self._ifid] = self._cfunc   # typed with the cfunc itself
            self._entry = compiled_entry(self._dyn.integrate_samples, c)
        entry, iz, z = self._entry, self._iz, self._z
        (call_p, yp, ap, sp), (call_y, yy, ay, sy) = lanes
        call_p[iz] = z[0]
        status = entry(*call_p)
        if status >= 0:
            raise SimulationUnstable(t0_s + status * self._dt, f"{AXES[0]}: {self._label}")
        call_y[iz] = z[1]
        status = entry(*call_y)
        if status >= 0:
            raise SimulationUnstable(t0_s + status * self._dt, f"{AXES[1]}: {self._label}")
        xp, xy = self._x
        xp[:] = sp
        xy[:] = sy
        (th_p, w_p, xp_p, fl_p, pl_p), (th_y, w_y, xp_y, fl_y, pl_y) = self._pick[0](yp.tolist()), \
            self._pick[1](yy.tolist())
        (tf_p, z_p, u_p), (tf_y, z_y, u_y) = self._aux(ap.tolist()), self._aux(ay.tolist())
        self._z = [z_p, z_y]
        return (th_p, th_y, w_p, w_y, xp_p, xp_y, fl_p, fl_y, pl_p, pl_y, tf_p, tf_y, u_p, u_y,
                *planar_thrust_direction(th_p, th_y))


class TaosCore:
    """The 3-D TAOS model (one engine, two actuators) as ``taos simulate --engine taos`` runs it."""

    def __init__(self, tm, dt_s: float):
        from ..taos3d import dynamics as dy
        from ..taos3d.simulate import pack, rest_state

        self._dy = dy
        self._dt = float(dt_s)
        self._pk = pack(tm)
        self._fid = tuple(FunctionAddress(f) for f in self._pk.fid)
        rec = {k: i for i, k in enumerate(dy.REC)}
        #: (theta, xp, fl, pl, tf, u), pitch then yaw, of a record
        self._pick = itemgetter(*(rec[f"{k}_{ax}"] for k in ("theta", "xp", "fl", "pl", "tf", "u") for ax in AXES))
        self._label = f"TAOS, {tm.base.friction.name} friction, dt = {dt_s} s"
        self._entry = None
        self._x = rest_state(self._pk)
        self._rest = self._x.copy()
        self._bs = np.zeros(self._dy.N_BEARING)
        self._chunks: dict = {}

    def reset(self) -> None:
        """Rest: identity attitude, every other state and the bearing state zero."""
        self._x[:] = self._rest
        self._bs[:] = 0.0

    def _chunk(self, n: int):
        """(samples (n + 1, 2), kernel argument list) of a chunk of ``n`` steps."""
        got = self._chunks.get(n)
        if got is None:
            if len(self._chunks) >= MAX_CHUNK_SHAPES:
                self._chunks.clear()
            every, nrec = _chunk_shape(n)
            pk = self._pk
            r = np.zeros((n + 1, 2))
            got = self._chunks[n] = (r, [pk.P, self._fid, pk.fp, pk.avp, self._x, self._bs, r, self._dt, every,
                                         np.empty((nrec, len(self._dy.REC)))])
        return got

    def samples(self, n: int) -> np.ndarray:
        """As :meth:`PlanarCore.samples`."""
        return self._chunk(n)[0]

    def advance(self, n: int, t0_s: float) -> tuple[float, ...]:
        """As :meth:`PlanarCore.advance` (but a failed chunk leaves the state where it failed)."""
        dy = self._dy
        call = self._chunk(n)[1]
        if self._entry is None:
            self._entry = compiled_entry(dy.integrate, [self._pk.fid if a is self._fid else a for a in call])
        status = self._entry(*call)
        if status >= 0:
            raise SimulationUnstable(t0_s + status * self._dt, self._label)
        th_p, th_y, xp_p, xp_y, fl_p, fl_y, pl_p, pl_y, tf_p, tf_y, u_p, u_y = self._pick(call[-1][-1].tolist())
        x = self._x
        qx, qy, qz, qw = x[dy.X_Q:dy.X_Q + 4].tolist()
        r0, r1, r2, th = dy._logq4(qx, qy, qz, qw)
        rd = np.array(dy._world_torque(r0, r1, r2, th, *x[dy.X_W:dy.X_W + 3].tolist()))
        axes = self._pk.P.bearing_axes
        R = dy._rotation(qx, qy, qz, qw)
        return (th_p, th_y, float(axes[0] @ rd), float(axes[1] @ rd), xp_p, xp_y, fl_p, fl_y, pl_p, pl_y,
                tf_p, tf_y, u_p, u_y, float(R[2]), float(R[5]), float(R[8]))
