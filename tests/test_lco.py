"""Flight-control limit cycle (seed paper secs. 3.1-3.2, figs. 6-8): the describing-function
prediction and the time-domain run of the closed flight loop, calibrated to the paper's
bounding results at ambient (115,000 lbf/in) and hot-fire (205,000 lbf/in) stiffness with
144,000 in-lbf friction."""

from __future__ import annotations

import math

import numpy as np
import pytest

from taos.flight.vehicle import load_flight
from taos.flight.lco import analyse_lco
from taos.model import Structure, load_model

from .conftest import MODELS, run_cli
from .inprocess import taos_json

#: slow (make check skips these, make test runs them): cycles confirmed in the time domain
pytestmark = pytest.mark.slow

DEG = math.pi / 180
LBF_IN = 4.4482216152605 / 0.0254
FLIGHT = MODELS / "flight" / "core_stage.toml"
AMPS = np.logspace(np.log10(0.01), 0.0, 8) * DEG
FREQ = np.logspace(np.log10(0.06), np.log10(0.5), 6)


@pytest.fixture(scope="module")
def reports():
    fl = load_flight(FLIGHT)
    out = {}
    for k, kl in (("ambient", 115000), ("hot", 205000)):
        for law in ("coulomb-switching", "dahl", "lugre"):
            m = load_model(MODELS / "rs25_flight.toml", friction=law)
            m = m.replace(structure=Structure(kl * LBF_IN))
            out[k, law] = analyse_lco(fl, m, amplitudes_rad=AMPS, freq_hz=FREQ, duration_s=160.0, window_s=60.0)
    return out


@pytest.mark.parametrize("law", ["coulomb-switching", "dahl", "lugre"])
def test_soft_structure_lco_about_0p1_deg_at_0p1_to_0p2_hz_in_prediction_and_time_domain(reports, law):
    """Paper fig. 7: with the ambient stiffness every bounding law limit-cycles, about 0.1 deg
    at 0.1-0.2 Hz; the describing function and the time-domain run agree within 12 % in
    amplitude and 10 % in frequency (achieved: Dahl and LuGre +3 % and +0.1 %, Coulomb, the
    least sinusoidal, -5.7 % and -5.1 %), and the predicted cycle is stable (Loeb)."""
    d = reports["ambient", law].to_dict()
    td = d["time_domain"]
    print(f"{law}: DF {d['amplitude_deg']:.4f} deg {d['frequency_hz']:.4f} Hz, time domain "
          f"{td['amplitude_deg']:.4f} deg {td['frequency_hz']:.4f} Hz: ratios "
          f"{td['amplitude_deg'] / d['amplitude_deg'] - 1:+.4f}, {td['frequency_hz'] / d['frequency_hz'] - 1:+.4f}")
    assert d["lco"] and d["stable"] and td["lco"]
    assert 0.1 <= d["frequency_hz"] <= 0.2 and 0.1 <= td["frequency_hz"] <= 0.2
    assert 0.03 <= d["engine_amplitude_deg"] <= 0.3 and 0.03 <= td["engine_amplitude_deg"] <= 0.3
    assert abs(td["amplitude_deg"] / d["amplitude_deg"] - 1) < 0.12
    assert abs(td["frequency_hz"] / d["frequency_hz"] - 1) < 0.10


def test_coulomb_cycle_is_largest_and_most_square(reports):
    """Paper fig. 7 (right): the Coulomb cycle has the largest amplitude and the most distorted,
    square-wave-like engine response (largest third harmonic)."""
    td = {law: reports["ambient", law].to_dict()["time_domain"] for law in ("coulomb-switching", "dahl", "lugre")}
    c = td.pop("coulomb-switching")
    for other in td.values():
        assert c["engine_amplitude_deg"] > other["engine_amplitude_deg"]
        assert c["engine_third_harmonic"] > 1.5 * other["engine_third_harmonic"]


def test_stiff_structure_no_lco_for_dahl_lugre_and_coulomb_about_halved(reports):
    """Paper fig. 8: at 205,000 lbf/in Dahl and LuGre do not limit-cycle (prediction and time
    domain), and the Coulomb amplitude is about half the ambient one: it scales with the
    breakaway deflection T_c/(K_L R^2), 115/205 = 0.561, within 8 % (achieved 0.571 to 0.581)."""
    for law in ("dahl", "lugre"):
        d = reports["hot", law].to_dict()
        assert not d["lco"] and d["margin_db"] > 0.3
        assert not d["time_domain"]["lco"]
    soft = reports["ambient", "coulomb-switching"].to_dict()
    hard = reports["hot", "coulomb-switching"].to_dict()
    assert hard["lco"] and hard["time_domain"]["lco"]
    for key in ("amplitude_deg", "engine_amplitude_deg"):
        print(f"hot / ambient {key}: DF {hard[key] / soft[key]:.4f}, "
              f"time domain {hard['time_domain'][key] / soft['time_domain'][key]:.4f}")
        assert hard[key] / soft[key] == pytest.approx(115 / 205, rel=0.08)
        assert hard["time_domain"][key] / soft["time_domain"][key] == pytest.approx(115 / 205, rel=0.08)


