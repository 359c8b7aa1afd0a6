"""The standalone FMU's parameter block and command modes (issue 41: one FMU, many conditions;
exact by default). Each check against taos's own Python: ``taos simulate``, the kernels, a model
variant's block, the friction law's ``check_step``."""

from __future__ import annotations

import dataclasses
import math
import shutil
import sys

import numpy as np
import pytest

fmpy = pytest.importorskip("fmpy")

from fmpy.fmi1 import FMICallException  # noqa: E402
from fmpy.fmi2 import FMU2Slave  # noqa: E402

from taos.cosim import TvcBlock  # noqa: E402
from taos.cosim._standalone import build_standalone_fmu  # noqa: E402
from taos.errors import InputError  # noqa: E402
from taos.model import load_model  # noqa: E402
from taos.planar.simulate import simulate  # noqa: E402
from taos.profiles import Recorded, TwoAxis, load_profile  # noqa: E402

from .conftest import MODELS  # noqa: E402

DEG = math.pi / 180
CC = shutil.which("cc") or shutil.which("gcc")
pytestmark = pytest.mark.skipif(CC is None or not sys.platform.startswith("linux"), reason="needs a C compiler on Linux")


@pytest.fixture(scope="module")
def cfmu(tmp_path_factory):
    return build_standalone_fmu(MODELS / "rs25_hotfire.toml", tmp_path_factory.mktemp("cfmu") / "tvc.fmu").path


def held_profile(t_points, c, dt):
    """The command ``c[j]`` held over each communication step [t_j, t_j+1) as ``taos simulate``
    samples it every ``dt``: the sample at a communication point is the command in force before
    it (a Recorded profile switching half an internal step after each point)."""
    tt = np.sort(np.concatenate([t_points, t_points[:-1] + 0.5 * dt]))
    v = np.empty(tt.size)
    v[0::2] = np.concatenate([[c[0]], c[:-1]])
    v[1::2] = c[:-1]
    return Recorded(tt, v)


@pytest.mark.parametrize("host_ms", [1, 2, 5])
def test_exact_mode_by_default_equals_taos_simulate_of_the_held_command(cfmu, hotfire, host_ms):
    """The default ``command_mode = 0`` at 1, 2 and 5 ms host steps (5, 10, 25 internal steps):
    the Green Run's first 1.5 s sampled at the host step and held, through FMPy and through
    ``taos simulate`` (the held command as a profile, :func:`held_profile`): every output at
    every communication point, the engine angles within 1e-6 deg (measured 3e-16 deg), no lag;
    ``command_mode = 2`` (a staircase switching at the point) differs by the half internal step
    of its edges (about 2e-4 deg here)."""
    prof = load_profile("greenrun_two_axis")
    dt, h = 2e-4, host_ms * 1e-3
    steps = round(1.5 / h)
    t = np.arange(steps + 1) * h
    c = np.atleast_2d(prof(t))
    th = simulate(hotfire, TwoAxis(held_profile(t, c[0], dt), held_profile(t, c[1], dt)), dt_s=dt,
                  record_every=round(h / dt), duration_s=steps * h)
    sig = np.zeros(t.size, dtype=[("time", float), ("pitch_command_rad", float), ("yaw_command_rad", float),
                                  ("thrust_N", float)])
    sig["time"], sig["pitch_command_rad"], sig["yaw_command_rad"] = t, c[0], c[1]
    sig["thrust_N"] = hotfire.engine.thrust_N
    res = fmpy.simulate_fmu(str(cfmu), input=sig, stop_time=float(t[-1]), step_size=h, output_interval=h)
    assert res["time"].size == th.t_s.size
    for i, ax in enumerate(th.axes):
        for name in ("engine_rad", "piston_m", "load_force_N", "load_pressure_Pa", "friction_torque_Nm",
                     "command_avionics_rad"):
            ref = getattr(th, name)[i]
            d = np.max(np.abs(res[f"{ax}_{name}"] - ref))
            assert d <= (1e-6 * DEG if name == "engine_rad" else 1e-9 * max(1.0, np.max(np.abs(ref)))), (ax, name, d)
    hold = fmpy.simulate_fmu(str(cfmu), input=sig, stop_time=float(t[-1]), step_size=h, output_interval=h,
                             start_values={"command_mode": 2})
    assert np.max(np.abs(hold["pitch_engine_rad"] - th.engine_rad[0])) > 1e-5 * DEG


def _slave(path, tmp_path, name="t"):
    md = fmpy.read_model_description(str(path))
    unz = fmpy.extract(str(path), unzipdir=str(tmp_path / f"unz_{name}"))
    s = FMU2Slave(guid=md.guid, unzipDirectory=unz, modelIdentifier=md.coSimulation.modelIdentifier,
                  instanceName=name)
    s.instantiate()
    return s, {v.name: v.valueReference for v in md.modelVariables}


