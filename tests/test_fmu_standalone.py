"""``taos fmu --standalone``: the FMI 2.0 co-simulation FMU in C, no Python at run time (issue 41).

Checked against ``taos simulate`` (the Green Run, to 1e-6 deg), against the Python kernels
themselves (the generated C's state derivative at random states, every built-in friction law),
in FMPy (validation, runs, FMU state, the statuses of host mistakes) and in a C master built
here with gcc that runs the whole life cycle and returns from ``main`` (no ``_exit``). The
FMU's library is loaded into this test process by FMPy (it holds no Python: nothing to guard)."""

from __future__ import annotations

import ctypes
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
from fmpy.model_description import read_build_description  # noqa: E402
from fmpy.validation import validate_fmu  # noqa: E402

from taos.cosim import BlockOutputs, TvcBlock  # noqa: E402
from taos.cosim._standalone import build_standalone_fmu, kernel_sources  # noqa: E402
from taos.planar.simulate import simulate  # noqa: E402
from taos.profiles import load_profile  # noqa: E402

from .conftest import MODELS, run_cli  # noqa: E402
from .test_fmu import profile_input  # noqa: E402

DEG = math.pi / 180
CC = shutil.which("cc") or shutil.which("gcc")
pytestmark = pytest.mark.skipif(CC is None or not sys.platform.startswith("linux"), reason="needs a C compiler on Linux")


@pytest.fixture(scope="module")
def cfmu(tmp_path_factory):
    return build_standalone_fmu(MODELS / "rs25_hotfire.toml", tmp_path_factory.mktemp("cfmu") / "tvc.fmu").path


@pytest.fixture(scope="module")
def md(cfmu):
    return fmpy.read_model_description(str(cfmu))


def test_fmpy_validates_it_and_it_declares_what_it_does(cfmu, md, hotfire):
    """FMPy's validation finds nothing; capabilities as implemented (FMU state and its
    serialisation yes, directional derivatives no); every variable described; outputs without
    direct feedthrough; the model hash and taos version in the description; the source FMU
    layout (sources listed, buildDescription.xml valid against FMI 3.0's schema)."""
    from taos.results import package_version

    assert validate_fmu(str(cfmu)) == []
    cs = md.coSimulation
    assert cs.canGetAndSetFMUstate and cs.canSerializeFMUstate and not cs.providesDirectionalDerivative
    assert not cs.needsExecutionTool and cs.canHandleVariableCommunicationStepSize
    assert all(v.description for v in md.modelVariables)
    from taos.cosim._standalone_params import VEHICLE_OUTPUTS
    assert [v.name for v in md.modelVariables if v.causality == "output"] == [*BlockOutputs.signal_names(),
                                                                              *VEHICLE_OUTPUTS]
    assert {v.name: v.variability for v in md.modelVariables if v.causality == "parameter"} == {
        "internal_step_s": "fixed", "load_stiffness_N_per_m": "fixed", "avionics_gain": "tunable",
        "vehicle_moment_arm_m": "tunable", "command_mode": "fixed",
        **{f"friction_{k}": "tunable" for k in ("coulomb_torque_Nm", "static_torque_Nm", "bristle_stiffness_Nm_per_rad",
                                                 "bristle_damping_Nms_per_rad", "viscous_damping_Nms_per_rad")}}
    assert all(u.dependencies == [] for u in md.outputs)
    assert hotfire.sha256 in md.description and package_version() in md.description
    assert sorted(md.buildConfigurations[0].sourceFileSets[0].sourceFiles) == ["fmi2_glue.c", "taos_kernels.c", "taos_params.c"]
    (bc,) = read_build_description(str(cfmu), validate=True)
    assert bc.modelIdentifier == cs.modelIdentifier
    with zipfile.ZipFile(cfmu) as z:
        names = set(z.namelist())
    assert {"sources/taos_kernels.c", "sources/taos_model.h", "sources/fmi2_glue.c", "sources/fmi2Functions.h",
            f"binaries/linux64/{cs.modelIdentifier}.so"} <= names


