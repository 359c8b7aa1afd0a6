"""The compiled kernels' packed arrays: the index tables the packers and the kernels share.

Every pack is read by name (a named tuple field or a module-level slot constant), never by a bare
index; these tests check that each table tiles its array: every name has its own slot(s), the
slots cover the array without gaps, and the packer fills an array of exactly that length. No
kernel is compiled here (the tables are plain integers)."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from taos.friction import _slots
from taos.model import load_model
from taos.planar import _avionics_slots as av_slots
from taos.planar import saturation
from taos.planar.avionics import Avionics

from .conftest import MODELS


def _consts(mod, prefix: str, exclude=()) -> dict[str, int]:
    return {k: v for k, v in vars(mod).items() if k.startswith(prefix) and k not in exclude and isinstance(v, int)}


def _tiles(slots: dict[str, int], widths: dict[str, int], length: int) -> None:
    """The named slots (each ``widths[name]`` long, default 1) cover 0..length-1 exactly once."""
    cover = []
    for name, start in slots.items():
        cover += range(start, start + widths.get(name, 1))
    assert sorted(cover) == list(range(length)), slots


def test_friction_slots_unique_and_dense():
    slots = _consts(_slots, "SLOT_")
    assert len(slots) == _slots.NPARAM
    _tiles(slots, {}, _slots.NPARAM)


def test_friction_laws_pack_by_their_slots():
    """Every law's packed vector has NPARAM slots and each field sits in its declared slot."""
    from taos.friction import registry

    for law_id, cls in registry.param_classes().items():
        law = cls()
        p = law.pack()
        assert p.shape == (_slots.NPARAM,)
        for f in dataclasses.fields(cls):
            slot = f.metadata.get("slot")
            if slot is not None:
                assert p[slot] == getattr(law, f.name), (law_id, f.name)


def test_avionics_slots_and_pack():
    _tiles(_consts(av_slots, "AV_"), {"AV_TABLE": 0}, av_slots.AV_TABLE)
    a = Avionics(quantization_bits=12, command_range_rad=0.4, rounding=True,
                 gain_table_rad=(0.0, 0.01, 0.05), gain_table=(0.9, 0.95, 1.0))
    p = a.pack()
    n = len(a.gain_table_rad)
    assert p.shape == (av_slots.AV_TABLE + 2 * n,)
    assert (p[av_slots.AV_BITS], p[av_slots.AV_LSB], p[av_slots.AV_ROUND], p[av_slots.AV_NTAB]) == (
        12.0, a.lsb_rad, 1.0, float(n))
    assert tuple(p[av_slots.AV_TABLE:av_slots.AV_TABLE + n]) == a.gain_table_rad
    assert tuple(p[av_slots.AV_TABLE + n:]) == a.gain_table
    assert Avionics().pack().shape == (av_slots.AV_TABLE,)


def test_limits_slots_and_rows():
    head = _consts(saturation, "LIM_")
    assert len(head) == saturation.N_HEAD
    _tiles(head, {}, saturation.N_HEAD)
    rows = _consts(saturation, "ROW_")
    assert len(rows) == saturation.N_ROWS == len(saturation.ROWS)
    assert {k: rows["ROW_" + k.upper()] for k in saturation.ROWS} == {k: i for i, k in enumerate(saturation.ROWS)}


def test_limits_packer_and_kernel_layout_agree():
    """pack_limits puts every head value and every row where the LIM_/ROW_ tables say."""
    m = 4
    rows = {k: np.arange(m) + 10.0 * (i + 1) for i, k in enumerate(saturation.ROWS)}
    lim = saturation.pack_limits(0.5, 2.0, 2e7, 0.18, 1e9, 3e5, rows, p_relief=2.1e7, k_relief_per_area=5e-8)
    assert lim.shape == (saturation.N_HEAD + saturation.N_ROWS * m,)
    assert saturation.n_limit_states(lim) == m
    assert (lim[saturation.LIM_VMAX], lim[saturation.LIM_KVR], lim[saturation.LIM_PS], lim[saturation.LIM_EPS],
            lim[saturation.LIM_PR], lim[saturation.LIM_KRA], lim[saturation.LIM_THMAX], lim[saturation.LIM_KS],
            lim[saturation.LIM_CS]) == (0.5, 2.0, 2e7, saturation.SQRT_LAW_EPS, 2.1e7, 5e-8, 0.18, 1e9, 3e5)
    # the pressure limit off turns the relief off with it (no relief slot left set)
    off = saturation.pack_limits(0.5, 2.0, 0.0, 0.18, 1e9, 3e5, rows, p_relief=2.1e7, k_relief_per_area=5e-8)
    assert off[saturation.LIM_PR] == math.inf and off[saturation.LIM_KRA] == 0.0
    for i, k in enumerate(saturation.ROWS):
        b = saturation.row_start(i, m)
        np.testing.assert_array_equal(lim[b:b + m], rows[k])
    big = saturation.embed_limits(lim, 7, 2)
    assert saturation.n_limit_states(big) == 7
    for i, k in enumerate(saturation.ROWS):
        b = saturation.row_start(i, 7)
        np.testing.assert_array_equal(big[b + 2:b + 2 + m], rows[k])
    assert saturation.pack_limits(0.0, 1.0, 0.0, 0.0, 1.0, 1.0, rows).size == 0