@pytest.mark.parametrize("law", ["coulomb-switching", "dahl", "lugre"])
def test_larger_command_amplitude_restores_stability(reports, law):
    """Paper sec. 3.2 (PTIs): above the LCO amplitude the friction degradation shrinks: at 3x
    the LCO command amplitude L0 N has positive low-frequency gain margin and phase margin
    (stable), while at a third of it the low-frequency margin is gone; at 1 deg most of the
    loop's own 7.2 dB low-frequency margin is back (the -1 dB bounding avionics and the friction's
    remaining loss take 2.6 dB) with a 30 deg phase margin. (The paper states no margin
    requirement; the former "typical 6 dB" at 1 deg belonged to the retuned 9.5 dB loop.)"""
    p = reports["ambient", law].prediction
    a = p.stable_cycle.amplitude_rad
    hi = p.margins_at(3 * a)
    assert hi.low_gain_margin_db > 1.0 and hi.phase_margin_deg > 20
    big = p.margins_at(1.0 * DEG)
    assert big.low_gain_margin_db >= 4.0 and big.phase_margin_deg >= 30.0


def test_cli_lco_json_and_plots(tmp_path):
    """``taos lco MODEL --flight F --json FILE`` gives the contract keys; plots are written (in this
    process, :mod:`tests.inprocess`); a bad value through the console script: one line, exit 2."""
    d = taos_json(tmp_path / "lco.json", "lco", MODELS / "rs25_flight.toml", "--flight", FLIGHT, "--friction",
                  "modified-lugre", "--amplitudes-deg", "0.02,0.1,0.5", "--freq-hz", "0.08,0.15,0.3", "--duration",
                  "40", "--plot", tmp_path / "n.png", "--plot-time", tmp_path / "t.svg")
    for k in ("lco", "amplitude_deg", "frequency_hz", "stable", "margin_db", "time_domain"):
        assert k in d
    assert d["lco"] is False and d["amplitude_deg"] is None and d["margin_db"] > 3
    assert (tmp_path / "n.png").exists() and (tmp_path / "t.svg").exists()
    bad = run_cli("lco", MODELS / "rs25_flight.toml", "--flight", FLIGHT, "--load-stiffness", "12 kg",
                  "--json", tmp_path / "x.json")
    assert bad.returncode == 2 and len(bad.stderr.strip().splitlines()) == 1 and "--load-stiffness" in bad.stderr
    assert not (tmp_path / "x.json").exists()


def test_lco_sweep_map_shows_where_the_verdict_flips(tmp_path):
    """Issue 12.2: ``taos lco --sweep`` over the flight loop's integral gain (the calibration
    knob) with the one Green Run friction set: at the old K_i = 0.6 1/s (low-frequency gain margin
    9.5 dB) soft-structure Dahl has no cycle, at the shipped 0.78 1/s (7.2 dB) it has one; the
    JSON names the flip and the loop margins, and the map is drawn (in this process,
    :mod:`tests.inprocess`); a bad --sweep through the console script: exit 2, nothing on stdout."""
    amps = ",".join(f"{a:.4g}" for a in np.degrees(AMPS))
    freqs = ",".join(f"{f:.4g}" for f in FREQ)
    d = taos_json(tmp_path / "map.json", "lco", MODELS / "rs25_flight.toml", "--flight", FLIGHT, "--friction", "dahl",
                  "--sweep", "integral_gain=0.6,0.78", "--amplitudes-deg", amps, "--freq-hz", freqs,
                  "--plot-map", tmp_path / "map.png")["sweep"]
    assert d["lco"] == [False, True]
    assert 0.3 < d["margin_db"][0] < 3.0 and d["margin_db"][1] == 0.0
    assert 0.05 <= d["engine_amplitude_deg"][1] <= 0.2 and 0.1 <= d["frequency_hz"][1] <= 0.2
    assert d["flips"] == [{"axis": "integral_gain", "between": [0.6, 0.78], "at": {}}]
    lgm = d["loop_low_gain_margin_db"]
    assert lgm["integral_gain=0.6"] == pytest.approx(9.46, abs=0.05)
    assert lgm["integral_gain=0.78"] == pytest.approx(7.18, abs=0.05)
    assert (tmp_path / "map.png").stat().st_size > 1000
    bad = run_cli("lco", MODELS / "rs25_flight.toml", "--flight", FLIGHT, "--sweep", "bogus=1,2", "--json", "-")
    assert bad.returncode == 2 and "--sweep" in bad.stderr and bad.stdout == ""


