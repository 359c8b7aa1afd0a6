"""Display kinematics: a recorded :class:`~taos.planar.simulate.TimeHistory` -> per-frame poses and colours.

Engine: rotation Ry(s theta_pitch) Rx(-s theta_yaw) about the gimbal pivot (s = ``angle_scale``,
1 = true motion), so each clevis moves by R s theta along its actuator line
(:mod:`taos.viewer.geometry`).

Load path: the simplex model lumps every compliance outside the actuator position loop into
K_L with F_L = K_L (x_p - R theta) (:mod:`taos.planar.simplex`); its deflection is
delta = x_p - R theta [m]. It is drawn at the structure-side attach point, which is pushed
back along the actuator line by k delta (k = ``deflection_scale``); the actuator spans that
point and the engine clevis, so the drawn rod stroke is |C - S'| - L0 ~ s R theta + k delta,
equal to the recorded piston position x_p when s = k = 1 (tested). The lower half turns with
the engine, the upper half stays with the structure. For a 3-D TAOS run (which records the
halves' deflections u_upper, u_lower = K^-1 W [m]) the upper half is drawn displaced by
g u_upper and the engine (with the lower half) by g (u_upper + u_lower), g =
``gimbal_scale``; the planar model has no separate gimbal compliance, so its halves stay put.

Colours: friction state per axis from the friction rate and torque: *stuck* where the engine
rate |d theta/dt| < ``stick_rate_rad_s`` while friction carries torque
(|T_f| > 2 % of the run's peak), else *slipping*; with no friction torque nothing is stuck.
Actuator colour: load force F_L relative to the run's peak |F_L| (red pushing, blue pulling,
grey unloaded).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from .geometry import EngineDrawing, geometry_for_run

AXES = ("pitch", "yaw")

STUCK_RGB = np.array([0.86, 0.12, 0.08])
SLIP_RGB = np.array([0.12, 0.72, 0.25])
IDLE_RGB = np.array([0.62, 0.62, 0.66])
PUSH_RGB = np.array([0.92, 0.22, 0.08])
PULL_RGB = np.array([0.12, 0.35, 0.92])


@dataclass(frozen=True, eq=False)
class ViewerFrames:
    """Frames of the 3-D view, resampled to ``fps`` on the run's own time base.

    Arrays per axis are (2, n) or (2, n, k) with axis 0 = (pitch, yaw); a single-axis run has
    zero yaw. Lengths [m], angles [rad], time [s].
    """

    t_s: np.ndarray                 # (n,) keyframe times, the run's time base
    engine_quat_xyzw: np.ndarray    # (n, 4) engine orientation
    engine_rad: np.ndarray          # (2, n) recorded engine angles (unscaled)
    piston_m: np.ndarray            # (2, n) recorded piston positions
    deflection_m: np.ndarray        # (2, n) load-path deflection x_p - R theta (true)
    structure_attach_m: np.ndarray  # (2, n, 3) displayed structure attach S' (deflected)
    clevis_m: np.ndarray            # (2, n, 3) engine clevis C
    actuator_quat_xyzw: np.ndarray  # (2, n, 4) rotation taking local +z to the unit vector S' -> C
    stroke_m: np.ndarray            # (2, n) displayed rod stroke |C - S'| - L0
    stuck: np.ndarray               # (2, n) bool friction state
    force_fraction: np.ndarray      # (2, n) F_L / max |F_L| in [-1, 1]
    angle_scale: float
    deflection_scale: float
    upper_gimbal_m: np.ndarray | None = None   # (n, 3) displayed upper-half translation (3-D runs)
    engine_offset_m: np.ndarray | None = None  # (n, 3) displayed engine/lower-half translation
    gimbal_scale: float = 0.0                  # gimbal-half deflection exaggeration (0: none drawn)

    def gimbal_rgb(self) -> np.ndarray:
        """(n, 3) colour of the gimbal halves: stuck if any axis is stuck."""
        return np.where(self.stuck.any(axis=0)[:, None], STUCK_RGB, SLIP_RGB)

    def pin_rgb(self) -> np.ndarray:
        """(2, n, 3) per-axis friction-state colour."""
        return np.where(self.stuck[..., None], STUCK_RGB, SLIP_RGB)

    def actuator_rgb(self) -> np.ndarray:
        """(2, n, 3) actuator colour by load force."""
        f = self.force_fraction[..., None]
        return np.where(f >= 0, IDLE_RGB + f * (PUSH_RGB - IDLE_RGB), IDLE_RGB - f * (PULL_RGB - IDLE_RGB))


def _axis_arrays(th, name: str) -> np.ndarray:
    a = np.asarray(getattr(th, name), float)
    out = np.zeros((2, a.shape[1]))
    for i, ax in enumerate(th.axes):
        out[AXES.index(ax)] = a[i]
    return out


def engine_rotation(theta_pitch, theta_yaw) -> Rotation:
    """Engine orientation Ry(theta_pitch) Rx(-theta_yaw) (arrays of angles [rad])."""
    # extrinsic x then y: R = Ry(theta_pitch) @ Rx(-theta_yaw)
    return Rotation.from_euler("xy", np.column_stack([-np.asarray(theta_yaw), theta_pitch]))


def _z_to(u: np.ndarray) -> Rotation:
    """Rotations taking +z to unit vectors u (n, 3), valid away from u = +z (actuators point down)."""
    flip = Rotation.from_rotvec(np.tile([np.pi, 0.0, 0.0], (u.shape[0], 1)))  # +z -> -z
    down = np.array([0.0, 0.0, -1.0])
    axis = np.cross(down, u)
    s = np.linalg.norm(axis, axis=1)
    ang = np.arctan2(s, u @ down)
    with np.errstate(invalid="ignore", divide="ignore"):
        rv = np.where(s[:, None] > 1e-15, axis / s[:, None] * ang[:, None], 0.0)
    return Rotation.from_rotvec(rv) * flip


#: displayed peak load-path deflection [m] when the exaggeration is chosen automatically
AUTO_DEFLECTION_M = 0.15


def auto_deflection_scale(peak_deflection_m: float) -> float:
    """A 1-2-5 exaggeration that draws the run's peak load-path deflection near 0.15 m (1 to 1000)."""
    if not peak_deflection_m > 0:
        return 1.0
    raw = AUTO_DEFLECTION_M / peak_deflection_m
    e = math.floor(math.log10(raw))
    nice = max(m * 10 ** e for m in (1, 2, 5) if m * 10 ** e <= raw) if raw >= 1 else 1.0
    return float(min(max(nice, 1.0), 1000.0))


