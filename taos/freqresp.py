"""Frequency responses of the TVC: exact linear, and amplitude-dependent by sine dwell.

Command -> piston is reported as x_p / (R theta_c) (piston position in engine-angle units)
and command -> engine as theta / theta_c, both dimensionless complex gains.

The sine-dwell response (the describing function of the nonlinear TVC) simulates
theta_c = A sin(w t) from rest, lets the transient settle for at least ``settle_cycles``
and ``settle_time_s`` (default from the slowest linear pole), and correlates the outputs
with sin and cos over ``measure_cycles`` whole cycles (steps per cycle an integer, so the
rectangle rule is exact for the fundamental of a periodic signal).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from . import _integrator as _ig
from .errors import SimulationUnstable
from .linear import gain_db, phase_deg
from .model import TvcModel
from .simplex import simplex_plant, simplex_state_space
from .simulate import DEFAULT_DT_S, check_step, kernel_args


@dataclass(frozen=True, eq=False)
class FrequencyResponse:
    """Command -> piston and command -> engine responses of one axis.

    ``amplitude_rad`` is None for the linear response."""

    freq_hz: np.ndarray
    piston: np.ndarray
    engine: np.ndarray
    amplitude_rad: float | None
    axis: str = "pitch"
    engine_model: str = "simplex"
    friction_model: str = "none"
    provenance: dict = field(default_factory=dict)

    def to_dict(self) -> dict:
        """The JSON contract of ``taos freqresp`` (these keys are kept from release to release)."""
        return {
            "freq_hz": [float(f) for f in self.freq_hz],
            "amplitude_deg": None if self.amplitude_rad is None else math.degrees(self.amplitude_rad),
            "axis": self.axis,
            "engine_model": self.engine_model,
            "friction_model": self.friction_model,
            "piston": {"gain_db": gain_db(self.piston).tolist(), "phase_deg": phase_deg(self.piston).tolist()},
            "engine": {"gain_db": gain_db(self.engine).tolist(), "phase_deg": phase_deg(self.engine).tolist()},
            "provenance": self.provenance,
        }


def linear_freqresp(model: TvcModel, freq_hz, axis: str = "pitch") -> FrequencyResponse:
    """Exact response of the linear simplex block (no friction, unity avionics)."""
    ss = simplex_state_space(model, axis)
    h = ss.freqresp(freq_hz, "command_rad", ["x_p_m", "theta_rad"])
    R = model.actuator.moment_arm_m
    return FrequencyResponse(np.atleast_1d(np.asarray(freq_hz, float)), h[:, 0] / R, h[:, 1], None, axis,
                             friction_model="none", provenance={"model_sha256": model.sha256, "method": "linear"})


def settle_time_s(model: TvcModel, axis: str = "pitch", decades: float = 4.0) -> float:
    """Time for the slowest linear mode to decay by ``decades`` decades [s]."""
    p = simplex_state_space(model, axis).poles()
    sigma = np.min(np.abs(p.real[np.abs(p.real) > 1e-9]))
    return decades * math.log(10) / sigma


def sine_dwell_grid(model: TvcModel, amplitudes_rad, freq_hz, axis: str = "pitch", *,
                    dt_max_s: float = DEFAULT_DT_S, settle_cycles: int = 2, measure_cycles: int = 2,
                    settle_s: float | None = None, min_steps_per_cycle: int = 64):
    """Sine-dwell responses over a grid of amplitudes x frequencies, in parallel.

    Returns (piston, engine) complex arrays of shape (n_amp, n_freq)."""
    amps = np.atleast_1d(np.asarray(amplitudes_rad, float))
    f = np.atleast_1d(np.asarray(freq_hz, float))
    plant = simplex_plant(model, axis)
    check_step(model, plant.inertia_kgm2, dt_max_s)
    ts = settle_time_s(model, axis) if settle_s is None else settle_s
    A, F = np.meshgrid(amps, f, indexing="ij")
    A, F = A.ravel(), F.ravel()
    npc = np.maximum(np.ceil(1.0 / (F * dt_max_s)), min_steps_per_cycle).astype(np.int64)
    nset = (np.maximum(settle_cycles, np.ceil(ts * F)) * npc).astype(np.int64)
    nmeas = (measure_cycles * npc).astype(np.int64)
    o = plant.ss.output_index
    Cy = np.ascontiguousarray(plant.ss.C[[o("x_p_m"), o("theta_rad")]])
    out = np.zeros((A.size, 2, 3))
    status = np.full(A.size, -1, np.int64)
    _ig.sine_dwell_batch(*kernel_args(plant, model), Cy, model.friction.entry.rates, model.friction.pack(),
                         model.avionics.pack(), A, F, npc, nset, nmeas, out, status)
    bad = np.flatnonzero(status >= 0)
    if bad.size:
        b = bad[0]
        raise SimulationUnstable(status[b] / (F[b] * npc[b]),
                                 f"sine dwell {math.degrees(A[b]):.3g} deg at {F[b]:.3g} Hz")
    # fundamental: y ~ a sin + b cos  ->  complex gain (a + j b) / A relative to A sin
    h = (out[:, :, 0] + 1j * out[:, :, 1]) / A[:, None]
    R = model.actuator.moment_arm_m
    shape = (amps.size, f.size)
    return (h[:, 0] / R).reshape(shape), h[:, 1].reshape(shape)


def sine_dwell_freqresp(model: TvcModel, freq_hz, amplitude_rad: float, axis: str = "pitch",
                        **kwargs) -> FrequencyResponse:
    """Amplitude-dependent response at one command amplitude (see :func:`sine_dwell_grid`)."""
    piston, engine = sine_dwell_grid(model, [amplitude_rad], freq_hz, axis, **kwargs)
    return FrequencyResponse(np.atleast_1d(np.asarray(freq_hz, float)), piston[0], engine[0],
                             float(amplitude_rad), axis, friction_model=model.friction.name,
                             provenance={"model_sha256": model.sha256, "method": "sine-dwell",
                                         "dt_max_s": kwargs.get("dt_max_s", DEFAULT_DT_S)})
