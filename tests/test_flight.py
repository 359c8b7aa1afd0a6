"""Notional flight-control loop (seed paper sec. 3.1, fig. 6): the loop transfer function
against its closed form, typical margins with a low-frequency gain margin, and the closed
Lur'e plant against the loop margins."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest

from taos.errors import InputError
from taos.flight.vehicle import fcs_filter_ss, fcs_filter_tf, flight_plant, load_flight, loop_freqresp, margins
from taos.planar.freqresp import linear_freqresp
from taos.model import load_model

from .conftest import MODELS

FLIGHT = MODELS / "flight" / "core_stage.toml"


def test_loop_equals_closed_form_rigid_body_pid_with_tail_wags_dog():
    """L0(jw) = (a + b s^2)/s^2 (K_p + K_i/s + K_d s) F(s) P(s) at s = jw, from the state
    space, to 1e-9."""
    fl = load_flight(FLIGHT)
    v, c = fl.vehicle, fl.fcs
    f = np.logspace(-2, 1, 50)
    s = 2j * np.pi * f
    a, b = v.control_acceleration_per_s2(fl.axis), v.twd_coefficient(fl.axis)
    num, den = fcs_filter_tf(c)
    ref = (a + b * s ** 2) / s ** 2 * (c.attitude_gain + c.integral_gain_per_s / s + c.rate_gain_s * s) \
        * np.polyval(num, s) / np.polyval(den, s)
    assert np.allclose(loop_freqresp(fl, f), ref, rtol=1e-9)
    # the tail-wags-dog frequency is the zero of the state-space loop (|L0| there ~1e-18 against
    # ~7e-4 one percent away)
    f_twd = v.twd_frequency_hz(fl.axis)
    assert abs(loop_freqresp(fl, [f_twd])[0]) < 1e-9 * abs(loop_freqresp(fl, [0.99 * f_twd])[0])


def test_fcs_filter_state_space_is_scipy_tf2ss_bit_for_bit():
    """The written-out controller canonical form equals ``scipy.signal.tf2ss`` exactly (same
    shapes, same floats) for every filter shape: with or without lag and notch, delays up to the
    bound, Pade orders 0-6, and the static filter's idle state."""
    import dataclasses

    import scipy.signal

    base = load_flight(FLIGHT).fcs
    for lag, notch, delay, order in itertools.product((0.0, 0.05, 10.0), (0.0, 3.0), (0.0, 0.02, 2.0), range(7)):
        c = dataclasses.replace(base, lag_time_constant_s=lag, notch_frequency_hz=notch, delay_s=delay,
                                pade_order=order)
        for got, ref in zip(fcs_filter_ss(c), scipy.signal.tf2ss(*fcs_filter_tf(c)), strict=True):
            assert got.shape == ref.shape and got.dtype == ref.dtype and np.array_equal(got, ref), (c, got, ref)


def test_loop_meets_typical_margins_and_is_conditionally_stable():
    """>= 6 dB gain margins and >= 30 deg phase margin, with a low-frequency -180 deg crossing
    (conditionally stable: a gain loss of the low-frequency margin destabilises it)."""
    fl = load_flight(FLIGHT)
    f = np.logspace(-2.5, 1.3, 3000)
    m = margins(f, loop_freqresp(fl, f))
    assert m.low_gain_margin_db >= 6 and m.high_gain_margin_db >= 6 and m.phase_margin_deg >= 30
    assert 0.05 < m.low_phase_crossover_hz < 0.2


def test_closed_lure_plant_goes_unstable_at_the_low_frequency_gain_margin():
    """The closed flight loop (vehicle + FCS + linear simplex TVC, no friction, command gain k on
    the avionics channel) is stable at k = 1 and has a pole pair on the imaginary axis at the
    low-frequency phase crossover of L0 x TVC when k = 10^(-GM/20): one model, two code paths."""
    fl = load_flight(FLIGHT)
    m = load_model(MODELS / "rs25_flight.toml", friction="none")
    p = flight_plant(fl, m)
    bc = p.ss.B[:, p.ss.input_index("command_rad")]
    f = np.logspace(-2.5, 1.3, 4000)
    mg = margins(f, loop_freqresp(fl, f) * linear_freqresp(m, f, fl.axis).engine)
    ev = np.linalg.eigvals(p.ss.A + np.outer(bc, p.cmd_c))
    assert ev.real.max() < 0
    k = 10 ** (-mg.low_gain_margin_db / 20)
    ev = np.linalg.eigvals(p.ss.A + k * np.outer(bc, p.cmd_c))
    i = np.argmax(ev.real)
    assert abs(ev[i].real) < 2e-3
    assert abs(abs(ev[i].imag) / (2 * np.pi) / mg.low_phase_crossover_hz - 1) < 0.01


def test_flight_file_bad_input_is_one_line(tmp_path):
    bad = tmp_path / "f.toml"
    bad.write_text(FLIGHT.read_text().replace('gimbal_arm = "40 m"', 'gimbal_arm = "40 kg"'))
    with pytest.raises(InputError, match="vehicle.gimbal_arm"):
        load_flight(bad)
    bad.write_text(FLIGHT.read_text().replace("engine_count = 4", "engine_count = 0"))
    with pytest.raises(InputError, match="vehicle.engine_count"):
        load_flight(bad)


def test_optional_bending_mode_against_hand_calculation_and_the_fcs_notch():
    """Issue 12.9: a first bending mode (eta'' + 2 zeta w_b eta' + w_b^2 eta = g a delta, sensed
    with the attitude) multiplies the rigid loop by exactly 1 + g (-w^2) / (w_b^2 - w^2 + 2 j zeta
    w_b w) when the tail-wags-dog term is off; the FCS notch at w_b takes the resonance out."""
    import dataclasses

    import numpy as np

    from taos.flight.vehicle import load_flight, loop_freqresp
    fl = load_flight(MODELS / "flight" / "core_stage.toml")
    assert fl.vehicle.bending_frequency_hz == 0.0  # off in the shipped LCO calibration
    rigid = dataclasses.replace(fl, vehicle=dataclasses.replace(fl.vehicle, engine_mass_kg=0.0,
                                                                  engine_inertia_kgm2=0.0))
    fb, zb, g = 6.0, 0.005, 0.02
    bent = dataclasses.replace(rigid, vehicle=dataclasses.replace(rigid.vehicle, bending_frequency_hz=fb,
                                                                    bending_damping_ratio=zb, bending_gain=g))
    f = np.array([0.05, 0.2, 1.0, 5.0, 6.0, 8.0])
    w, wb = 2 * np.pi * f, 2 * np.pi * fb
    expect = loop_freqresp(rigid, f) * (1 + g * (-w ** 2) / (wb ** 2 - w ** 2 + 2j * zb * wb * w))
    np.testing.assert_allclose(loop_freqresp(bent, f), expect, rtol=1e-9)
    notched = dataclasses.replace(bent, fcs=dataclasses.replace(bent.fcs, notch_frequency_hz=fb,
                                                                  notch_zeta_num=0.005, notch_zeta_den=0.5))
    peak = abs(loop_freqresp(bent, [fb])[0]) / abs(loop_freqresp(rigid, [fb])[0])
    assert peak == pytest.approx(math.hypot(1.0, g / (2 * zb)), rel=1e-9)  # |1 + j g / (2 zeta)| at w_b
    assert abs(loop_freqresp(notched, [fb])[0]) < 0.05 * abs(loop_freqresp(bent, [fb])[0])