def _start(s, vr, before=()):
    s.setupExperiment(startTime=0.0)
    s.enterInitializationMode()
    for name, v in before:
        s.setReal([vr[name]], [v])
    s.exitInitializationMode()


def test_load_stiffness_set_before_initialisation_equals_the_variant(cfmu, hotfire, tmp_path):
    """``load_stiffness_N_per_m`` set at initialisation (the plant from CasADi's C of the
    symbolic state space) equals the variant's Python block (``with_values``) over 0.3 s of a
    held 0.5 deg pitch command, within 1e-6 deg; after initialisation, and outside its
    documented range, it is refused with fmi2Error and nothing changes."""
    k = 120000 * 4.4482216152605 / 0.0254   # 120000 lbf/in [N/m]
    var = hotfire.with_values({"structure.load_stiffness": "120000 lbf/in"})
    assert var.structure.load_stiffness_N_per_m == pytest.approx(k, rel=1e-12)
    s, vr = _slave(cfmu, tmp_path)
    _start(s, vr, [("load_stiffness_N_per_m", var.structure.load_stiffness_N_per_m), ("pitch_command_rad", 0.5 * DEG)])
    b = TvcBlock(var)
    b.reset(0.5 * DEG, 0.0)
    worst = 0.0
    for j in range(300):
        s.doStep(j * 1e-3, 1e-3)
        want = b.step(1e-3, 0.5 * DEG, 0.0)
        got = s.getReal([vr["pitch_engine_rad"], vr["pitch_load_force_N"]])
        worst = max(worst, abs(got[0] - want.pitch_engine_rad))
        assert got[1] == pytest.approx(want.pitch_load_force_N, rel=1e-9, abs=1e-6)
    assert worst <= 1e-6 * DEG
    for bad in (var.structure.load_stiffness_N_per_m, 0.0):
        with pytest.raises(FMICallException) as e:
            s.setReal([vr["load_stiffness_N_per_m"]], [bad])
        assert e.value.status == 3
    assert s.getReal([vr["load_stiffness_N_per_m"]]) == [var.structure.load_stiffness_N_per_m]
    s.terminate()
    s.freeInstance()


def _kernel_run(model, x, z, cmd, n, dt=2e-4):
    """``n`` RK4 steps of taos simulate's kernel for ``model``'s pitch plant from (x, z) with the
    command ``cmd`` held: (x, z) at the end."""
    from taos.planar import dynamics as dyn
    from taos.planar.simplex import simplex_plant
    from taos.planar.simulate import kernel_args

    pa = kernel_args(simplex_plant(model, "pitch"), model)
    m = pa.A.shape[0]
    y, aux = np.empty((n + 1, m)), np.empty((n + 1, dyn.N_AUX))
    r = np.full((n + 1, 1), cmd)
    st = dyn.integrate_samples(*pa, np.eye(m), model.friction.entry.rates, model.friction.pack(),
                               model.avionics.pack(), x, z, r, dt, 1, y, aux)
    assert st < 0
    return y[-1].copy(), float(aux[-1, dyn.AUX_Z])


def test_friction_levels_and_avionics_gain_tuned_between_steps_equal_the_kernels(cfmu, hotfire, tmp_path):
    """Tunable parameters set between steps: 0.1 s of a held 0.3 deg pitch command, then the
    friction levels x 1.5 and the avionics gain 0.9, 0.1 s more: the engine angle equals taos
    simulate's kernel run on the original model, then on the variant (``FrictionLaw.scaled``,
    the gains times 0.9) from the state reached, within 1e-6 deg."""
    from taos.planar.simplex import simplex_plant

    s, vr = _slave(cfmu, tmp_path)
    _start(s, vr, [("pitch_command_rad", 0.3 * DEG)])
    for j in range(50):
        s.doStep(j * 2e-3, 2e-3)
    law = hotfire.friction
    names = [n for n in vr if n.startswith("friction_")]
    assert names and all(n.endswith(("_Nm", "_Nm_per_rad", "_Nms_per_rad")) for n in names)
    vals = s.getReal([vr[n] for n in names])
    s.setReal([vr[n] for n in names] + [vr["avionics_gain"]], [1.5 * v for v in vals] + [0.9])
    for j in range(50, 100):
        s.doStep(j * 2e-3, 2e-3)
    got = s.getReal([vr["pitch_engine_rad"]])[0]
    av = hotfire.avionics
    var = dataclasses.replace(hotfire, friction=law.scaled(1.5),
                              avionics=dataclasses.replace(av, gain_table=tuple(g * 0.9 for g in av.gain_table))
                              if av.gain_table else
                              dataclasses.replace(av, gain_table_rad=(0.0,), gain_table=(0.9,)))
    n = simplex_plant(hotfire, "pitch").ss.A.shape[0]
    x, z = _kernel_run(hotfire, np.zeros(n), 0.0, 0.3 * DEG, 500)
    x, z = _kernel_run(var, x, z, 0.3 * DEG, 500)
    th = x[simplex_plant(hotfire, "pitch").ss.state_index("theta_rad")]
    assert abs(got - th) <= 1e-6 * DEG
    s.terminate()
    s.freeInstance()


