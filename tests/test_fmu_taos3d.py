"""The standalone 3-D FMU (``taos fmu MODEL --engine taos``, issue 41 point 1): the TAOS model's
own run loop (:func:`taos.taos3d.dynamics._steps`) translated to C, checked against ``taos
simulate --engine taos`` over the Green Run, in FMPy (validation, declarations, FMU state, host
mistakes), for its dynamic dependencies (``readelf -d``: no Python), in a C master through the
whole life cycle, and chained with the planar FMU in libcosimpy."""

from __future__ import annotations

import math
import shutil
import subprocess
import sys
import zipfile

import numpy as np
import pytest

fmpy = pytest.importorskip("fmpy")

from fmpy.fmi1 import FMICallException  # noqa: E402
from fmpy.fmi2 import FMU2Slave  # noqa: E402
from fmpy.validation import validate_fmu  # noqa: E402

from taos.cosim._standalone3d import OUTPUTS, build_standalone_fmu_3d  # noqa: E402
from taos.profiles import load_profile  # noqa: E402

from .conftest import MODELS, run_cli  # noqa: E402
from .test_fmu_standalone import _C_MASTER  # noqa: E402

DEG = math.pi / 180
CC = shutil.which("cc") or shutil.which("gcc")
pytestmark = pytest.mark.skipif(CC is None or not sys.platform.startswith("linux"), reason="needs a C compiler on Linux")


@pytest.fixture(scope="module")
def fmu3(tmp_path_factory):
    return str(build_standalone_fmu_3d(MODELS / "rs25_hotfire.toml", tmp_path_factory.mktemp("f3") / "t3.fmu").path)


@pytest.fixture(scope="module")
def md3(fmu3):
    return fmpy.read_model_description(fmu3)


@pytest.fixture(scope="module")
def tm(hotfire):
    from taos.taos3d import taos_model

    return taos_model(hotfire)


def _slave(path, tmp_path, name):
    md = fmpy.read_model_description(path)
    s = FMU2Slave(guid=md.guid, unzipDirectory=fmpy.extract(path, str(tmp_path / name)),
                  modelIdentifier=md.coSimulation.modelIdentifier, instanceName=name)
    s.instantiate()
    s.setupExperiment(startTime=0.0)
    return s, {v.name: v.valueReference for v in md.modelVariables}


def test_fmpy_validates_it_and_it_declares_what_it_does(fmu3, md3):
    """FMPy finds nothing; FMU state implemented and declared, no directional derivatives; every
    variable described; the outputs (engine angles, pistons, load forces and pressures, friction
    torques, post-avionics commands, bearing slips) with no direct feedthrough; the internal
    step the one (fixed) parameter; the source FMU layout."""
    assert validate_fmu(fmu3) == []
    cs = md3.coSimulation
    assert cs.canGetAndSetFMUstate and cs.canSerializeFMUstate and not cs.providesDirectionalDerivative
    assert all(v.description for v in md3.modelVariables)
    assert [v.name for v in md3.modelVariables if v.causality == "output"] == [o[0] for o in OUTPUTS]
    assert all(u.dependencies == [] for u in md3.outputs)
    assert {v.name: v.variability for v in md3.modelVariables if v.causality == "parameter"} == {
        "internal_step_s": "fixed"}
    with zipfile.ZipFile(fmu3) as z:
        names = set(z.namelist())
    assert {"sources/taos_kernels.c", "sources/taos_model.h", "sources/fmi2_glue3d.c", "sources/buildDescription.xml",
            f"binaries/linux64/{cs.modelIdentifier}.so"} <= names
    assert not any(n.endswith(".py") for n in names)


def test_the_binary_needs_no_python(fmu3, md3, tmp_path):
    """``readelf -d``: the 3-D FMU's library needs libc and libm only."""
    readelf = shutil.which("readelf")
    if readelf is None:
        pytest.skip("needs readelf")
    with zipfile.ZipFile(fmu3) as z:
        z.extractall(tmp_path)
    so = tmp_path / "binaries" / "linux64" / f"{md3.coSimulation.modelIdentifier}.so"
    dyn = subprocess.run([readelf, "-d", str(so)], capture_output=True, text=True, check=True).stdout
    needed = sorted(line.split("[")[1].split("]")[0] for line in dyn.splitlines() if "(NEEDED)" in line)
    assert needed == ["libc.so.6", "libm.so.6"], needed
    assert "python" not in dyn.lower()


