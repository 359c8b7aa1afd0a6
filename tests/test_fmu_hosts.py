"""The default (standalone C) FMU of ``taos fmu`` in real hosts (issue 41 points 2 and 5): FMPy's
``simulate_fmu`` with the host steps that ended the former pythonfmu FMU's runs early (an
output interval of 3e-4 s, an input step at 0.1003 s), the standard's discard (fmi2Discard with
fmi2Terminated true only when the FMU cannot go on, false otherwise), and libcosimpy (the Open
Simulation Platform's co-simulation library) chaining two instances, checked against FMPy
runs of the same FMU (an independent importer).

FMPy's messages are read from its own logger's output (``capsys``), never through
``simulate_fmu(logger=...)``: FMPy 0.3.32's native logger proxy keeps the last such callback in a
process-wide variable after the call returns, and a later FMU's log message in the same process
then calls the freed callback (a segmentation fault, found here with gdb: ``logMessage`` in
fmpy/logging/linux64/logging.so)."""

from __future__ import annotations

import math
import shutil
import sys

import numpy as np
import pytest

fmpy = pytest.importorskip("fmpy")

from fmpy.fmi1 import FMICallException  # noqa: E402
from fmpy.fmi2 import FMU2Slave, fmi2LastSuccessfulTime, fmi2Terminated  # noqa: E402

from taos.cosim._standalone import build_standalone_fmu  # noqa: E402

from .conftest import MODELS  # noqa: E402

DEG = math.pi / 180
CC = shutil.which("cc") or shutil.which("gcc")
pytestmark = pytest.mark.skipif(CC is None or not sys.platform.startswith("linux"), reason="needs a C compiler on Linux")
INPUT = np.dtype([("time", float), ("pitch_command_rad", float), ("yaw_command_rad", float), ("thrust_N", float)])


@pytest.fixture(scope="module")
def cfmu(tmp_path_factory):
    return str(build_standalone_fmu(MODELS / "rs25_hotfire.toml", tmp_path_factory.mktemp("hosts") / "tvc.fmu").path)


@pytest.fixture(scope="module")
def vr(cfmu):
    return {v.name: v.valueReference for v in fmpy.read_model_description(cfmu).modelVariables}


def _slave(cfmu, tmp_path, name="tvc"):
    md = fmpy.read_model_description(cfmu)
    s = FMU2Slave(guid=md.guid, unzipDirectory=fmpy.extract(cfmu, str(tmp_path / name)),
                  modelIdentifier=md.coSimulation.modelIdentifier, instanceName=name)
    s.instantiate()
    return s


def test_fmpy_host_steps_that_ended_runs_early_now_refuse_clearly_or_run_to_the_end(cfmu, capsys):
    """An input step at 0.1003 s (FMPy steps to it: a 3e-4 s communication step) and an output
    interval of 3e-4 s, at the build's 2e-4 s internal step: FMPy raises fmi2Error with the
    FMU's one log line naming ``internal_step_s`` (never a silent early end). With
    ``internal_step_s`` = 1e-4 s (a fixed parameter, set before initialisation) both runs reach
    1 s, and, the command being exact at every communication point, they agree bit for bit at
    their common points."""
    sig = np.array([(0.0, 0.0, 0.0, 2e6), (0.1003, 0.0, 0.0, 2e6), (0.1003, 0.3 * DEG, 0.0, 2e6),
                    (1.0, 0.3 * DEG, 0.0, 2e6)], dtype=INPUT)
    for interval in (3e-4, 2e-3):
        capsys.readouterr()
        with pytest.raises(FMICallException) as e:
            fmpy.simulate_fmu(cfmu, stop_time=1.0, input=sig, output_interval=interval)
        msgs = [m for m in capsys.readouterr().out.splitlines() if m.startswith("[ERROR]")]   # FMPy's own logger
        assert e.value.status == 3 and len(msgs) == 1 and "internal_step_s" in msgs[0] and "0.0003" in msgs[0], msgs
    runs = {iv: fmpy.simulate_fmu(cfmu, stop_time=1.0, input=sig, output_interval=iv,
                                  start_values={"internal_step_s": 1e-4}) for iv in (3e-4, 2e-3)}
    for r in runs.values():
        assert r["time"][-1] == pytest.approx(1.0, abs=1e-12)
        assert abs(r["pitch_engine_rad"][-1]) > 0.2 * DEG   # the step reached the engine
    a, b = runs[3e-4], runs[2e-3]
    common = [t for t in np.round(b["time"], 9) if abs(t / 6e-3 - round(t / 6e-3)) < 1e-6 or abs(t - 1.0) < 1e-9]
    ia = [int(np.argmin(np.abs(a["time"] - t))) for t in common]
    ib = [int(np.argmin(np.abs(b["time"] - t))) for t in common]
    assert len(common) > 100
    assert np.array_equal(a["pitch_engine_rad"][ia], b["pitch_engine_rad"][ib])


