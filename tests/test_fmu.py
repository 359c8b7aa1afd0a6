"""``taos fmu``: the FMI 2.0 co-simulation FMU, checked by FMPy (an independent FMI importer).

FMPy validates the model description and runs the FMU as any host would (its own input
interpolation, communication loop and output recorder); the reference is ``taos simulate``'s
own run. Every FMPy run is a child process that ends with ``os._exit`` (:func:`fmpy_in_child`),
so the FMU's binary is never loaded into the test process itself (pythonfmu 0.7.0's binary
mishandles references; the FMU works around the two faults found, and one test runs several
instances in one host process that then exits normally). With ``command_hold = 1`` (ramp) the FMU reads the command FMPy sets at t_k as the end
point of the ramp over [t_k, t_k + h], i.e. ``taos simulate``'s linear interpolation one
communication step later: FMPy's row k + 1 is ``taos simulate``'s sample k, compared within the
acceptance's 1e-6 deg (achieved: bit for bit)."""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

fmpy = pytest.importorskip("fmpy")
pytest.importorskip("pythonfmu")

from fmpy.validation import validate_fmu  # noqa: E402

from taos.cosim import BlockOutputs, TvcBlock, build_fmu  # noqa: E402
from taos.planar.simulate import simulate  # noqa: E402
from taos.profiles import Step, TwoAxis, load_profile  # noqa: E402

from . import _forkserver  # noqa: E402
from .conftest import MODELS, run_cli  # noqa: E402

DEG = math.pi / 180
SIGNALS = ("engine_rad", "piston_m", "load_force_N", "load_pressure_Pa", "friction_torque_Nm")


@pytest.fixture(scope="module")
def simplex_fmu(tmp_path_factory):
    return build_fmu(MODELS / "rs25_hotfire.toml", tmp_path_factory.mktemp("fmu") / "tvc.fmu").path


_CHILD = """
import json, os, sys, time
import numpy as np
import fmpy
a = json.loads(sys.argv[1])
msgs = []
kw = dict(a["kw"])
if a.get("input"):
    kw["input"] = np.load(a["input"])
err = None
t0 = time.perf_counter()
try:
    res = fmpy.simulate_fmu(a["fmu"], logger=lambda e, i, st, c, m: msgs.append((st, m.decode())), debug_logging=True,
                            **kw)
    np.save(a["out"], res)
except Exception as e:
    err = str(e)
el = time.perf_counter() - t0
with open(a["out"] + ".json", "w") as f:
    json.dump({"messages": msgs, "error": err, "elapsed_s": el}, f)
sys.stdout.flush()
os._exit(0)
"""


def fmpy_in_child(path, workdir, inputs=None, **kw):
    """``fmpy.simulate_fmu(path, **kw)`` in a child Python (ended with ``os._exit``; forked from the
    test process's fork server, :mod:`tests._forkserver`, as ``python -c``); ``inputs`` an FMPy
    input array. Returns (result array or None, log messages [(status, text)], the
    error text or None, the simulation's wall time [s])."""
    workdir = Path(workdir)
    n = len(list(workdir.glob("run*.npy.json")))
    out = workdir / f"run{n}.npy"
    arg = {"fmu": str(path), "kw": kw, "out": str(out)}
    if inputs is not None:
        np.save(workdir / f"in{n}.npy", inputs)
        arg["input"] = str(workdir / f"in{n}.npy")
    r = _forkserver.run([sys.executable, "-c", _CHILD, json.dumps(arg)], workdir, timeout=3600)
    meta_file = Path(str(out) + ".json")
    assert meta_file.exists(), r.stderr[-2000:]
    meta = json.loads(meta_file.read_text())
    res = np.load(out) if out.exists() else None
    return res, [tuple(m) for m in meta["messages"]], meta["error"], meta["elapsed_s"]


def profile_input(prof, dt: float, duration_s: float) -> np.ndarray:
    """The profile's samples every ``dt`` as an FMPy input array."""
    t = np.arange(int(round(duration_s / dt)) + 1) * dt
    c = np.atleast_2d(prof(t))
    sig = np.zeros(t.size, dtype=[("time", float), ("pitch_command_rad", float), ("yaw_command_rad", float)])
    sig["time"], sig["pitch_command_rad"], sig["yaw_command_rad"] = t, c[0], c[1] if c.shape[0] > 1 else 0.0
    return sig