def test_greenrun_equals_taos_simulate_engine_taos(fmu3, tm, tmp_path):
    """The whole two-axis Green Run (its 32 s profile plus 1 s, as ``taos simulate``) at the
    FMU's 0.4 ms internal step, the host setting the profile's sample at the step's end before
    each step: the engine angles equal ``simulate_taos`` (numba, fast-math) to 1e-12 deg, the
    pistons to 1e-12 of their range (measured: 4e-15 deg; the C has no fast-math
    reassociation, so the two differ at the rounding level only)."""
    from taos.taos3d.simulate import simulate_taos

    prof = load_profile(MODELS / "profiles" / "greenrun_two_axis.toml")
    dt = 4e-4
    ref = simulate_taos(tm, prof, dt_s=dt, record_every=1)
    cmd = ref.command_rad
    s, vr = _slave(fmu3, tmp_path, "g")
    s.enterInitializationMode()
    s.setReal([vr["pitch_command_rad"], vr["yaw_command_rad"]], list(cmd[:, 0]))
    s.exitInitializationMode()
    names = ["pitch_engine_rad", "yaw_engine_rad", "pitch_piston_m", "yaw_piston_m"]
    outs = [vr[n] for n in names]
    got = np.empty((cmd.shape[1], 4))
    got[0] = s.getReal(outs)
    for k in range(cmd.shape[1] - 1):
        s.setReal([0, 1], [cmd[0, k + 1], cmd[1, k + 1]])
        s.doStep(k * dt, dt)
        got[k + 1] = s.getReal(outs)
    s.terminate()
    s.freeInstance()
    assert ref.t_s[-1] == pytest.approx(33.0)
    assert np.max(np.abs(got[:, :2] - ref.engine_rad.T)) <= 1e-12 * DEG
    assert np.max(np.abs(got[:, 2:] - ref.piston_m.T)) <= 1e-12 * np.max(np.abs(ref.piston_m))
    assert np.max(np.abs(ref.engine_rad)) > 0.3 * DEG


def test_exact_at_multiples_of_the_internal_step_and_state_restore(fmu3, tm, tmp_path):
    """At 2 ms host steps (5 internal steps) a held pitch/yaw command equals taos simulate's run
    of the same samples (the command in force before each point, then the new one) to 1e-12
    deg; an FMU state saved at 0.1 s and restored (also through serialisation) repeats the run."""
    from taos.taos3d import dynamics as dy
    from taos.taos3d.simulate import run_samples

    dt, n, m = 4e-4, 5, 100
    cmds = np.array([[0.3 * DEG * math.sin(0.2 * j), -0.2 * DEG * math.cos(0.1 * j)] for j in range(m)])
    samples = np.zeros((n * m + 1, 2))
    for j in range(m):
        samples[j * n + 1:(j + 1) * n + 1] = cmds[j]
    ref = run_samples(tm, samples, dt, n)[:, [dy.REC.index("theta_pitch"), dy.REC.index("theta_yaw")]]
    s, vr = _slave(fmu3, tmp_path, "e")
    s.enterInitializationMode()
    s.exitInitializationMode()
    got, saved = [s.getReal([2, 3])], None
    for j in range(m):
        if j == 50:
            saved = s.serializeFMUstate(s.getFMUstate())
        s.setReal([0, 1], list(cmds[j]))
        s.doStep(j * n * dt, n * dt)
        got.append(s.getReal([2, 3]))
    assert np.max(np.abs(np.array(got) - ref)) <= 1e-12 * DEG
    s.setFMUstate(s.deSerializeFMUstate(saved))
    for j in range(50, m):
        s.setReal([0, 1], list(cmds[j]))
        s.doStep(j * n * dt, n * dt)
    assert s.getReal([2, 3]) == got[-1]
    s.terminate()
    s.freeInstance()


