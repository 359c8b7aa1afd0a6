"""python-control interoperation and the one margin routine.

Round trips: each linear model (simplex block, vehicle + FCS block, open flight loop, the whole
MASV model) and each kind of frequency response (linear, sine-dwell, estimated from data, MASV)
goes to python-control and back; python-control's own evaluation of the converted object must
match the project's response to 1e-9. Margins: every crossing of the shipped flight loop,
from the sampled loop and from the exact state space, against python-control's
``stability_margins(returnall=True)`` evaluated independently on the same model.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

control = pytest.importorskip("control")

from taos.flight.vehicle import (flight_loop_margins, load_flight, loop_freqresp, margins,  # noqa: E402
                                 open_loop_state_space, vehicle_fcs_state_space)
from taos.planar.freqresp import linear_freqresp, sine_dwell_freqresp  # noqa: E402
from taos.interop import (freqresp_from_control, frd_samples, from_control_ss, measured_to_control,  # noqa: E402
                          to_control, to_control_ss)
from taos.linear import StateSpace  # noqa: E402
from taos.stability import loop_margins  # noqa: E402
from taos.model import load_model  # noqa: E402
from taos.planar.simplex import simplex_state_space  # noqa: E402

F = np.logspace(-2, 2, 200)
DEG = math.pi / 180


def _rel(a, b):
    return float(np.max(np.abs(a - b)) / np.max(np.abs(b)))


def _ct_response(sys, f):
    """python-control's own evaluation: (F, n_out, n_in)."""
    return np.moveaxis(np.asarray(sys(2j * np.pi * f, squeeze=False)), -1, 0)


def _masv_system():
    from masv.config import load_config
    from masv.system import build_system
    return build_system(load_config("models/masv/core_stage.toml"))


def _linear_models():
    m = load_model("rs25_hotfire")
    fl = load_flight("models/flight/core_stage.toml")
    return {"simplex": simplex_state_space(m, "pitch"), "vehicle_fcs": vehicle_fcs_state_space(fl),
            "open_flight_loop": open_loop_state_space(fl)}


@pytest.mark.parametrize("name", ["simplex", "vehicle_fcs", "open_flight_loop"])
def test_state_space_round_trip(name):
    ss = _linear_models()[name]
    sys = to_control_ss(ss)
    assert list(sys.input_labels) == list(ss.inputs) and list(sys.state_labels) == list(ss.states)
    assert _rel(_ct_response(sys, F), ss.freqresp(F)) < 1e-9
    back = from_control_ss(sys)
    assert back.inputs == ss.inputs and back.outputs == ss.outputs and back.states == ss.states
    for M in "ABCD":
        assert np.array_equal(getattr(back, M), getattr(ss, M))


def test_masv_state_space_round_trip_keeps_dotted_names():
    s = _masv_system()
    ss = s.state_space()
    sys = to_control(s)
    assert all("." not in n for n in sys.input_labels)
    f = np.logspace(-1, 1.5, 40)
    xp, th = s.frf(f)           # the block-elimination response, an independent path
    H = _ct_response(sys, f)
    na = s.n_actuators
    assert _rel(H[:, :na], xp) < 1e-9 and _rel(H[:, na:], th) < 1e-9
    back = from_control_ss(sys)
    assert back.inputs == ss.inputs and back.states == ss.states and np.array_equal(back.A, ss.A)


def test_transfer_function_comes_in_as_state_space():
    """A loop designer's own filter, written as a transfer function, comes in as a taos block."""
    w = 2 * math.pi * 3.0
    tf = control.tf([1, 0, w * w], [1, 2 * 0.7 * w, w * w], inputs="u_rad", outputs="y_rad")
    ss = from_control_ss(tf)
    assert isinstance(ss, StateSpace) and ss.inputs == ("u_rad",)
    s = 2j * np.pi * F
    assert _rel(ss.freqresp(F)[:, 0, 0], (s * s + w * w) / (s * s + 2 * 0.7 * w * s + w * w)) < 1e-9


def test_linear_and_sine_dwell_freqresp_round_trip():
    m = load_model("rs25_hotfire")
    f = np.array([0.5, 2.0, 7.0])
    for fr in (linear_freqresp(m, F), sine_dwell_freqresp(m, f, 0.4 * DEG, settle_s=1.0)):
        data = to_control(fr)
        H = _ct_response(data, fr.freq_hz)     # python-control evaluates its FRD at its points
        assert _rel(H[:, 0, 0], fr.piston) < 1e-9 and _rel(H[:, 1, 0], fr.engine) < 1e-9
        back = freqresp_from_control(data, fr.amplitude_rad, fr.axis, fr.friction_model)
        assert np.allclose(back.freq_hz, fr.freq_hz, rtol=1e-15, atol=0)
        assert _rel(back.piston, fr.piston) < 1e-12 and _rel(back.engine, fr.engine) < 1e-12
        assert back.amplitude_rad == fr.amplitude_rad


