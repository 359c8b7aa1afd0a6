"""MASV with the shipped fem_data thrust structure: all eight position loops stable, margins
unchanged by the engine-section modes, weak engine-to-engine coupling (paper sec. 1: MASV
found the local modes do not couple adversely and the engines couple only weakly)."""

from __future__ import annotations

import numpy as np

from masv import build_system, closed_loop_eigenvalues, coupling, load_config
from masv.analysis import structure_effect

from .conftest import MODELS


def test_fem_thrust_structure_loops_stable_and_weakly_coupled():
    system = build_system(load_config(MODELS / "masv" / "core_stage.toml"))
    assert np.max(closed_loop_eigenvalues(system).eigenvalues.real) < 0
    eff = structure_effect(system)
    assert eff["worst_phase_margin_deg"] > 25.0 and eff["worst_gain_margin_db"] > 6.0
    assert eff["largest_phase_margin_loss_deg"] < 2.0
    c = coupling(system).to_dict()
    assert c["strongest_engine_to_engine"]["gain_db"] < -20.0