def test_taos3d_state_bearing_aux_and_record_tables():
    from taos.taos3d import dynamics as dy

    _tiles({"X_P": dy.X_P, "X_Q": dy.X_Q, "X_V": dy.X_V, "X_W": dy.X_W},
           {"X_P": 3, "X_Q": 4, "X_V": 3, "X_W": 3}, dy.N_BODY)
    _tiles(_consts(dy, "BS_"), {"BS_PHI": 2, "BS_Z": 2, "BS_T": 2, "BS_PHI_PREV": 2, "BS_Z_PREV": 2,
                                     "BS_W": 2},
           dy.N_BEARING)
    _tiles(_consts(dy, "AUX_"), {"AUX_W": 6, "AUX_FL": 2, "AUX_PHI": 2, "AUX_THETA": 2}, dy.N_AUX)
    _tiles(_consts(dy, "U_"), {"U_START": 2, "U_MID": 2, "U_END": 2}, 6)
    rec = _consts(dy, "REC_")
    _tiles(rec, {"REC_W": 6, "REC_P": 3, **{k: 2 for k in rec if k not in ("REC_W", "REC_P")}}, len(dy.REC))
    for name, col in rec.items():  # each group starts at its pitch (or x) column
        assert dy.REC[col] in ("theta_pitch", "xp_pitch", "fl_pitch", "tf_pitch", "z_pitch", "phi_pitch",
                               "u_pitch", "w_fx", "px", "pl_pitch", "q_pitch"), name
    assert [dy.REC[c] for c in dy._DWELL_COLS] == ["xp_pitch", "xp_yaw", "theta_pitch", "theta_yaw"]


@pytest.fixture(scope="module")
def packed():
    from taos.taos3d import load_taos_model
    from taos.taos3d.simulate import pack

    tm = load_taos_model(MODELS / "rs25_hotfire.toml")
    return tm, pack(tm)


def test_taos3d_pack_fills_every_field(packed):
    """The packer builds the named tuple by field name, every field with its documented shape,
    and hands the kernels its record (the same fields, the same values)."""
    from taos.planar.actuator import actuator_state_space
    from taos.taos3d import dynamics as dy

    tm, pk = packed
    P = pk.P
    assert isinstance(P, np.record) and P.dtype.names == dy.TaosParams._fields
    for name, v in zip(dy.TaosParams._fields, dy.as_params(P)):
        assert np.array_equal(v, P[name]), name
    na = pk.n_act
    assert pk.n_state == dy.N_BODY + 2 * na
    shapes = {"spatial_inertia": (6, 6), "spatial_inertia_inv": (6, 6), "chain_stiffness": (6, 6),
              "slip_gain": (2, 6), "bearing_compliance": (2, 2), "bearing_selection": (6, 2),
              "structure_attach_m": (2, 3), "engine_attach_m": (2, 3), "act_A": (na, na), "act_b_xc": (na,),
              "act_b_fl": (na,), "act_c_xp": (na,), "bearing_axes": (2, 3), "line_length0_m": (2,),
              "torque_wrench": (6, 2), "line_stiffness_N_per_m": (2,), "line_damping_Ns_per_m": (2,)}
    for name in dy.TaosParams._fields:  # every field is documented in the class docstring
        assert f"\n    {name} " in dy.TaosParams.__doc__, name
    for name, shape in shapes.items():
        a = getattr(P, name)
        assert a.shape == shape and a.dtype == np.float64 and a.flags.c_contiguous, name
    for name in ("moment_arm_m", "engine_stiffness_Nm_per_rad"):
        assert isinstance(getattr(P, name), float), name
    assert np.array_equal(P.line_stiffness_N_per_m, tm.line_load_stiffnesses_N_per_m)
    assert P.line_stiffness_N_per_m[0] == tm.line_load_stiffness_N_per_m
    assert P.moment_arm_m == tm.base.actuator.moment_arm_m
    assert P.engine_stiffness_Nm_per_rad == tm.base.engine.rotational_stiffness_Nm_per_rad
    act = actuator_state_space(tm.base.actuator)
    assert act.states[P.act_vp_index] == "v_p_m_s"
    assert act.states[P.act_pl_index] == "p_load_Pa" and act.states[P.act_q_index] == "q_m_s"
    assert P.limits.size == 0 or saturation.n_limit_states(P.limits) == na
    np.testing.assert_allclose(P.torque_wrench, P.chain_stiffness @ P.bearing_selection @ P.bearing_compliance)


def test_planar_plant_limits_cover_the_state():
    from taos.planar.simplex import simplex_limits, simplex_plant

    m = load_model(MODELS / "rs25_ambient.toml")
    lim = simplex_limits(m)
    assert saturation.n_limit_states(lim) == simplex_plant(m).ss.A.shape[0]
