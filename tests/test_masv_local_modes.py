"""MASV in the paper's condition (issue 24.7, finding F12): engine-section local modes inside the
actuator band (models/masv/core_stage_local_modes.toml, the notional frame softened so that its
modes lie at 5.0, 5.0, 7.4, 9.7 and 14.9 Hz; scripts/build_local_modes.py).

The paper (sec. 1): MASV confirmed that the local modes, "despite their frequency density near the
actuator bandwidth, do not adversely couple with the actuator position feedback servocontrol loop",
and that engine-to-engine coupling "was present" but not significant. What this notional structure
gives with the recalibrated flight servo (models/actuators/tvc_actuator.toml, issue 24.1; measured
by `masv coupling models/masv/core_stage_local_modes.toml` and the analysis calls below; re-measure
after any servo recalibration):

* the first claim holds, with a measurable cost: all eight loops stable and inside the flight
  specification (worst phase margin 51.4 deg, gain margin 33.2 dB, against >= 45 deg / 6 dB), but
  each loop loses 7.4-7.5 deg of phase margin against a rigid structure (58.9 deg), where the
  nominal frame costs 0.45 deg. Physical reason: the engines-on-sway mode (3.04 Hz) lies at the
  servo's position-loop gain crossover (3.29 Hz rigid, 2.94 Hz with the structure). With the
  previous, faster notional servo (K_v 40 1/s) the crossover sat above that mode and no margin was
  lost (35.4 deg against 30.3 rigid); the credible servo is slower, so the mode is now in its
  crossover region. Its gain margin rises (15.6 -> 33.2 dB) because the structure's phase moves
  the -180 deg crossing from 6.0 Hz to the valve's 99 Hz;
* the second holds: engine-to-engine coupling rises by 12 dB, from -15.4 dB at 12.8 Hz (nominal
  structure, 19.6 dB below the direct response) to -3.4 dB at 3.06 Hz, which stays 6.8 dB below
  the commanded engine's own peak (+3.5 dB). (With the old servo: +5.9 dB, only 3.1 dB below the
  direct response: a peaky servo amplified the sway mode; the credible servo's dynamic pressure
  feedback damps it, 3.3 % against 1.1 %.) It still comes from the engines' inertia (tail wags dog)
  on the aft section's lateral sway: the four engines (14 t) on the softened sway modes make a
  3.04 Hz mode in which they all move; through the elastic path alone (no c.g. offset) the
  coupling is -13.2 dB. Reaching the same frequencies with a heavier rather than a softer
  structure keeps it 12.3 dB below the direct response (-8.2 dB): the engines' mass against the
  structure's modal mass at the gimbals, which the public data do not fix, still decides it.
"""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest

from masv import build_system, closed_loop_eigenvalues, coupling, load_config
from masv.analysis import frequency_response, structure_effect
from masv.cli import main

from .conftest import MODELS

LOCAL = MODELS / "masv" / "core_stage_local_modes.toml"
NOMINAL = MODELS / "masv" / "core_stage.toml"


@pytest.fixture(scope="module")
def local():
    return build_system(load_config(LOCAL))


@pytest.fixture(scope="module")
def nominal():
    return build_system(load_config(NOMINAL))


def test_local_modes_lie_in_the_actuator_band_with_the_papers_damping(local):
    cfg = local.config
    f = cfg.structure.freq_hz
    assert np.sum((f >= 3.0) & (f <= 9.0)) >= 3 and 3.0 <= f[0] <= 9.0
    assert np.all(cfg.structure.damping_ratio == 0.005)
    # the same engines and actuators as the nominal configuration (one model file for both)
    nom = load_config(NOMINAL)
    assert {e.model.source for e in cfg.engines} == {e.model.source for e in nom.engines}
    assert cfg.reference is not None and cfg.reference.endswith("core_stage.toml")
    # same mass, softer: the nominal mode shapes (up to sign) at the frequencies x sqrt(0.118)
    ratio = f / nom.structure.freq_hz
    assert np.allclose(ratio, ratio[0], rtol=1e-6) and ratio[0] == pytest.approx(5.0 / nom.structure.freq_hz[0], rel=1e-4)


def test_f12_loops_stay_stable_and_keep_their_margins_with_local_modes_in_band(local):
    assert closed_loop_eigenvalues(local).stable
    eff = structure_effect(local)
    # measured: worst PM 51.4 deg (rigid 58.9), worst GM 33.2 dB (rigid 15.6): inside the flight
    # specification (>= 45 deg, >= 6 dB) the servo was calibrated to (tests/test_servo_calibration.py)
    assert eff["worst_phase_margin_deg"] > 45.0 and eff["worst_gain_margin_db"] > 6.0
    assert 48.0 < eff["worst_phase_margin_deg"] < 55.0
    # ... but not for free: 7.46 deg of phase margin lost, the engines-on-sway mode (3.04 Hz) sitting
    # at the loop's gain crossover (3.29 Hz rigid); the nominal frame (modes from 14.5 Hz) costs 0.45
    assert 5.0 < eff["largest_phase_margin_loss_deg"] < 10.0
    rigid = eff["loops"][0]["rigid"]
    assert 2.9 < rigid["gain_crossover_hz"] < 3.6
    assert structure_effect(build_system(load_config(NOMINAL)))["largest_phase_margin_loss_deg"] < 1.0


