"""One meaning of load stiffness for every condition (issue 12.7), derived at load (issue 24.5).

The model files' ``[structure] load_stiffness`` is the Green Run FIT: the total compliance
outside the actuator position loop, as the paper's planar simplex model carries it. The 3-D
TAOS model splits that total into the FEM gimbal halves (``[gimbal] stiffness_file``) and the
rest of the load path, the actuator line (``[gimbal] line_load_stiffness``). The line stiffness
is derived the same way for every condition: the value for which the 3-D linear command ->
piston notch sits on the planar load resonance of the fitted total, w_L = sqrt((K_L R^2 + K_n)/J)
(paper eq. 1), with that condition's FEM gimbal in series.

Per axis: ``[structure] load_stiffness_yaw`` (optional) is the yaw axis' own fitted total; the
yaw actuator line's stiffness is then derived the same way for the yaw axis (its notch on
w_L,yaw = sqrt((K_L,yaw R^2 + K_n)/J_yaw), the pitch line held), else it equals the pitch
line's (the shipped files: one derivation, bit for bit as before the key).

It is a derived key: :func:`taos_model`, the builder every command and the library use,
derives it from ``[structure] load_stiffness`` and the gimbal when the file leaves it out (the
shipped files do, so an edited load stiffness moves the 3-D notch with it), and checks it
against that derivation within 1 % when the file gives it (one-line
:class:`~taos.errors.InputError` naming both keys, their values and the expected value). Every
other input check runs first (:func:`taos.taos3d.model.assemble_taos_model`), before any
simulation.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from ..errors import InputError
from ..model import TvcModel, load_model
from ..units import N_PER_M_PER_LBF_PER_IN
from .model import DERIVED_RTOL, TaosModel, assemble_taos_model, line_stiffness_basis


def taos_notch_hz(tm: TaosModel, guess_hz: float, axis: str = "pitch") -> float:
    """Frequency [Hz] of the 3-D linear command -> piston notch near ``guess_hz``."""
    import scipy.optimize as so

    from .simulate import taos_freqresp
    res = so.minimize_scalar(lambda f: abs(taos_freqresp(tm, [f], None, axis).piston[0]),
                             bounds=(0.7 * guess_hz, 1.3 * guess_hz), method="bounded", options={"xatol": 1e-5})
    return float(res.x)


def _line_stiffness(model: TvcModel, tm0: TaosModel, rtol: float, axis: str = "pitch") -> float:
    """Line stiffness [N/m] of ``axis``' actuator putting that axis' 3-D command -> piston notch
    (``tm0``'s gimbal in series) on the axis' planar load resonance
    w_L = sqrt((K_L,axis R^2 + K_n) / J_axis) (SciPy and the compiled dynamics are imported
    here, after every cheap input check). Pitch: the line stiffness of both lines while the
    yaw one follows it (the key ``load_stiffness_yaw`` absent, as the shipped files); yaw: the
    yaw line's alone, the pitch line's held at ``tm0``'s."""
    import scipy.optimize as so

    target = model.load_resonance_hz(axis)
    K = model.structure.stiffness_N_per_m(axis)
    key = "line_load_stiffness_N_per_m" if axis == "pitch" else "line_load_stiffness_yaw_N_per_m"
    field = "structure.load_stiffness" if axis == "pitch" else "structure.load_stiffness_yaw"

    def err(k_line):
        tm = dataclasses.replace(tm0, gimbal=dataclasses.replace(tm0.gimbal, **{key: k_line}))
        return taos_notch_hz(tm, target, axis) / target - 1.0

    lo, hi = 0.9 * K, 3.0 * K
    e_lo, e_hi = err(lo), err(hi)
    if not (np.sign(e_lo) != np.sign(e_hi)):
        raise InputError(model.source, "gimbal.line_load_stiffness" if axis == "pitch" else field,
                         f"a value derivable from {field} ({K:.6g} N/m): a line stiffness of "
                         f"0.9 to 3 x that putting the 3-D command -> piston notch on the load resonance "
                         f"{target:.4g} Hz ({axis}) with the gimbal {tm0.stiffness_source} in series",
                         got=f"a notch {100 * e_lo:+.2g} % to {100 * e_hi:+.2g} % off over that range (a gimbal too "
                             f"soft, or a servo without a notch)")
    return float(so.brentq(err, lo, hi, rtol=rtol))


def line_stiffness_for_total(model: TvcModel, K_upper=None, K_lower=None, rtol: float = 1e-4) -> float:
    """Line stiffness [N/m] that, with the model's FEM gimbal in series, puts the 3-D notch on
    the planar load resonance of ``model.structure.load_stiffness_N_per_m`` (the fitted total)."""
    return _line_stiffness(model, assemble_taos_model(model, K_upper, K_lower), rtol)


def taos_model(model: TvcModel, K_upper: np.ndarray | None = None, K_lower: np.ndarray | None = None) -> TaosModel:
    """Build the TAOS model from a loaded model file; ``K_upper``/``K_lower`` override the
    ``[gimbal] stiffness_file`` (for synthetic or scaled matrices).

    Every input check runs here, before any simulation: keys, units, geometry, stiffness
    matrices and the friction coefficient (:func:`~taos.taos3d.model.assemble_taos_model`),
    then the derived line stiffness: derived from ``[structure] load_stiffness`` with the gimbal
    in series when the file leaves it out, else checked against that within 1 %
    (:class:`~taos.errors.InputError` naming ``gimbal.line_load_stiffness`` and
    ``structure.load_stiffness``, their values and the expected value)."""
    tm0 = assemble_taos_model(model, K_upper, K_lower)
    given = tm0.gimbal.line_load_stiffness_N_per_m
    expected = _line_stiffness(model, tm0, rtol=1e-4)
    if given is None:
        tm = dataclasses.replace(tm0, gimbal=dataclasses.replace(tm0.gimbal, line_load_stiffness_N_per_m=expected))
        tm = _with_yaw_line(model, tm)
        return dataclasses.replace(tm, gimbal=dataclasses.replace(tm.gimbal, line_stiffness_basis=line_stiffness_basis(tm)))
    if abs(given - expected) > DERIVED_RTOL * expected:
        K = model.structure.load_stiffness_N_per_m
        lbf = N_PER_M_PER_LBF_PER_IN  # the messages quote the files' units too
        raise InputError(model.source, "gimbal.line_load_stiffness",
                         f"{expected:.6g} N/m ({expected / lbf:.6g} lbf/in) within 1 %, derived from "
                         f"structure.load_stiffness = {K:.6g} N/m ({K / lbf:.6g} lbf/in) with the gimbal "
                         f"{tm0.stiffness_source} in series (3-D notch on the load resonance "
                         f"{model.load_resonance_hz():.4g} Hz); delete the key to have it derived",
                         got=f"{given:.6g} N/m ({given / lbf:.6g} lbf/in)")
    return _with_yaw_line(model, tm0)


def _with_yaw_line(model: TvcModel, tm: TaosModel) -> TaosModel:
    """``tm`` with the yaw actuator line's own stiffness when the file gives ``[structure]
    load_stiffness_yaw`` (:func:`_line_stiffness` for yaw, the pitch line held); unchanged (the
    yaw line = the pitch line, as before the key) when it is absent."""
    if model.structure.load_stiffness_yaw_N_per_m == 0:
        return tm
    k = _line_stiffness(model, tm, 1e-4, "yaw")
    return dataclasses.replace(tm, gimbal=dataclasses.replace(tm.gimbal, line_load_stiffness_yaw_N_per_m=k))


def with_values(tm: TaosModel, values) -> TaosModel:
    """The 3-D model of the variant ``tm.base.with_values(values)`` (:mod:`taos.variants`: the
    model file with other values, through the loader), rebuilt with every 3-D check and the line
    stiffness derived for it; gimbal halves given in code stay."""
    code = tm.stiffness_source == "<code>"
    return taos_model(tm.base.with_values(values), tm.K_upper if code else None, tm.K_lower if code else None)


def load_taos_model(path, friction: str | None = None, K_upper=None, K_lower=None) -> TaosModel:
    """Load a model file (with ``[gimbal]`` and ``[geometry]``) as a TAOS model (:func:`taos_model`)."""
    return taos_model(load_model(path, friction=friction), K_upper, K_lower)