def test_discard_reports_terminated_only_when_the_fmu_cannot_go_on(cfmu, vr, tmp_path, capsys):
    """fmi2Terminated is false through good steps (the former pythonfmu FMU said true at all
    times). A step whose state becomes non-finite (a bristle stiffness of 1e11 N m/rad, a
    tunable level, makes the 0.2 ms explicit step unstable) is fmi2Discard: the FMU stays at
    the step's start (fmi2LastSuccessfulTime, the outputs unchanged) and reports
    fmi2Terminated true, as it cannot go on; a further step is fmi2Error; restoring an FMU
    state taken before (and the good parameter) lets it run on. FMPy ends such a run at the
    last successful time with the discard logged, not silently."""
    s = _slave(cfmu, tmp_path)
    s.setupExperiment(startTime=0.0)
    s.enterInitializationMode()
    s.exitInitializationMode()
    s.setReal([vr["pitch_command_rad"]], [0.3 * DEG])
    for k in range(3):
        s.doStep(k * 2e-3, 2e-3)
        assert s.getBooleanStatus(fmi2Terminated) is False
    good = s.getFMUstate()
    before = s.getReal([vr["pitch_engine_rad"]])
    sigma0 = s.getReal([vr["friction_bristle_stiffness_Nm_per_rad"]])
    s.setReal([vr["friction_bristle_stiffness_Nm_per_rad"]], [1e11])
    with pytest.raises(FMICallException) as e:
        s.doStep(6e-3, 2e-3)
    assert e.value.status == 2   # fmi2Discard
    assert s.getBooleanStatus(fmi2Terminated) is True
    assert s.getRealStatus(fmi2LastSuccessfulTime) == pytest.approx(6e-3, abs=1e-15)
    assert s.getReal([vr["pitch_engine_rad"]]) == before
    with pytest.raises(FMICallException) as e:
        s.doStep(6e-3, 2e-3)
    assert e.value.status == 3
    s.setFMUstate(good)
    s.setReal([vr["friction_bristle_stiffness_Nm_per_rad"]], sigma0)
    assert s.getBooleanStatus(fmi2Terminated) is False
    s.doStep(6e-3, 2e-3)
    s.freeFMUstate(good)
    s.terminate()
    s.freeInstance()
    capsys.readouterr()
    r = fmpy.simulate_fmu(cfmu, stop_time=0.1, output_interval=2e-3,
                          start_values={"pitch_command_rad": 0.3 * DEG, "friction_bristle_stiffness_Nm_per_rad": 1e11})
    msgs = capsys.readouterr().out.splitlines()   # FMPy's own logger (not logger=: module docstring)
    assert r["time"][-1] < 0.1 and any(m.startswith("[DISCARD]") and "not finite" in m for m in msgs), msgs