def fmpy_run(path, workdir, prof, dt: float, duration_s: float, **start):
    """FMPy's co-simulation of the FMU driven by the profile's samples every ``dt`` (ramp);
    returns (result, messages, error)."""
    sig = profile_input(prof, dt, duration_s)
    res, msgs, err, _ = fmpy_in_child(path, workdir, sig, stop_time=float(sig["time"][-1]), step_size=dt,
                                      output_interval=dt, start_values={"command_hold": 1, **start})
    return res, msgs, err


def worst_difference_deg(res, th) -> float:
    """Largest |FMU - taos simulate| engine angle [deg] (FMU row k + 1 against sample k), after
    checking that every other recorded signal is equal too."""
    n = th.t_s.size
    assert res.size >= n + 1
    worst = 0.0
    for i, ax in enumerate(th.axes):
        for name in SIGNALS:
            d = np.max(np.abs(res[f"{ax}_{name}"][1:n + 1] - getattr(th, name)[i]))
            if name == "engine_rad":
                worst = max(worst, math.degrees(d))
            else:
                assert d <= 1e-9 * max(1.0, np.max(np.abs(getattr(th, name)[i])))
    return worst


def two_axis_step():
    return TwoAxis(Step(0.4 * DEG, 0.05, 0.5), Step(-0.3 * DEG, 0.1, 0.45), name="two-axis step")


def test_fmpy_validates_the_fmu_and_its_interface(simplex_fmu, hotfire):
    """No problem from FMPy's validation (schema, names, structure, start values, units); the
    inputs and outputs the issue names, the model's values as parameters in SI with their units,
    and the model hash in the description."""
    assert validate_fmu(str(simplex_fmu)) == []
    md = fmpy.read_model_description(str(simplex_fmu))
    var = {v.name: v for v in md.modelVariables}
    assert {n for n, v in var.items() if v.causality == "input"} == {"pitch_command_rad", "yaw_command_rad"}
    assert [n for n, v in var.items() if v.causality == "output"] == list(BlockOutputs.signal_names())
    assert var["pitch_load_pressure_Pa"].unit == "Pa" and var["yaw_engine_rate_rad_s"].unit == "rad/s"
    k = var["structure.load_stiffness_N_per_m"]
    assert k.causality == "parameter" and k.variability == "fixed" and k.unit == "N/m"
    assert float(k.start) == hotfire.structure.load_stiffness_N_per_m
    assert float(var["actuator.supply_pressure_Pa"].start) == hotfire.actuator.supply_pressure_Pa
    assert hotfire.sha256 in md.description
    assert {u.name for u in md.unitDefinitions} >= {"rad", "N/m", "Pa", "m3/(s.Pa)"}


@pytest.mark.parametrize("which, duration_s", [("step", 0.6), ("greenrun", 2.0)])
def test_fmpy_run_matches_taos_simulate(simplex_fmu, hotfire, tmp_path, which, duration_s):
    """FMPy's run of the FMU at the kernel's step is ``taos simulate`` (simplex) within 1e-6 deg
    (achieved 0): a step on each axis and the start of the two-axis Green Run (the whole profile:
    the slow test below)."""
    prof = two_axis_step() if which == "step" else load_profile("greenrun_two_axis")
    dt = 2e-4
    th = simulate(hotfire, prof, dt_s=dt, record_every=1, duration_s=duration_s)
    res, _, err = fmpy_run(simplex_fmu, tmp_path, prof, dt, duration_s + dt)
    assert err is None
    assert worst_difference_deg(res, th) <= 1e-6


@pytest.mark.slow
def test_fmpy_whole_greenrun_matches_taos_simulate(simplex_fmu, hotfire, tmp_path):
    """The whole two-axis Green Run profile (32 s, 160,001 FMU steps of 0.2 ms) through FMPy: within 1e-6 deg."""
    prof = load_profile("greenrun_two_axis")
    dt = 2e-4
    th = simulate(hotfire, prof, dt_s=dt, record_every=1)
    res, _, err = fmpy_run(simplex_fmu, tmp_path, prof, dt, th.t_s[-1] + dt)
    assert err is None
    d = worst_difference_deg(res, th)
    print(f"whole Green Run through FMPy: worst engine-angle difference {d:.3g} deg")
    assert d <= 1e-6


