"""TAOS speed and physics figures (writes nothing; paste the output into benchmarks/RESULTS.md).

Run:  .venv/bin/python benchmarks/bench_taos.py [--naive-seconds 0.05] [--physics-only]

1. Speed: 60 s two-axis Green Run profile (models/profiles/greenrun_two_axis.toml repeated to
   60 s), hot-fire FEM gimbal matrices, modified-LuGre bearing friction, dt = 2e-4 s: simulated
   seconds per wall second of the compiled condensed integrator (one core: the run is serial).
   Peer baseline, same run: scipy solve_ivp (RK45 and LSODA) on the *uncondensed* right-hand
   side, in which the lower gimbal half keeps its rotational inertia J_b about the bearing
   (J_b phi'' = K_phi (psi(e) - phi) - T_f(phi', z)), so the bearing is an ODE; the engine,
   actuator and friction terms are the same compiled functions. It runs a short window and
   is extrapolated; the two models are compared over that window.
2. Convergence: the same 10 s with dt and dt/2.
3. Physics figures: two-axis dither, out-of-plane effect vs the planar model.
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np
import scipy.integrate

from taos.planar.freqresp import sine_dwell_grid
from taos.linear import gain_db
from taos.profiles import Sequence, TwoAxis, load_profile
from taos.taos3d import load_taos_model, two_axis_dwell
from taos.taos3d import dynamics as dy
from taos.taos3d.simulate import pack, rest_state, run_samples

DT = 2e-4
J_HALF = 0.24  # lower-half rotational inertia about the bearing [kg m^2] (24.5 kg, 0.36 m x 0.145 m disc)


def greenrun60():
    p = load_profile("models/profiles/greenrun_two_axis.toml")
    return TwoAxis(Sequence((p.pitch,) * 2), Sequence((p.yaw,) * 3), "Green Run x2, 60 s")


def commands(profile, T, dt):
    n = int(round(T / dt))
    t = np.arange(n + 1) * dt
    return t, np.ascontiguousarray(np.asarray(profile(t)).T)


def naive_rhs_factory(tm, cmd_fun):
    """Uncondensed ODE: y = (x, phi (2), phi_dot (2), z (2))."""
    pk = pack(tm)
    P, fp, avp = pk.P, pk.fp, pk.avp
    law = tm.base.friction.entry  # the vector kernels (Python-callable C callbacks)
    n = pk.n_state
    Kphi = np.linalg.inv(P.bearing_compliance)
    aux = np.empty(dy.N_AUX)
    from taos.planar import avionics as av

    def f(t, y):
        x = y[:n]
        phi, w, z = y[n:n + 2], y[n + 2:n + 4], y[n + 4:n + 6]
        ps = np.array(dy.pose_psi(x, P))
        T = Kphi @ (ps - phi)  # chain torque on the bearing
        c = cmd_fun(t)
        dx = np.empty(n)
        dy.rhs(x, T[0], T[1], av.apply(c[0], avp), av.apply(c[1], avp), P, dx, aux)
        dz = law.zdot3(w[0], w[1], z[0], z[1], fp)
        tf = law.torque3(w[0], w[1], z[0], z[1], dz[0], dz[1], 0.0, 0.0, fp)
        out = np.empty_like(y)
        out[:n] = dx
        out[n:n + 2] = w
        out[n + 2:n + 4] = (T - np.array(tf)) / J_HALF
        out[n + 4:n + 6] = dz
        return out
    return f, n


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--naive-seconds", type=float, default=0.05)
    ap.add_argument("--physics-only", action="store_true",
                    help="only the physics figures (part 3): no timing, no scipy baseline")
    args = ap.parse_args()
    tm = load_taos_model("models/rs25_hotfire.toml", friction="modified-lugre")
    print(f"model: hot fire, gimbal {tm.stiffness_source}, friction {tm.base.friction.name}, "
          f"T_c = {tm.coulomb_torque_Nm:.0f} N m (lambda {tm.friction_scale:.4f})")
    if not args.physics_only:
        timing_and_baseline(tm, args)
    physics_figures(tm)


def timing_and_baseline(tm, args):
    """Parts 1 and 2: speed against the scipy baseline, and step convergence."""
    prof = greenrun60()
    t, cmd = commands(prof, 60.0, DT)
    run_samples(tm, cmd[:11], DT, 10)  # compile / load cache
    t0 = time.perf_counter()
    out = run_samples(tm, cmd, DT, 10)
    wall = time.perf_counter() - t0
    print(f"[speed] condensed RK4 + implicit bearing, dt {DT}: 60 s simulated in {wall:.2f} s wall "
          f"= {60 / wall:.1f} x real time ({len(cmd) - 1} steps, {1e6 * wall / (len(cmd) - 1):.2f} us/step)")
    print(f"        peak engine angle pitch {np.degrees(np.abs(out[:, 0]).max()):.3f} deg, yaw "
          f"{np.degrees(np.abs(out[:, 1]).max()):.3f} deg; peak |T_f| "
          f"{np.hypot(out[:, 6], out[:, 7]).max():.0f} N m")

    # convergence: 10 s with dt and dt/2
    _, c1 = commands(prof, 10.0, DT)
    _, c2 = commands(prof, 10.0, DT / 2)
    a = run_samples(tm, c1, DT, 10)
    b = run_samples(tm, c2, DT / 2, 20)
    print(f"[convergence] 10 s, dt vs dt/2: max |d theta| = {np.degrees(np.abs(a[:, :2] - b[:, :2]).max()):.2e} deg, "
          f"max |d x_p| = {1e3 * np.abs(a[:, 2:4] - b[:, 2:4]).max():.2e} mm, "
          f"max |d T_f| = {np.abs(a[:, 6:8] - b[:, 6:8]).max():.1f} N m")

    # naive baseline
    Tn = args.naive_seconds
    f, n = naive_rhs_factory(tm, lambda tt: np.asarray(prof(np.array([tt])))[:, 0])
    y0 = np.zeros(n + 6)
    y0[:n] = rest_state(pack(tm))
    f(0.0, y0)
    _, cn = commands(prof, Tn, DT)
    ref = run_samples(tm, cn, DT, 50)
    tt = np.arange(ref.shape[0]) * DT * 50
    for method in ("RK45", "LSODA"):
        t0 = time.perf_counter()
        sol = scipy.integrate.solve_ivp(f, (0, Tn), y0, method=method, t_eval=tt, rtol=1e-6, atol=1e-9,
                                        max_step=DT * 5)
        w = time.perf_counter() - t0
        th = []
        for k in range(sol.y.shape[1]):
            r = np.empty(3)
            dy._logq(sol.y[3:7, k].copy(), r)
            th.append([r[1], -r[0]])
        th = np.array(th)
        m = min(len(th), len(ref))
        err = np.degrees(np.abs(th[:m] - ref[:m, :2]).max())
        print(f"[naive] solve_ivp {method} (uncondensed, J_b = {J_HALF} kg m^2): {Tn} s simulated in {w:.1f} s "
              f"wall = {Tn / w:.4f} x real time, {sol.nfev} rhs calls, status {sol.status}; "
              f"max |theta_naive - theta_condensed| = {err:.2e} deg; speed-up of the condensed "
              f"integrator {(w / Tn) / (wall / 60):.0f}x")



def physics_figures(tm):
    """Part 3: two-axis dither and the out-of-plane effect (LuGre)."""
    m = tm.base.with_friction("lugre")
    tl = tm.with_friction("lugre")
    print("[dither] LuGre, pitch 0.5 Hz alone vs with yaw 0.4 deg at 5 Hz: pitch engine gain dB")
    for a_deg in (0.02, 0.05, 0.1, 0.4):
        a = math.radians(a_deg)
        _, e = two_axis_dwell(tl, [[a, 0], [a, math.radians(0.4)]], [[0.5, 5.0], [0.5, 5.0]], settle_s=1.0,
                              measure_cycles=1)
        print(f"    {a_deg:5.2f} deg: alone {gain_db(e[0]):7.2f}  with yaw dither {gain_db(e[1]):7.2f}")
    print("[out-of-plane] LuGre, equal friction (hot fire lambda = 1), 1 Hz pitch: engine gain dB")
    for a_deg in (0.02, 0.05, 0.1, 0.4):
        a = math.radians(a_deg)
        _, pl = sine_dwell_grid(m, [a], [1.0], "pitch", settle_s=1.0, measure_cycles=1)
        _, e = two_axis_dwell(tl, [[a, 0], [a, math.radians(0.4)]], [[1.0, 5.0], [1.0, 5.0]], settle_s=1.0,
                              measure_cycles=1)
        print(f"    {a_deg:5.2f} deg: planar {gain_db(pl[0, 0]):7.2f}  3-D one axis {gain_db(e[0]):7.2f}  "
              f"3-D with yaw 0.4 deg 5 Hz {gain_db(e[1]):7.2f}")


if __name__ == "__main__":
    main()
