"""The TVC as a co-simulation block: one engine's nonlinear TVC, both axes, stepped by a host.

:class:`TvcBlock` computes exactly what ``taos simulate`` computes (the same model, the same
compiled kernels, the same fixed internal step: servo, gimbal friction, command avionics,
valve flow and supply-pressure limits, hard stops), advanced by whatever communication step the
host takes, as long as it is a whole multiple of the internal step (else it is refused, naming
the step to use). Between two communication points the FCS command is either

* ``hold`` (default, the FMI co-simulation convention: a digital flight computer's command is a
  staircase): the command given to :meth:`TvcBlock.step` is held over the step;
* ``ramp``: the command moves linearly from the previous step's command to the one given, which
  it reaches at the end of the step; this is how ``taos simulate`` reads its command samples (a
  linear interpolation between samples), so stepping the block with ``ramp`` through the samples
  of a profile, ``step(dt, profile(t + dt))``, reproduces ``taos simulate`` bit for bit.

Checks, before the first step (the ones ``taos simulate`` makes): the internal step against the
fastest linear mode and the friction law's explicit-step rule, the linear model's stability.
At every step: the commands finite and within the gimbal range, the step a positive multiple of
the internal step; a non-finite state stops with :class:`~taos.errors.SimulationUnstable`, an
engine beyond the hard stops or a load beyond 3 x the stall force with
:class:`~taos.errors.EnvelopeExceeded` (the envelope ``taos simulate`` checks after its run).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

import numpy as np

from ..bounds import GIMBAL_RANGE_RAD, HARD_STOP_RAD, LOAD_FORCE_FACTOR, check_command_angle
from ..errors import EnvelopeExceeded, InputError
from ..model import TvcModel
from ._cores import AXES, SIGNALS, PlanarCore, TaosCore
from ._options import HOLDS

#: a communication step counts as a whole multiple of the internal step within this fraction of it
STEP_TOLERANCE = 1e-6
SOURCE = "taos.cosim"
#: the most internal steps one communication step may take (the command samples of a step are
#: held in memory: 16 MB at this bound)
MAX_SUBSTEPS = 10 ** 6


@dataclass(frozen=True)
class BlockOutputs:
    """The block's outputs at ``time_s`` [s] (the end of the last step), SI units.

    Per axis (``pitch_*``, ``yaw_*``): the engine angle [rad] and rate [rad/s], the piston
    position [m], the actuator load force F_L [N] and load pressure P_L [Pa], the gimbal friction
    torque [N m] and the command after the avionics [rad]. ``thrust_direction_x/y/z`` [-]: the
    unit vector of the thrust on the vehicle in the gimbal frame (origin at the gimbal, z along
    the undeflected engine axis towards the thrust structure, pitch about +y, yaw about -x;
    :mod:`taos.cosim._cores`)."""

    time_s: float
    pitch_engine_rad: float
    yaw_engine_rad: float
    pitch_engine_rate_rad_s: float
    yaw_engine_rate_rad_s: float
    pitch_piston_m: float
    yaw_piston_m: float
    pitch_load_force_N: float
    yaw_load_force_N: float
    pitch_load_pressure_Pa: float
    yaw_load_pressure_Pa: float
    pitch_friction_torque_Nm: float
    yaw_friction_torque_Nm: float
    pitch_command_avionics_rad: float
    yaw_command_avionics_rad: float
    thrust_direction_x: float
    thrust_direction_y: float
    thrust_direction_z: float

    @classmethod
    def signal_names(cls) -> tuple[str, ...]:
        """The output signals (every field but ``time_s``), in order."""
        return tuple(f.name for f in fields(cls) if f.name != "time_s")

    def to_dict(self) -> dict:
        return {f.name: getattr(self, f.name) for f in fields(self)}


assert BlockOutputs.signal_names() == SIGNALS   # the cores return the outputs in this order
_FIELDS = ("time_s",) + SIGNALS
#: positions in SIGNALS of the engine angles and load forces (the envelope)
_TH_P, _TH_Y, _FL_P, _FL_Y = (SIGNALS.index(k) for k in ("pitch_engine_rad", "yaw_engine_rad", "pitch_load_force_N",
                                                         "yaw_load_force_N"))
_new = object.__new__


def _outputs(t: float, values: tuple) -> BlockOutputs:
    """The outputs at ``t`` [s] of the core's end values (:data:`taos.cosim._cores.SIGNALS`).
    Built as the frozen dataclass's own ``__init__`` would (its instance dictionary: every
    field set, nothing else), without its one ``object.__setattr__`` call per field: one of
    these per communication step."""
    out = _new(BlockOutputs)
    out.__dict__.update(zip(_FIELDS, (t, *values)))
    return out


class TvcBlock:
    """One engine's nonlinear TVC, both axes, as a co-simulation block (module docstring).

    Parameters
    ----------
    model : TvcModel
        The model (:func:`taos.model.load_model`; ``--friction`` and avionics variants are
        model variants).
    engine : str
        ``"simplex"`` (planar, each axis its own plant) or ``"taos"`` (3-D, two actuators).
    dt_s : float, optional
        Internal (kernel) step [s]; default the engine's ``taos simulate`` step (2e-4 s simplex,
        4e-4 s taos).
    hold : str
        ``"hold"`` or ``"ramp"``: the command between communication points (:data:`HOLDS`).
    allow_unstable : bool
        Accept a model whose linear block is unstable (``--allow-unstable``).
    taos : TaosModel, optional
        The 3-D model when already built (else :func:`taos.taos3d.taos_model` of ``model``).
    """

    def __init__(self, model: TvcModel, *, engine: str = "simplex", dt_s: float | None = None, hold: str = "hold",
                 allow_unstable: bool = False, taos=None):
        from ..planar.envelope import check_linear_stability, check_run_step, default_dt_s

        dt = default_dt_s(engine, source=SOURCE, field="engine") if dt_s is None else float(dt_s)
        if hold not in HOLDS:
            raise InputError(SOURCE, "hold", " or ".join(HOLDS), got=repr(hold))
        check_run_step(dt, model, source=SOURCE, field="dt_s", pressure_limit=engine != "taos")
        check_linear_stability(model, allow=allow_unstable)
        if engine == "taos":
            if taos is None:
                from ..taos3d import taos_model
                taos = taos_model(model)
            self._core: PlanarCore | TaosCore = TaosCore(taos, dt)
        else:
            self._core = PlanarCore(model, dt)
        self.model, self.engine, self.dt_s, self.hold = model, engine, dt, hold
        self.allow_unstable = allow_unstable
        self._stall_N = model.actuator.stall_force_N
        self._ramp = hold == "ramp"
        #: the envelope's load-force bound [N] (:meth:`_check_envelope`)
        self._force_limit_N = LOAD_FORCE_FACTOR * self._stall_N
        #: the last communication step [s] given and its internal steps (:meth:`substeps`)
        self._last_step: tuple = (None, 0)
        #: the ramp fractions k / n, k = 0..n (n + 1, 1) of the last ramp of n > 1 steps
        self._frac = np.zeros((2, 1))
        self._restart(0.0, 0.0)

    # -- state ----------------------------------------------------------------------------
    def reset(self, pitch_command_rad: float = 0.0, yaw_command_rad: float = 0.0) -> BlockOutputs:
        """Back to rest at time 0 with the given commands [rad] (the start of a ``ramp``);
        returns the outputs there."""
        self._restart(pitch_command_rad, yaw_command_rad)
        return self.outputs

    def _restart(self, pitch_command_rad: float, yaw_command_rad: float) -> None:
        """Rest at time 0 with the given commands; the outputs there computed when first asked
        for (:attr:`outputs`: a block built only for its checks, as ``taos fmu`` builds one,
        never loads the compiled kernels)."""
        self._core.reset()
        self._k = 0
        self._cmd = self._checked(pitch_command_rad, yaw_command_rad)
        self._out = None

    @property
    def time_s(self) -> float:
        """Time of the last communication point [s] (whole internal steps since reset)."""
        return self._k * self.dt_s

    @property
    def outputs(self) -> BlockOutputs:
        """The outputs at :attr:`time_s`."""
        if self._out is None:   # at rest at time 0 (_restart): the kernels' values there
            r = self._core.samples(0)
            r[0, 0], r[0, 1] = self._cmd
            self._out = _outputs(0.0, self._core.advance(0, 0.0))
        return self._out

    # -- stepping -------------------------------------------------------------------------
    def substeps(self, step_s: float) -> int:
        """Internal steps in a communication step of ``step_s`` [s]; refuses a step that is not a
        positive whole multiple of :attr:`dt_s` (within :data:`STEP_TOLERANCE` of it)."""
        n = round(step_s / self.dt_s) if math.isfinite(step_s) and step_s > 0 else 0
        if n < 1 or abs(step_s - n * self.dt_s) > STEP_TOLERANCE * self.dt_s:
            raise InputError(SOURCE, "communication step", f"a positive whole multiple of the internal step "
                             f"{self.dt_s:g} s (or set the internal step to divide it)", got=f"{step_s!r} s")
        if n > MAX_SUBSTEPS:
            raise InputError(SOURCE, "communication step", f"at most {MAX_SUBSTEPS:.0e} internal steps "
                             f"({MAX_SUBSTEPS * self.dt_s:g} s)", got=f"{step_s!r} s")
        return n

    def step(self, dt_s: float, pitch_command_rad: float, yaw_command_rad: float) -> BlockOutputs:
        """Advance by the communication step ``dt_s`` [s] with the FCS engine-angle commands
        [rad] (before the avionics; held or ramped over the step, :attr:`hold`); returns the
        outputs at the end of the step (a refused step or command changes nothing)."""
        last, n = self._last_step
        if dt_s != last:   # a step checked once (NaN never equals: always checked and refused)
            n = self.substeps(dt_s)
            self._last_step = (dt_s, n)
        p1, y1 = cmd = self._checked(pitch_command_rad, yaw_command_rad)
        core = self._core
        r = core.samples(n)
        if self._ramp:
            p0, y0 = self._cmd
            if n > 1:
                frac = self._frac
                if frac.shape[0] != n + 1:
                    frac = self._frac = np.arange(n + 1)[:, None] / n
                np.multiply(frac, (p1 - p0, y1 - y0), out=r)   # c0 + k / n (c1 - c0), as taos simulate's
                r += (p0, y0)                                   # linear interpolation of its samples
            r[0, 0], r[0, 1] = p0, y0   # the end points exactly
            r[n, 0], r[n, 1] = p1, y1
        elif n == 1:
            r[0, 0], r[0, 1] = r[1, 0], r[1, 1] = cmd
        else:
            r[:, 0], r[:, 1] = cmd
        k0 = self._k
        end = core.advance(n, k0 * self.dt_s)
        self._k = k0 + n
        self._cmd = cmd
        self._out = out = _outputs(self._k * self.dt_s, end)
        if not self.allow_unstable:
            hs, fl = HARD_STOP_RAD, self._force_limit_N
            if not (abs(end[_TH_P]) <= hs and abs(end[_TH_Y]) <= hs and
                    abs(end[_FL_P]) <= fl and abs(end[_FL_Y]) <= fl):
                self._check_envelope(out)   # beyond (or NaN): raises, naming the signal
        return out

    # -- checks ---------------------------------------------------------------------------
    def _checked(self, pitch: float, yaw: float) -> tuple[float, float]:
        """The commands as floats [rad], refused unless numbers within the gimbal range
        (:func:`taos.bounds.check_command_angle`; two floats within +-GIMBAL_RANGE_RAD pass at once)."""
        if type(pitch) is float and type(yaw) is float and -GIMBAL_RANGE_RAD <= pitch <= GIMBAL_RANGE_RAD \
                and -GIMBAL_RANGE_RAD <= yaw <= GIMBAL_RANGE_RAD:
            return (pitch, yaw)
        out = []
        for ax, v in zip(AXES, (pitch, yaw)):
            try:
                v = float(v)
            except (TypeError, ValueError):
                raise InputError(SOURCE, f"{ax}_command_rad", "a number of radians", got=repr(v)[:40]) from None
            out.append(check_command_angle(v, SOURCE, f"{ax}_command_rad"))
        return (out[0], out[1])

    def _check_envelope(self, o: BlockOutputs) -> None:
        """The envelope of :func:`taos.planar.envelope.check_envelope` at this communication point."""
        if self.allow_unstable:
            return
        for ax in AXES:
            th = getattr(o, f"{ax}_engine_rad")
            fl = getattr(o, f"{ax}_load_force_N")
            if not abs(th) <= HARD_STOP_RAD:
                raise EnvelopeExceeded(o.time_s, f"{ax} engine angle {math.degrees(th):.4g} deg beyond the hard "
                                       f"stops +-{math.degrees(HARD_STOP_RAD):.3g} deg",
                                       "a command too fast or too large for the actuator's flow and force")
            if not abs(fl) <= self._force_limit_N:
                raise EnvelopeExceeded(o.time_s, f"{ax} load force {fl:.4g} N beyond {LOAD_FORCE_FACTOR:g} x the "
                                       f"stall force A P_s = {self._stall_N:.4g} N",
                                       "a command too fast or too large for the actuator")

    def provenance(self) -> dict:
        """Model hash, package version and solver settings of this block."""
        from ..planar.simulate import SolverSettings, provenance
        method = "rk4-fixed-step" if self.engine == "simplex" else \
            "rk4, trapezoidal bearing torque + BDF2 bearing substeps"
        return provenance(self.model, SolverSettings(method=method, dt_s=self.dt_s, record_every=1),
                          engine=self.engine, command_hold=self.hold)
