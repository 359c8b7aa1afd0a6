"""TAOS 3-D model speed and step accuracy, beside a MuJoCo rigid-engine peer in the same run
(writes nothing; paste the output into benchmarks/RESULTS.md).

Run:  PYTHONPATH=. .venv/bin/python benchmarks/bench_taos3d.py [--repeat 5] [--only-speed]
      (the peer needs the optional extra: pip install -e .[bench], i.e. mujoco >= 3.1;
      without it the peer is skipped with one line)

1. Speed: 60 s two-axis Green Run profile (models/profiles/greenrun_two_axis.toml repeated to
   60 s, as benchmarks/bench_taos.py), hot-fire FEM gimbal, modified-LuGre bearing, at the
   model's time-run default step (taos.taos3d.simulate.DEFAULT_DT_S, 8e-4 s since issue 44) and
   at 4e-4 s (the former default, now the dwells' step DWELL_DT_S); records every 4 ms. Best and median of ``--repeat`` runs (the machine is
   shared: both are printed), and the best CPU time (process time: on a shared machine it
   leaves out the waiting). ``--only-speed``: this part and the peer (5.) alone.
2. Accuracy of the step: 4 s of the same run (modified LuGre, and Coulomb smooth, whose error
   is not masked by stick-slip timing) against a 2.5e-5 s reference, at the default step and
   at 4e-4 s (the former kernel's stored records, removed from tests/data (git history),
   predate the servo recalibration and the pressure limit of issue 24: no longer the same
   model, not compared). Then sine dwells (``taos_freqresp_family``, pitch, 0.5-20 Hz, 0.05 and
   0.4 deg) at the dwells' step (DWELL_DT_S, 4e-4 s) and 2e-4 s against 6.25e-6 s, and the 1.25e-5 s run against
   6.25e-6 s (how far the reference itself has converged); with TAOS_BEFORE=<checkout of the
   former kernel> the former kernel's dwells at 2e-4 and 1.25e-5 s are run from that source
   tree on this venv and compared with the same reference (``--no-dwells`` skips this part).
   Energy balance of a free swing with bearing friction (the test
   tests/test_taos3d.py::test_energy_balance_with_bearing_friction, at four steps; the former
   kernel's too with TAOS_BEFORE).
4. Modified LuGre over the whole 60 s (issue 24, point 6; ``--no-conv60`` skips it): engine
   angle at 8e-4, 4e-4, 2e-4 and 1e-4 s against 2.5e-5 and 1.25e-5 s references, the references
   against each other and against a 2.5e-5 s run whose commands are offset by 1e-10 rad (data
   sensitivity at a fixed step), for the shipped law (rational bristle-damping decay
   sigma_1 v_1 / (v_1 + s)), the same law with constant bristle damping (v_1 = 0) and, as a
   bench-local reference (kernels below, not shipped), the former exponential decay
   sigma_1 exp(-(s/v_1)^2), whose torque at a frozen bristle state falls with the slip rate
   above v_1 / sqrt 2: the massless bearing's implicit equation then folds with no fast
   branch to land on, and the limit of fine steps does not exist at the 1e-3 deg level
   (docs/theory/taos3d.md, why the decay is rational). ``--decay-impact`` alone: the planar
   model's sine dwells with the shipped decay against the former exponential (what the
   change moved).
5. Peer: MuJoCo (mujoco.rollout, native loop, one thread) with the same rigid engine (mass,
   c.g. and inertia of the Pinocchio model, pivot at the gimbal point O, gravity off as in
   TAOS where it is inside K_n) on two hinges (pitch about +y, yaw about -x, the TAOS axes)
   with dry friction (frictionloss = the bearing's Coulomb torque T_c), the feedline/gravity
   spring K_n as joint stiffness, and two position servos (kp = K_L R^2, the line stiffness
   at the engine; kv = kp / K_v, the actuator loop's first-order lag 1/K_v), implicitfast
   integrator, at 1 ms and 0.1 ms, driven by the same Green Run commands. The peer has no
   hydraulics, compliant gimbal or bearing slip: it is the cheaper model of the two.
6. Head to head (``--only-speed`` and the full run): TAOS at its default step and at the former
   default (4e-4 s, the same kernel: bit-identical there) and the peer at 1 ms in alternating rounds of the same process (``--repeat`` rounds), so that both see the
   same load; the best CPU time of each, their ratio, and the median of the rounds' ratios.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import statistics
import subprocess
import time
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_taos import commands, greenrun60  # noqa: E402  (the same 60 s profile and sampling)

from numba import cfunc, njit

from taos.friction import _vector as V
from taos.friction._slots import SLOT_SIGMA1, SLOT_V1
from taos.friction.registry import BEARING_SIG, TORQUE3_SIG
from taos.taos3d import load_taos_model
from taos.taos3d import dynamics as dy
from taos.taos3d.model import PITCH_AXIS, YAW_AXIS
from taos.taos3d.simulate import DEFAULT_DT_S, DWELL_DT_S, pack, run_samples

MODEL = "models/rs25_hotfire.toml"
FRICTION = "modified-lugre"
T_RUN = 60.0
REC_S = 4e-3  # record interval [s]: a whole multiple of every step here
OLD_DT = 2e-4  # the former kernel's step (TAOS_BEFORE dwells)
ALT_DT = 4e-4  # the former default (issue 44: now the dwells' step), half the step: speed and accuracy for comparison
REF_DT = 2.5e-5
T_ACC = 4.0


CPU = {}  # best process (CPU) time of the last timed() call [s]: on a shared machine it excludes waiting


def timed(fn, repeat):
    walls, cpus = [], []
    for _ in range(repeat):
        t0, c0 = time.perf_counter(), time.process_time()
        out = fn()
        walls.append(time.perf_counter() - t0)
        cpus.append(time.process_time() - c0)
    CPU["best"] = min(cpus)
    return out, min(walls), statistics.median(walls)


def taos_speed(tm, prof, dt, repeat):
    _, cmd = commands(prof, T_RUN, dt)
    pk = pack(tm)
    every = int(round(REC_S / dt))
    run_samples(tm, cmd[:11], dt, every, pk)  # compile / load the cache
    out, best, med = timed(lambda: run_samples(tm, cmd, dt, every, pk), repeat)
    n = len(cmd) - 1
    print(f"[taos3d] dt {dt:g} s: 60 s Green Run in {best:.3f} s wall (best of {repeat}; median {med:.3f} s) "
          f"= {T_RUN / best:.1f}x real time (median {T_RUN / med:.1f}x), {1e6 * best / n:.2f} us/step "
          f"(median {1e6 * med / n:.2f}), {n} steps; best CPU time {CPU['best']:.3f} s = {T_RUN / CPU['best']:.1f}x")
    return out


def errors(a, b):
    """max |d theta| [deg], max |d x_p| [mm], max |d F_L| [N], max |d T_f| [N m], rms |d theta| [deg]."""
    d = a - b
    return (math.degrees(np.abs(d[:, 0:2]).max()), 1e3 * np.abs(d[:, 2:4]).max(), np.abs(d[:, 4:6]).max(),
            np.abs(d[:, 6:8]).max(), math.degrees(np.sqrt((d[:, 0:2] ** 2).mean())))


def accuracy(prof):
    print(f"[accuracy] {T_ACC:g} s of the run, records every 8 ms, against dt = {REF_DT:g} s (this kernel): "
          f"max |d theta| deg, "
          f"max |d x_p| mm, max |d F_L| N, max |d T_f| N m, rms |d theta| deg")
    for law in (FRICTION, "coulomb-smooth"):
        tm = load_taos_model(MODEL, friction=law)

        def run(dt):
            _, cmd = commands(prof, T_ACC, dt)
            return run_samples(tm, cmd, dt, int(round(0.008 / dt)))  # every 8 ms: a multiple of every step
        ref = run(REF_DT)
        rows = [(f"dt {dt:g} s (this kernel)", run(dt)) for dt in (DEFAULT_DT_S, ALT_DT)]
        for name, a in rows:
            e = errors(a[:, :8], ref[:, :8])
            print(f"    {law:15s} {name:36s} {e[0]:.2e}  {e[1]:.2e}  {e[2]:7.1f}  {e[3]:7.1f}  {e[4]:.2e}")


DWELL_F = np.geomspace(0.5, 20.0, 8)  # [Hz]
DWELL_A = (0.05, 0.4)  # [deg]
DWELL_LAWS = (FRICTION, "coulomb-smooth")

DWELL_CODE = """
import json, sys, numpy as np
from taos.taos3d import load_taos_model
from taos.taos3d.simulate import taos_freqresp_family
out = {}
for law in %r:
    tm = load_taos_model(%r, friction=law)
    for dt in %r:
        fam = taos_freqresp_family(tm, np.array(%r), np.radians(%r), dt_max_s=dt)
        out[f"{law} {dt:g}"] = [[[v.real, v.imag] for v in r.engine] + [[v.real, v.imag] for v in r.piston] for r in fam]