@pytest.mark.slow
def test_taos3d_fmu_matches_taos_simulate(tmp_path, hotfire):
    """The 3-D engine's FMU (``--engine taos``) through FMPy against ``taos simulate --engine
    taos``: a two-axis step and the first 3 s of the Green Run, within 1e-6 deg."""
    from taos.taos3d import simulate_taos, taos_model

    path = build_fmu(MODELS / "rs25_hotfire.toml", tmp_path / "tvc3d.fmu", engine="taos").path
    assert validate_fmu(str(path)) == []
    tm = taos_model(hotfire)
    dt = 4e-4
    for prof, T in ((two_axis_step(), 0.6), (load_profile("greenrun_two_axis"), 3.0)):
        th = simulate_taos(tm, prof, dt_s=dt, record_every=1, duration_s=T)
        res, _, err = fmpy_run(path, tmp_path, prof, dt, T + dt)
        assert err is None and worst_difference_deg(res, th) <= 1e-6


def test_parameters_set_in_fmpy_reach_the_block(simplex_fmu, hotfire, tmp_path):
    """A changed parameter (load stiffness halved, 10 internal steps per communication step, hold)
    gives the block of the changed model: FMPy's run equals the Python block's, bit for bit."""
    import dataclasses

    k = 0.5 * hotfire.structure.load_stiffness_N_per_m
    res, _, err, _ = fmpy_in_child(simplex_fmu, tmp_path, stop_time=0.2, step_size=2e-3, output_interval=2e-3,
                                   start_values={"structure.load_stiffness_N_per_m": k, "pitch_command_rad": 0.3 * DEG})
    assert err is None
    b = TvcBlock(hotfire.replace(structure=dataclasses.replace(hotfire.structure, load_stiffness_N_per_m=k)))
    b.reset(0.3 * DEG, 0.0)
    ref = [b.outputs.pitch_engine_rad] + [b.step(2e-3, 0.3 * DEG, 0.0).pitch_engine_rad for _ in range(100)]
    assert np.array_equal(res["pitch_engine_rad"], ref)


@pytest.mark.parametrize("case", ["nan", "range", "step"])
def test_bad_run_time_input_is_a_logged_discarded_step_not_a_crash(simplex_fmu, tmp_path, case):
    """A NaN or out-of-range command or a communication step that is no multiple of the internal
    step: fmi2DoStep is refused (fmi2Discard, the block stays at the last good point, FMPy stops
    there) with one error-status log line naming the value."""
    if case == "step":
        res, msgs, err, _ = fmpy_in_child(simplex_fmu, tmp_path, stop_time=0.01, step_size=3e-4, output_interval=3e-4)
        want = "whole multiple of the internal step"
    else:
        bad = float("nan") if case == "nan" else 12 * DEG
        prof = TwoAxis(Step(bad, 0.01, 0.1), Step(0.0, 0.0, 0.1))
        res, msgs, err = fmpy_run(simplex_fmu, tmp_path, prof, 2e-4, 0.05)
        want = "pitch_command_rad: expected a command within the gimbal range"
    assert err is None   # FMPy stops at the discarded step and returns what it has
    assert res["time"][-1] < 0.011
    assert np.all(np.isfinite(res["pitch_engine_rad"]))
    errors = [m for st, m in msgs if st == 3]
    assert len(errors) == 1 and want in errors[0]


def test_bad_parameter_is_refused_at_initialisation(simplex_fmu, tmp_path):
    """A refused parameter: fmi2ExitInitializationMode fails (fatal: pythonfmu's status for a
    Python exception) with one error-status log line naming the parameter and the value."""
    res, msgs, err, _ = fmpy_in_child(simplex_fmu, tmp_path, stop_time=0.01, step_size=2e-4,
                                      start_values={"actuator.piston_area_m2": -1.0})
    assert res is None and "fmi2ExitInitializationMode" in err
    assert any(st == 3 and "actuator.piston_area_m2: expected a finite positive value" in m for st, m in msgs)


def test_cli_builds_and_refuses_bad_input_without_writing(tmp_path):
    """``taos fmu --python`` (the pythonfmu route): exit 0 and a valid FMU; a bad model, a bad --out, an impossible --dt, an
    existing file it did not write at --out: exit 2, one line, no file written or replaced; its
    own FMU is replaced."""
    ok = run_cli("fmu", MODELS / "rs25_ambient.toml", "--out", tmp_path / "a.fmu", "--python", "--friction", "dahl",
                 "--avionics", "bounding")
    assert ok.returncode == 0, ok.stderr
    md = fmpy.read_model_description(str(tmp_path / "a.fmu"))
    assert "friction dahl" in md.description and "avionics bounding" in md.description
    bad = tmp_path / "bad.toml"
    bad.write_text((MODELS / "rs25_ambient.toml").read_text().replace('"115000 lbf/in"', '"-5 lbf/in"'))
    keep = tmp_path / "keep.fmu"
    keep.write_bytes(b"not mine")
    for args in ([bad, "--out", keep], [MODELS / "rs25_ambient.toml", "--out", tmp_path / "x.zip"],
                 [MODELS / "rs25_ambient.toml", "--out", tmp_path / "y.fmu", "--dt", "0.01"]):
        r = run_cli("fmu", *args, "--python")
        assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1, r.stderr
    r = run_cli("fmu", MODELS / "rs25_ambient.toml", "--out", keep, "--python")   # a good model, a foreign file
    assert r.returncode == 2 and "did not write" in r.stderr
    assert keep.read_bytes() == b"not mine"
    again = run_cli("fmu", MODELS / "rs25_ambient.toml", "--out", tmp_path / "a.fmu", "--python")   # its own FMU: replaced
    assert again.returncode == 0, again.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == [".taos-output.json", "a.fmu", "bad.toml", "keep.fmu"]


