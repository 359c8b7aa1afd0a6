"""Per-axis load stiffness (issue 39, "load stiffness (per axis allowed)"): ``[structure]
load_stiffness_yaw`` is the yaw axis' own K_L. Absent (the shipped files) nothing changes; given,
the planar yaw axis uses it (load resonance, simplex block, load-path damping), the 3-D model
derives the yaw actuator line's own stiffness from it (each axis' notch on its own load
resonance), the line-stiffness fingerprint covers it, and the 3-D fit frees it and fits a record
made with different pitch and yaw stiffness back within its standard errors."""

from __future__ import annotations

import math

import numpy as np
import pytest

from taos.errors import InputError
from tests._records3d import IN_LBF, LBF_PER_IN, ROOT, write_record3d

HOT = ROOT / "models" / "rs25_hotfire.toml"
YAW_KL = 150000.0 * LBF_PER_IN


@pytest.fixture(scope="module")
def hot():
    from taos.model import load_model
    return load_model(HOT)


@pytest.fixture(scope="module")
def hot3d(hot):
    from taos.taos3d import taos_model
    return taos_model(hot)


def test_absent_key_is_the_pitch_value(hot):
    s = hot.structure
    assert s.load_stiffness_yaw_N_per_m == 0.0 and s.stiffness_N_per_m("yaw") == s.load_stiffness_N_per_m
    assert hot.load_resonance_hz("yaw") == hot.load_resonance_hz("pitch")


def test_planar_yaw_axis_uses_its_own_stiffness(hot):
    from taos.planar.simplex import simplex_state_space

    v = hot.with_values({"structure.load_stiffness_yaw": "150000 lbf/in"})
    same = hot.with_values({"structure.load_stiffness": YAW_KL})   # both axes at the yaw value
    assert v.structure.stiffness_N_per_m("yaw") == pytest.approx(YAW_KL, rel=1e-12)
    assert v.load_resonance_hz("pitch") == hot.load_resonance_hz("pitch")
    assert v.load_resonance_hz("yaw") == pytest.approx(same.load_resonance_hz("yaw"), rel=1e-12)
    for ax, ref in (("pitch", hot), ("yaw", same)):   # each axis' block is that of its own K_L
        np.testing.assert_allclose(simplex_state_space(v, ax).A, simplex_state_space(ref, ax).A, rtol=1e-12,
                                   atol=0)
    assert ("structure.load_stiffness_yaw", "150000 lbf/in") in v.overrides and v.sha256 != hot.sha256


def test_yaw_stiffness_bounds_are_input_errors(hot):
    with pytest.raises(InputError, match="structure.load_stiffness_yaw"):
        hot.with_values({"structure.load_stiffness_yaw": 10.0})
    with pytest.raises(InputError, match="structure.load_stiffness_yaw"):
        hot.with_values({"structure.load_stiffness_yaw": -1.0})


def test_3d_yaw_line_puts_each_notch_on_its_own_resonance(hot3d):
    from taos.taos3d import with_values
    from taos.taos3d.calibrate import taos_notch_hz
    from taos.taos3d.simulate import pack

    assert hot3d.gimbal.line_load_stiffness_yaw_N_per_m is None
    kp, ky = hot3d.line_load_stiffnesses_N_per_m
    assert kp == ky == hot3d.line_load_stiffness_N_per_m
    v = with_values(hot3d, {"structure.load_stiffness_yaw": YAW_KL})
    lines = v.line_load_stiffnesses_N_per_m
    assert lines[0] == pytest.approx(kp, rel=1e-4) and lines[1] < 0.8 * lines[0]
    for ax in ("pitch", "yaw"):
        f = v.base.load_resonance_hz(ax)
        assert taos_notch_hz(v, f, ax) == pytest.approx(f, rel=1e-3), ax
    assert np.array_equal(pack(v).P.line_stiffness_N_per_m, lines)
    assert v.gimbal.line_stiffness_basis != hot3d.gimbal.line_stiffness_basis   # the fingerprint covers it
    assert math.isclose(v.base.structure.stiffness_N_per_m("yaw"), YAW_KL, rel_tol=1e-12)


@pytest.mark.slow
def test_fit_recovers_different_pitch_and_yaw_stiffness(hot3d, tmp_path):
    from taos.identify.data import load_test_data
    from taos.identify.fit3d import fit_taos
    from taos.taos3d import with_values
    from taos.taos3d.model import normal_load_N

    kl, tc = 180000.0 * LBF_PER_IN, 100000.0 * IN_LBF
    mu = tc / (normal_load_N(hot3d.base) * hot3d.gimbal.bearing_radius_m)
    truth = with_values(hot3d, {"structure.load_stiffness": kl, "structure.load_stiffness_yaw": YAW_KL,
                                "friction.coulomb_torque": tc, "gimbal.friction_coefficient": mu})
    data = load_test_data(write_record3d(truth, tmp_path / "yaw.csv", seed=9))
    res = fit_taos(hot3d, [data], ["load_stiffness", "load_stiffness_yaw", "coulomb_torque"])
    for name, t in (("load_stiffness", kl), ("load_stiffness_yaw", YAW_KL), ("coulomb_torque", tc)):
        i = res.names.index(name)
        assert abs(res.values[i] - t) <= 3.0 * res.std_errors[i], (name, res.values[i], t, res.std_errors[i])
        assert res.std_errors[i] < 5e-3 * t, name
    assert res.identifiable and res.adequacy().verdict == "adequate"
    d = res.to_dict()
    assert d["line_load_stiffness_yaw_N_per_m"] < 0.9 * d["line_load_stiffness_N_per_m"]