def test_the_binary_needs_no_python(cfmu, tmp_path):
    """``readelf -d``: the shared library needs libc and libm, nothing else (no libpython)."""
    readelf = shutil.which("readelf")
    if readelf is None:
        pytest.skip("no readelf")
    with zipfile.ZipFile(cfmu) as z:
        z.extractall(tmp_path)
    so = next((tmp_path / "binaries" / "linux64").glob("*.so"))
    dyn = subprocess.run([readelf, "-d", str(so)], capture_output=True, text=True, check=True).stdout
    needed = {line.split("[")[1].rstrip("]") for line in dyn.splitlines() if "(NEEDED)" in line}
    assert needed <= {"libc.so.6", "libm.so.6"}, needed
    assert "python" not in dyn.lower()


def _compile_kernels(model, tmp_path) -> ctypes.CDLL:
    src, head = kernel_sources(model)
    (tmp_path / "taos_kernels.c").write_text(src)
    (tmp_path / "taos_kernels.h").write_text(head)
    so = tmp_path / f"k_{model.friction.name}.so"
    subprocess.run([CC, "-std=c99", "-O2", "-fPIC", "-shared", str(tmp_path / "taos_kernels.c"), "-o", str(so), "-lm"],
                   check=True)
    return ctypes.CDLL(str(so))


class _Tup3(ctypes.Structure):
    _fields_ = [("v", ctypes.c_double * 3)]


@pytest.mark.parametrize("law", ["none", "coulomb-switching", "coulomb-smooth", "dahl", "lugre", "modified-lugre"])
def test_generated_derivative_equals_the_kernels(law, tmp_path):
    """The C emitted from the kernels gives the kernels' own state derivative, friction-state
    rate, friction torque and post-avionics command (taos.planar.dynamics._rates, compiled by
    numba) at 300 random states spread over twice the magnitudes of a full-range step, a third of
    them with the relative rate within +-2 v_eps (measured: hard stops in about 30 %, valve flow
    saturation in 90 %, the square-root law near stall in 25 %, relief in 45 %; the third near zero
    rate half inside the switching law's stick band), and at rest with no and with full-range commands (the gain table's
    two ends): within 1e-12 relative (the two compilers may contract multiply-adds differently)."""
    from taos.friction import ids
    from taos.friction._slots import SLOT_VEPS
    from taos.model import load_model
    from taos.planar import dynamics as dyn
    from taos.planar.simplex import simplex_plant
    from taos.planar.simulate import kernel_args

    assert law in ids()
    model = load_model(MODELS / "rs25_hotfire.toml", friction=law)
    lib = _compile_kernels(model, tmp_path)
    plant = simplex_plant(model, "pitch")
    pa = kernel_args(plant, model)
    n = pa.A.shape[0]
    fp, avp = model.friction.pack(), model.avionics.pack()
    # state magnitudes of a 9 deg step (the kernel recording y = x)
    r = np.full((1501, 1), 9 * DEG)
    y, aux = np.empty((1501, n)), np.empty((1501, dyn.N_AUX))
    assert dyn.integrate_samples(*pa, np.eye(n), model.friction.entry.rates, fp, avp, np.zeros(n), 0.0, r, 2e-4, 1,
                                 y, aux) < 0
    scale = np.max(np.abs(y), axis=0) + 1e-12
    zs = max(np.max(np.abs(aux[:, dyn.AUX_Z])), 1e-6)
    rates = lib.taos_rates
    rates.restype = _Tup3
    P = ctypes.POINTER(ctypes.c_double)
    L, D = ctypes.c_long, ctypes.c_double

    def arr(a):
        return a.ctypes.data_as(P)

    fixed = []
    for a in pa:
        fixed += [arr(a)] + [L(s) for s in a.shape]
    fixed += [arr(fp), L(fp.size), arr(avp), L(avp.size)]
    rng = np.random.default_rng(41)
    veps = max(fp[SLOT_VEPS], 1e-4)
    cw = pa.cw
    for k in range(303):
        x = rng.uniform(-2, 2, n) * scale
        z = float(rng.uniform(-2, 2) * zs)
        rr = np.array([rng.uniform(-10.5, 10.5) * DEG])
        if k % 3 == 0:   # the relative rate within +-2 v_eps: stick (switching law), the bristles' slow regime
            x -= cw * ((cw @ x - rng.uniform(-2, 2) * veps) / (cw @ cw))
        if k >= 300:     # at rest with no command, and with the full range: the gain table's two ends
            x[:], z, rr[0] = 0.0, 0.0, (0.0, 10.5 * DEG, -10.5 * DEG)[k - 300]
        dx_py, dx_c = np.zeros(n), np.zeros(n)
        want = dyn._rates(x, z, rr, *pa, model.friction.entry.rates, fp, avp, dx_py)
        got = rates(arr(x), L(n), D(z), arr(rr), L(1), *fixed, arr(dx_c), L(n))
        np.testing.assert_allclose(list(got.v), want, rtol=1e-12, atol=1e-300)
        np.testing.assert_allclose(dx_c, dx_py, rtol=1e-12, atol=1e-12 * np.max(np.abs(dx_py)))


