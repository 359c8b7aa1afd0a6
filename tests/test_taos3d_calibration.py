"""TAOS 3-D model with the shipped FEM gimbal pairs reproduces the Green Run notches: the
ambient (hanging gimbal) and hot-fire (thrust-loaded) command -> piston notches sit on the
load resonances of the 115,000 and 205,000 lbf/in fits (paper sec. 4, fig. 11)."""

from __future__ import annotations

import pytest
import scipy.optimize as so

from taos.model import load_model
from taos.taos3d import load_taos_model, taos_freqresp

from .conftest import MODELS


@pytest.mark.parametrize("name", ["rs25_ambient", "rs25_hotfire"])
def test_taos_notch_on_green_run_load_resonance(name):
    tm = load_taos_model(MODELS / f"{name}.toml")
    target = load_model(MODELS / f"{name}.toml").load_resonance_hz()
    res = so.minimize_scalar(lambda f: abs(taos_freqresp(tm, [f]).piston[0]), bounds=(0.7 * target, 1.3 * target),
                             method="bounded", options={"xatol": 1e-5})
    assert res.x == pytest.approx(target, rel=0.01)


@pytest.mark.parametrize("name", ["rs25_ambient", "rs25_hotfire", "rs25_flight"])
def test_one_meaning_of_load_stiffness_line_derived_the_same_way(name):
    """Issue 12.7: [structure] load_stiffness is the fitted total in every file; every file
    carries the line stiffness solved the same way (3-D notch on the total's load resonance with
    that condition's FEM gimbal in series), to 0.1 %."""
    from taos.taos3d.calibrate import line_stiffness_for_total
    m = load_model(MODELS / f"{name}.toml")
    tm = load_taos_model(MODELS / f"{name}.toml")
    assert tm.gimbal.line_load_stiffness_N_per_m is not None
    assert tm.gimbal.line_load_stiffness_N_per_m == pytest.approx(line_stiffness_for_total(m, rtol=1e-5), rel=1e-3)
