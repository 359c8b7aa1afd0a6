"""TAOS model definition: engine mass properties (Pinocchio), actuator geometry, gimbal halves.

Frame (the gimbal frame, shared with ``fem_data`` and :mod:`taos.viewer`): origin O at the
bearing centre, z along the engine axis from the engine towards the thrust structure (the
engine hangs along -z), x pitch-lateral, y yaw-lateral. Pitch is a rotation about +y, yaw a
rotation about -x; the pitch actuator works in the x-z plane, the yaw actuator in the y-z
plane. Engine angles are the pitch/yaw components of the engine's rotation vector.

Model-file tables read here (the loader keeps them raw in ``TvcModel.extra``)::

    [gimbal]    friction_coefficient  mu [-], bearing friction coefficient [derived key: optional;
                                      when absent mu = T_c / (N r_b) from [friction] coulomb_torque,
                                      when given checked against it within 1 %]
                bearing_radius        r_b [m], effective friction radius of the spherical seat
                stiffness_file        fem_data .npz with K_upper, K_lower (path relative to the
                                      model file, else to the shipped models/ folder:
                                      taos.shipped.resolve_reference)
                line_load_stiffness   actuator-line stiffness outside the gimbal [N/m] [derived key:
                                      optional; when absent derived from [structure] load_stiffness
                                      with the FEM gimbal in series, when given checked against that
                                      within 1 % (:mod:`taos.taos3d.calibrate`)]; the pitch line's.
                                      The yaw line's is always derived: from [structure]
                                      load_stiffness_yaw when the file gives it, else equal to the
                                      pitch line's
                upper_stiffness_scale s_u [-], factor on the upper half's 6x6 stiffness K_upper
                lower_stiffness_scale s_l [-], factor on the lower half's K_lower [optional, default
                                      1: the FEM matrices as computed; a fit's handle on the FEM
                                      gimbal's compliance, K_s = ((s_u K_u)^-1 + (s_l K_l)^-1)^-1,
                                      :mod:`taos.identify.fit3d`; bounds in taos.bounds]
    [geometry]  pitch_structure_attach, pitch_engine_attach, yaw_structure_attach,
                yaw_engine_attach     [x, y, z] attach points [m] (engine points at zero angle)
                engine_cg             [x, y, z] engine centre of mass [m]
                engine_roll_inertia   engine inertia about its own axis through the c.g. [kg m^2]

Engine inertia: pitch/yaw inertias about O are ``[engine] inertia_pitch/inertia_yaw`` (the
same J_n as the planar model), so the inertia about the c.g. is J_n - m (distance to the
axis)^2; the roll inertia comes from ``engine_roll_inertia``.

Bearing normal load N: the thrust when firing, the engine weight m g0 when hanging. The
bearing's friction torque level is T_c = mu N r_b: one friction for the planar and the 3-D
model. The model file's ``[friction] coulomb_torque`` is that level (the planar contract key),
so ``friction_coefficient`` is derived from it, or checked against it within 1 % when given
(:func:`check_friction_coefficient`), at load; the 3-D model then simulates the model's own
friction law, unscaled (:attr:`TaosModel.bearing_friction`): the law and levels every summary
shows, including a ``--friction`` swap.

Every check here (keys, units, ranges, geometry, moment arms against ``[actuator]
moment_arm``, the engine's c.g. inertia, the stiffness file symmetric positive definite, the
friction coefficient) runs in :func:`assemble_taos_model`, before any simulation; the derived
line stiffness is then derived or checked by :func:`taos.taos3d.calibrate.taos_model`, the
builder every command uses.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from ..errors import InputError
from ..model import TvcModel
from ..shipped import resolve_reference
from ..units import NM_PER_IN_LBF, to_si

G0 = 9.80665  # standard gravity [m/s^2]
AXES = ("pitch", "yaw")
#: bearing rotation axes in the gimbal frame: pitch about +y, yaw about -x
PITCH_AXIS = np.array([0.0, 1.0, 0.0])
YAW_AXIS = np.array([-1.0, 0.0, 0.0])
GIMBAL_KEYS = {"friction_coefficient", "bearing_radius", "stiffness_file", "line_load_stiffness",
               "upper_stiffness_scale", "lower_stiffness_scale"}
GEOMETRY_KEYS = {"pitch_structure_attach", "pitch_engine_attach", "yaw_structure_attach",
                 "yaw_engine_attach", "engine_cg", "engine_roll_inertia"}


@dataclass(frozen=True)
class GimbalParams:
    """Bearing friction and the FEM stiffness source (SI). ``friction_coefficient`` and
    ``line_load_stiffness_N_per_m`` are derived keys: the built model carries the value given
    (and checked) or derived at load."""

    friction_coefficient: float
    bearing_radius_m: float
    stiffness_file: str | None = None
    line_load_stiffness_N_per_m: float | None = None
    #: :func:`line_stiffness_basis` of the model the line stiffness was derived for ('' when
    #: given by the file): a model changed since is refused, never run on a stale value
    line_stiffness_basis: str = ""
    #: the yaw actuator line's stiffness [N/m], derived from ``[structure] load_stiffness_yaw``
    #: (:mod:`taos.taos3d.calibrate`); None: the pitch line's (the key absent)
    line_load_stiffness_yaw_N_per_m: float | None = None
    #: s_u, s_l [-]: factors on the upper and lower halves' FEM stiffness (``[gimbal]
    #: upper_stiffness_scale``/``lower_stiffness_scale``, default 1; applied by
    #: :func:`assemble_taos_model` to the matrices of ``stiffness_file``)
    upper_stiffness_scale: float = 1.0
    lower_stiffness_scale: float = 1.0


@dataclass(frozen=True, eq=False)
class ActuatorGeometry:
    """Attach points [m] in the gimbal frame (rows: pitch, yaw) and engine mass layout."""

    structure_attach_m: np.ndarray
    engine_attach_m: np.ndarray
    engine_cg_m: np.ndarray
    engine_roll_inertia_kgm2: float

    def moment_arm_m(self, i: int) -> float:
        """|E x u| [m]: moment arm of actuator ``i`` about O at zero engine angle."""
        u = self.line_of_action(i)
        return float(np.linalg.norm(np.cross(self.engine_attach_m[i], u)))

    def line_of_action(self, i: int) -> np.ndarray:
        """Unit vector from the structure attach point to the engine attach point."""
        d = self.engine_attach_m[i] - self.structure_attach_m[i]
        return d / np.linalg.norm(d)

    def rotation_axis(self, i: int) -> np.ndarray:
        """Unit axis n about which engine rotation extends actuator ``i`` (n ~ E x u)."""
        a = np.cross(self.engine_attach_m[i], self.line_of_action(i))
        return a / np.linalg.norm(a)


@dataclass(frozen=True, eq=False)
class TaosModel:
    """One engine on a two-half compliant gimbal with two actuators (SI).

    ``base`` is the planar model (actuator, avionics, friction law, K_L, K_n, J_n);
    ``K_upper``/``K_lower`` (6, 6) are the halves' stiffness at O in DOF order
    (ux, uy, uz, rx, ry, rz) [N/m, N/rad, N m/m, N m/rad]. The bearing friction simulated is
    ``base.friction`` itself (:attr:`bearing_friction`).
    """

    base: TvcModel
    gimbal: GimbalParams
    geometry: ActuatorGeometry
    K_upper: np.ndarray
    K_lower: np.ndarray
    stiffness_source: str = "<code>"

    # -- derived -------------------------------------------------------------------------
    @property
    def normal_load_N(self) -> float:
        """Bearing normal load N [N]: thrust if firing, else the engine weight m g0."""
        return normal_load_N(self.base)

    @property
    def coulomb_torque_Nm(self) -> float:
        """T_c = mu N r_b [N m]: the bearing's friction level (equal to the law's
        ``coulomb_torque`` within 1 %, checked at load)."""
        g = self.gimbal
        return g.friction_coefficient * self.normal_load_N * g.bearing_radius_m

    @property
    def bearing_friction(self):
        """The friction law the 3-D model simulates at the bearing: the model's own law
        (``base.friction``, a ``--friction`` swap included) with its own levels, the one the
        summaries show. Its level follows the normal load through ``[friction] coulomb_torque``
        = mu N r_b (:func:`check_friction_coefficient`), not through a second scaling."""
        return self.base.friction

    @property
    def friction_scale(self) -> float:
        """lambda, the factor on the law's torque-like parameters in the 3-D run: 1 (one
        friction for both models, :attr:`bearing_friction`); kept in the records."""
        return 1.0

    @property
    def line_load_stiffness_N_per_m(self) -> float:
        """The actuator-line stiffness outside the gimbal [N/m], derived at build from
        ``[structure] load_stiffness`` with the gimbal in series (:mod:`taos.taos3d.calibrate`).
        A model whose inputs to that derivation changed since (a ``replace`` of its base, its
        halves or geometry) raises :class:`InputError`: rebuild it
        (:func:`taos.taos3d.calibrate.with_values`, :func:`~taos.taos3d.calibrate.taos_model`)."""
        g = self.gimbal
        if g.line_stiffness_basis and g.line_stiffness_basis != line_stiffness_basis(self):
            raise InputError(self.base.source, "gimbal.line_load_stiffness",
                             "a line stiffness derived for this model (rebuild the 3-D model after changing its "
                             "load stiffness, engine, moment arm, geometry or gimbal halves)",
                             got="the value derived for another model")
        return self.base.structure.load_stiffness_N_per_m if g.line_load_stiffness_N_per_m is None \
            else g.line_load_stiffness_N_per_m

    @property
    def line_load_stiffnesses_N_per_m(self) -> np.ndarray:
        """(pitch, yaw) actuator-line stiffnesses outside the gimbal [N/m] (2,): the pitch one
        :attr:`line_load_stiffness_N_per_m`, the yaw one derived from ``[structure]
        load_stiffness_yaw`` (:mod:`taos.taos3d.calibrate`), the pitch one when the file leaves
        that key out; stale values refused as :attr:`line_load_stiffness_N_per_m`."""
        kp = self.line_load_stiffness_N_per_m
        ky = self.gimbal.line_load_stiffness_yaw_N_per_m
        return np.array([kp, kp if ky is None else ky], dtype=np.float64)

    @property
    def chain_stiffness(self) -> np.ndarray:
        """K_s = (K_upper^-1 + K_lower^-1)^-1: the two halves in series at O (6, 6)."""
        C = np.linalg.inv(self.K_upper) + np.linalg.inv(self.K_lower)
        K = np.linalg.inv(C)
        return 0.5 * (K + K.T)

    @property
    def bearing_selection(self) -> np.ndarray:
        """S (6, 2): chain DOFs released by the bearing (pitch, yaw rotations)."""
        S = np.zeros((6, 2))
        S[3:, 0] = PITCH_AXIS
        S[3:, 1] = YAW_AXIS
        return S

    @property
    def engine_inertia_cg(self) -> np.ndarray:
        """Engine inertia about its c.g. in the gimbal frame [kg m^2] (3, 3)."""
        e = self.base.engine
        c = self.geometry.engine_cg_m
        m = e.mass_kg
        # about O: I_O = I_c + m (|c|^2 I - c c^T); pitch (y) and yaw (x) from the file
        shift = m * (np.dot(c, c) * np.eye(3) - np.outer(c, c))
        Ic = np.diag([e.inertia_yaw_kgm2 - shift[0, 0], e.inertia_pitch_kgm2 - shift[1, 1],
                      self.geometry.engine_roll_inertia_kgm2])
        return Ic

    def with_friction(self, name: str) -> "TaosModel":
        """The same model with friction law ``name`` (the line stiffness does not depend on it)."""
        return replace(self, base=self.base.with_friction(name))

    def replace(self, **changes) -> "TaosModel":
        """Copy with fields replaced in code (a derived line stiffness is checked on use)."""
        return replace(self, **changes)


def line_stiffness_basis(tm: "TaosModel") -> str:
    """Fingerprint of everything the derived line stiffnesses depend on: the total load
    stiffness of each axis (``load_stiffness``, ``load_stiffness_yaw``), the engine, the moment
    arm, the geometry and both gimbal halves."""
    import hashlib

    b = tm.base
    h = hashlib.sha256(repr((b.structure.load_stiffness_N_per_m, b.engine, b.actuator.moment_arm_m,
                             tm.geometry.engine_roll_inertia_kgm2, b.structure.load_stiffness_yaw_N_per_m)).encode())
    for a in (tm.geometry.structure_attach_m, tm.geometry.engine_attach_m, tm.geometry.engine_cg_m,
              tm.K_upper, tm.K_lower):
        h.update(np.ascontiguousarray(a, float).tobytes())
    return h.hexdigest()


# -- Pinocchio ---------------------------------------------------------------------------
def engine_pin_model(tm: TaosModel):
    """Pinocchio model of the engine: one free-flyer joint at O (gimbal frame), the engine
    body (mass, c.g., inertia), operational frames at the actuator attach points; gravity
    off (its restoring torque is inside K_n, as in the planar model)."""
    import pinocchio as pin

    m = pin.Model()
    m.gravity = pin.Motion.Zero()
    jid = m.addJoint(0, pin.JointModelFreeFlyer(), pin.SE3.Identity(), "engine")
    m.appendBodyToJoint(jid, pin.Inertia(tm.base.engine.mass_kg, np.array(tm.geometry.engine_cg_m, float),
                                         tm.engine_inertia_cg), pin.SE3.Identity())
    for i, ax in enumerate(AXES):
        m.addFrame(pin.Frame(f"{ax}_attach", jid, 0, pin.SE3(np.eye(3), tm.geometry.engine_attach_m[i]),
                             pin.FrameType.OP_FRAME))
    return m


def spatial_inertia(tm: TaosModel) -> np.ndarray:
    """6x6 spatial inertia of the engine at its joint frame (Pinocchio, linear first)."""
    return np.array(engine_pin_model(tm).inertias[1].matrix())


# -- validation and loading --------------------------------------------------------------
def _vec3(tab, key, src, sec):
    v = tab.get(key)
    if not isinstance(v, list) or len(v) != 3:
        raise InputError(src, f"{sec}.{key}", "a list of three lengths like ['0.8 m', '0 m', '-0.55 m']",
                         got="nothing (key missing)" if v is None else repr(v))
    return np.array([to_si(x, "length", source=src, field=f"{sec}.{key}[{i}]") for i, x in enumerate(v)])


def _table(model: TvcModel, name: str, keys: set[str]) -> dict:
    tab = model.extra.get(name)
    if not isinstance(tab, dict):
        raise InputError(model.source, f"[{name}]", f"a [{name}] table for the TAOS engine model",
                         got="nothing (section missing)")
    from ..errors import check_keys

    check_keys(tab, keys, model.source, name)
    return tab


def parse_gimbal(model: TvcModel) -> GimbalParams:
    """Validate ``[gimbal]`` (InputError on a missing key, wrong unit or bad range); the
    friction coefficient derived or checked (:func:`check_friction_coefficient`); the line
    stiffness as given, or None (derived by :func:`taos.taos3d.calibrate.taos_model`)."""
    src = model.source
    g = _table(model, "gimbal", GIMBAL_KEYS)
    if "bearing_radius" not in g:
        raise InputError(src, "gimbal.bearing_radius", "a value like '0.11 m'", got="nothing (key missing)")
    rb = to_si(g["bearing_radius"], "length", source=src, field="gimbal.bearing_radius", positive=True)
    mu = None
    if "friction_coefficient" in g:
        mu = to_si(g["friction_coefficient"], "dimensionless", source=src, field="gimbal.friction_coefficient",
                   nonnegative=True)
    mu = check_friction_coefficient(model, mu, rb)
    path = None
    if "stiffness_file" in g:
        if not isinstance(g["stiffness_file"], str):
            raise InputError(src, "gimbal.stiffness_file", "a path string", got=repr(g["stiffness_file"]))
        # the one rule for file references: beside the model file, else from the shipped models/
        path = str(resolve_reference(g["stiffness_file"], src, field="gimbal.stiffness_file", kind="model",
                                     what="a gimbal stiffness file (.npz with K_upper, K_lower)"))
    kl = None
    if "line_load_stiffness" in g:
        kl = to_si(g["line_load_stiffness"], "stiffness", source=src, field="gimbal.line_load_stiffness",
                   positive=True)
    from ..bounds import check_bound

    scales = []
    for key in ("upper_stiffness_scale", "lower_stiffness_scale"):
        v = 1.0
        if key in g:
            v = to_si(g[key], "dimensionless", source=src, field=f"gimbal.{key}", positive=True)
            check_bound(v, f"gimbal.{key}", src)
        scales.append(float(v))
    return GimbalParams(mu, rb, path, kl, upper_stiffness_scale=scales[0], lower_stiffness_scale=scales[1])


def normal_load_N(model: TvcModel) -> float:
    """Bearing normal load N [N]: the thrust if firing, else the engine weight m g0."""
    e = model.engine
    return e.thrust_N if e.thrust_N > 0 else e.mass_kg * G0


#: relative tolerance of a derived key given in a file against its source keys
DERIVED_RTOL = 0.01


def check_friction_coefficient(model: TvcModel, mu: float | None, bearing_radius_m: float) -> float:
    """The bearing friction coefficient mu [-]: derived as T_c / (N r_b) from the law's level
    ``[friction] coulomb_torque`` T_c [N m], the normal load N [N] (:func:`normal_load_N`) and the
    bearing radius r_b [m] when ``mu`` is None; else ``mu`` checked against that within
    :data:`DERIVED_RTOL` (InputError naming both keys, their values and the expected mu).
    A law without friction (``has_friction`` false: ``none``) checks nothing."""
    N = normal_load_N(model)
    tc = model.friction.coulomb_torque_Nm
    expected = tc / (N * bearing_radius_m)
    if mu is None:
        return expected
    if model.friction.has_friction and abs(mu - expected) > DERIVED_RTOL * expected:
        load = f"thrust {N / 1e3:.6g} kN" if model.engine.thrust_N > 0 else f"engine weight m g0 {N / 1e3:.6g} kN"
        raise InputError(model.source, "gimbal.friction_coefficient",
                         f"{expected:.4g} within 1 %, from friction.coulomb_torque = {tc:.6g} N m "
                         f"({tc / NM_PER_IN_LBF:.6g} in*lbf) = mu N r_b with N = {load}, r_b = {bearing_radius_m:.4g} m "
                         f"(one friction for the planar and 3-D models; delete the key to have it derived)",
                         got=f"{mu:.6g} (mu N r_b = {mu * N * bearing_radius_m:.6g} N m)")
    return mu


def parse_geometry(model: TvcModel) -> ActuatorGeometry:
    """Validate ``[geometry]``: moment arms equal [actuator] moment_arm within 1 %, the two
    actuators turn the engine about roughly orthogonal axes (within 30 deg) near the gimbal
    pitch/yaw axes, and the engine's c.g. inertia is positive and physical."""
    src = model.source
    t = _table(model, "geometry", GEOMETRY_KEYS)
    S = np.vstack([_vec3(t, f"{ax}_structure_attach", src, "geometry") for ax in AXES])
    E = np.vstack([_vec3(t, f"{ax}_engine_attach", src, "geometry") for ax in AXES])
    cg = _vec3(t, "engine_cg", src, "geometry")
    if "engine_roll_inertia" not in t:
        raise InputError(src, "geometry.engine_roll_inertia", "an inertia like '2000 kg*m**2'",
                         got="nothing (key missing)")
    roll = to_si(t["engine_roll_inertia"], "inertia", source=src, field="geometry.engine_roll_inertia",
                 positive=True)
    geo = ActuatorGeometry(S, E, cg, roll)
    R = model.actuator.moment_arm_m
    for i, ax in enumerate(AXES):
        if np.linalg.norm(E[i] - S[i]) <= 0:
            raise InputError(src, f"geometry.{ax}_engine_attach", "a point apart from the structure attach point")
        arm = geo.moment_arm_m(i)
        if abs(arm - R) > 0.01 * R:
            raise InputError(src, f"geometry.{ax}_engine_attach",
                             f"attach points giving a moment arm of {R:.4g} m ([actuator] moment_arm) within 1 %",
                             got=f"{arm:.4g} m")
        ref = PITCH_AXIS if i == 0 else YAW_AXIS
        if np.dot(geo.rotation_axis(i), ref) < math.cos(math.radians(30)):
            raise InputError(src, f"geometry.{ax}_engine_attach",
                             f"a line of action that turns the engine about the {ax} axis "
                             f"({'+y' if i == 0 else '-x'}) within 30 deg, extending with a positive angle")
    tmp = TaosModel(model, GimbalParams(0.0, 1.0), geo, np.eye(6), np.eye(6))
    Ic = np.diag(tmp.engine_inertia_cg)
    if np.any(Ic <= 0) or Ic[0] + Ic[1] < Ic[2] or Ic[1] + Ic[2] < Ic[0] or Ic[0] + Ic[2] < Ic[1]:
        raise InputError(src, "geometry.engine_cg",
                         "a c.g. and roll inertia giving a physical inertia about the c.g. "
                         "(positive, triangle inequality)", got=f"principal inertias {Ic.round(1).tolist()} kg m^2")
    return geo