json.dump(out, sys.stdout)
"""


def run_in_tree(code, tree=None):
    """Run ``code`` in a child interpreter on this venv with the source tree ``tree`` (default:
    this one) first on the path and as the working folder; returns its JSON on stdout."""
    env = dict(os.environ, PYTHONPATH=tree) if tree else None
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True, cwd=tree, env=env)
    return json.loads(res.stdout)


def dwells(dts, tree=None):
    """Engine and piston responses of DWELL_LAWS x DWELL_A x DWELL_F at each step, by the
    source tree ``tree`` (default: this one): {"law dt": (amp, 2 F) complex}."""
    out = run_in_tree(DWELL_CODE % (DWELL_LAWS, MODEL, tuple(dts), DWELL_F.tolist(), DWELL_A), tree)
    return {k: np.array(v)[..., 0] + 1j * np.array(v)[..., 1] for k, v in out.items()}


def dwell_accuracy():
    n = len(DWELL_F)
    print(f"[dwells] pitch sine dwells {DWELL_F[0]:g}-{DWELL_F[-1]:g} Hz ({n} points), max over the frequencies of "
          f"|d gain| dB / |d phase| deg against this kernel at 6.25e-6 s; engine | piston")
    new = dwells((DWELL_DT_S, 2e-4, 1.25e-5, 6.25e-6))
    rows = [(f"this kernel, dt {dt:g} s", new, dt) for dt in (DWELL_DT_S, 2e-4, 1.25e-5)]
    before = os.environ.get("TAOS_BEFORE")
    if before:
        old = dwells((OLD_DT, 1.25e-5), before)
        rows += [(f"former kernel, dt {dt:g} s", old, dt) for dt in (OLD_DT, 1.25e-5)]
    for law in DWELL_LAWS:
        ref = new[f"{law} {6.25e-6:g}"]
        for name, d, dt in rows:
            r = d[f"{law} {dt:g}"] / ref
            db, ph = np.abs(20 * np.log10(np.abs(r))), np.abs(np.degrees(np.angle(r)))
            cells = "   ".join(f"{a:g} deg: {db[k, :n].max():.3f} dB {ph[k, :n].max():.2f} deg | "
                               f"{db[k, n:].max():.3f} dB {ph[k, n:].max():.2f} deg" for k, a in enumerate(DWELL_A))
            print(f"    {law:15s} {name:30s} {cells}")
    law = FRICTION
    print(f"[dwells] {law}, {DWELL_A[0]:g} deg, engine gain [dB] at " + " ".join(f"{f:.3g}" for f in DWELL_F) + " Hz:")
    for name, d, dt in [("this kernel, dt 6.25e-06 s", new, 6.25e-6)] + rows:
        print(f"    {name:30s} " + " ".join(f"{v:7.3f}" for v in 20 * np.log10(np.abs(d[f'{law} {dt:g}'][0, :n]))))


ENERGY_CODE = """
import json, sys, numpy as np
sys.path.insert(0, %r)
from test_taos3d import _free_engine
from taos.model import load_model
from taos.taos3d import dynamics as dy
from taos.taos3d.simulate import rest_state
hot = load_model(%r)
out = {}
for law in %r:
    pk, energy = _free_engine(hot, law)
    for dt in %r:
        x = rest_state(pk)
        x[7:13] = [0, 0, 0, 0.03, -0.04, 0.002]
        E0 = energy(x, np.zeros(2))
        bs = np.zeros(getattr(dy, "N_BEARING", 6))  # 6 in the former kernel
        n = int(round(1.0 / dt))
        rec = np.empty((n + 1, len(dy.REC)))
        assert dy.integrate(pk.P, pk.fid, pk.fp, pk.avp, x, bs, np.zeros((n + 1, 2)), dt, 1, rec) == -1
        work = np.sum(0.5 * (rec[1:, 6:8] + rec[:-1, 6:8]) * np.diff(rec[:, 10:12], axis=0))
        out[f"{law} {dt:g}"] = (energy(x, bs[0:2]) + work - E0) / E0
