"""One meaning of load stiffness for every condition (issue 12.7).

The model files' ``[structure] load_stiffness`` is the Green Run FIT: the total compliance
outside the actuator position loop, as the paper's planar simplex model carries it. The 3-D
TAOS model splits that total into the FEM gimbal halves (``[gimbal] stiffness_file``) and the
rest of the load path, the actuator line (``[gimbal] line_load_stiffness``). The line stiffness
is derived the same way for every condition: the value for which the 3-D linear command ->
piston notch sits on the planar load resonance of the fitted total, w_L = sqrt((K_L R^2 + K_n)/J)
(paper eq. 1), with that condition's FEM gimbal in series.
"""

from __future__ import annotations

import dataclasses

import scipy.optimize as so

from ..model import TvcModel
from .model import TaosModel, taos_model


def taos_notch_hz(tm: TaosModel, guess_hz: float, axis: str = "pitch") -> float:
    """Frequency [Hz] of the 3-D linear command -> piston notch near ``guess_hz``."""
    from .simulate import taos_freqresp
    res = so.minimize_scalar(lambda f: abs(taos_freqresp(tm, [f], None, axis).piston[0]),
                             bounds=(0.7 * guess_hz, 1.3 * guess_hz), method="bounded", options={"xatol": 1e-5})
    return float(res.x)


def line_stiffness_for_total(model: TvcModel, K_upper=None, K_lower=None, rtol: float = 1e-4) -> float:
    """Line stiffness [N/m] that, with the model's FEM gimbal in series, puts the 3-D notch on
    the planar load resonance of ``model.structure.load_stiffness_N_per_m`` (the fitted total)."""
    target = model.load_resonance_hz()
    tm0 = taos_model(model, K_upper, K_lower)
    K = model.structure.load_stiffness_N_per_m

    def err(k_line):
        tm = dataclasses.replace(tm0, gimbal=dataclasses.replace(tm0.gimbal, line_load_stiffness_N_per_m=k_line))
        return taos_notch_hz(tm, target) / target - 1.0

    return float(so.brentq(err, 0.9 * K, 3.0 * K, rtol=rtol))