def check_stiffness(K, src: str, field: str) -> np.ndarray:
    """A 6x6 symmetric positive-definite stiffness of real numbers, else InputError (a complex,
    text or boolean matrix is refused, never cast)."""
    try:
        raw = np.asarray(K)
    except (TypeError, ValueError):
        raise InputError(src, field, "a finite 6x6 stiffness matrix", got=repr(K)[:40]) from None
    if raw.dtype.kind not in "iuf":
        raise InputError(src, field, "a finite 6x6 stiffness matrix of real numbers", got=f"dtype {raw.dtype}")
    K = raw.astype(float)
    if K.shape != (6, 6) or not np.all(np.isfinite(K)):
        raise InputError(src, field, "a finite 6x6 stiffness matrix", got=f"shape {K.shape}")
    if not np.allclose(K, K.T, rtol=1e-6, atol=1e-9 * np.abs(K).max()):
        raise InputError(src, field, "a symmetric stiffness matrix",
                         got=f"max asymmetry {np.abs(K - K.T).max():.3g}")
    K = 0.5 * (K + K.T)
    if np.linalg.eigvalsh(K).min() <= 0:
        raise InputError(src, field, "a positive-definite stiffness matrix (halves held at one face)",
                         got=f"smallest eigenvalue {np.linalg.eigvalsh(K).min():.3g}")
    return K