json.dump(out, sys.stdout)
"""
ENERGY_LAWS = ("coulomb-smooth", "coulomb-switching", "dahl", FRICTION)


def energy_balance():
    """Free swing, 1 s (tests/test_taos3d.py::test_energy_balance_with_bearing_friction): energy
    left + work on the bearing - energy given, relative to the energy given, at four steps;
    the former kernel's too with TAOS_BEFORE."""
    tests = str(Path(__file__).resolve().parent.parent / "tests")
    dts = (8e-4, 4e-4, 2e-4, 1e-4)
    runs = [("this kernel", None)]
    if os.environ.get("TAOS_BEFORE"):
        runs.append(("former kernel", os.environ["TAOS_BEFORE"]))
    print("[energy] free swing 1 s, friction on: (energy left + work on the bearing - energy given) / energy given "
          "at dt " + ", ".join(f"{dt:g}" for dt in dts) + " s")
    for name, tree in runs:
        r = run_in_tree(ENERGY_CODE % (tests, MODEL, ENERGY_LAWS, dts), tree)
        for law in ENERGY_LAWS:
            print(f"    {name:14s} {law:18s} " + "  ".join(f"{r[f'{law} {dt:g}']:+.2e}" for dt in dts))


def head_to_head(tm, prof, repeat):
    """Point 6 of the module docstring: TAOS at the default step and at the former default
    ALT_DT (issue 44) against the MuJoCo peer at 1 ms, alternating within each of ``repeat``
    rounds (CPU time, ``time.process_time``)."""
    try:
        import mujoco
        from mujoco import rollout
    except ImportError:
        print("[head-to-head] skipped: mujoco is not installed (pip install -e .[bench])")
        return
    dt_m = 1e-3
    pk = pack(tm)
    m, d, s0, ctrl = _mujoco_run(mujoco, tm, prof, dt_m)
    runs, steps = {}, {}
    for dt in (DEFAULT_DT_S, ALT_DT):
        _, cmd = commands(prof, T_RUN, dt)
        every = int(round(REC_S / dt))
        run_samples(tm, cmd[:11], dt, every, pk)  # compile / load the cache
        runs[dt] = lambda cmd=cmd, dt=dt, every=every: run_samples(tm, cmd, dt, every, pk)
        steps[dt] = len(cmd) - 1
    runs["mujoco"] = lambda: rollout.rollout(m, d, s0[None], ctrl)
    rollout.rollout(m, d, s0[None], ctrl[:, :10])
    ct = {k: [] for k in runs}
    for _ in range(repeat):
        for k, f in runs.items():
            c0 = time.process_time()
            f()
            ct[k].append(time.process_time() - c0)
    cm = ct["mujoco"]
    print(f"[head-to-head] {repeat} alternating rounds, CPU time of the 60 s run; MuJoCo {mujoco.__version__} rollout "
          f"dt {dt_m:g} s best {min(cm):.4f} s = {T_RUN / min(cm):.1f}x real time")
    for dt in (DEFAULT_DT_S, ALT_DT):
        c = ct[dt]
        ratios = [b / a for a, b in zip(c, cm)]
        print(f"    TAOS dt {dt:g} s{' (default)' if dt == DEFAULT_DT_S else ' (former default)'}: best {min(c):.4f} s "
              f"= {T_RUN / min(c):.1f}x real time ({1e6 * min(c) / steps[dt]:.3f} us/step); TAOS / MuJoCo speed "
              f"{min(cm) / min(c):.2f} (best against best), median of the rounds {statistics.median(ratios):.2f}")


