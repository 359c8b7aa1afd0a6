"""TAOS 3-D model with the shipped FEM gimbal pairs reproduces the Green Run notches: the
ambient (hanging gimbal) and hot-fire (thrust-loaded) command -> piston notches sit on the
load resonances of the 115,000 and 205,000 lbf/in fits (paper sec. 4, fig. 11)."""

from __future__ import annotations

import numpy as np
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