def test_greenrun_segment_equals_taos_simulate(cfmu, hotfire):
    """FMPy runs the FMU through the first 4 s of the two-axis Green Run at the internal step
    with ``command_mode = 1`` (ramp; its output at t + h is taos simulate's at t): every signal equals
    ``taos simulate``'s, the engine angles within 1e-6 deg (achieved about 1e-16 deg; the whole
    profile: benchmarks/bench_fmu.py)."""
    prof = load_profile("greenrun_two_axis")
    dt, T = 2e-4, 4.0
    th = simulate(hotfire, prof, dt_s=dt, record_every=1, duration_s=T)
    sig = profile_input(prof, dt, T + dt)
    res = fmpy.simulate_fmu(str(cfmu), input=sig, stop_time=float(sig["time"][-1]), step_size=dt, output_interval=dt,
                            start_values={"command_mode": 1})
    n = th.t_s.size
    worst = 0.0
    for i, ax in enumerate(th.axes):
        for name in ("engine_rad", "piston_m", "load_force_N", "load_pressure_Pa", "friction_torque_Nm",
                     "command_avionics_rad"):
            ref = getattr(th, name)[i]
            d = np.max(np.abs(res[f"{ax}_{name}"][1:n + 1] - ref))
            assert d <= 1e-9 * max(1.0, np.max(np.abs(ref))), (ax, name, d)
            if name == "engine_rad":
                worst = max(worst, math.degrees(d))
    assert worst <= 1e-6


@pytest.mark.parametrize("every", [1, 5, 10, 25])
def test_held_command_at_multiples_of_the_internal_step_equals_the_kernel(cfmu, hotfire, every):
    """``command_mode = 2`` (hold, a staircase) at communication steps of 1, 5, 10 and 25 internal
    steps, a staircase of the Green Run's first 1.5 s: equal to the Python block holding the same
    commands (taos simulate's kernel over the held samples) within 1e-6 deg, every output."""
    prof = load_profile("greenrun_two_axis")
    dt = 2e-4
    h = every * dt
    steps = int(round(1.5 / h))
    t = np.arange(steps + 1) * h
    c = np.atleast_2d(prof(t))
    sig = np.zeros(t.size, dtype=[("time", float), ("pitch_command_rad", float), ("yaw_command_rad", float)])
    sig["time"], sig["pitch_command_rad"], sig["yaw_command_rad"] = t, c[0], c[1]
    res = fmpy.simulate_fmu(str(cfmu), input=sig, stop_time=float(t[-1]), step_size=h, output_interval=h,
                            start_values={"command_mode": 2})
    b = TvcBlock(hotfire)
    ref = [b.reset(c[0, 0], c[1, 0])] + [b.step(h, c[0, k], c[1, k]) for k in range(steps)]
    for name in BlockOutputs.signal_names():
        want = np.array([getattr(o, name) for o in ref])
        d = np.max(np.abs(res[name] - want))
        tol = 1e-6 * DEG if name.endswith("engine_rad") else 1e-9 * max(1.0, np.max(np.abs(want)))
        assert d <= tol, (name, d)


