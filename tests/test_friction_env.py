"""Gimbal friction against its environment (issue 43, part 2; taos.flight.friction_env): the
Coulomb level follows the bearing normal load through thrust in both engines and along an ascent,
and the modified-LuGre vibration level follows a vibration environment."""

from __future__ import annotations

import math

import numpy as np
import pytest

from taos.errors import InputError
from taos.flight.friction_env import at_thrust, bearing_level_Nm, friction_scale, vibration_velocity, with_vibration
from taos.model import load_model

MU, RB = 0.0649, 0.110   # models/rs25_*.toml [gimbal] friction_coefficient, bearing_radius


@pytest.mark.parametrize("name", ["rs25_flight", "rs25_hotfire"])
@pytest.mark.parametrize("thrust_N", [1.86e6, 2.279e6, 1.0e6])
def test_friction_scales_with_thrust_as_mu_N_rb_in_both_engines(name, thrust_N):
    """Acceptance: friction scales with thrust as mu N r_b in both engines. Planar: the variant
    at thrust N has T_c = mu N r_b and its torque-like parameters in proportion (pre-sliding angle
    kept); 3-D: the 3-D model's bearing level is the same mu N r_b."""
    from taos.taos3d.calibrate import taos_model

    m = load_model(name)
    v = at_thrust(m, thrust_N)
    assert v.friction.coulomb_torque_Nm == pytest.approx(MU * thrust_N * RB, rel=1e-12)
    assert v.engine.thrust_N == thrust_N and "engine.thrust" in dict(v.overrides)
    pre = lambda law: law.coulomb_torque_Nm / law.bristle_stiffness_Nm_per_rad  # noqa: E731  pre-sliding angle
    assert pre(v.friction) == pytest.approx(pre(m.friction), rel=1e-12)
    tm = taos_model(v)
    assert tm.coulomb_torque_Nm == pytest.approx(MU * thrust_N * RB, rel=1e-12)
    assert tm.bearing_friction.coulomb_torque_Nm == pytest.approx(tm.coulomb_torque_Nm, rel=1e-12)


def test_hanging_engine_and_a_file_without_gimbal_table():
    m = load_model("rs25_ambient")
    assert bearing_level_Nm(m, 0.0) == pytest.approx(MU * m.engine.mass_kg * 9.80665 * RB)
    g = load_model("generic_upper_engine")   # no [gimbal]: mu r_b = T_c / N of the file itself
    assert bearing_level_Nm(g, 90e3) == pytest.approx(0.5 * g.friction.coulomb_torque_Nm)
    for bad in (-1.0, float("nan"), True, "1 MN", 1e9):
        with pytest.raises(InputError):
            bearing_level_Nm(m, bad)


def test_ascent_friction_level_follows_the_thrust_profile():
    """Along an ascent (friction_follows_thrust): the law packed for each update interval is the
    model's scaled by N(t) / N_model, so the level at two times matches their thrusts
    (T_c = mu N(t) r_b); with the trajectory's thrust equal to the model's the run is bit-identical
    to the run at the file's level."""
    from taos.flight.ascent import load_ascent
    from taos.flight.ascent_sim import _external_inputs, _grid, _lane, simulate_ascent
    from taos.flight.lco import with_bounding_avionics

    asc = load_ascent("ascent")
    m = with_bounding_avionics(load_model(asc.tvc_model, friction="lugre"))
    _, rec, t, bounds = _grid(asc, 20.0, 140.0, 1e-3, 0.01)
    ln = _lane(asc, m, "yaw", t, bounds, rec, 1e-3, 20.0, 0.0, _external_inputs(asc, "yaw", t, 0, 1e-3), True)
    mids = [t[a] + 0.5 * (t[b] - t[a]) for a, b in zip(bounds[:-1], bounds[1:])]
    for tq in (30.0, 135.0):
        s = int(np.searchsorted(mids, tq))
        n = float(asc.trajectory.at("core_thrust_per_engine_N", mids[s]))
        law = m.friction.scaled(n / m.engine.thrust_N)
        assert np.array_equal(ln.fpack[s], law.pack())
        assert law.coulomb_torque_Nm == pytest.approx(MU * n * RB, rel=2e-5)   # the file's T_c is mu N r_b to 5 digits
    assert friction_scale(m, 1.86e6) == pytest.approx(1.86 / 2.279)
    kw = {"axes": ("yaw",), "start_s": 200.0, "end_s": 215.0, "dt_s": 1e-3, "attitude0_rad": 0.002}
    a = simulate_ascent(asc, m, **kw)
    b = simulate_ascent(asc, m, friction_follows_thrust=True, **kw)   # thrust 2279 kN = the model's
    for k in a.signals:
        assert np.array_equal(a.signals[k], b.signals[k]), k
    assert b.provenance["friction_follows_thrust"] is True and "friction_follows_thrust" not in a.provenance


