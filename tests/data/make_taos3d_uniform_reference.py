#!/usr/bin/env python
"""Make tests/data/taos3d_mlugre_uniform_1.5625e-6.npz: an independent fine-step reference for
tests/test_taos3d_step.py (modified LuGre, hot fire, first 4 s of the two-axis Green Run).

The independent solver is the former constant-step 3-D kernel of commit abb8363 (RK4 +
trapezoidal torque kick + constant-step BDF2 bearing, no bearing substeps), run from its own
source tree (``git archive``, with its own model files: ideal valve, line load stiffness
206,520 lbf/in as that tree gave it) at a uniform 1.5625e-6 s, on this venv. The one change
made to that tree is the friction law's definition: its ``_sigma1`` (the exponential decay of
the bristle damping) is replaced by the shipped rational decay sigma_1 v_1 / (v_1 + |v|)
(taos/friction/_kernels.py), so the reference computes the law the shipped kernel does;
the script refuses to run if that line is not found exactly once. Records every 10 ms:
theta, x_p, F_L, T_f (pitch, yaw; SI).

Usage (about 1-3 min: the old tree's kernels compile afresh):
    .venv/bin/python tests/data/make_taos3d_uniform_reference.py
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
OUT = Path(__file__).resolve().parent / "taos3d_mlugre_uniform_1.5625e-6.npz"
COMMIT = "abb8363"
DT = 1.5625e-6
T_RUN = 4.0
REC_S = 0.01
EXPONENTIAL = "        return p[SLOT_SIGMA1] * math.exp(-(v / v1) ** 2)\n"
RATIONAL = "        return p[SLOT_SIGMA1] * v1 / (v1 + abs(v))\n"

CODE = """
import json, sys, numpy as np
from taos.profiles import Sequence, TwoAxis, load_profile
from taos.taos3d import load_taos_model
from taos.taos3d.simulate import run_samples
p = load_profile("models/profiles/greenrun_two_axis.toml")
prof = TwoAxis(Sequence((p.pitch,) * 2), Sequence((p.yaw,) * 3), "Green Run x2, 60 s")
tm = load_taos_model("models/rs25_hotfire.toml", friction="modified-lugre")
assert not tm.base.actuator.pressure_limited
n = int(round(%r / %r))
cmd = np.ascontiguousarray(np.asarray(prof(np.arange(n + 1) * %r)).T)
rec = run_samples(tm, cmd, %r, int(round(%r / %r)))[:, :8]
json.dump({"records": rec.tolist(), "k_line": float(tm.line_load_stiffness_N_per_m)}, sys.stdout)
"""


def main() -> int:
    with tempfile.TemporaryDirectory() as tmp:
        archive = subprocess.run(["git", "-C", str(ROOT), "archive", COMMIT, "taos", "models", "fem_data"],
                                 capture_output=True, check=True).stdout
        subprocess.run(["tar", "-x", "-C", tmp], input=archive, check=True)
        kern = Path(tmp) / "taos" / "friction" / "_kernels.py"
        src = kern.read_text()
        if src.count(EXPONENTIAL) != 1:
            print(f"{kern}: the exponential decay line was not found exactly once; refusing", file=sys.stderr)
            return 2
        kern.write_text(src.replace(EXPONENTIAL, RATIONAL))
        code = CODE % (T_RUN, DT, DT, DT, REC_S, DT)
        res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=tmp,
                             env={**os.environ, "PYTHONPATH": tmp})
        if res.returncode:
            print(res.stderr, file=sys.stderr)
            return 1
        out = json.loads(res.stdout)
    about = (f"modified-lugre with the rational bristle-damping decay sigma_1 v_1/(v_1 + |v|), hot fire, two-axis "
             f"Green Run (tests/test_taos3d_step.py::_greenrun), first {T_RUN:g} s, records every 10 ms (theta, x_p, "
             f"F_L, T_f; pitch, yaw; SI), the former constant-step kernel (commit {COMMIT}: RK4 + trapezoidal torque "
             f"kick + constant-step BDF2 bearing, no substeps; its own model files: ideal valve, line load stiffness "
             f"{out['k_line'] / 175.126835:.6g} lbf/in) at a uniform {DT:g} s, its _sigma1 replaced by the rational "
             f"decay: an independent fine-step reference. Made by tests/data/make_taos3d_uniform_reference.py")
    np.savez_compressed(OUT, records=np.array(out["records"]), line_load_stiffness_N_per_m=out["k_line"],
                        about=about)
    print(f"wrote {OUT}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