#: libcosimpy run in a child process (libcosim's execution, its worker threads and its own FMI
#: library stay out of the test process; the child's exit status shows the run ended cleanly); args: JSON {"fmus": [[path, name], ...],
#: "initial": [[slave, vr, value], ...], "connect": [[a, vr_out, b, vr_in], ...], "observe": vr,
#: "h": step [s], "n": steps}; prints JSON [[sample steps, values] per slave]
_COSIM_CHILD = r"""
import json, sys
from libcosimpy.CosimEnums import CosimVariableType
from libcosimpy.CosimExecution import CosimExecution
from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
from libcosimpy.CosimObserver import CosimObserver
from libcosimpy.CosimSlave import CosimLocalSlave
a = json.loads(sys.argv[1])
log_output_level(CosimLogLevel.ERROR)
ns = int(round(a["h"] * 1e9))
ex = CosimExecution.from_step_size(step_size=ns)
idx = [ex.add_local_slave(CosimLocalSlave(fmu_path=p, instance_name=nm)) for p, nm in a["fmus"]]
for sl, vr, v in a["initial"]:
    ex.real_initial_value(idx[sl], vr, v)
for sa, vo, sb, vi in a["connect"]:
    assert ex.connect_real_variables(idx[sa], vo, idx[sb], vi) == 0   # libcosim: 0 = success
ts = CosimObserver.create_time_series()
ex.add_observer(ts)
for i in idx:
    ts.start_time_series(i, a["observe"], CosimVariableType.REAL)
assert ex.simulate_until(target_time=a["n"] * ns)
out = []
for i in idx:
    t, _, y = ts.time_series_real_samples(i, a["observe"], 0, a["n"] + 1)
    out.append([[round(x / ns) for x in t], list(y)])
print(json.dumps(out))
"""


def cosim_child(fmus, initial, connect, observe, h, n):
    """libcosimpy's fixed-step co-simulation of ``fmus`` in a child process (:data:`_COSIM_CHILD`):
    per slave (sample step numbers, values of ``observe``)."""
    import json
    import subprocess

    pytest.importorskip("libcosimpy")
    arg = json.dumps({"fmus": fmus, "initial": initial, "connect": connect, "observe": observe, "h": h, "n": n})
    r = subprocess.run([sys.executable, "-c", _COSIM_CHILD, arg], capture_output=True, text=True, timeout=600,
                       check=False)
    assert r.returncode == 0, r.stderr[-3000:]
    return [(np.array(k), np.array(y)) for k, y in json.loads(r.stdout.strip().splitlines()[-1])]


def test_libcosimpy_chains_two_instances_as_fmpy_runs_them(cfmu, vr, tmp_path):
    """libcosimpy (OSP libcosim, fixed 2 ms steps; in a child process): instance a holds a
    0.3 deg pitch command, instance b's pitch command is a's engine angle. a's engine angle
    equals an FMPy run of the same FMU; b's equals an FMPy run fed a's samples at the start of
    each step (libcosim's fixed-step transfer): both bit for bit at the 250 samples the observer
    keeps (0 to 0.498 s); the child exits 0 after libcosim frees the instances."""
    h, n = 2e-3, 250
    (ka, ya), (kb, yb) = cosim_child([[cfmu, "a"], [cfmu, "b"]], [[0, vr["pitch_command_rad"], 0.3 * DEG]],
                                     [[0, vr["pitch_engine_rad"], 1, vr["pitch_command_rad"]]], vr["pitch_engine_rad"],
                                     h, n)
    assert ka.size == kb.size == n and ka[-1] == kb[-1] == n - 1 and abs(ya[-1]) > 0.2 * DEG

    def fmpy_run(cmds, name):
        s = _slave(cfmu, tmp_path, name)
        s.setupExperiment(startTime=0.0)
        s.enterInitializationMode()
        s.setReal([vr["pitch_command_rad"]], [cmds[0]])
        s.exitInitializationMode()
        y = [s.getReal([vr["pitch_engine_rad"]])[0]]
        for k in range(n):
            s.setReal([vr["pitch_command_rad"]], [cmds[k]])
            s.doStep(k * h, h)
            y.append(s.getReal([vr["pitch_engine_rad"]])[0])
        s.terminate()
        s.freeInstance()
        return np.array(y)

    ra = fmpy_run([0.3 * DEG] * n, "ra")
    assert np.array_equal(ya, ra[ka])
    assert np.array_equal(yb, fmpy_run(list(ra[:n]), "rb")[kb])