def load_stiffness_file(path: str) -> tuple[np.ndarray, np.ndarray]:
    """(K_upper, K_lower) from a fem_data .npz or .csv (:func:`taos.fem.load_gimbal_stiffness`),
    validated."""
    from ..fem import load_gimbal_stiffness

    if not Path(path).is_file():
        raise InputError(path, "(file)", "a gimbal stiffness file (.npz with K_upper, K_lower)",
                         got="no such file")
    data = load_gimbal_stiffness(path)
    return check_stiffness(data.K_upper, path, "K_upper"), check_stiffness(data.K_lower, path, "K_lower")


def assemble_taos_model(model: TvcModel, K_upper: np.ndarray | None = None,
                        K_lower: np.ndarray | None = None) -> TaosModel:
    """The TAOS model of a loaded model file with every input check done (keys, units, geometry,
    stiffness matrices, the friction coefficient) and the line stiffness as given (None when the
    file leaves it to be derived: :func:`taos.taos3d.calibrate.taos_model` derives or checks it;
    use that). ``K_upper``/``K_lower`` override the ``[gimbal] stiffness_file``."""
    from ..bounds import check_instance

    check_instance(model, "model", TvcModel, "a TvcModel (taos.load_model)")
    if (K_upper is None) != (K_lower is None):   # one matrix alone would be silently ignored
        given, other = ("K_upper", "K_lower") if K_lower is None else ("K_lower", "K_upper")
        raise InputError("argument", other, f"a 6x6 matrix with {given} (both halves, or neither for the "
                         "model file's gimbal.stiffness_file)", got="None")
    gim = parse_gimbal(model)
    geo = parse_geometry(model)
    if K_upper is None or K_lower is None:
        if gim.stiffness_file is None:
            raise InputError(model.source, "gimbal.stiffness_file",
                             "a fem_data .npz path (or matrices passed in code)", got="nothing (key missing)")
        Ku, Kl = load_stiffness_file(gim.stiffness_file)
        src = gim.stiffness_file
        if gim.upper_stiffness_scale != 1.0:   # s_u K_u (the file's matrices unchanged at 1: bit-identical)
            Ku = gim.upper_stiffness_scale * Ku
        if gim.lower_stiffness_scale != 1.0:
            Kl = gim.lower_stiffness_scale * Kl
    else:
        Ku = check_stiffness(K_upper, "<code>", "K_upper")
        Kl = check_stiffness(K_lower, "<code>", "K_lower")
        src = "<code>"
    return TaosModel(model, gim, geo, Ku, Kl, src)


