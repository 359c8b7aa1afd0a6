"""MASV with the shipped fem_data thrust structure: all eight position loops stable, margins
unchanged by the engine-section modes (paper sec. 1: MASV found the local modes do not couple
adversely with the actuator position loops), weak engine-to-engine coupling through the
structure's elasticity, and the engines' inertial (tail-wags-dog) coupling through the aft
section's lateral sway modes: a TVSE loop (paper sec. 3.3) with gain above 0 dB near the sway
mode and a positive phase margin ("favourable phasing")."""

from __future__ import annotations

import dataclasses

import numpy as np

from masv import build_system, closed_loop_eigenvalues, coupling, load_config
from masv.analysis import structure_effect, tvse_loops

from .conftest import MODELS


def test_fem_thrust_structure_loops_stable_and_weakly_coupled():
    cfg = load_config(MODELS / "masv" / "core_stage.toml")
    system = build_system(cfg)
    assert np.max(closed_loop_eigenvalues(system).eigenvalues.real) < 0
    eff = structure_effect(system)
    assert eff["worst_phase_margin_deg"] > 25.0 and eff["worst_gain_margin_db"] > 6.0
    assert eff["largest_phase_margin_loss_deg"] < 2.0
    # recalibrated flight servo (models/actuators/tvc_actuator.toml): worst PM 58.4 deg, GM 16.3 dB,
    # 0.45 deg lost against a rigid structure: inside the flight specification (>= 45 deg, >= 6 dB)
    assert eff["worst_phase_margin_deg"] > 45.0
    # the elastic path alone (engines as point masses at the gimbals, no c.g. offset): weak
    point = dataclasses.replace(cfg, engines=tuple(dataclasses.replace(e, cg_offset_m=(0.0, 0.0, 0.0))
                                                  for e in cfg.engines))
    assert coupling(build_system(point)).to_dict()["strongest_engine_to_engine"]["gain_db"] < -25.0
    # with the engines' c.g. offset the lateral sway of the aft section carries each engine's
    # inertial force to the others: measured -15.4 dB at 12.8 Hz, the engines-on-sway mode (notional
    # FEM; `masv coupling models/masv/core_stage.toml`). With the old peaky servo (+11.7 dB at
    # 4.9 Hz) the strongest crossing was -6.0 dB at its 4.95 Hz peak, the servo amplifying the
    # engine's inertial force there; the recalibrated servo peaks +4.3 dB at 4.4 Hz, so at 4.95 Hz
    # the cross response is now -19 dB and the sway mode itself sets the strongest crossing
    c = coupling(system).to_dict()["strongest_engine_to_engine"]
    assert -18.0 < c["gain_db"] < -12.0 and 12.0 < c["freq_hz"] < 13.5


def test_fem_tvse_loops_peak_above_0_db_with_favourable_phasing():
    system = build_system(load_config(MODELS / "masv" / "core_stage.toml"))
    loops = tvse_loops(system)
    for lp in loops:
        assert 9.0 < lp.peak_db < 14.0 and 11.0 < lp.peak_hz < 12.5      # measured +10.2 dB at 11.8 Hz, PM 15.8 deg
        assert lp.margin.phase_margin_deg > 10.0 and lp.margin.gain_margin_db > 40.0