def _slave(cfmu, md, tmp_path):
    unz = fmpy.extract(str(cfmu), unzipdir=str(tmp_path / "unz"))
    s = FMU2Slave(guid=md.guid, unzipDirectory=unz, modelIdentifier=md.coSimulation.modelIdentifier,
                  instanceName="t")
    s.instantiate()
    return s


def test_fmu_state_get_set_and_serialise_restore_the_run(cfmu, md, tmp_path):
    """fmi2GetFMUstate/SetFMUstate and the serialised state restore the run exactly: 0.2 s,
    save, 0.2 s more; back to the saved state (directly and through bytes) and the same 0.2 s
    again gives the same outputs bit for bit."""
    vr = {v.name: v.valueReference for v in md.modelVariables}
    outs = [vr[n] for n in BlockOutputs.signal_names()]
    s = _slave(cfmu, md, tmp_path)
    s.setupExperiment(startTime=0.0)
    s.enterInitializationMode()
    s.setReal([vr["pitch_command_rad"], vr["yaw_command_rad"]], [0.5 * DEG, -0.3 * DEG])
    s.exitInitializationMode()
    t, h = 0.0, 1e-3

    def run(k):
        nonlocal t
        for _ in range(k):
            s.doStep(t, h)
            t += h
        return s.getReal(outs)

    run(200)
    state, t_saved = s.getFMUstate(), t
    blob = s.serializeFMUstate(state)
    first = run(200)
    s.setFMUstate(state)
    t = t_saved
    assert run(200) == first
    s.setFMUstate(s.deSerializeFMUstate(blob))
    t = t_saved
    assert run(200) == first
    s.freeFMUstate(state)
    s.terminate()
    s.freeInstance()


def test_host_mistakes_are_errors_not_fatal_and_change_nothing(cfmu, md, tmp_path):
    """A communication point that is not the FMU's time, a step that is no multiple of the
    internal step, a NaN or out-of-range command, command_mode or a fixed parameter set after initialisation, an
    unknown value reference: each is fmi2Error (never fmi2Fatal) with one log line, and the run
    goes on as if the call had not been made."""
    vr = {v.name: v.valueReference for v in md.modelVariables}
    s = _slave(cfmu, md, tmp_path)
    s.setupExperiment(startTime=0.0)
    s.enterInitializationMode()
    s.setInteger([vr["command_mode"]], [1])
    s.setReal([vr["pitch_command_rad"]], [0.2 * DEG])
    s.exitInitializationMode()
    s.doStep(0.0, 2e-3)
    before = s.getReal([vr["pitch_engine_rad"]])
    mistakes = [lambda: s.doStep(0.5, 2e-3), lambda: s.doStep(2e-3, 3e-4), lambda: s.doStep(2e-3, -2e-4),
                lambda: s.setReal([vr["pitch_command_rad"]], [float("nan")]),
                lambda: s.setReal([vr["yaw_command_rad"]], [11 * DEG]),
                lambda: s.setReal([vr["pitch_engine_rad"]], [0.0]),
                lambda: s.setInteger([vr["command_mode"]], [0]), lambda: s.getReal([999]),
                lambda: s.setReal([vr["internal_step_s"]], [1e-4]), lambda: s.setInteger([vr["command_mode"]], [3]),
                lambda: s.setReal([vr["avionics_gain"]], [2.0]), lambda: s.setReal([vr["vehicle_force_x_N"]], [0.0])]
    for call in mistakes:
        with pytest.raises(FMICallException) as e:
            call()
        assert e.value.status == 3   # fmi2Error
    assert s.getReal([vr["pitch_engine_rad"]]) == before
    assert s.getInteger([vr["command_mode"]]) == [1]
    s.doStep(2e-3, 2e-3)   # still running
    s.terminate()
    s.freeInstance()