def test_full_range_reversals_at_the_pressure_limit_equal_taos_simulate(fmu3, tm, tmp_path):
    """A 5 Hz full-range square wave on both axes (pitch +-range, yaw opposite): the valves open
    wide against the engine's inertia and the load pressure passes the supply pressure (relief
    open), where the supply-pressure limit's rate (up to 3,946 1/s, tests/test_taos3d_stall.py)
    exceeds 1 / dt at the FMU's 0.4 ms internal step, so the C step takes its exponential branch
    for the load pressures (taos.taos3d.dynamics._etd_rk4) as the numba kernel does. 2 ms host
    steps against run_samples of the same samples (numba, fast-math): engine angles within
    5e-14 deg, load pressures within 2e-13 of the supply pressure (measured 9.1e-15 deg,
    4.4e-14 P_s: rounding, the C has no fast-math reassociation)."""
    from taos.taos3d import dynamics as dy
    from taos.taos3d._rhs import pressure_guard
    from taos.taos3d.simulate import pack, run_samples

    dt, n, m = 4e-4, 5, 300
    rng = tm.base.engine.gimbal_range_rad
    sq = np.where(np.sin(2 * np.pi * 5.0 * n * dt * np.arange(m)) >= 0.0, rng, -rng)
    cmds = np.stack([sq, -sq], axis=1)
    samples = np.zeros((n * m + 1, 2))
    for j in range(m):
        samples[j * n + 1:(j + 1) * n + 1] = cmds[j]
    cols = [dy.REC.index("theta_pitch"), dy.REC.index("theta_yaw"), dy.REC_PL, dy.REC_PL + 1]
    ref = run_samples(tm, samples, dt, n)[:, cols]
    s, vr = _slave(fmu3, tmp_path, "rev")
    s.enterInitializationMode()
    s.exitInitializationMode()
    outs = [vr[k] for k in ("pitch_engine_rad", "yaw_engine_rad", "pitch_load_pressure_Pa", "yaw_load_pressure_Pa")]
    got = [s.getReal(outs)]
    for j in range(m):
        s.setReal([0, 1], list(cmds[j]))
        s.doStep(j * n * dt, n * dt)
        got.append(s.getReal(outs))
    s.terminate()
    s.freeInstance()
    got = np.array(got)
    ps = tm.base.actuator.supply_pressure_Pa
    pk = pack(tm)
    x = np.zeros(pk.n_state)   # the guard acts from 1.02 P_s at full valve rate (its rate above 1 / dt)
    x[dy.N_BODY + pk.P.act_q_index] = tm.base.actuator.max_rate_m_per_s
    x[dy.N_BODY + pk.P.act_pl_index] = 1.02 * ps
    assert pressure_guard(x, dt, pk.P)[0] > 0.0
    assert np.abs(ref[:, 2:]).max() > 1.05 * ps   # measured 1.15 P_s
    assert np.max(np.abs(got[:, :2] - ref[:, :2])) <= 5e-14 * DEG
    assert np.max(np.abs(got[:, 2:] - ref[:, 2:])) <= 2e-13 * ps


def test_host_mistakes_are_errors_and_change_nothing(fmu3, tm, tmp_path):
    """A wrong communication point, a step not a multiple of the internal step, the internal
    step set after initialisation, a command beyond the gimbal range, an output set: fmi2Error,
    and the run goes on. Before initialisation the internal step can be set within (0, 1 ms]:
    at 1 ms a 1 ms host runs it, equal to taos simulate's kernel at 1 ms to 1e-12 deg."""
    from taos.taos3d import dynamics as dy
    from taos.taos3d.simulate import run_samples

    s, vr = _slave(fmu3, tmp_path, "m")
    s.enterInitializationMode()
    s.exitInitializationMode()
    s.setReal([0], [0.2 * DEG])
    s.doStep(0.0, 2e-3)
    before = s.getReal([2])
    for call in (lambda: s.doStep(0.5, 2e-3), lambda: s.doStep(2e-3, 3e-4), lambda: s.setReal([vr["internal_step_s"]],
                 [2e-4]), lambda: s.setReal([1], [30 * DEG]), lambda: s.setReal([2], [0.0])):
        with pytest.raises(FMICallException) as e:
            call()
        assert e.value.status == 3
    assert s.getReal([2]) == before
    s.doStep(2e-3, 2e-3)
    s.terminate()
    s.freeInstance()
    s, vr = _slave(fmu3, tmp_path, "ms")
    with pytest.raises(FMICallException):
        s.setReal([vr["internal_step_s"]], [2e-3])
    s.setReal([vr["internal_step_s"]], [1e-3])
    s.enterInitializationMode()
    s.exitInitializationMode()
    s.setReal([0], [0.2 * DEG])
    for k in range(200):
        s.doStep(k * 1e-3, 1e-3)
    samples = np.zeros((201, 2))
    samples[1:, 0] = 0.2 * DEG
    ref = run_samples(tm, samples, 1e-3, 200)[-1, dy.REC.index("theta_pitch")]
    assert abs(s.getReal([2])[0] - ref) <= 1e-12 * DEG and ref > 0.1 * DEG
    s.terminate()
    s.freeInstance()