#: displayed peak gimbal-half deflection [m] when that exaggeration is chosen automatically
AUTO_GIMBAL_M = 0.03


def _check_drawn(drawn: float, limit: float, field: str, expected: str, unit: str) -> None:
    """A drawn (exaggerated) peak within ``limit``, else InputError naming the scale: beyond it the
    drawing means nothing (and a huge scale overflows the geometry)."""
    if not drawn <= limit:
        from taos.errors import InputError
        raise InputError("view", field, expected, got=f"a drawn peak of {drawn:.3g} {unit}")


def viewer_frames(th, geometry: EngineDrawing | None = None, *, angle_scale: float = 1.0,
                  deflection_scale: float | None = None, fps: float = 100.0,
                  stick_rate_rad_s: float = 1.75e-3, gimbal_scale: float | None = None) -> ViewerFrames:
    """Poses and colours for the 3-D view of run ``th`` (see the module docstring).

    Parameters
    ----------
    th : TimeHistory
        Recorded run (axes pitch and/or yaw; t_s [s], engine_rad, piston_m, friction_torque_Nm,
        load_force_N).
    geometry : EngineDrawing
        Display geometry; default RS-25 with the run's moment arm.
    angle_scale : float
        Engine-angle exaggeration s [-] (1 = true angles).
    deflection_scale : float, optional
        Load-path deflection exaggeration k [-]; default :func:`auto_deflection_scale`.
    fps : float
        Keyframe rate [1/s]; never above the recorded sample rate.
    stick_rate_rad_s : float
        Engine-rate threshold below which friction that carries torque counts as stuck [rad/s].
    gimbal_scale : float, optional
        Gimbal-half deflection exaggeration g [-] for 3-D runs; default: the peak drawn near
        3 cm (1-2-5 steps).
    """
    g = geometry or geometry_for_run(th)
    t = np.asarray(th.t_s, float)
    theta = _axis_arrays(th, "engine_rad")
    xp = _axis_arrays(th, "piston_m")
    tf = _axis_arrays(th, "friction_torque_Nm")
    fl = _axis_arrays(th, "load_force_N")
    rate = np.gradient(theta, t, axis=1) if t.size > 1 else np.zeros_like(theta)
    tmax = float(np.max(np.abs(tf))) if tf.size else 0.0
    stuck_raw = (np.abs(rate) < stick_rate_rad_s) & (np.abs(tf) > 0.02 * tmax) & (tmax > 0)

    dt_rec = float(np.median(np.diff(t))) if t.size > 1 else 1.0
    step = max(1.0 / fps, dt_rec)
    tk = np.arange(t[0], t[-1] + 1e-12, step) if t.size > 1 else t.copy()
    if tk[-1] < t[-1] - 1e-9:
        tk = np.append(tk, t[-1])
    interp = lambda a: np.vstack([np.interp(tk, t, row) for row in a])  # noqa: E731
    theta, xp, fl = interp(theta), interp(xp), interp(fl)
    stuck = interp(stuck_raw.astype(float)) > 0.5
    R = g.moment_arm_m
    delta = xp - R * theta
    if deflection_scale is None:
        deflection_scale = auto_deflection_scale(float(np.max(np.abs(delta))))
    _check_drawn(angle_scale * float(np.max(np.abs(theta))), math.pi / 2, "angle_scale (--angle-scale)",
                 "an exaggeration drawing the engine within 90 deg (it would turn over)", "rad")
    _check_drawn(deflection_scale * float(np.max(np.abs(delta))), g.actuator_length_m,
                 "deflection_scale (--deflection-scale)", "an exaggeration drawing the load-path deflection "
                 f"within the actuator's length {g.actuator_length_m:g} m (the drawn rod would turn inside out)", "m")

    extra = getattr(th, "extra", None) or {}
    upper = engine_off = None
    if "upper_deflection" in extra and "lower_deflection" in extra:
        uu = interp(np.asarray(extra["upper_deflection"], float)[:3])
        ul = interp(np.asarray(extra["lower_deflection"], float)[:3])
        if gimbal_scale is None:
            peak = float(np.max(np.linalg.norm(uu + ul, axis=0)))
            gimbal_scale = auto_deflection_scale(peak * AUTO_DEFLECTION_M / AUTO_GIMBAL_M)
        _check_drawn(gimbal_scale * float(np.max(np.abs(uu) + np.abs(ul))), g.actuator_length_m,
                     "gimbal_scale (--gimbal-scale)", "an exaggeration drawing the gimbal halves' deflection within "
                     f"the actuator's length {g.actuator_length_m:g} m", "m")
        upper = (gimbal_scale * uu).T
        engine_off = (gimbal_scale * (uu + ul)).T
    rot = engine_rotation(angle_scale * theta[0], angle_scale * theta[1])
    S = np.empty((2, tk.size, 3))
    C = np.empty((2, tk.size, 3))
    Q = np.empty((2, tk.size, 4))
    stroke = np.empty((2, tk.size))
    for i, ax in enumerate(AXES):
        s0, c0 = g.structure_attach_m(ax), g.engine_attach_m(ax)
        C[i] = rot.apply(c0) + (0.0 if engine_off is None else engine_off)
        u = C[i] - s0
        u /= np.linalg.norm(u, axis=1)[:, None]
        S[i] = s0 - u * (deflection_scale * delta[i])[:, None]
        d = C[i] - S[i]
        L = np.linalg.norm(d, axis=1)
        stroke[i] = L - g.actuator_length_m
        Q[i] = _z_to(d / L[:, None]).as_quat()
    fmax = float(np.max(np.abs(fl)))
    ff = fl / fmax if fmax > 0 else np.zeros_like(fl)
    return ViewerFrames(t_s=tk, engine_quat_xyzw=rot.as_quat(), engine_rad=theta, piston_m=xp,
                        deflection_m=delta, structure_attach_m=S, clevis_m=C, actuator_quat_xyzw=Q,
                        stroke_m=stroke, stuck=stuck, force_fraction=np.clip(ff, -1, 1),
                        angle_scale=float(angle_scale), deflection_scale=float(deflection_scale),
                        upper_gimbal_m=upper, engine_offset_m=engine_off,
                        gimbal_scale=float(gimbal_scale or 0.0))