def test_smooth_coulomb_converges_to_switching_as_regularisation_shrinks(reports):
    """Issue 12.3: the smooth (regularised) Coulomb cycle approaches the switching one as the
    regularisation velocity v_eps shrinks (predicted command amplitude, monotone), and at the
    shipped v_eps (0.01 deg/s, under a tenth of the cycle's peak engine rate) the time-domain cycle is
    within 10 % of the switching form in engine amplitude. At the old 0.06 deg/s (about the
    cycle's own peak rate) the smooth form acted as a viscous damper."""
    import dataclasses
    fl = load_flight(FLIGHT)
    sw = reports["ambient", "coulomb-switching"].to_dict()
    base = load_model(MODELS / "rs25_flight.toml", friction="coulomb-smooth")
    assert base.friction.regularization_velocity_rad_s == pytest.approx(0.01 * DEG)
    peak_rate = 2 * math.pi * sw["time_domain"]["frequency_hz"] * sw["time_domain"]["engine_amplitude_deg"] * DEG
    assert base.friction.regularization_velocity_rad_s <= 0.1 * peak_rate
    # the smooth maps on the 4 x 4 corner of AMPS x FREQ around the cycle (0.15-0.25 deg command at
    # 0.14-0.16 Hz): the map is interpolated bilinearly cell by cell (taos.flight.describing), so the
    # predicted cycles are the full map's (measured: within 2e-13) at a third of the CPU; the
    # switching reference stays the fixture's full map, and each cycle is checked to lie inside
    amps, freq = AMPS[3:7], FREQ[1:5]
    err = []
    for veps in (0.06, 0.03, 0.01):
        m = base.replace(friction=dataclasses.replace(base.friction, regularization_velocity_rad_s=veps * DEG))
        rep = analyse_lco(fl, m, amplitudes_rad=amps, freq_hz=freq, time_domain=False)
        d = rep.to_dict()
        assert d["lco"]
        assert amps[0] < d["amplitude_deg"] * DEG < amps[-1] and freq[0] < d["frequency_hz"] < freq[-1]
        err.append(abs(d["amplitude_deg"] / sw["amplitude_deg"] - 1))
    assert err[0] > err[1] > err[2]
    # the last model of the loop is the shipped one (v_eps = 0.01 deg/s): its describing-function
    # map (the costly part at this small v_eps) is the one the time-domain
    # analysis would make again, so it is reused (analyse_lco's df=)
    assert m == base
    td = analyse_lco(fl, base, df=rep.prediction.df, duration_s=160.0, window_s=60.0).to_dict()
    assert abs(td["time_domain"]["engine_amplitude_deg"] / sw["time_domain"]["engine_amplitude_deg"] - 1) < 0.10


@pytest.mark.parametrize("law", ["none", "dahl"])
def test_flown_avionics_quantiser_cycle_prediction_and_time_domain_agree(law):
    """Issue 12.4: with the flown 12-bit truncation (--avionics model) the describing-function
    grid starts at half an LSB, so the quantiser's own cycle is inside the map: on the stiff
    structure, with no friction and with Dahl, prediction and time domain both find the small
    cycle (a few LSB of command, ~0.1 Hz) and the JSON's one verdict says so, decided by the time
    domain. (Measured: no friction 0.0060 / 0.0057 deg at 0.105 / 0.080 Hz; Dahl 0.018 / 0.020 deg
    at 0.113 / 0.116 Hz, prediction / time domain.)"""
    import dataclasses
    from taos.flight.lco import model_avionics_amplitudes_rad
    fl = load_flight(FLIGHT)
    m = load_model(MODELS / "rs25_flight.toml", friction=law)
    m = m.replace(structure=dataclasses.replace(m.structure, load_stiffness_N_per_m=205000 * LBF_IN))
    amps = model_avionics_amplitudes_rad(m)
    assert amps[0] < m.avionics.lsb_rad
    rep = analyse_lco(fl, m, avionics="model", freq_hz=FREQ, duration_s=240.0, window_s=100.0)
    d = rep.to_dict()
    assert rep.prediction.df.amplitude_rad[0] == pytest.approx(0.5 * m.avionics.lsb_rad)
    td = d["time_domain"]
    assert d["lco"] and td["lco"]
    assert {k: d["verdict"][k] for k in ("lco", "decided_by", "agree", "prediction_lco", "note")} == {
        "lco": True, "decided_by": "time domain", "agree": True, "prediction_lco": True, "note": None}
    lsb = math.degrees(m.avionics.lsb_rad)
    for a in (d["amplitude_deg"], td["amplitude_deg"]):
        assert 0.5 * lsb < a < 6 * lsb
    assert 0.06 <= d["frequency_hz"] <= 0.2 and 0.06 <= td["frequency_hz"] <= 0.2
