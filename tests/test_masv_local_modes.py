"""MASV in the paper's condition (issue 24.7, finding F12): engine-section local modes inside the
actuator band (models/masv/core_stage_local_modes.toml, the notional frame softened so that its
modes lie at 5.0, 5.0, 7.4, 9.7 and 14.9 Hz; scripts/build_local_modes.py).

The paper (sec. 1): MASV confirmed that the local modes, "despite their frequency density near the
actuator bandwidth, do not adversely couple with the actuator position feedback servocontrol loop",
and that engine-to-engine coupling "was present" but not significant. What this notional structure
gives (measured with the hot-fire servo of models/rs25_hotfire.toml; re-measure after a servo
recalibration):

* the first claim holds: all eight loops stable, no position-loop margin lost against a rigid
  structure (phase margin 35 deg against 30 rigid);
* the second holds only in part: engine-to-engine coupling rises from -6.0 dB (nominal structure,
  17.6 dB below the direct response) to +5.9 dB at 3.1 Hz, which is 3.1 dB below the commanded
  engine's own peak (+9.0 dB). The "+3..+5 dB" of the issue is the cross gain relative to the
  *other* engine's command (|theta_i / theta_c,j|), not relative to the direct response. It comes
  from the engines' inertia (tail wags dog) on the aft section's lateral sway: the four engines
  (14 t) on the softened sway modes make a 3.1 Hz mode with 1.1 % damping in which they all move;
  through the elastic path alone (no c.g. offset) the coupling is -8.9 dB. Reaching the same
  frequencies with a heavier rather than a softer structure keeps it about 10 dB below the direct
  response: what decides the coupling is the engines' mass against the structure's modal mass at
  the gimbals, which the public data do not fix.
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
    # measured: worst PM 35.4 deg (rigid 30.3), worst GM 27.1 dB (rigid 11.6)
    assert eff["worst_phase_margin_deg"] > 25.0 and eff["worst_gain_margin_db"] > 6.0
    assert eff["largest_phase_margin_loss_deg"] < 2.0


def test_f12_engine_to_engine_coupling_rises_but_stays_below_the_direct_response(local, nominal):
    c, n = coupling(local), coupling(nominal)
    e, e0 = c.engine_to_engine("engine"), n.engine_to_engine("engine")
    # nominal structure: -6.0 dB, 17.6 dB below the direct response
    assert -9.0 < e0["cross_db"] < -3.0 and 14.0 < e0["below_direct_db"] < 21.0
    # modes in band: +5.9 dB at 3.09 Hz, 3.1 dB below the commanded engine's own peak (+9.0 dB)
    assert e["cross_db"] - e0["cross_db"] > 8.0
    assert 3.0 < e["cross_db"] < 9.0 and 2.7 < e["cross_hz"] < 3.5
    assert 1.5 < e["below_direct_db"] < 6.0
    p = c.engine_to_engine("piston")   # piston: +1.1 dB, 4.0 dB below the direct +5.1 dB
    assert 2.0 < p["below_direct_db"] < 8.0 and -2.0 < p["cross_db"] < 4.0
    # the reported peak is the 8x8 response itself at that frequency
    fr = frequency_response(local, [e["cross_hz"]])
    i, j = fr.index(e["response"]), fr.index(e["command"])
    assert 20 * np.log10(abs(fr.engine[0, i, j])) == pytest.approx(e["cross_db"], abs=1e-9)
    # per engine pair: every cross pair below its diagonal
    pk = np.asarray(c.engine_pairs("engine")["peak_db"])
    off = ~np.eye(4, dtype=bool)
    assert np.all((pk - np.diag(pk)[None, :])[off] < -1.5)


def test_f12_coupling_is_the_engines_inertia_on_a_lightly_damped_sway_mode(local):
    # the least damped closed-loop mode: the engines on the lateral sway, 3.09 Hz, 1.1 % damping
    z = closed_loop_eigenvalues(local).least_damped(1)[0]
    assert 2.7 < z["freq_hz"] < 3.5 and 0.005 < z["damping_ratio"] < 0.03
    # the elastic path alone (engines as point masses at the gimbals): -8.9 dB
    cfg = local.config
    point = dataclasses.replace(cfg, engines=tuple(dataclasses.replace(e, cg_offset_m=(0.0, 0.0, 0.0))
                                                  for e in cfg.engines))
    assert coupling(build_system(point)).engine_to_engine("engine")["cross_db"] < -5.0
    # the same frequencies from a heavier (mass x s^2, shapes / s) instead of a softer structure:
    # -0.1 dB, 10 dB below the direct response
    s = float(load_config(NOMINAL).structure.freq_hz[0] / cfg.structure.freq_hz[0])
    st = cfg.structure
    heavy = dataclasses.replace(cfg, structure=dataclasses.replace(st, phi=st.phi / s))
    h = coupling(build_system(heavy)).engine_to_engine("engine")
    assert h["below_direct_db"] > 7.0 and h["cross_db"] < 2.0


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