def test_vibration_level_mappings():
    """V_d from an environment (module docstring): a sine rate is V_d itself; a Gaussian rate of
    RMS sigma gives the same small-rate slope as the law's sine average, checked numerically;
    an acceleration PSD at the nozzle integrates to that rate RMS."""
    from scipy.special import erf

    assert vibration_velocity(rate_amplitude_rad_s=0.01) == 0.01
    sigma = 0.004
    vd = vibration_velocity(rate_rms_rad_s=sigma)
    v = 1e-6   # slopes at v -> 0: (2/pi) asin(v / V_d) against erf(v / (sqrt(2) sigma))
    assert (2 / math.pi) * math.asin(v / vd) == pytest.approx(erf(v / (math.sqrt(2) * sigma)), rel=1e-6)
    f = np.linspace(20.0, 2000.0, 200001)
    L, W = 3.0, 0.01
    rate_psd = W * 9.80665 ** 2 / (L ** 2 * (2 * np.pi * f) ** 2)
    rms = math.sqrt(np.trapezoid(rate_psd, f))
    assert vibration_velocity(psd_g2_per_hz=W, band_hz=(20.0, 2000.0), arm_m=L) == pytest.approx(
        math.sqrt(2 / math.pi) * rms, rel=1e-6)
    assert vibration_velocity(accel_amplitude_m_s2=2 * math.pi * 10.0 * 3.0 * 0.01, freq_hz=10.0, arm_m=3.0) \
        == pytest.approx(0.01)
    m = with_vibration(load_model("rs25_flight"), vd)
    assert m.friction.name == "modified-lugre" and m.friction.vibration_velocity_rad_s == vd
    assert "friction.vibration_velocity" in dict(m.overrides)
    for bad in ({}, {"rate_rms_rad_s": -1.0}, {"psd_g2_per_hz": 0.01, "arm_m": 3.0},
                {"psd_g2_per_hz": 0.01, "band_hz": (20, 10), "arm_m": 3.0}, {"rate_rms_rad_s": 1, "rate_amplitude_rad_s": 1}):
        with pytest.raises(InputError):
            vibration_velocity(**bad)


def test_three_explanations_study_on_the_shipped_models():
    """The study (taos.flight.friction_study): each explanation is the flight model with one
    difference; less dither, less vibration and more thrust each lower the low-frequency engine
    gain (more effective friction), and dither on the stand keeps the flight loop out of the LCO
    that its absence gives."""
    import taos
    from taos.flight.friction_study import friction_explanations

    res = friction_explanations(taos.load_flight("core_stage"), load_model("rs25_flight"))
    by = {e.name: e for e in res.explanations}
    assert set(by) == {"cross-axis dither", "vibration environment", "thrust"}
    for e in res.explanations:
        assert e.gain_change_db < 0, e.name
    d = by["cross-axis dither"]
    assert d.lco == (False, True) and d.margin_db[0] > 0 and d.margin_change_db is None
    v = by["vibration environment"]
    assert v.margin_change_db is not None and v.margin_change_db < 0
    assert res.to_dict()["explanations"][2]["lco_engine_amplitude_deg"][1] > 0
