"""MASV configuration files (TOML): which engines, which actuators, which structure.

Format (every physical value with its unit, parsed by pint; paths relative to the file)::

    name = "SLS core stage, four RS-25, hot fire"
    reference = "core_stage.toml"  # optional: another MASV configuration (the nominal structure)
                                 # that ``masv coupling`` compares this one with
    [structure]
    modes = "../../fem_data/thrust_structure_modes.npz"   # or "rigid" (no modes), or an FE file
                                 # (.uff/.unv Universal File 55, .pch Nastran punch, .op2) with the
                                 # keys nodes, length_unit, mass_unit, modal_mass, fe_to_vehicle
                                 # (masv.fe_import; docs/reference/masv_files.md)
    damping_ratio = 0.005        # every mode (default, paper sec. 3.3); "file" keeps the file's
    max_frequency = "200 Hz"     # optional: drop modes above this
    engine_mass_in_modes = false # optional: true when the modes already lump the engines'
                                 # translational mass at the gimbals (default false: MASV adds it)
    [band]                       # band of interest for notches, coupling and truncation checks
    low = "0.5 Hz"
    high = "20 Hz"
    [[engine]]                   # one per engine
    name = "engine_1"
    model = "../rs25_hotfire.toml"   # taos model file: J_n, K_n, R, K_L, actuator parameters
    gimbal_node = "gimbal_1"         # node of the modal file at the gimbal point
    cg_offset = ["-1.5 m", "0 m", "0 m"]  # optional: gimbal -> engine c.g. (vehicle frame); default
                                     # the model's [geometry] engine_cg distance along -x (aft)
    [[actuator]]                 # one per actuator (engine axis)
    name = "actuator_1_pitch"
    engine = "engine_1"
    axis = "pitch"                   # engine axis it drives: pitch or yaw
    attach_node = "actuator_1_pitch" # structure attach point (node of the modal file)
    direction = [0.0, 0.0, 1.0]      # line of action, structure attach -> engine attach (vehicle frame)
    rotation_axis = [0.0, 1.0, 0.0]  # optional: engine rotation axis for positive extension;
                                     # default unit((attach - gimbal) x direction)

Engine positions in the core-stage layout are the gimbal nodes' coordinates in the modal file.
One to :data:`MAX_ENGINES` engines, one or two actuators each, any number of structure nodes.
Every key, array, unit and frame: ``docs/reference/masv_files.md``.
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Mapping

import numpy as np

from taos.errors import InputError, check_keys
from taos.model import TvcModel, load_model, read_toml
from taos.shipped import resolve, resolve_reference
from taos.units import to_si

from .structure import DEFAULT_DAMPING_RATIO, ModalStructure, load_modes, rigid_structure

AXES = ("pitch", "yaw")
#: most engines a configuration may hold
MAX_ENGINES = 8


@dataclass(frozen=True, eq=False)
class EngineSpec:
    """One gimballed engine: its taos model (m_e, J_n, K_n and its actuators' parameters), the
    modal node at its gimbal and ``cg_offset_m``, the vector gimbal -> engine centre of mass in
    the vehicle frame [m] (None: :func:`engine_cg_offset` derives it from the model)."""

    name: str
    model: TvcModel
    gimbal_node: str
    cg_offset_m: tuple[float, float, float] | None = None

    @property
    def cg_vector_m(self) -> np.ndarray:
        """Gimbal -> engine c.g. [m], vehicle frame (:func:`engine_cg_offset` when not given)."""
        return engine_cg_offset(self.model) if self.cg_offset_m is None else np.asarray(self.cg_offset_m, float)


def engine_cg_offset(model: TvcModel) -> np.ndarray:
    """Gimbal -> engine c.g. in the vehicle frame [m] from the taos model's ``[geometry]
    engine_cg`` (gimbal frame, z along the engine axis towards the structure): its distance
    |engine_cg| placed along the engine axis aft, vehicle -x (the engine hangs aft of its
    gimbal; the shipped files put the c.g. on the engine axis). Zero without ``[geometry]
    engine_cg``."""
    geo = model.extra.get("geometry")
    v = geo.get("engine_cg") if isinstance(geo, Mapping) else None
    if v is None:
        return np.zeros(3)
    if not isinstance(v, list) or len(v) != 3:
        raise InputError(model.source, "geometry.engine_cg", "a list of three lengths like ['0 m', '0 m', '-1.5 m']",
                         got=repr(v))
    c = [to_si(x, "length", source=model.source, field=f"geometry.engine_cg[{i}]") for i, x in enumerate(v)]
    return np.array([-float(np.linalg.norm(c)), 0.0, 0.0])


@dataclass(frozen=True, eq=False)
class ActuatorSpec:
    """One actuator: the engine and axis it drives, its structure attach node, its unit line of
    action ``direction`` (structure attach -> engine attach) and the unit ``rotation_axis`` about
    which the engine turns when the actuator extends (both vehicle frame, dimensionless)."""

    name: str
    engine: str
    axis: str
    attach_node: str
    direction: tuple[float, float, float]
    rotation_axis: tuple[float, float, float]


@dataclass(frozen=True, eq=False)
class MasvConfig:
    """A validated MASV configuration (SI inside): engines, actuators, modal structure and the
    band of interest [Hz]; ``reference`` the path of another configuration to compare with
    (``masv coupling``), or None; ``structure_import`` how an FE file was imported (format,
    unit scales, normalisation; :func:`masv.fe_import.load_fe_modes`), empty otherwise."""

    name: str
    engines: tuple[EngineSpec, ...]
    actuators: tuple[ActuatorSpec, ...]
    structure: ModalStructure
    band_low_hz: float
    band_high_hz: float
    source: str = "<code>"
    sha256: str = ""
    reference: str | None = None
    structure_import: dict = field(default_factory=dict)

    def engine(self, name: str) -> EngineSpec:
        return next(e for e in self.engines if e.name == name)

    @property
    def actuator_names(self) -> tuple[str, ...]:
        return tuple(a.name for a in self.actuators)


def _unit(v, src: str, field: str) -> np.ndarray:
    if not isinstance(v, list) or len(v) != 3 or not all(isinstance(c, (int, float)) and not isinstance(c, bool)
                                                         for c in v):
        raise InputError(src, field, "a list of three numbers (vehicle frame x, y, z)", got=repr(v))
    a = np.asarray(v, float)
    nrm = float(np.linalg.norm(a))
    if not np.all(np.isfinite(a)) or nrm < 1e-12:
        raise InputError(src, field, "a non-zero finite direction", got=repr(v))
    return a / nrm


def _str(tab: Mapping, key: str, src: str, field: str) -> str:
    v = tab.get(key)
    if not isinstance(v, str) or not v:
        raise InputError(src, field, "a non-empty string", got="nothing (key missing)" if v is None else repr(v))
    return v


def default_rotation_axis(structure: ModalStructure, gimbal_node: str, attach_node: str,
                          direction: np.ndarray, src: str = "<code>", field: str = "rotation_axis") -> np.ndarray:
    """unit((x_attach - x_gimbal) x direction): the axis a rotation about which extends the
    actuator (elongation = theta a . (r x n) for a line of action n through r)."""
    r = structure.node_position(attach_node) - structure.node_position(gimbal_node)
    a = np.cross(r, direction)
    nrm = float(np.linalg.norm(a))
    if nrm < 1e-9:
        raise InputError(src, field, "a rotation axis (the line of action passes through the gimbal, "
                         "so none follows from the geometry)")
    return a / nrm


def make_config(engines, actuators, structure: ModalStructure | None = None, band_hz=(0.5, 20.0),
                name: str = "masv", source: str = "<code>") -> MasvConfig:
    """Build and validate a configuration in code (tests, scripts). ``structure`` None = rigid."""
    st = rigid_structure() if structure is None else structure
    cfg = MasvConfig(name, tuple(engines), tuple(actuators), st, float(band_hz[0]), float(band_hz[1]), source)
    check_config(cfg)
    return cfg


def check_config(cfg: MasvConfig) -> None:
    """Cross-checks: unique names, engines referenced, one actuator per engine axis, nodes exist
    (when the structure has modes), a sensible band."""
    src = cfg.source
    if not 1 <= len(cfg.engines) <= MAX_ENGINES:
        raise InputError(src, "engine", f"1 to {MAX_ENGINES} [[engine]] tables", got=str(len(cfg.engines)))
    if not cfg.actuators:
        raise InputError(src, "actuator", "at least one [[actuator]] table")
    names = [e.name for e in cfg.engines]
    if len(set(names)) != len(names):
        raise InputError(src, "engine.name", "distinct engine names", got="a repeated name")
    anames = [a.name for a in cfg.actuators]
    if len(set(anames)) != len(anames):
        raise InputError(src, "actuator.name", "distinct actuator names", got="a repeated name")
    seen = set()
    for i, a in enumerate(cfg.actuators):
        if a.engine not in names:
            raise InputError(src, f"actuator[{i}].engine", "the name of an [[engine]]", got=repr(a.engine))
        if a.axis not in AXES:
            raise InputError(src, f"actuator[{i}].axis", "pitch or yaw", got=repr(a.axis))
        if (a.engine, a.axis) in seen:
            raise InputError(src, f"actuator[{i}].axis", "one actuator per engine axis",
                             got=f"a second {a.axis} actuator on {a.engine}")
        seen.add((a.engine, a.axis))
        if cfg.structure.n_modes:
            cfg.structure.node_index(a.attach_node, src, f"actuator[{i}].attach_node")
    for i, e in enumerate(cfg.engines):
        if cfg.structure.n_modes:
            cfg.structure.node_index(e.gimbal_node, src, f"engine[{i}].gimbal_node")
    if not 0 < cfg.band_low_hz < cfg.band_high_hz:
        raise InputError(src, "band", "0 < low < high", got=f"{cfg.band_low_hz} Hz .. {cfg.band_high_hz} Hz")


def _structure(doc: Mapping, src: str) -> tuple[ModalStructure, dict]:
    from .fe_import import FE_KEYS, is_fe_file, load_fe_modes

    st = doc.get("structure")
    if not isinstance(st, Mapping):
        raise InputError(src, "[structure]", "a [structure] table", got="nothing (section missing)")
    check_keys(st, {"modes", "damping_ratio", "max_frequency", "engine_mass_in_modes"} | FE_KEYS, src, "structure")
    modes = _str(st, "modes", src, "structure.modes")
    fe = modes != "rigid" and is_fe_file(modes)
    extra = sorted(k for k in FE_KEYS if k in st)
    if extra and not fe:
        raise InputError(src, f"structure.{extra[0]}", "no FE import key with a .npz modal file or \"rigid\" "
                         "(FE files: .uff, .unv, .pch, .op2)", got=repr(modes))
    if modes == "rigid":
        return rigid_structure(), {}
    path = resolve_reference(modes, src, field="structure.modes", kind="masv",
                             what="a modal file (.npz, .uff/.unv, .pch or .op2)")
    info: dict = {}
    if fe:
        s, info = load_fe_modes(path, st, src)
    else:
        s = load_modes(path)
    inm = st.get("engine_mass_in_modes", False)
    if not isinstance(inm, bool):
        raise InputError(src, "structure.engine_mass_in_modes", "true or false", got=repr(inm))
    if inm:
        from dataclasses import replace
        s = replace(s, engine_mass_in_modes=True)
    z = st.get("damping_ratio", DEFAULT_DAMPING_RATIO)
    if z == "file" and info.get("format") in ("nastran-punch", "nastran-op2"):
        raise InputError(src, "structure.damping_ratio", "a damping ratio (a Nastran punch or OP2 file holds "
                         "none)", got='"file"')
    if z != "file":
        zeta = to_si(z, "dimensionless", source=src, field="structure.damping_ratio", nonnegative=True)
        if zeta >= 1:
            raise InputError(src, "structure.damping_ratio", "a damping ratio below 1 (or \"file\")", got=repr(z))
        s = s.with_damping(zeta)
    if "max_frequency" in st:
        s = s.truncated(to_si(st["max_frequency"], "frequency", source=src, field="structure.max_frequency",
                              positive=True))
    return s, info


def load_config(path) -> MasvConfig:
    """Read and validate a MASV configuration file (format in the module docstring).

    Raises InputError (one line: file, field, expectation) on any bad value, including the
    referenced taos model files and the modal file.
    """
    p = resolve(path, "masv")
    src = str(p)
    raw, doc = read_toml(p, "a readable MASV configuration file")
    check_keys(doc, {"name", "description", "reference", "structure", "band", "engine", "actuator"}, src)
    structure, st_info = _structure(doc, src)
    band = doc.get("band", {})
    if not isinstance(band, Mapping):
        raise InputError(src, "[band]", "a [band] table with low and high", got=repr(band)[:60])
    check_keys(band, {"low", "high"}, src, "band")
    lo = to_si(band.get("low", "0.5 Hz"), "frequency", source=src, field="band.low", positive=True)
    hi = to_si(band.get("high", "20 Hz"), "frequency", source=src, field="band.high", positive=True)
    etabs = doc.get("engine")
    if not isinstance(etabs, list) or not etabs:
        raise InputError(src, "engine", "one or more [[engine]] tables", got="none")
    cache: dict[Path, TvcModel] = {}
    engines = []
    for i, t in enumerate(etabs):
        check_keys(t, {"name", "model", "gimbal_node", "cg_offset"}, src, f"engine[{i}]")
        mpath = resolve_reference(_str(t, "model", src, f"engine[{i}].model"), p, field=f"engine[{i}].model",
                                  kind="masv", what="a TVC model file")
        if mpath not in cache:
            cache[mpath] = load_model(mpath)
        cg = None
        if "cg_offset" in t:
            v = t["cg_offset"]
            if not isinstance(v, list) or len(v) != 3:
                raise InputError(src, f"engine[{i}].cg_offset", "a list of three lengths like ['-1.5 m', '0 m', '0 m']",
                                 got=repr(v))
            cg = tuple(to_si(x, "length", source=src, field=f"engine[{i}].cg_offset[{j}]") for j, x in enumerate(v))
        engines.append(EngineSpec(_str(t, "name", src, f"engine[{i}].name"), cache[mpath],
                                  _str(t, "gimbal_node", src, f"engine[{i}].gimbal_node"), cg))
    atabs = doc.get("actuator")
    if not isinstance(atabs, list) or not atabs:
        raise InputError(src, "actuator", "one or more [[actuator]] tables", got="none")
    gimbal_of = {e.name: e.gimbal_node for e in engines}
    actuators = []
    for i, t in enumerate(atabs):
        f = f"actuator[{i}]"
        check_keys(t, {"name", "engine", "axis", "attach_node", "direction", "rotation_axis"}, src, f)
        eng = _str(t, "engine", src, f"{f}.engine")
        if eng not in gimbal_of:
            raise InputError(src, f"{f}.engine", "the name of an [[engine]]", got=repr(eng))
        node = _str(t, "attach_node", src, f"{f}.attach_node")
        n = _unit(t.get("direction"), src, f"{f}.direction")
        if "rotation_axis" in t:
            ax = _unit(t["rotation_axis"], src, f"{f}.rotation_axis")
        elif structure.n_modes:
            structure.node_index(node, src, f"{f}.attach_node")
            structure.node_index(gimbal_of[eng], src, f"engine.gimbal_node ({eng})")
            ax = default_rotation_axis(structure, gimbal_of[eng], node, n, src, f"{f}.rotation_axis")
        else:
            ax = np.zeros(3)  # rigid structure: the axis is never used
        actuators.append(ActuatorSpec(_str(t, "name", src, f"{f}.name"), eng, _str(t, "axis", src, f"{f}.axis"),
                                      node, tuple(float(c) for c in n), tuple(float(c) for c in ax)))
    ref = None
    if "reference" in doc:
        rp = resolve_reference(_str(doc, "reference", src, "reference"), p, field="reference", kind="masv",
                               what="another MASV configuration file")
        if not rp.is_file() or rp == p.resolve():
            raise InputError(src, "reference", "the path of another MASV configuration file",
                             got=repr(doc["reference"]))
        ref = str(rp)
    cfg = MasvConfig(str(doc.get("name", p.stem)), tuple(engines), tuple(actuators), structure, lo, hi, src,
                     hashlib.sha256(raw).hexdigest(), ref, st_info)
    check_config(cfg)
    return cfg