def test_internal_step_is_a_fixed_parameter_within_the_laws_rule(tmp_path, hotfire):
    """``internal_step_s``: 1e-4 s set at initialisation equals the block at 1e-4 s; above its
    maximum, after initialisation, or (coulomb-smooth law) where the law's explicit-step rule
    fails (``FrictionLaw.check_step`` refuses the same step), fmi2Error; so is a friction level
    that would make the rule fail at the step in use."""
    path = build_standalone_fmu(MODELS / "rs25_hotfire.toml", tmp_path / "smooth.fmu", friction="coulomb-smooth").path
    model = load_model(MODELS / "rs25_hotfire.toml", friction="coulomb-smooth")
    md = fmpy.read_model_description(str(path))
    dtv = next(v for v in md.modelVariables if v.name == "internal_step_s")
    dtmax = float(dtv.max)
    law, J = model.friction, min(model.engine.inertia("pitch"), model.engine.inertia("yaw"))
    limit = 2.0 * law.regularization_velocity_rad_s * J / law.coulomb_torque_Nm   # the rule's largest step
    res = fmpy.simulate_fmu(str(path), stop_time=0.05, step_size=1e-3, output_interval=1e-3,
                            start_values={"internal_step_s": 1e-4, "pitch_command_rad": 0.4 * DEG})
    b = TvcBlock(model, dt_s=1e-4)
    b.reset(0.4 * DEG, 0.0)
    want = [b.outputs.pitch_engine_rad] + [b.step(1e-3, 0.4 * DEG, 0.0).pitch_engine_rad for _ in range(50)]
    assert np.max(np.abs(res["pitch_engine_rad"] - want)) <= 1e-6 * DEG
    s, vr = _slave(path, tmp_path, "s")
    s.setupExperiment(startTime=0.0)
    s.enterInitializationMode()
    bad = [1.01 * dtmax, -1e-4]
    if limit < dtmax:
        bad.append(1.01 * limit)
        with pytest.raises(InputError):
            law.check_step(J, 1.01 * limit, "t")
    for v in bad:
        with pytest.raises(FMICallException):
            s.setReal([vr["internal_step_s"]], [v])
    s.setReal([vr["internal_step_s"]], [2e-4])
    s.exitInitializationMode()
    with pytest.raises(FMICallException):
        s.setReal([vr["internal_step_s"]], [1e-4])
    tc = 2.0 * law.regularization_velocity_rad_s * J / 2e-4      # T_c at which 2e-4 s breaks the rule
    with pytest.raises(FMICallException):
        s.setReal([vr["friction_coulomb_torque_Nm"]], [1.01 * tc])
    s.setReal([vr["friction_coulomb_torque_Nm"]], [0.99 * tc])
    s.doStep(0.0, 2e-4)
    s.terminate()
    s.freeInstance()


def test_vehicle_outputs_are_the_thrust_along_the_engine_and_its_moment(cfmu, hotfire, tmp_path):
    """``vehicle_force_*`` = T d (the thrust input times the thrust direction) and
    ``vehicle_moment_*`` = (l F_y, -l F_x, 0) about a point l ahead of the gimbal; the thrust
    input changes them from the next step and nothing else."""
    s, vr = _slave(cfmu, tmp_path)
    _start(s, vr, [("pitch_command_rad", 0.5 * DEG), ("yaw_command_rad", -0.3 * DEG), ("vehicle_moment_arm_m", 25.0)])
    names = ["thrust_direction_x", "thrust_direction_y", "thrust_direction_z", "vehicle_force_x_N",
             "vehicle_force_y_N", "vehicle_force_z_N", "vehicle_moment_x_Nm", "vehicle_moment_y_Nm",
             "vehicle_moment_z_Nm", "pitch_engine_rad"]
    t = 0.0
    for T in (hotfire.engine.thrust_N, 0.5 * hotfire.engine.thrust_N):
        s.setReal([vr["thrust_N"]], [T])
        for _ in range(100):
            s.doStep(t, 1e-3)
            t += 1e-3
        d = dict(zip(names, s.getReal([vr[n] for n in names])))
        F = [T * d[f"thrust_direction_{c}"] for c in "xyz"]
        assert [d[f"vehicle_force_{c}_N"] for c in "xyz"] == pytest.approx(F, rel=1e-15)
        assert [d[f"vehicle_moment_{c}_Nm"] for c in "xyz"] == pytest.approx([25.0 * F[1], -25.0 * F[0], 0.0], rel=1e-15)
        assert d["thrust_direction_x"] > 0 and d["pitch_engine_rad"] > 0
    with pytest.raises(FMICallException):
        s.setReal([vr["thrust_N"]], [-1.0])
    s.terminate()
    s.freeInstance()