def test_a_tampered_model_copy_is_refused_at_instantiation(simplex_fmu, tmp_path):
    """The FMU checks its model copy against the SHA-256 it was built from: a changed byte in
    the copied model file (a comment) and the FMU refuses to start, naming the hash."""
    import zipfile

    bad = tmp_path / "tampered.fmu"
    with zipfile.ZipFile(simplex_fmu) as zin, zipfile.ZipFile(bad, "w") as zout:
        for item in zin.infolist():
            data = zin.read(item.filename)
            if item.filename.endswith("models/rs25_hotfire.toml"):
                data += b"\n# edited after the build\n"
            zout.writestr(item, data)
    res, msgs, err, _ = fmpy_in_child(bad, tmp_path, stop_time=0.01, step_size=2e-4)
    assert res is None and "instantiate" in err
    assert any("model_sha256" in m and "files changed" in m for _, m in msgs)


_C_HOST = r"""
/* A minimal FMI 2.0 co-simulation master with no Python of its own: pitch command held at
   argv[4] rad for argv[5] steps of argv[6] s; prints the pitch engine angle. */
#include <dlfcn.h>
#include <stdio.h>
#include <stdlib.h>
#include <unistd.h>
typedef void *C;
typedef struct {
  void (*logger)(void *, const char *, int, const char *, const char *, ...);
  void *(*alloc)(size_t, size_t); void (*freeMemory)(void *); void *stepFinished; void *env;
} CB;
static void lg(void *e, const char *i, int s, const char *c, const char *m, ...) { printf("LOG %d %s\n", s, m); }
int main(int argc, char **argv) {
  void *lib = dlopen(argv[1], RTLD_NOW | RTLD_LOCAL);
  if (!lib) { printf("dlopen: %s\n", dlerror()); return 1; }
  C (*inst)(const char *, int, const char *, const char *, const CB *, int, int) = dlsym(lib, "fmi2Instantiate");
  int (*setup)(C, int, double, double, int, double) = dlsym(lib, "fmi2SetupExperiment");
  int (*enter)(C) = dlsym(lib, "fmi2EnterInitializationMode");
  int (*leave)(C) = dlsym(lib, "fmi2ExitInitializationMode");
  int (*setr)(C, const unsigned *, size_t, const double *) = dlsym(lib, "fmi2SetReal");
  int (*getr)(C, const unsigned *, size_t, double *) = dlsym(lib, "fmi2GetReal");
  int (*step)(C, double, double, int) = dlsym(lib, "fmi2DoStep");
  CB cb = {lg, calloc, free, NULL, NULL};
  C c = inst("tvc", 1, argv[3], argv[2], &cb, 0, 1);
  if (!c) { printf("instantiate failed\n"); fflush(stdout); _exit(2); }
  unsigned vin = 0, vout = 2;
  double cmd = atof(argv[4]), h = atof(argv[6]), th = 0.0;
  int n = atoi(argv[5]);
  if (setup(c, 0, 0.0, 0.0, 0, 0.0) || enter(c) || setr(c, &vin, 1, &cmd) || leave(c)) { printf("init failed\n"); fflush(stdout); _exit(3); }
  for (int k = 0; k < n; k++) if (step(c, k * h, h, 1)) { printf("step %d failed\n", k); fflush(stdout); _exit(4); }
  getr(c, &vout, 1, &th);
  printf("pitch_engine_rad %.17g\n", th);
  fflush(stdout);
  _exit(0);
}
"""