def mujoco_xml(tm, dt):
    eng, act = tm.base.engine, tm.base.actuator
    cg = tm.geometry.engine_cg_m
    J = tm.engine_inertia_cg
    kp = tm.line_load_stiffness_N_per_m * act.moment_arm_m ** 2
    kv = kp / act.loop_gain_per_s
    tc = tm.coulomb_torque_Nm
    lim = math.degrees(eng.gimbal_range_rad) + 1.0
    ax = lambda a: " ".join(f"{v:g}" for v in a)  # noqa: E731
    return f"""<mujoco model="rigid engine on two hinges (TAOS peer)">
  <compiler angle="degree"/>
  <option timestep="{dt}" gravity="0 0 0" integrator="implicitfast"/>
  <worldbody>
    <body name="engine" pos="0 0 0">
      <joint name="pitch" type="hinge" axis="{ax(PITCH_AXIS)}" frictionloss="{tc}"
             stiffness="{eng.rotational_stiffness_Nm_per_rad}" range="-{lim} {lim}" limited="true"/>
      <joint name="yaw" type="hinge" axis="{ax(YAW_AXIS)}" frictionloss="{tc}"
             stiffness="{eng.rotational_stiffness_Nm_per_rad}" range="-{lim} {lim}" limited="true"/>
      <inertial pos="{ax(cg)}" mass="{eng.mass_kg}"
                fullinertia="{J[0, 0]} {J[1, 1]} {J[2, 2]} {J[0, 1]} {J[0, 2]} {J[1, 2]}"/>
    </body>
  </worldbody>
  <actuator>
    <position joint="pitch" kp="{kp}" kv="{kv}"/>
    <position joint="yaw" kp="{kp}" kv="{kv}"/>
  </actuator>
</mujoco>"""


