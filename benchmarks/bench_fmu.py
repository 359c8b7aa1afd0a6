"""The FMU and the co-simulation block against ``taos simulate`` in the same run: agreement and
speed (writes nothing but a temporary FMU; paste the output into benchmarks/RESULTS.md).

Run:  PYTHONPATH=. .venv/bin/python benchmarks/bench_fmu.py [--duration S] [--engine simplex|taos|both]
      [--skip-pythonfmu]

For each engine (hot-fire model, its default step dt: 2e-4 s simplex, 4e-4 s taos), the two-axis
Green Run profile (models/profiles/greenrun_two_axis.toml, 32 s long) over ``--duration``
seconds (default: the profile plus 1 s, 33 s, as ``taos simulate`` runs it; a longer run adds
zero command):

* peer: ``taos simulate``'s own run (the uncut kernel, every sample recorded);
* the Python block (:class:`taos.cosim.TvcBlock`) stepped at h = dt with ``ramp`` (the samples
  of the profile: ``taos simulate`` bit for bit), and at h = 10 dt with ``hold`` (a host's
  staircase command at 1/10 the rate: the difference is the zero-order hold's, not the
  block's);
* the FMU (``taos fmu``) in FMPy (``fmpy.simulate_fmu`` in a child process ended with
  ``os._exit``, as tests/test_fmu.py runs it), at h = dt with ``command_hold = 1`` (its output at
  t + h against ``taos simulate`` at t) and at h = 10 dt with ``command_hold = 0``;
* the standalone FMU (``taos fmu``'s default, C, no Python; simplex and 3-D) in FMPy (in this
  process: it holds no Python): simplex with ``command_mode`` 1 ramp at h = dt and 2 hold at
  h = 10 dt; both engines in the default exact mode at h = 5, 10, 25 dt (simplex) or 1, 5,
  10 dt (3-D) against ``taos simulate`` of the same held command (the held profile of
  ``tests/test_fmu_standalone_params.held_profile``, one more ``taos simulate`` run per host
  step); and its bare per-step cost in a C master (the FMU's ``fmi2DoStep`` and
  ``fmi2GetReal`` of every output in a loop, no FMPy; held command, h = dt, timed inside the
  master with ``clock_gettime``). ``--skip-pythonfmu`` leaves out the pythonfmu FMU's rows
  (``taos fmu --python``, the slowest).

Agreement: the largest |engine angle - taos simulate| over both axes [deg] at the common
samples. Speed: wall time of the run (FMU: of ``simulate_fmu`` inside the child, instantiation
included) and real-time factor (simulated / wall time). The machine is shared: ``uptime`` is
printed.
"""

from __future__ import annotations

import argparse
import math
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from taos.cosim import TvcBlock, build_fmu  # noqa: E402
from taos.model import load_model  # noqa: E402
from taos.profiles import load_profile  # noqa: E402
from tests.test_fmu import fmpy_in_child, profile_input  # noqa: E402  (the tests' child-process runner)


def reference(model, prof, engine: str, dt: float, T: float):
    """``taos simulate`` (the library call the command makes; the 3-D model built beforehand) and
    its wall time [s], the better of two runs (the first loads the kernels)."""
    walls = []
    if engine == "taos":
        from taos.taos3d import simulate_taos, taos_model
        tm = taos_model(model)
        run = lambda: simulate_taos(tm, prof, dt_s=dt, record_every=1, duration_s=T)  # noqa: E731
    else:
        from taos.planar.simulate import simulate
        run = lambda: simulate(model, prof, dt_s=dt, record_every=1, duration_s=T)  # noqa: E731
    for _ in range(2):
        t0 = time.perf_counter()
        th = run()
        walls.append(time.perf_counter() - t0)
    return th, min(walls)


def block_run(model, prof, engine: str, dt: float, T: float, every: int, hold: str):
    """The block stepped every ``every`` internal steps; engine angles (2, n) and wall time [s]."""
    b = TvcBlock(model, engine=engine, hold=hold)
    n = int(round(T / dt)) // every
    t = np.arange(n + 1) * every * dt
    c = np.atleast_2d(prof(t))
    out = [b.reset(c[0, 0], c[1, 0]) if hold == "ramp" else b.reset()]
    t0 = time.perf_counter()
    for k in range(1, n + 1):
        out.append(b.step(every * dt, *(c[:, k] if hold == "ramp" else c[:, k - 1])))
    wall = time.perf_counter() - t0
    return np.array([[o.pitch_engine_rad for o in out], [o.yaw_engine_rad for o in out]]), wall


def worst_deg(eng: np.ndarray, th, every: int, shift: int = 0) -> float:
    """max |engine - taos simulate| [deg] over both axes, at every ``every``-th sample; the
    block's sample k + shift against the reference's k."""
    ref = th.engine_rad[:, ::every]
    m = min(ref.shape[1], eng.shape[1] - shift)
    return math.degrees(float(np.max(np.abs(eng[:, shift:shift + m] - ref[:, :m]))))


