#!/usr/bin/env python
"""Make ``independent_record.csv``: a pitch Green Run style sine-dwell record made WITHOUT taos.

Purpose: a test record for ``taos fit`` that this project's simulator did not make (the
scikit-rf practice of keeping a reference with the independent script that made it). The
equations are written here from the theory pages (docs/theory/simplex.md, avionics.md,
friction.md, and the limits of taos/planar/saturation.py's docstring), integrated by
``scipy.integrate.solve_ivp`` (adaptive RK45), with no import of taos. Values are written
out in SI from the shipped hardware sets (models/actuators/tvc_actuator.toml,
models/friction/rs25_gimbal.toml, the engine of models/rs25_*.toml), with a load path and
friction level that are NEITHER shipped model's:

* load stiffness K_L = 160,000 lbf/in (ambient 115,000, hot fire 205,000), load damping
  ratio 0.005;
* modified LuGre friction at T_c = T_s = 90,000 in-lbf (ambient 2,185, hot fire 117,525), its
  bristle stiffness and damping scaled from the set's 144,000 in-lbf reference with the level.

State x = (q, q', p_f, P_L, x_p, v_p, theta, omega, z); equations (SI)::

    c' = g_x(|c_q|) c_q,  c_q = LSB trunc(theta_c / LSB)           avionics (12 bits over 21 deg)
    u_v = K_v (R c' - x_p) - K_pf (P_L - p_f),  clipped to +-v_max  valve input (rate limit)
    q'' = w_v^2 (u_v - q) - 2 zeta_v w_v q'                         servovalve
    p_f' = (P_L - p_f) / tau_pf                                     pressure-feedback washout
    (V_t / 4 beta) P_L' = A q s(d) - (K_c + C_l) P_L - A v_p - Q_r  continuity, s(d) = sqrt law,
                                                                    d = (P_s - sgn(q) P_L) / P_s
    M_p v_p' = A P_L - F_L - B_p v_p,  F_L = K_L (x_p - R theta) + c_L (v_p - R omega)
    J theta'' = R F_L - K_n theta - T_f                             engine on its gimbal
    z' = v - sigma_0 |v| z / g(v),  g = T_c h(v),  h = (2/pi) asin(min(1, |v| / V_d))
    T_f = sigma_0 z + sigma_1 v_1 / (v_1 + |v|) z' + sigma_2 v      modified LuGre

with c_L = 2 zeta_L sqrt(K_L R^2 J) / R^2. Profile: the notional Green Run pitch dwells (0.4 deg
at 0.5, 1, 2, 4, 7 Hz; 0.8 deg at 10, 14 Hz), one after the other (each starts and ends at a zero of the command). Recorded
at 500 Hz with Gaussian noise (piston 0.001 in rms, engine 0.004 deg rms, engine angle offset
0.02 deg: string pots have no absolute reference), seed 29.

Usage: ``python tests/data/make_independent_record.py`` (about a minute); writes
``tests/data/independent_record.csv`` beside this script, its true values in the header.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp

IN = 0.0254
LBF = 4.4482216152605
PSI = LBF / IN ** 2
DEG = math.pi / 180
INLBF = LBF * IN

# -- the record's truth (neither shipped model's) ----------------------------------------------
K_L = 160000 * LBF / IN           # load stiffness [N/m]
ZETA_L = 0.005                     # load damping ratio
T_C = 90000 * INLBF                # Coulomb (= static) friction torque [N m]

# -- engine (models/rs25_*.toml [engine]) -------------------------------------------------------
J = 12396.0                        # pitch inertia about the gimbal [kg m^2]
K_N = 5e5                          # rotational stiffness (feedlines) [N m/rad]
R = 0.8                            # moment arm [m]

# -- actuator (models/actuators/tvc_actuator.toml) ----------------------------------------------
A = 15 * IN ** 2
P_S = 3000 * PSI
BETA = 150000 * PSI
V_T = 100 * IN ** 3
M_P = 45.0
B_P = 1e4
K_V = 20.0
W_V = 2 * math.pi * 100.0
ZETA_V = 0.7
K_C = 5e-12
C_LEAK = 0.0
K_PF = 1e-8
TAU_PF = 0.15
V_MAX = 20 * IN
P_R = 3000 * PSI
K_R = 5e-10
EPS_SQRT = 0.05                    # square-root law made linear within 5 % of stall (numerics)

# -- friction (models/friction/rs25_gimbal.toml, scaled from 144,000 in-lbf to T_C) --------------
SCALE = T_C / (144000 * INLBF)
SIGMA0 = 1.3e7 * SCALE
SIGMA1 = 4e5 * SCALE
V1 = 3 * DEG
SIGMA2 = 0.0
V_D = 0.3 * DEG

# -- avionics (models/rs25_*.toml [avionics]) ---------------------------------------------------
LSB = 21 * DEG / 2 ** 12
X_TAB = np.array([0, 0.02, 0.1, 0.5, 1, 2, 5, 10.5]) * DEG
G_TAB = np.array([0.97, 0.95, 0.95, 0.955, 0.97, 0.985, 0.995, 1.0])

C_L = 2 * ZETA_L * math.sqrt(K_L * R * R * J) / (R * R)
DWELLS = ((0.5, 0.4, 4), (1, 0.4, 6), (2, 0.4, 10), (4, 0.4, 16), (7, 0.4, 21), (10, 0.8, 30), (14, 0.8, 42))
FS = 500.0


def avionics(theta_c: float) -> float:
    cq = LSB * math.trunc(theta_c / LSB)
    return float(np.interp(abs(cq), X_TAB, G_TAB)) * cq


def friction(v: float, z: float) -> tuple[float, float]:
    """(z', T_f) of the modified LuGre law; |v| / h(v) -> pi V_d / 2 as v -> 0."""
    av = abs(v)
    if av < 1e-9 * V_D:
        ratio = math.pi * V_D / 2 / T_C
    else:
        ratio = av / (T_C * (2 / math.pi) * math.asin(min(1.0, av / V_D)))
    zd = v - SIGMA0 * ratio * z
    return zd, SIGMA0 * z + SIGMA1 * V1 / (V1 + av) * zd + SIGMA2 * v


def sqrt_law(d: float) -> float:
    return math.copysign(math.sqrt(abs(d)), d) if abs(d) >= EPS_SQRT else d / math.sqrt(EPS_SQRT)


def rhs(t, x, cmd):
    q, qd, pf, pl, xp, vp, th, om, z = x
    uv = K_V * (R * avionics(cmd(t)) - xp) - K_PF * (pl - pf)
    uv = min(max(uv, -V_MAX), V_MAX)
    d = (P_S - math.copysign(1.0, q) * pl) / P_S
    qr = K_R * (abs(pl) - P_R) * math.copysign(1.0, pl) if abs(pl) > P_R else 0.0
    fl = K_L * (xp - R * th) + C_L * (vp - R * om)
    zd, tf = friction(om, z)
    return [qd, W_V ** 2 * (uv - q) - 2 * ZETA_V * W_V * qd, (pl - pf) / TAU_PF,
            4 * BETA / V_T * (A * q * sqrt_law(d) - (K_C + C_LEAK) * pl - A * vp - qr),
            vp, (A * pl - fl - B_P * vp) / M_P, om, (R * fl - K_N * th - tf) / J, zd]


def make(seed: int = 29):
    t_all, c_all, x_all = [], [], []
    x = np.zeros(9)
    t0 = 0.0
    for f, amp_deg, cycles in DWELLS:
        dur = cycles / f
        n = int(round(dur * FS))
        cmd = lambda t, t0=t0, f=f, a=amp_deg * DEG: a * math.sin(2 * math.pi * f * (t - t0))  # noqa: E731
        te = t0 + np.arange(n) / FS
        sol = solve_ivp(rhs, (t0, t0 + n / FS), x, method="RK45", t_eval=te, args=(cmd,), rtol=1e-7,
                        atol=1e-10, max_step=2e-4)
        if not sol.success:
            raise RuntimeError(sol.message)
        t_all.append(te)
        c_all.append(np.array([cmd(t) for t in te]))
        x_all.append(sol.y)
        x = solve_ivp(rhs, (te[-1], t0 + n / FS), sol.y[:, -1], method="RK45", args=(cmd,), rtol=1e-7,
                      atol=1e-10, max_step=2e-4).y[:, -1]
        t0 += n / FS
        print(f"{f:5.1f} Hz dwell done ({t0:.1f} s)")
    t = np.concatenate(t_all)
    c = np.concatenate(c_all)
    y = np.concatenate(x_all, axis=1)
    rng = np.random.default_rng(seed)
    piston = y[4] / IN + 0.001 * rng.standard_normal(t.size)
    engine = y[6] / DEG + 0.02 + 0.004 * rng.standard_normal(t.size)
    return t, c / DEG, piston, engine


HEADER = """# condition = "independent reference"
# synthetic = true
# engine_angle_reference = "relative"
# description = "INDEPENDENT record made by tests/data/make_independent_record.py (scipy solve_ivp, no taos code)"
# true_load_stiffness = "160000 lbf/in"
# true_coulomb_torque = "90000 in*lbf"
# friction_model = "modified-lugre"
# piston_noise_rms = "0.001 in"
# engine_noise_rms = "0.004 deg"
# engine_offset_deg = "0.02"
# seed = 29
time [s],pitch_command [deg],pitch_piston [in],pitch_engine [deg]
"""


def main() -> None:
    t, c, p, e = make()
    out = Path(__file__).with_name("independent_record.csv")
    rows = "\n".join(f"{a:.6f},{b:.7g},{x:.7g},{y:.7g}" for a, b, x, y in zip(t, c, p, e))
    out.write_text(HEADER + rows + "\n")
    print(f"wrote {out} ({t.size} samples)")


if __name__ == "__main__":
    main()
