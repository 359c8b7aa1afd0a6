"""Per-step cost of the co-simulation block (:class:`taos.cosim.TvcBlock.step`) and of the FMU's
slave around it, at one internal step per communication step (the costliest use: Python around
a one-step kernel call). Writes nothing; paste the output into benchmarks/RESULTS.md.

Run:  PYTHONPATH=. .venv/bin/python benchmarks/bench_cosim_step.py [--steps 20000] [--repeat 5]

Rows (hot-fire model, the two-axis Green Run profile's samples from t = 0, each engine at its
default step dt):

* ``TvcBlock.step`` with ``ramp`` and with ``hold``, simplex and 3-D engines: wall time per
  call [us], the best of ``--repeat`` runs of ``--steps`` calls each (a fresh reset before
  each run);
* the FMU's slave (:class:`taos.cosim._slave.TvcSlave`) as pythonfmu's binary drives it at each
  FMPy step: ``set_real`` of the two inputs, ``do_step``, ``get_real`` of the 17 outputs (without
  the binary and FMPy themselves), simplex, ``ramp``.

With ``--fmu SECONDS``: also the FMU (built as ``taos fmu`` builds it) run by FMPy over that much
of the profile at h = dt, ``command_hold`` 1, in a child process as tests/test_fmu.py runs it
(:func:`tests.test_fmu.fmpy_in_child`): the child's wall time of ``simulate_fmu`` and its CPU
time (start-up included: imports, instantiation, kernel loading).

A digest of every output at every step of one more run (SHA-256 of the values, untimed) and the
last pitch engine angle are printed, so that runs before and after a change can be compared bit
for bit.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from taos.cosim import BlockOutputs, TvcBlock  # noqa: E402
from taos.model import load_model  # noqa: E402
from taos.profiles import load_profile  # noqa: E402


def block_row(block: TvcBlock, c: np.ndarray, dt: float, repeat: int):
    """Best wall time per step [us] over ``repeat`` runs through the samples ``c`` (2, n + 1),
    and the last outputs."""
    n = c.shape[1] - 1
    pc, yc = c[0].tolist(), c[1].tolist()
    best = float("inf")
    for _ in range(repeat):
        block.reset(pc[0], yc[0])
        step = block.step
        t0 = time.perf_counter()
        for k in range(1, n + 1):
            out = step(dt, pc[k], yc[k])
        best = min(best, time.perf_counter() - t0)
    outs = [block.reset(pc[0], yc[0])] + [block.step(dt, pc[k], yc[k]) for k in range(1, n + 1)]
    return best / n * 1e6, out, digest([list(o.to_dict().values()) for o in outs])


def digest(rows) -> str:
    """SHA-256 (first 12 hex digits) of every value of every step (bit-for-bit comparisons)."""
    import hashlib
    return hashlib.sha256(np.asarray(rows, dtype=np.float64).tobytes()).hexdigest()[:12]


def slave_row(model_path: Path, c: np.ndarray, dt: float, repeat: int, tmp: Path):
    """The FMU slave (built like ``taos fmu``'s, resources written by hand) stepped as
    pythonfmu's binary does: set the two inputs, ``do_step``, get every output."""
    import json
    import shutil

    from taos.cosim._fmu import CONFIG, RESOURCE_DIR
    from taos.cosim._slave import TvcSlave
    from taos.model import load_model as lm

    model = lm(model_path)
    res = tmp / RESOURCE_DIR
    (res / "model").mkdir(parents=True, exist_ok=True)
    from taos.cosim._fmu import _copy_model_files
    mf = _copy_model_files(model, res / "model")
    (res / CONFIG).write_text(json.dumps({"engine": "simplex", "friction": model.friction.name, "avionics": "model",
                                          "dt_s": dt, "allow_unstable": False, "model_name": model.name,
                                          "model_sha256": model.sha256, "model_file": mf}))
    s = TvcSlave(instance_name="bench", resources=str(tmp))
    s._hold = 1
    vr = {v.name: r for r, v in s.vars.items()}
    vin = [vr["pitch_command_rad"], vr["yaw_command_rad"]]
    vout = [vr[k] for k in BlockOutputs.signal_names()]
    n = c.shape[1] - 1
    pc, yc = c[0].tolist(), c[1].tolist()

    def run(rec):
        s.set_real(vin, [pc[0], yc[0]])
        s.exit_initialization_mode()
        t0 = time.perf_counter()
        for k in range(1, n + 1):
            s.set_real(vin, [pc[k], yc[k]])
            if not s.do_step(k * dt, dt):
                raise SystemExit(f"do_step refused at step {k}")
            vals = s.get_real(vout)
            if rec is not None:
                rec.append(vals)
        return time.perf_counter() - t0, vals

    best = min(run(None)[0] for _ in range(repeat))
    rec: list = []
    _, vals = run(rec)
    shutil.rmtree(res)
    return best / n * 1e6, vals, digest(rec)


def fmu_row(prof, seconds: float, dt: float = 2e-4) -> None:
    """The FMU in FMPy over ``seconds`` of ``prof`` at h = dt (ramp), in a child process."""
    import resource
    import tempfile

    from taos.cosim import build_fmu
    from tests.test_fmu import fmpy_in_child, profile_input

    with tempfile.TemporaryDirectory(prefix="bench_cosim_fmu_") as tmp:
        fmu = build_fmu(ROOT / "models" / "rs25_hotfire.toml", Path(tmp) / "tvc.fmu").path
        sig = profile_input(prof, dt, seconds + dt)
        cpu0 = resource.getrusage(resource.RUSAGE_CHILDREN)
        res, _, err, wall = fmpy_in_child(fmu, tmp, sig, stop_time=float(sig["time"][-1]), step_size=dt,
                                          output_interval=dt, start_values={"command_hold": 1})
        cpu1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    if err:
        raise SystemExit(f"FMPy: {err}")
    cpu = (cpu1.ru_utime - cpu0.ru_utime) + (cpu1.ru_stime - cpu0.ru_stime)
    n = res.size - 1
    print(f"FMU in FMPy, {seconds:g} s at h = dt ({n} steps): simulate_fmu {wall:.2f} s wall "
          f"({wall / n * 1e6:.1f} us/step); child CPU {cpu:.2f} s; digest {digest(res.tolist())}")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=20000, help="communication steps a run (default 20000)")
    ap.add_argument("--repeat", type=int, default=5, help="runs per row, the best kept (default 5)")
    ap.add_argument("--fmu", type=float, default=0.0, metavar="SECONDS",
                    help="also run the FMU in FMPy over this much of the profile (default: not run)")
    args = ap.parse_args(argv)
    print("uptime:", subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip())
    print(f"python {sys.version.split()[0]}, {os.cpu_count()} cores; hot fire, Green Run two-axis samples, "
          f"{args.steps} steps x best of {args.repeat}")
    model = load_model("rs25_hotfire")
    prof = load_profile("greenrun_two_axis")
    print(f"{'row':44s} {'us/step':>8s}  {'outputs sha':12s}  last pitch engine [rad]")
    for engine, dt in (("simplex", 2e-4), ("taos", 4e-4)):
        c = np.atleast_2d(prof(np.arange(args.steps + 1) * dt))
        for hold, every in (("ramp", 1), ("hold", 1), ("ramp", 10)):
            us, out, h = block_row(TvcBlock(model, engine=engine, hold=hold), c[:, ::every], every * dt, args.repeat)
            print(f"{f'TvcBlock.step, {engine}, {hold}, h = {every} dt':44s} {us:8.2f}  {h}  {out.pitch_engine_rad!r}")
    import tempfile
    c = np.atleast_2d(prof(np.arange(args.steps + 1) * 2e-4))
    with tempfile.TemporaryDirectory(prefix="bench_cosim_") as tmp:
        us, vals, h = slave_row(ROOT / "models" / "rs25_hotfire.toml", c, 2e-4, args.repeat, Path(tmp))
    print(f"{'TvcSlave set_real + do_step + get_real, ramp':44s} {us:8.2f}  {h}  {vals[0]!r}")
    if args.fmu > 0:
        fmu_row(prof, args.fmu)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