_C_BENCH = r"""
#include <dlfcn.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
#include "fmi2Functions.h"
static void lg(fmi2ComponentEnvironment e, fmi2String n, fmi2Status s, fmi2String c, fmi2String m, ...) { puts(m); }
int main(int argc, char **argv) {
  void *lib = dlopen(argv[1], RTLD_NOW | RTLD_LOCAL);
  fmi2InstantiateTYPE *inst = (fmi2InstantiateTYPE *)dlsym(lib, "fmi2Instantiate");
  fmi2EnterInitializationModeTYPE *en = (fmi2EnterInitializationModeTYPE *)dlsym(lib, "fmi2EnterInitializationMode");
  fmi2ExitInitializationModeTYPE *ex = (fmi2ExitInitializationModeTYPE *)dlsym(lib, "fmi2ExitInitializationMode");
  fmi2SetRealTYPE *setr = (fmi2SetRealTYPE *)dlsym(lib, "fmi2SetReal");
  fmi2GetRealTYPE *getr = (fmi2GetRealTYPE *)dlsym(lib, "fmi2GetReal");
  fmi2DoStepTYPE *step = (fmi2DoStepTYPE *)dlsym(lib, "fmi2DoStep");
  fmi2FreeInstanceTYPE *fr = (fmi2FreeInstanceTYPE *)dlsym(lib, "fmi2FreeInstance");
  fmi2CallbackFunctions cb = {lg, calloc, free, NULL, NULL};
  fmi2Component c = inst("b", fmi2CoSimulation, argv[2], "", &cb, fmi2False, fmi2False);
  long n = atol(argv[3]); double h = atof(argv[4]), cmd[2] = {0.007, -0.005}, out[64];
  int nout = atoi(argv[5]);
  fmi2ValueReference vin[2] = {0, 1}, vout[64];
  for (int i = 0; i < nout; i++) vout[i] = 2 + i;
  en(c); setr(c, vin, 2, cmd); ex(c);
  struct timespec t0, t1;
  clock_gettime(CLOCK_MONOTONIC, &t0);
  for (long k = 0; k < n; k++) { if (step(c, k * h, h, fmi2True) || getr(c, vout, nout, out)) return 2; }
  clock_gettime(CLOCK_MONOTONIC, &t1);
  printf("%.6f\n", (t1.tv_sec - t0.tv_sec) + 1e-9 * (t1.tv_nsec - t0.tv_nsec));
  fr(c);
  return 0;
}
"""


def c_master_per_step(fmu: Path, tmp: str, steps: int, h: float) -> float:
    """Wall time [s] per communication step of the standalone FMU in a bare C master (module docstring)."""
    import shutil
    import zipfile

    import fmpy

    from taos.cosim._standalone import fmi_headers

    d = Path(tmp) / "cbench"
    d.mkdir(exist_ok=True)
    (d / "m.c").write_text(_C_BENCH)
    cc = shutil.which("cc") or shutil.which("gcc")
    subprocess.run([cc, "-O2", "-I", str(fmi_headers()), "-o", str(d / "m"), str(d / "m.c"), "-ldl"], check=True)
    with zipfile.ZipFile(fmu) as z:
        z.extractall(d / "fmu")
    md = fmpy.read_model_description(str(fmu))
    so = d / "fmu" / "binaries" / "linux64" / f"{md.coSimulation.modelIdentifier}.so"
    outs = {v.valueReference for v in md.modelVariables if v.causality == "output"}
    nout = 0
    while 2 + nout in outs:   # the block of outputs from value reference 2 (17 planar, 14 3-D)
        nout += 1
    r = subprocess.run([str(d / "m"), str(so), md.guid, str(steps), repr(h), str(nout)], capture_output=True,
                       text=True, check=True)
    return float(r.stdout.split()[-1]) / steps


def held_reference(engine: str, model, sig, dt: float):
    """``taos simulate`` (either engine) of the host's command held over each communication step."""
    from taos.profiles import TwoAxis
    from tests.test_fmu_standalone_params import held_profile

    tj = sig["time"]
    prof = TwoAxis(held_profile(tj, sig["pitch_command_rad"], dt), held_profile(tj, sig["yaw_command_rad"], dt))
    if engine == "taos":
        from taos.taos3d import simulate_taos, taos_model
        return simulate_taos(taos_model(model), prof, dt_s=dt, record_every=1, duration_s=float(tj[-1]))
    from taos.planar.simulate import simulate
    return simulate(model, prof, dt_s=dt, record_every=1, duration_s=float(tj[-1]))