def _mujoco_run(mujoco, tm, prof, dt):
    """The MuJoCo peer's model, data, initial full-physics state and the 60 s command at step
    ``dt`` [s] (the command at each step's end), ready for ``rollout.rollout(m, d, s0[None], ctrl)``."""
    m = mujoco.MjModel.from_xml_string(mujoco_xml(tm, dt))
    d = mujoco.MjData(m)
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    s0 = np.empty(mujoco.mj_stateSize(m, spec))
    mujoco.mj_getState(m, d, s0, spec)
    _, cmd = commands(prof, T_RUN, dt)
    return m, d, s0, np.ascontiguousarray(cmd[1:][None, :, :])


def mujoco_peer(tm, prof, repeat, taos_rec):
    try:
        import mujoco
        from mujoco import rollout
    except ImportError:
        print("[mujoco] peer skipped: mujoco is not installed (pip install -e .[bench])")
        return
    for dt in (1e-3, 1e-4):
        m, d, s0, ctrl = _mujoco_run(mujoco, tm, prof, dt)
        rollout.rollout(m, d, s0[None], ctrl[:, :10])  # warm up
        (state, _), best, med = timed(lambda: rollout.rollout(m, d, s0[None], ctrl), repeat)
        n = ctrl.shape[1]
        th = state[0, :, 1:3]  # qpos after time: pitch, yaw [rad]
        every = int(round(REC_S / dt))
        k = min(taos_rec.shape[0] - 1, th[every - 1::every].shape[0])
        diff = np.degrees(np.sqrt(((th[every - 1::every][:k] - taos_rec[1:k + 1, 0:2]) ** 2).mean()))
        print(f"[mujoco {mujoco.__version__}] dt {dt:g} s, rollout (native, 1 thread): 60 s in {best:.3f} s wall "
              f"(best of {repeat}; median {med:.3f} s) = {T_RUN / best:.1f}x real time (median {T_RUN / med:.1f}x), "
              f"{1e6 * best / n:.2f} us/step, best CPU time {CPU['best']:.3f} s = {T_RUN / CPU['best']:.1f}x; peak angles {np.degrees(np.abs(th).max(axis=0)).round(3)} deg, "
              f"rms angle difference from TAOS {diff:.3f} deg")
        if dt == 1e-3:  # the same peer stepped from Python, as a user script would
            d2 = mujoco.MjData(m)
            t0 = time.perf_counter()
            for i in range(n):
                d2.ctrl[:] = ctrl[0, i]   # the command at step i's end
                mujoco.mj_step(m, d2)
            w = time.perf_counter() - t0
            print(f"[mujoco {mujoco.__version__}] dt {dt:g} s, mj_step from a Python loop: {T_RUN / w:.1f}x real time, "
                  f"{1e6 * w / n:.2f} us/step")


# -- the former bristle-damping decay (a bench-local REFERENCE, not a shipped law) -------------------
@njit(inline="always")
def _sigma1_exponential(s, p):
    """The former decay sigma_1(s) = sigma_1 exp(-(s/v_1)^2) [N m s/rad] (Canudas de Wit et al.
    1995, eq. 9), kept here only to show why it was replaced: s sigma_1(s) peaks at
    v_1 / sqrt 2 and falls to 0, so the torque at a frozen bristle state falls with the slip
    rate and the massless bearing has impasse points (docs/theory/taos3d.md). The shipped
    law is the rational decay of taos.friction._kernels._sigma1."""
    v1 = p[SLOT_V1]
    return p[SLOT_SIGMA1] * math.exp(-(s / v1) ** 2)