def test_the_fmu_runs_in_a_host_without_python(simplex_fmu, tmp_path, hotfire):
    """A C co-simulation master (no Python of its own) runs the FMU given what the guide says
    it needs: libpython loaded (``LD_PRELOAD``), ``PYTHONHOME`` the Python's installation and
    ``TAOS_FMU_SITE_PACKAGES`` the site-packages of the environment with taos (this test's own
    environment, an editable install: its .pth files must be processed); the engine angle after 0.5 s of a held
    0.4 deg command equals the Python block's bit for bit. Skipped without a C compiler or a
    shared libpython."""
    import os
    import shutil
    import site
    import sysconfig
    import zipfile

    cc = shutil.which("cc") or shutil.which("gcc")
    libpython = Path(sysconfig.get_config_var("LIBDIR") or "") / (sysconfig.get_config_var("INSTSONAME") or "")
    if cc is None or not sys.platform.startswith("linux") or not libpython.is_file():
        pytest.skip("needs a C compiler and a shared libpython on Linux")
    (tmp_path / "host.c").write_text(_C_HOST)
    subprocess.run([cc, "-O1", "-o", str(tmp_path / "host"), str(tmp_path / "host.c"), "-ldl"], check=True)
    with zipfile.ZipFile(simplex_fmu) as z:
        z.extractall(tmp_path / "fmu")
    md = fmpy.read_model_description(str(simplex_fmu))
    vr = {v.name: v.valueReference for v in md.modelVariables}
    assert (vr["pitch_command_rad"], vr["pitch_engine_rad"]) == (0, 2)   # the host's value references
    env = {"PATH": "/usr/bin:/bin", "HOME": os.environ.get("HOME", "/tmp"), "LD_PRELOAD": str(libpython),
           "PYTHONHOME": sys.base_prefix, "TAOS_FMU_SITE_PACKAGES": os.pathsep.join(site.getsitepackages())}
    r = subprocess.run([str(tmp_path / "host"), str(tmp_path / "fmu" / "binaries" / "linux64" / "TaosTvc.so"),
                        (tmp_path / "fmu" / "resources").as_uri(), md.guid, repr(0.4 * DEG), "2500", "2e-4"],
                       capture_output=True, text=True, env=env, timeout=600)
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    got = float(r.stdout.split("pitch_engine_rad")[1])
    b = TvcBlock(hotfire)
    b.reset(0.4 * DEG, 0.0)
    for _ in range(2500):
        out = b.step(2e-4, 0.4 * DEG, 0.0)
    assert got == out.pitch_engine_rad


def test_one_host_process_runs_several_instances_and_exits_cleanly(simplex_fmu, tmp_path, hotfire):
    """Two instances at once (two engines), then a third after both were freed, in one FMPy
    process that then exits normally (status 0); each run equals the Python block's. pythonfmu
    0.7.0 released a reference to the entry script's globals at every instantiation (a second
    instance crashed or found no class: :func:`taos.cosim._slave.keep_alive`) and corrupted the
    heap when it deallocated a slave holding compiled kernels (about half of the exits aborted:
    :data:`taos.cosim._slave._ALIVE`). Without the first workaround this test fails every time,
    without the second in about half of its processes (three are run)."""
    script = f"""
import fmpy
from fmpy.simulation import instantiate_fmu
md = fmpy.read_model_description({str(simplex_fmu)!r})
unz = fmpy.extract({str(simplex_fmu)!r})
out = []
a = instantiate_fmu(unz, md, "CoSimulation")
b = instantiate_fmu(unz, md, "CoSimulation")
for inst, c in ((a, 0.004), (b, 0.002)):
    r = fmpy.simulate_fmu(unz, model_description=md, fmu_instance=inst, stop_time=0.02, step_size=2e-4,
                          start_values={{"pitch_command_rad": c}})
    out.append(r["pitch_engine_rad"][-1])
a.freeInstance()
b.freeInstance()
r = fmpy.simulate_fmu({str(simplex_fmu)!r}, stop_time=0.02, step_size=2e-4, start_values={{"pitch_command_rad": 0.004}})
out.append(r["pitch_engine_rad"][-1])
print("ENGINE", repr(out))
"""
    want = []
    for c in (0.004, 0.002, 0.004):
        blk = TvcBlock(hotfire)
        blk.reset(c, 0.0)
        want.append([blk.step(2e-4, c, 0.0) for _ in range(100)][-1].pitch_engine_rad)
    for _ in range(3):
        r = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=300)
        assert r.returncode == 0 and "ENGINE" in r.stdout, r.stdout[-1000:] + r.stderr[-1000:]
        assert eval(r.stdout.split("ENGINE", 1)[1]) == want