_C_MASTER = r"""
/* A C co-simulation master: the whole FMI 2.0 life cycle, then return from main. */
#include <dlfcn.h>
#include <stdio.h>
#include <stdlib.h>
#include "fmi2Functions.h"
static void logger(fmi2ComponentEnvironment e, fmi2String n, fmi2Status s, fmi2String c, fmi2String m, ...) {
  printf("LOG %d %s %s\n", (int)s, c, m);
}
#define SYM(T, name) T *name = (T *)dlsym(lib, #name); if (!name) { printf("missing %s\n", #name); return 10; }
int main(int argc, char **argv) {
  void *lib = dlopen(argv[1], RTLD_NOW | RTLD_LOCAL);
  if (!lib) { printf("dlopen: %s\n", dlerror()); return 1; }
  SYM(fmi2InstantiateTYPE, fmi2Instantiate) SYM(fmi2SetupExperimentTYPE, fmi2SetupExperiment)
  SYM(fmi2EnterInitializationModeTYPE, fmi2EnterInitializationMode)
  SYM(fmi2ExitInitializationModeTYPE, fmi2ExitInitializationMode) SYM(fmi2SetRealTYPE, fmi2SetReal)
  SYM(fmi2GetRealTYPE, fmi2GetReal) SYM(fmi2DoStepTYPE, fmi2DoStep) SYM(fmi2TerminateTYPE, fmi2Terminate)
  SYM(fmi2FreeInstanceTYPE, fmi2FreeInstance)
  fmi2CallbackFunctions cb = {logger, calloc, free, NULL, NULL};
  double cmd = atof(argv[4]), h = atof(argv[6]), th = 0.0;
  int n = atoi(argv[5]);
  for (int run = 0; run < 2; run++) {   /* two instances one after the other in one process */
    fmi2Component c = fmi2Instantiate("tvc", fmi2CoSimulation, argv[3], argv[2], &cb, fmi2False, fmi2False);
    if (!c) { printf("instantiate failed\n"); return 2; }
    fmi2ValueReference vin = 0, vout = 2;
    if (fmi2SetupExperiment(c, fmi2False, 0.0, 0.0, fmi2False, 0.0) || fmi2EnterInitializationMode(c)
        || fmi2SetReal(c, &vin, 1, &cmd) || fmi2ExitInitializationMode(c)) { printf("init failed\n"); return 3; }
    for (int k = 0; k < n; k++)
      if (fmi2DoStep(c, k * h, h, fmi2True) != fmi2OK) { printf("step %d failed\n", k); return 4; }
    if (fmi2GetReal(c, &vout, 1, &th) != fmi2OK) return 5;
    if (fmi2Terminate(c) != fmi2OK) return 6;
    fmi2FreeInstance(c);
  }
  if (dlclose(lib)) return 7;
  printf("pitch_engine_rad %.17g\n", th);
  return 0;
}
"""


def test_a_c_master_runs_the_whole_life_cycle_and_exits_cleanly(cfmu, md, tmp_path, hotfire):
    """A C master compiled here (gcc, FMPy's FMI 2.0 headers) runs instantiate, setup, enter and
    exit initialisation, 2500 steps of 0.2 ms with a held 0.4 deg pitch command, terminate and
    free, twice, then dlclose and return 0 from main (no _exit): exit status 0, nothing on
    standard error, and the engine angle of the Python block within 1e-6 deg."""
    from taos.cosim._standalone import fmi_headers

    (tmp_path / "master.c").write_text(_C_MASTER)
    subprocess.run([CC, "-std=c99", "-O1", "-I", str(fmi_headers()), "-o", str(tmp_path / "master"),
                    str(tmp_path / "master.c"), "-ldl"], check=True)
    with zipfile.ZipFile(cfmu) as z:
        z.extractall(tmp_path / "fmu")
    vr = {v.name: v.valueReference for v in md.modelVariables}
    assert (vr["pitch_command_rad"], vr["pitch_engine_rad"]) == (0, 2)
    so = tmp_path / "fmu" / "binaries" / "linux64" / f"{md.coSimulation.modelIdentifier}.so"
    r = subprocess.run([str(tmp_path / "master"), str(so), (tmp_path / "fmu" / "resources").as_uri(), md.guid,
                        repr(0.4 * DEG), "2500", "2e-4"], capture_output=True, text=True, timeout=300,
                       env={"PATH": "/usr/bin:/bin"}, check=False)
    assert r.returncode == 0 and r.stderr == "", r.stdout[-2000:] + r.stderr[-2000:]
    got = float(r.stdout.split("pitch_engine_rad")[1])
    b = TvcBlock(hotfire)
    b.reset(0.4 * DEG, 0.0)
    for _ in range(2500):
        out = b.step(2e-4, 0.4 * DEG, 0.0)
    assert abs(got - out.pitch_engine_rad) <= 1e-6 * DEG


