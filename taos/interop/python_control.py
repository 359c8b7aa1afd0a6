"""python-control interoperation: take a TVC model into a control engineer's own loop design.

Linear models (:class:`taos.linear.StateSpace`: the simplex block
:func:`taos.planar.simplex.simplex_state_space`, the vehicle + FCS block and the open flight loop
:func:`taos.flight.vehicle.vehicle_fcs_state_space` / :func:`~taos.flight.vehicle.open_loop_state_space`,
the whole MASV model ``masv.system.MasvSystem.state_space()``) become ``control.StateSpace``
with their signal names; frequency responses (:class:`taos.planar.freqresp.FrequencyResponse`,
linear or sine-dwell; :class:`taos.identify.estimation.MeasuredResponse`, estimated from data;
``masv.analysis.MasvFrequencyResponse``) become ``control.FrequencyResponseData``. Both come
back: :func:`from_control_ss` and :func:`freqresp_from_control`.

Conventions: python-control's frequencies are angular, w = 2 pi f [rad/s]; taos keeps f [Hz].
Signal names are the taos names (units in the name); python-control forbids '.' in a signal
name, so the MASV names ``E1P.command_rad`` travel as ``E1P__command_rad`` and come back with
the dot. A FrequencyResponse travels as a 2-output, 1-input FRD: input ``command_rad``,
outputs ``piston`` (x_p / (R theta_c) [-]) and ``engine`` (theta / theta_c [-]); a
MeasuredResponse as outputs ``piston_m_per_rad`` (x_p / theta_c [m/rad]) and, when the data
has engine angles, ``engine``.

python-control is imported only when a conversion is asked for (it costs seconds to import).
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from taos.planar.freqresp import FrequencyResponse
from taos.identify.estimation import MeasuredResponse
from taos.linear import StateSpace

if TYPE_CHECKING:
    import control

_DOT = "__"
FR_INPUTS = ("command_rad",)
FR_OUTPUTS = ("piston", "engine")


def _ct():
    import control
    return control


def _out_name(name: str) -> str:
    return name.replace(".", _DOT)


def _in_name(name: str) -> str:
    return name.replace(_DOT, ".")


# -- state space ----------------------------------------------------------------------------
def to_control_ss(model, name: str | None = None):
    """A numeric :class:`~taos.linear.StateSpace` (or anything with a ``state_space()`` method
    returning one, such as a MASV system) as a ``control.StateSpace`` with the same matrices
    and signal names (continuous time)."""
    ss = model.state_space() if hasattr(model, "state_space") and not isinstance(model, StateSpace) else model
    if not isinstance(ss, StateSpace):
        from taos.errors import InputError
        raise InputError("argument", "model", "a taos StateSpace (or a system with state_space())",
                         got=f"{type(model).__name__} {repr(model)[:30]}")
    ct = _ct()
    mats = [np.asarray(M, float) for M in (ss.A, ss.B, ss.C, ss.D)]
    kw = {"name": _out_name(name)} if name else {}
    return ct.ss(*mats, inputs=[_out_name(s) for s in ss.inputs], outputs=[_out_name(s) for s in ss.outputs],
                 states=[_out_name(s) for s in ss.states], **kw)


def from_control_ss(sys: control.LTI) -> StateSpace:
    """A continuous-time python-control LTI system (state space or transfer function) as a
    :class:`~taos.linear.StateSpace`, keeping its signal names. A transfer function is realised
    by ``control.ss`` first."""
    from taos.errors import InputError

    ct = _ct()
    if not isinstance(sys, ct.LTI) or sys.dt not in (0, None):
        raise InputError("argument", "sys", "a continuous-time (dt = 0) python-control state space or transfer function",
                         got=f"{type(sys).__name__} {repr(sys)[:30]}" if not isinstance(sys, ct.LTI) else f"dt = {sys.dt}")
    s = sys if isinstance(sys, ct.StateSpace) else ct.ss(sys)
    return StateSpace(np.array(s.A, float), np.array(s.B, float), np.array(s.C, float), np.array(s.D, float),
                      tuple(_in_name(n) for n in s.state_labels), tuple(_in_name(n) for n in s.input_labels),
                      tuple(_in_name(n) for n in s.output_labels))


# -- frequency responses ----------------------------------------------------------------------
def frd(freq_hz, H, inputs, outputs, name: str | None = None):
    """A ``control.FrequencyResponseData`` from samples H [F, n_out, n_in] (or [F] for SISO) at
    ``freq_hz`` [Hz]."""
    ct = _ct()
    f = np.asarray(freq_hz, float)
    H = np.asarray(H, complex)
    if H.ndim == 1:
        H = H[:, None, None]
    if H.shape[0] != f.size:
        raise ValueError(f"frd: {H.shape[0]} responses for {f.size} frequencies")
    if np.unique(f).size != f.size:
        raise ValueError("frd: repeated frequencies (select one amplitude first)")
    kw = {"name": _out_name(name)} if name else {}
    return ct.frd(np.moveaxis(H, 0, -1), 2 * np.pi * f, inputs=[_out_name(s) for s in inputs],
                  outputs=[_out_name(s) for s in outputs], **kw)


def frd_samples(data) -> tuple[np.ndarray, np.ndarray, tuple[str, ...], tuple[str, ...]]:
    """(freq_hz [F], H [F, n_out, n_in], inputs, outputs) of a ``control.FrequencyResponseData``."""
    return (np.asarray(data.omega, float) / (2 * np.pi), np.moveaxis(np.asarray(data.frdata, complex), -1, 0),
            tuple(_in_name(n) for n in data.input_labels), tuple(_in_name(n) for n in data.output_labels))


def freqresp_to_control(fr: FrequencyResponse):
    """A command -> (piston, engine) :class:`~taos.planar.freqresp.FrequencyResponse` (linear or
    sine-dwell at one amplitude) as a 2x1 FRD (:data:`FR_OUTPUTS` x :data:`FR_INPUTS`)."""
    H = np.stack([fr.piston, fr.engine], axis=1)[:, :, None]
    amp = "linear" if fr.amplitude_rad is None else f"{math.degrees(fr.amplitude_rad):.4g}deg"
    return frd(fr.freq_hz, H, FR_INPUTS, FR_OUTPUTS, name=f"{fr.axis}_{fr.friction_model}_{amp}")


def freqresp_from_control(data, amplitude_rad: float | None = None, axis: str = "pitch",
                          friction_model: str = "none", provenance: dict | None = None) -> FrequencyResponse:
    """An FRD with outputs ``piston`` and ``engine`` (as made by :func:`freqresp_to_control`) back as
    a :class:`~taos.planar.freqresp.FrequencyResponse`; ``amplitude_rad`` None for a linear response."""
    f, H, ins, outs = frd_samples(data)
    if len(ins) != 1 or set(FR_OUTPUTS) - set(outs):
        raise ValueError(f"freqresp_from_control: need one input and outputs {FR_OUTPUTS}, got {outs} x {ins}")
    p, e = outs.index("piston"), outs.index("engine")
    return FrequencyResponse(f, H[:, p, 0], H[:, e, 0], amplitude_rad, axis, engine_model="python-control",
                             friction_model=friction_model, provenance=dict(provenance or {"method": "python-control"}))


def measured_to_control(mr: MeasuredResponse):
    """An estimated :class:`~taos.identify.estimation.MeasuredResponse` as an FRD: outputs
    ``piston_m_per_rad`` [m/rad] and (with engine data) ``engine`` [-], input ``command_rad``.
    Frequencies must be distinct: pick one amplitude with ``mr.select(...)`` first."""
    cols = [mr.piston_m_per_rad] + ([mr.engine] if mr.engine is not None else [])
    outs = ("piston_m_per_rad",) + (("engine",) if mr.engine is not None else ())
    return frd(mr.freq_hz, np.stack(cols, axis=1)[:, :, None], FR_INPUTS, outs,
               name=f"{mr.axis}_{mr.method}".replace("-", "_"))


def masv_freqresp_to_control(fr):
    """A ``masv.analysis.MasvFrequencyResponse`` as one FRD: inputs the eight
    ``<actuator>.command_rad``, outputs ``<actuator>.piston`` (x_p / (R theta_c)) then
    ``<actuator>.theta_rad``."""
    H = np.concatenate([fr.piston, fr.engine], axis=1)
    return frd(fr.freq_hz, H, [f"{a}.command_rad" for a in fr.actuators],
               [f"{a}.piston" for a in fr.actuators] + [f"{a}.theta_rad" for a in fr.actuators])


def to_control(obj: object) -> control.StateSpace | control.FrequencyResponseData:
    """Whichever of the conversions above fits ``obj``: a StateSpace (or a system with
    ``state_space()``) -> ``control.StateSpace``; a FrequencyResponse, MeasuredResponse or MASV
    frequency response -> ``control.FrequencyResponseData``."""
    if isinstance(obj, FrequencyResponse):
        return freqresp_to_control(obj)
    if isinstance(obj, MeasuredResponse):
        return measured_to_control(obj)
    if hasattr(obj, "actuators") and hasattr(obj, "piston") and np.ndim(obj.piston) == 3:
        return masv_freqresp_to_control(obj)
    if not isinstance(obj, StateSpace) and not hasattr(obj, "state_space"):
        from taos.errors import InputError
        raise InputError("argument", "obj", "a StateSpace, a system with state_space(), a FrequencyResponse, a "
                         "MeasuredResponse or a MASV frequency response", got=f"{type(obj).__name__} {repr(obj)[:30]}")
    return to_control_ss(obj)
