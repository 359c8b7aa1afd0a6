"""Notional flight-control loop (seed paper sec. 3.1, fig. 6): the loop transfer function
against its closed form, typical margins with a low-frequency gain margin, and the closed
Lur'e plant against the loop margins."""

from __future__ import annotations

import numpy as np
import pytest

from taos.errors import InputError
from taos.flight.vehicle import fcs_filter_tf, flight_plant, load_flight, loop_freqresp, margins
from taos.freqresp import linear_freqresp
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