def test_f12_engine_to_engine_coupling_rises_but_stays_below_the_direct_response(local, nominal):
    c, n = coupling(local), coupling(nominal)
    e, e0 = c.engine_to_engine("engine"), n.engine_to_engine("engine")
    # nominal structure: -15.4 dB at 12.8 Hz, 19.6 dB below the direct response (+4.3 dB)
    assert -18.0 < e0["cross_db"] < -12.0 and 17.0 < e0["below_direct_db"] < 22.0
    # modes in band: -3.4 dB at 3.06 Hz (12.0 dB up), 6.8 dB below the commanded engine's own peak
    # (+3.5 dB). With the old peaky servo it was +5.9 dB, only 3.1 dB below: the credible servo's
    # pressure feedback damps the engines-on-sway mode (3.3 % against 1.1 %)
    assert 9.0 < e["cross_db"] - e0["cross_db"] < 15.0
    assert -6.0 < e["cross_db"] < -1.0 and 2.7 < e["cross_hz"] < 3.5
    assert 5.0 < e["below_direct_db"] < 9.0
    p = c.engine_to_engine("piston")   # piston: -7.2 dB, 8.4 dB below the direct +1.2 dB
    assert 6.0 < p["below_direct_db"] < 11.0 and -10.0 < p["cross_db"] < -4.5
    # the reported peak is the 8x8 response itself at that frequency
    fr = frequency_response(local, [e["cross_hz"]])
    i, j = fr.index(e["response"]), fr.index(e["command"])
    assert 20 * np.log10(abs(fr.engine[0, i, j])) == pytest.approx(e["cross_db"], abs=1e-9)
    # per engine pair: every cross pair below its diagonal
    pk = np.asarray(c.engine_pairs("engine")["peak_db"])
    off = ~np.eye(4, dtype=bool)
    assert np.all((pk - np.diag(pk)[None, :])[off] < -5.0)


def test_f12_coupling_is_the_engines_inertia_on_a_lightly_damped_sway_mode(local):
    # the least damped closed-loop mode: the engines on the lateral sway, 3.04 Hz, 3.3 % damping
    # (1.1 % with the old servo; the structure alone has 0.5 %: the rest is the actuators' pressure
    # feedback, which makes each actuator a damper in series with its load path near w_L)
    z = closed_loop_eigenvalues(local).least_damped(1)[0]
    assert 2.7 < z["freq_hz"] < 3.5 and 0.02 < z["damping_ratio"] < 0.05
    # the elastic path alone (engines as point masses at the gimbals): -13.2 dB, 10 dB less
    cfg = local.config
    point = dataclasses.replace(cfg, engines=tuple(dataclasses.replace(e, cg_offset_m=(0.0, 0.0, 0.0))
                                                  for e in cfg.engines))
    assert coupling(build_system(point)).engine_to_engine("engine")["cross_db"] < -10.0
    # the same frequencies from a heavier (mass x s^2, shapes / s) instead of a softer structure:
    # -8.2 dB, 12.3 dB below the direct response (the softer one: 6.8 dB)
    s = float(load_config(NOMINAL).structure.freq_hz[0] / cfg.structure.freq_hz[0])
    st = cfg.structure
    heavy = dataclasses.replace(cfg, structure=dataclasses.replace(st, phi=st.phi / s))
    h = coupling(build_system(heavy)).engine_to_engine("engine")
    assert h["below_direct_db"] > 10.0 and h["cross_db"] < -6.0


def test_cli_coupling_reports_engine_pairs_against_the_reference(capsys):
    assert main(["coupling", str(LOCAL), "--json", "-"]) == 0
    d = json.loads(capsys.readouterr().out)
    ep = d["coupling"]["engine_pairs"]["engine"]
    assert ep["engines"] == ["engine_1", "engine_2", "engine_3", "engine_4"]
    assert np.asarray(ep["peak_db"]).shape == (4, 4)
    assert d["reference"]["config_file"].endswith("core_stage.toml") and d["reference"]["stable"]
    assert d["this"]["stable"]
    assert (d["this"]["engine_to_engine"]["engine"]["cross_db"]
            > d["reference"]["engine_to_engine"]["engine"]["cross_db"] + 8.0)
    assert main(["coupling", str(LOCAL)]) == 0
    out = capsys.readouterr().out
    assert "below the direct response" in out and "against the reference" in out


def test_rigid_structure_engine_pairs_have_only_the_direct_response():
    c = coupling(build_system(load_config(MODELS / "masv" / "core_stage_rigid.toml")))
    pk = np.asarray(c.engine_pairs("piston")["peak_db"])
    assert np.all(pk[~np.eye(4, dtype=bool)] == -400.0)
    assert np.allclose(np.diag(pk), [c.piston_peak_db[k, k] for k in (0, 2, 4, 6)], atol=0.5)