def test_cli_standalone_by_default_and_its_refusals(tmp_path):
    """``taos fmu`` builds the standalone FMU by default (``--standalone`` says so explicitly):
    exit 0 and a valid FMU with the friction law asked for, no Python file in it; with both
    ``--python`` and ``--standalone``, a 3-D step beyond 1 ms, or a foreign file at ``--out``:
    exit 2, one line (never offering ``--force``), nothing written or replaced. (The 3-D
    standalone FMU from the command line: tests/test_fmu_taos3d.py.)"""
    ok = run_cli("fmu", MODELS / "rs25_ambient.toml", "--out", tmp_path / "a.fmu", "--friction", "dahl")
    assert ok.returncode == 0, ok.stderr
    assert "no Python at run time" in ok.stdout
    assert validate_fmu(str(tmp_path / "a.fmu")) == []
    md = fmpy.read_model_description(str(tmp_path / "a.fmu"))
    assert "friction dahl" in md.description and "standalone C" in md.description
    with zipfile.ZipFile(tmp_path / "a.fmu") as z:
        assert "sources/buildDescription.xml" in z.namelist() and not any(n.endswith(".py") for n in z.namelist())
    ok = run_cli("fmu", MODELS / "rs25_ambient.toml", "--out", tmp_path / "s.fmu", "--standalone")
    assert ok.returncode == 0 and "no Python at run time" in ok.stdout, ok.stderr
    for extra in (["--python", "--standalone"], ["--engine", "taos", "--dt", "2e-3"]):
        r = run_cli("fmu", MODELS / "rs25_ambient.toml", "--out", tmp_path / "b.fmu", *extra)
        assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1, r.stderr
        assert "--force" not in r.stderr
    keep = tmp_path / "keep.fmu"
    keep.write_bytes(b"not mine")
    r = run_cli("fmu", MODELS / "rs25_ambient.toml", "--out", keep)
    assert r.returncode == 2 and "did not write" in r.stderr and "--force" not in r.stderr
    assert keep.read_bytes() == b"not mine"
    assert sorted(p.name for p in tmp_path.iterdir() if not p.name.startswith(".")) == ["a.fmu", "keep.fmu", "s.fmu"]


def test_a_model_variant_is_built_with_its_provenance(tmp_path, hotfire):
    """A variant (``model.with_values``) builds its own FMU: its hash in the description, its
    overrides in the vendor annotation, and its numbers: 0.1 s of a held 0.3 deg pitch command
    equals the variant's Python block within 1e-6 deg."""
    k = "120000 lbf/in"
    var = hotfire.with_values({"structure.load_stiffness": k})
    path = build_standalone_fmu(var, tmp_path / "var.fmu").path
    md = fmpy.read_model_description(str(path))
    assert var.sha256 in md.description and hotfire.sha256 not in md.description
    with zipfile.ZipFile(path) as z:
        assert "structure.load_stiffness" in z.read("modelDescription.xml").decode()
    res = fmpy.simulate_fmu(str(path), stop_time=0.1, step_size=1e-3, output_interval=1e-3,
                            start_values={"pitch_command_rad": 0.3 * DEG})
    b = TvcBlock(var)
    b.reset(0.3 * DEG, 0.0)
    want = [b.outputs.pitch_engine_rad] + [b.step(1e-3, 0.3 * DEG, 0.0).pitch_engine_rad for _ in range(100)]
    assert np.max(np.abs(res["pitch_engine_rad"] - want)) <= 1e-6 * DEG