def test_linear_freqresp_frd_matches_state_space_conversion():
    """The FRD of the linear response equals python-control's own response of the converted simplex
    block: two conversion paths, one answer."""
    m = load_model("rs25_hotfire")
    sys = to_control_ss(simplex_state_space(m, "pitch"))
    H = _ct_response(sys, F)
    R = m.actuator.moment_arm_m
    fr = linear_freqresp(m, F)
    _, Hd, _, _ = frd_samples(to_control(fr))
    o = list(sys.output_labels)
    assert _rel(Hd[:, 0, 0], H[:, o.index("x_p_m"), 0] / R) < 1e-9
    assert _rel(Hd[:, 1, 0], H[:, o.index("theta_rad"), 0]) < 1e-9


def test_measured_response_round_trip():
    from taos.identify.data import load_test_data
    from taos.identify.estimation import estimate
    rs = estimate(load_test_data("models/data/greenrun_hotfire_synthetic.csv"))
    mr = rs[0]
    _, idx = np.unique(mr.freq_hz, return_index=True)
    mr = mr.select(np.isin(np.arange(len(mr)), idx))
    data = measured_to_control(mr)
    H = _ct_response(data, mr.freq_hz)
    assert _rel(H[:, 0, 0], mr.piston_m_per_rad) < 1e-9
    f, Hs, ins, outs = frd_samples(data)
    assert ins == ("command_rad",) and outs[0] == "piston_m_per_rad"
    assert np.allclose(f, mr.freq_hz, rtol=1e-15, atol=0)


def test_masv_freqresp_round_trip():
    from masv.analysis import frequency_response
    fr = frequency_response(_masv_system(), np.logspace(-1, 1.5, 30))
    data = to_control(fr)
    f, H, ins, outs = frd_samples(data)
    assert ins[0] == f"{fr.actuators[0]}.command_rad"
    na = len(fr.actuators)
    assert _rel(H[:, :na], fr.piston) < 1e-12 and _rel(H[:, na:], fr.engine) < 1e-12


# -- margins ------------------------------------------------------------------------------------
def _ct_margins(fl):
    """python-control on the loop built independently here: L0 = -(H_delta + s H_rate) of the
    vehicle + FCS block, as the transfer-function product of its two channels."""
    vf = to_control_ss(vehicle_fcs_state_space(fl))
    s = control.tf("s")
    sub = control.ss2tf(vf)
    L = -(sub[0, 0] + s * sub[0, 1])
    L = control.minreal(L, tol=1e-9, verbose=False)
    gm, pm, _sm, wpc, wgc, _ = control.stability_margins(L, returnall=True)
    return 20 * np.log10(gm), np.asarray(wpc) / (2 * np.pi), pm, np.asarray(wgc) / (2 * np.pi)


def test_flight_loop_margins_list_every_crossing_as_python_control():
    fl = load_flight("models/flight/core_stage.toml")
    gm, fpc, pm, fgc = _ct_margins(fl)
    # every phase crossover of the reference: 0.091, 2.27, 3.21 (notch zero), 14.4 Hz
    assert fpc.size == 4 and fgc.size == 1
    exact = flight_loop_margins(fl)
    c = exact.crossings
    assert np.allclose(c.phase_crossover_hz, fpc, rtol=1e-7)
    finite = gm < 200   # the notch zero |L| ~ 1e-15 is fixed only to rounding
    assert np.allclose(c.gain_margin_db[finite], gm[finite], rtol=0, atol=1e-4)
    assert np.allclose(c.gain_crossover_hz, fgc, rtol=1e-7) and np.allclose(c.phase_margin_deg, pm, atol=1e-4)
    # the binding margins: the 14.4 Hz crossing (28.5 dB) not the first one above crossover (29.7 dB)
    assert exact.high_gain_margin_db == pytest.approx(28.51, abs=0.01)
    assert exact.high_phase_crossover_hz == pytest.approx(14.41, abs=0.01)
    # (the shipped loop's K_i is the LCO calibration knob: 7.18 dB low margin at 0.104 Hz)
    assert exact.low_gain_margin_db == pytest.approx(7.18, abs=0.01)
    assert exact.phase_margin_deg == pytest.approx(51.63, abs=0.01)
    # the sampled routine on a fine grid finds the same crossings
    f = np.logspace(-2, 2, 4000)
    smp = margins(f, loop_freqresp(fl, f)).crossings
    assert np.allclose(smp.phase_crossover_hz, fpc, rtol=3e-6)   # grid 1e-3 decade
    assert np.allclose(smp.gain_margin_db[finite], gm[finite], atol=1e-3)
    assert np.allclose(smp.gain_crossover_hz, fgc, rtol=1e-6) and np.allclose(smp.phase_margin_deg, pm, atol=1e-4)
    assert smp.gain_margin_db[~finite] > 100


def test_sampled_margins_of_a_known_loop():
    """L = k / (s (s + 1)^2): one phase crossover at w = 1 rad/s with GM = 2 / k, analytic."""
    k = 0.5
    w = np.logspace(-2, 2, 2000)
    s = 1j * w
    lm = loop_margins(w / (2 * np.pi), k / (s * (s + 1) ** 2))
    assert lm.phase_crossover_hz.size == 1
    assert lm.phase_crossover_hz[0] == pytest.approx(1 / (2 * np.pi), rel=3e-5)   # grid 2e-3 decade
    assert lm.gain_margin_db[0] == pytest.approx(20 * math.log10(2 / k), abs=3e-4)
    with pytest.raises(ValueError):
        loop_margins(w[::-1], k / (s * (s + 1) ** 2))