@njit(inline="always")
def _exponential_coeffs(s, p, dt, kappa):
    return V.bristle_coeffs(s, p, dt, kappa, _sigma1_exponential(s, p))


@cfunc(BEARING_SIG, cache=True)
def exponential_bearing(p, Kc, d0, d1, z0, z1, dt, s0):
    return V.coeff_bearing_step(_exponential_coeffs, V.lugre_rho, True, 1.0, p, Kc, d0, d1, z0, z1, dt, s0)


@cfunc(TORQUE3_SIG, cache=True)
def exponential_torque3(w0, w1, z0, z1, dz0, dz1, t0, t1, p):
    return V.bristle_torque3(w0, w1, z0, z1, dz0, dz1, _sigma1_exponential(math.sqrt(w0 * w0 + w1 * w1), p), p)


def conv60_variants():
    """(name, model, packed) for the shipped modified LuGre (rational decay), the same with
    constant bristle damping (v_1 = 0) and with the former exponential decay (reference)."""
    import dataclasses
    tm = load_taos_model(MODEL, friction=FRICTION)
    law = tm.base.friction
    const = tm.replace(base=tm.base.replace(friction=dataclasses.replace(law, damping_decay_velocity_rad_s=0.0)))
    pk = pack(tm)
    expo = dataclasses.replace(pk, fid=(exponential_bearing, pk.fid[1], exponential_torque3))
    return [("shipped, sigma_1 v_1/(v_1 + s)", tm, pk), ("sigma_1 constant (v_1 = 0)", const, pack(const)),
            ("former (reference), sigma_1 exp(-(s/v_1)^2)", tm, expo)]


def decay_impact():
    """``--decay-impact``: what replacing the exponential decay by the rational one changed in
    the planar (simplex) model: engine sine-dwell responses of the hot-fire and ambient files
    with the shipped law against the former exponential decay (registered at run time as
    ``modified-lugre-exponential``, same parameters, planar kernel below), ratio in dB and
    deg; and the shipped law's passivity and monotonicity in both files."""
    from taos.friction import _kernels as K
    from taos.friction import registry
    from taos.friction._laws import ModifiedLuGre
    from taos.friction.registry import RATES_SIG, FrictionLawEntry
    from taos.model import load_model
    from taos.planar.freqresp import sine_dwell_family

    class ExponentialDecay(ModifiedLuGre):  # the same fields; only sigma_1(v) differs
        name = "modified-lugre-exponential"

        def _sigma1(self, v):
            v1 = self.damping_decay_velocity_rad_s
            return self.bristle_damping_Nms_per_rad * np.exp(-(np.asarray(v, float) / v1) ** 2)

    @cfunc(RATES_SIG)
    def rates(v, z, t_app, p):
        dz = K.lugre_zdot(v, z, p)
        return dz, p[K.SLOT_SIGMA0] * z + _sigma1_exponential(abs(v), p) * dz + p[K.SLOT_SIGMA2] * v

    e = registry.get(FRICTION)
    registry.register(FrictionLawEntry(ExponentialDecay.name, ExponentialDecay, rates, e.zdot3, exponential_torque3,
                                       exponential_bearing), replace_existing=True)
    f = np.array([0.5, 1.0, 2.0, 4.0, 5.0, 7.0, 10.0])
    amps = np.radians([0.05, 0.2, 0.8])
    v = np.geomspace(1e-7, 1e2, 4001)  # [rad/s]
    for mf in (MODEL, "models/rs25_ambient.toml"):
        m = load_model(mf)
        law = m.with_friction(FRICTION).friction
        ds1 = np.diff(v * law._sigma1(v))
        print(f"[decay-impact] {mf}: shipped (rational) decay passive (LuGre's condition) at every rate "
              f"1e-7-1e2 rad/s: {bool(law.passive_at(v).all())}, sufficient-bound ratios "
              f"{', '.join(f'{r:.3f}' for r in law.passivity_ratios())}; s sigma_1(s) non-decreasing: "
              f"{bool((ds1 >= 0).all())}")
        new, old = (sine_dwell_family(m.with_friction(name), f, amps) for name in (FRICTION, ExponentialDecay.name))
        print(f"[decay-impact] {mf}, planar engine response, shipped (rational) / former (exponential) decay at "
              + " ".join(f"{v:g}" for v in f) + " Hz: dB | deg")
        for a, rn, ro in zip(np.degrees(amps), new, old):
            r = rn.engine / ro.engine
            print(f"    {a:.2f} deg: " + " ".join(f"{v:+.2f}" for v in 20 * np.log10(np.abs(r))) + " | "
                  + " ".join(f"{v:+.1f}" for v in np.degrees(np.angle(r))))