def standalone_rows(engine: str, model, prof, th, dt: float, T: float, tmp: str) -> list:
    """The standalone FMU's rows (module docstring)."""
    import fmpy

    from taos.cosim._standalone import build_standalone_fmu
    from taos.cosim._standalone3d import build_standalone_fmu_3d

    build = build_standalone_fmu_3d if engine == "taos" else build_standalone_fmu
    t0 = time.perf_counter()
    fmu = build(ROOT / "models" / "rs25_hotfire.toml", Path(tmp) / f"standalone_{engine}.fmu").path
    rows = [(engine, "standalone FMU: taos fmu (build)", dt, float("nan"), time.perf_counter() - t0)]
    runs = ((1, 0), (5, 0), (10, 0)) if engine == "taos" else ((1, 1), (10, 2), (5, 0), (10, 0), (25, 0))
    for every, mode in runs:
        h = every * dt
        sig = profile_input(prof, dt, T + h)[::every]
        ref = held_reference(engine, model, sig, dt) if mode == 0 else th
        t0 = time.perf_counter()
        res = fmpy.simulate_fmu(str(fmu), input=sig, stop_time=float(sig["time"][-1]), step_size=h, output_interval=h,
                                start_values={} if engine == "taos" else {"command_mode": mode})
        wall = time.perf_counter() - t0
        eng = np.vstack([res["pitch_engine_rad"], res["yaw_engine_rad"]])
        what = {0: "exact (default) vs taos simulate of the held command", 1: "ramp", 2: "hold"}[mode]
        rows.append((engine, f"standalone FMU in FMPy, h = {every} dt, mode {mode} {what}", h,
                     worst_deg(eng, ref, every, shift=1 if mode == 1 else 0), wall))
    steps = int(round(T / dt))
    per = c_master_per_step(fmu, tmp, steps, dt)
    rows.append((engine, f"standalone FMU in a C master, h = dt ({per * 1e6:.2f} us/step)", dt, float("nan"),
                 per * steps))
    return rows


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--duration", type=float, default=None,
                    help="simulated time [s] (default: the profile's 32 s plus 1 s, as taos simulate)")
    ap.add_argument("--engine", choices=("simplex", "taos", "both"), default="both")
    ap.add_argument("--skip-pythonfmu", action="store_true", help="leave out the pythonfmu FMU's rows")
    args = ap.parse_args(argv)
    print("uptime:", subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip())
    model = load_model("rs25_hotfire")
    prof = load_profile("greenrun_two_axis")
    if args.duration is None:
        args.duration = prof.duration_s + 1.0
    print(f"python {sys.version.split()[0]}, {os.cpu_count()} cores; Green Run two-axis (profile {prof.duration_s:g} s), "
          f"hot fire, {args.duration:g} s simulated")
    engines = ("simplex", "taos") if args.engine == "both" else (args.engine,)
    rows = []
    with tempfile.TemporaryDirectory(prefix="bench_fmu_") as tmp:
        for engine in engines:
            dt = 2e-4 if engine == "simplex" else 4e-4
            T = args.duration
            th, w_ref = reference(model, prof, engine, dt, T)
            rows.append((engine, "taos simulate (peer)", dt, 0.0, w_ref))
            for every, hold in ((1, "ramp"), (10, "hold")):
                eng, w = block_run(model, prof, engine, dt, T, every, hold)
                rows.append((engine, f"TvcBlock, h = {every} dt, {hold}", every * dt, worst_deg(eng, th, every), w))
            rows += standalone_rows(engine, model, prof, th, dt, T, tmp)
            if args.skip_pythonfmu:
                continue
            fmu = build_fmu(ROOT / "models" / "rs25_hotfire.toml", Path(tmp) / f"{engine}.fmu", engine=engine).path
            *_, fixed = fmpy_in_child(fmu, tmp, stop_time=dt, step_size=dt, output_interval=dt)
            rows.append((engine, "pythonfmu FMU (taos fmu --python) in FMPy, one step (start-up)", dt, float("nan"),
                         fixed))
            for every, hold in ((1, 1), (10, 0)):
                h = every * dt
                sig = profile_input(prof, dt, T + h)
                sig = sig[::every]
                res, msgs, err, wall = fmpy_in_child(fmu, tmp, sig, stop_time=float(sig["time"][-1]), step_size=h,
                                                     output_interval=h, start_values={"command_hold": hold})
                if err:
                    raise SystemExit(f"FMPy: {err}")
                eng = np.vstack([res["pitch_engine_rad"], res["yaw_engine_rad"]])
                rows.append((engine, f"pythonfmu FMU in FMPy, h = {every} dt, command_hold {hold}", h,
                             worst_deg(eng, th, every, shift=1 if hold == 1 else 0), wall))
    print("uptime at the end:", subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip())
    print(f"{'engine':8s} {'run':58s} {'h [s]':>8s} {'max |d engine| [deg]':>21s} {'wall [s]':>9s} {'x real time':>12s}")
    for engine, what, h, d, w in rows:
        one = math.isnan(d)   # the start-up row: one step, no agreement or real-time figure
        print(f"{engine:8s} {what:58s} {h:8.1e} {'-' if one else f'{d:.3g}':>21s} {w:9.2f} "
              f"{'-' if one else f'{args.duration / w:.1f}':>12s}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