def beam_half_stiffness(axial_N_per_m: float, shear_N_per_m: float, bending_Nm_per_rad: float,
                        torsion_Nm_per_rad: float, length_m: float) -> np.ndarray:
    """Synthetic 6x6 stiffness of a short elastic post at its free end (clamped at distance
    ``length_m`` along z), Euler-Bernoulli bending coupling with shear flexibility; for tests
    and for running without FEM files. Lateral: 1/k = L^3/(3EI) + 1/k_shear."""
    EI = bending_Nm_per_rad * length_m
    L = length_m
    # flexibility of the tip (lateral u, rotation r) for bending in one plane
    F = np.array([[L ** 3 / (3 * EI) + 1.0 / shear_N_per_m, L ** 2 / (2 * EI)],
                  [L ** 2 / (2 * EI), L / EI]])
    Kb = np.linalg.inv(F)
    K = np.zeros((6, 6))
    K[2, 2] = axial_N_per_m
    K[5, 5] = torsion_Nm_per_rad
    # x-z plane: ux with ry (a +ux tip shift with the root below pairs with +ry)
    K[np.ix_([0, 4], [0, 4])] = Kb * np.array([[1, 1], [1, 1]])
    K[np.ix_([1, 3], [1, 3])] = Kb * np.array([[1, -1], [-1, 1]])
    return K