def convergence60(prof):
    """Point 4 of the module docstring."""
    refs, dts = (2.5e-5, 1.25e-5), (DEFAULT_DT_S, ALT_DT, 2e-4, 1e-4)
    print(f"[conv60] modified LuGre, {T_RUN:g} s two-axis Green Run, records every 8 ms: max |d theta| [deg] "
          f"against the {refs[-1]:g} s run; real time at {DEFAULT_DT_S:g} s (under load)")

    def run(tm, pk, dt, offset=0.0):
        _, cmd = commands(prof, T_RUN, dt)
        t0 = time.perf_counter()
        out = run_samples(tm, cmd + offset, dt, int(round(0.008 / dt)), pk)
        return out[:, 0:2], time.perf_counter() - t0

    for name, tm, pk in conv60_variants():
        run(tm, pk, DEFAULT_DT_S)  # compile / load the cache
        ref, _ = run(tm, pk, refs[-1])
        err = lambda a: math.degrees(np.abs(a - ref).max())  # noqa: E731
        cells = []
        for dt in dts:
            a, wall = run(tm, pk, dt)
            cells.append(f"{dt:g} s {err(a):.2e}")
            if dt == DEFAULT_DT_S:
                rt = T_RUN / wall
        r0, _ = run(tm, pk, refs[0])
        r1, _ = run(tm, pk, refs[0], 1e-10)
        print(f"    {name:34s} " + "  ".join(cells) + f"  | {refs[0]:g} s {err(r0):.2e}; {refs[0]:g} s with "
              f"commands +1e-10 rad vs without {math.degrees(np.abs(r1 - r0).max()):.2e} | {rt:.1f}x real time")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--no-dwells", action="store_true", help="skip the sine-dwell accuracy part")
    ap.add_argument("--no-conv60", action="store_true", help="skip the 60 s modified-LuGre convergence part")
    ap.add_argument("--only-conv60", action="store_true", help="run the 60 s convergence part alone")
    ap.add_argument("--only-speed", action="store_true", help="run the speed part and the MuJoCo peer alone")
    ap.add_argument("--only-head-to-head", action="store_true",
                    help="run the alternating TAOS / MuJoCo rounds alone (point 6)")
    ap.add_argument("--decay-impact", action="store_true",
                    help="run only the planar impact of the rational decay against the former exponential")
    args = ap.parse_args()
    up = subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip()
    print(f"machine load (uptime): {up}")
    tm = load_taos_model(MODEL, friction=FRICTION)
    print(f"model: hot fire, gimbal {tm.stiffness_source}, friction {tm.base.friction.name}, "
          f"T_c = {tm.coulomb_torque_Nm:.0f} N m; default step {DEFAULT_DT_S:g} s; {len(dy.REC)} recorded columns")
    prof = greenrun60()
    if args.decay_impact:
        decay_impact()
        return
    if args.only_conv60:
        convergence60(prof)
        return
    if args.only_head_to_head:
        head_to_head(tm, prof, args.repeat)
        print(f"machine load (uptime): {subprocess.run(['uptime'], capture_output=True, text=True).stdout.strip()}")
        return
    rec = taos_speed(tm, prof, DEFAULT_DT_S, args.repeat)
    taos_speed(tm, prof, ALT_DT, args.repeat)
    mujoco_peer(tm, prof, args.repeat, rec)
    head_to_head(tm, prof, max(args.repeat, 5))
    if args.only_speed:
        print(f"machine load (uptime): {subprocess.run(['uptime'], capture_output=True, text=True).stdout.strip()}")
        return
    accuracy(prof)
    if not args.no_conv60:
        convergence60(prof)
    energy_balance()
    if not args.no_dwells:
        dwell_accuracy()
    print(f"machine load (uptime): {subprocess.run(['uptime'], capture_output=True, text=True).stdout.strip()}")


if __name__ == "__main__":
    main()