def test_a_c_master_runs_the_whole_life_cycle_and_exits_cleanly(fmu3, md3, tmp_path):
    """The C master of tests/test_fmu_standalone.py (gcc, FMPy's headers): two instances, each
    through instantiate ... terminate and free, then dlclose and return from main (no _exit):
    exit 0, nothing on standard error, and the engine angle of an FMPy run of the same steps."""
    from taos.cosim._standalone import fmi_headers

    (tmp_path / "master.c").write_text(_C_MASTER)
    subprocess.run([CC, "-std=c99", "-O1", "-I", str(fmi_headers()), "-o", str(tmp_path / "master"),
                    str(tmp_path / "master.c"), "-ldl"], check=True)
    with zipfile.ZipFile(fmu3) as z:
        z.extractall(tmp_path / "fmu")
    so = tmp_path / "fmu" / "binaries" / "linux64" / f"{md3.coSimulation.modelIdentifier}.so"
    r = subprocess.run([str(tmp_path / "master"), str(so), (tmp_path / "fmu" / "resources").as_uri(), md3.guid,
                        repr(0.4 * DEG), "500", "2e-3"], capture_output=True, text=True, timeout=300,
                       env={"PATH": "/usr/bin:/bin"}, check=False)
    assert r.returncode == 0 and r.stderr == "", r.stdout[-2000:] + r.stderr[-2000:]
    got = float(r.stdout.split("pitch_engine_rad")[1])
    s, _ = _slave(fmu3, tmp_path, "c")
    s.enterInitializationMode()
    s.setReal([0], [0.4 * DEG])
    s.exitInitializationMode()
    for k in range(500):
        s.doStep(k * 2e-3, 2e-3)
    assert got == s.getReal([2])[0] and abs(got) > 0.3 * DEG
    s.terminate()
    s.freeInstance()


def test_cli_builds_the_3d_standalone_fmu(tmp_path):
    """``taos fmu MODEL --engine taos``: exit 0, the standalone 3-D FMU (no Python in it)."""
    r = run_cli("fmu", MODELS / "rs25_hotfire.toml", "--out", tmp_path / "t.fmu", "--engine", "taos")
    assert r.returncode == 0 and "no Python at run time" in r.stdout, r.stderr
    md = fmpy.read_model_description(str(tmp_path / "t.fmu"))
    assert md.coSimulation.modelIdentifier == "TaosTvc3dC" and "3-D TAOS model" in md.description


def test_libcosimpy_chains_the_planar_and_the_3d_fmu(fmu3, tmp_path):
    """libcosimpy (fixed 2 ms steps, in a child process: tests/test_fmu_hosts.cosim_child): the
    planar FMU holds a 0.3 deg pitch command, the 3-D FMU's pitch command is the planar engine
    angle. Each equals an FMPy run of the same FMU fed the same samples (libcosim's fixed-step
    transfer: the value at the step's start), bit for bit."""
    from taos.cosim._standalone import build_standalone_fmu

    from .test_fmu_hosts import cosim_child

    planar = str(build_standalone_fmu(MODELS / "rs25_hotfire.toml", tmp_path / "p.fmu").path)
    h, n = 2e-3, 150
    # value reference 0: pitch_command_rad, 2: pitch_engine_rad, in both FMUs
    (ka, ya), (kb, yb) = cosim_child([[planar, "planar"], [fmu3, "taos3d"]], [[0, 0, 0.3 * DEG]], [[0, 2, 1, 0]], 2,
                                     h, n)
    assert ka[-1] == kb[-1] == n - 1 and abs(yb[-1]) > 0.1 * DEG

    def fmpy_run(path, cmds, name):
        s, _ = _slave(path, tmp_path, name)
        s.enterInitializationMode()
        s.setReal([0], [cmds[0]])
        s.exitInitializationMode()
        y = [s.getReal([2])[0]]
        for k in range(n):
            s.setReal([0], [cmds[k]])
            s.doStep(k * h, h)
            y.append(s.getReal([2])[0])
        s.terminate()
        s.freeInstance()
        return np.array(y)

    ra = fmpy_run(planar, [0.3 * DEG] * n, "ra")
    assert np.array_equal(ya, ra[ka])
    assert np.array_equal(yb, fmpy_run(fmu3, list(ra[:n]), "rb")[kb])
