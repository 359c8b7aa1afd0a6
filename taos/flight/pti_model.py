"""The model's prediction of what a PTI shows (:mod:`taos.flight.pti`): the flight-control open loop
broken at the PTI injection point and the TVC command-to-piston response, linear and
friction-degraded.

Where the PTI enters (:func:`taos.flight.ascent_sim.ascent_plant`, :func:`taos.flight.vehicle.flight_plant`):
the flight-control output u_fcs = -P_n F (K_p theta + K_i int theta + K_d theta') is summed with the
PTI r, and the sum u = u_fcs + r is what every TVC receives: the core TVC through its avionics
(gain g) and the booster TVC (first order, before separation). Breaking the loop at that summing
point, with u the loop's input and u_fcs its output,

    u_fcs = -L(jw) u,      L = L_core(jw) + L_b(jw)

    L_core = -(d u_fcs / d delta) g G_tvc(jw)          (TVC: command -> engine angle, linear)
    L_b    = -(d u_fcs / d delta_b) / (tau_b jw + 1)   (booster part; zero after separation)

(negative-feedback convention, critical point -1, as :func:`taos.flight.vehicle.loop_freqresp`).
It is computed here from the ascent plant itself, frozen at a time t (:func:`taos.flight.ascent_sim.flight_at`):
the plant's booster row is cut from u_fcs and driven by the loop input instead, the TVC command is
g times the loop input, the friction torque is zero, and L = -C_fcs (jw I - A_open)^-1 B_open.
With the friction replaced by its describing function N(A, w) (engine / command, avionics
included; :func:`taos.planar.freqresp.sine_dwell_points`),

    L_DF = L_b + L_core N(A, w) / (g G_tvc(jw)).

The record gives the same loop from the measured phasors, u_fcs = u - r:
L = -U_fcs / U = -U_fcs / (R + U_fcs) (:mod:`taos.flight.pti`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from taos.model import TvcModel


def avionics_gain(model: TvcModel, amplitude_rad: float) -> float:
    """The avionics' small-signal gain g [-] at ``amplitude_rad`` [rad]: the crossover gain table
    interpolated at that command magnitude (1 without a table). Quantisation is not linear and
    is left out (it vanishes with the bounding avionics of the flight analyses)."""
    av = model.avionics
    if not av.gain_table_rad:
        return 1.0
    return float(np.interp(amplitude_rad, av.gain_table_rad, av.gain_table))


@dataclass(frozen=True, eq=False)
class LoopPrediction:
    """The model's responses at ``freq_hz`` [Hz] (complex): ``loop`` L (linear TVC, module
    docstring), ``booster`` its L_b part, ``engine`` g G_tvc (engine / command [-]),
    ``piston`` g x_p / command [m/rad]; ``avionics_gain`` g; the time t [s] the plant was frozen at."""

    freq_hz: np.ndarray
    loop: np.ndarray
    booster: np.ndarray
    engine: np.ndarray
    piston: np.ndarray
    avionics_gain: float
    t_s: float

    def degraded(self, engine_df: np.ndarray) -> np.ndarray:
        """L_DF = L_b + (L - L_b) N / (g G_tvc) for the describing function ``engine_df`` = N at
        :attr:`freq_hz`."""
        return self.booster + (self.loop - self.booster) * np.asarray(engine_df) / self.engine


def predict_loop(ascent, model: TvcModel, axis: str, t_s: float, freq_hz, amplitude_rad: float = 0.0) -> LoopPrediction:
    """The linear prediction (module docstring) of the loop broken at the PTI injection point, of
    the ascent ``ascent`` (:class:`taos.flight.ascent.Ascent`) with the TVC ``model`` on ``axis``,
    frozen at ``t_s`` [s], at ``freq_hz`` [Hz]; ``amplitude_rad`` [rad] the command magnitude for
    the avionics gain table."""
    from taos.flight.ascent_sim import ascent_plant, flight_at

    f = np.atleast_1d(np.asarray(freq_hz, float))
    flight, a_b = flight_at(ascent, t_s, axis)
    tau = ascent.boosters.actuator_time_constant_s
    p = ascent_plant(flight, model, axis, a_b, tau)
    ss = p.ss
    g = avionics_gain(model, amplitude_rad)
    ib = ss.state_index("booster_deflection_rad")
    A = ss.A.copy()
    A[ib, :] = 0.0
    A[ib, ib] = -1.0 / tau                     # the booster driven by the loop input, not by u_fcs
    b_core = g * ss.B[:, ss.input_index("command_rad")]
    b_boost = ss.B[:, ss.input_index("pti_rad")]   # 1 / tau on the booster state
    C = p.cmd_c                                   # u_fcs over the state
    o = ss.output_index
    n = A.shape[0]
    L, Lb, eng, pis = (np.empty(f.size, complex) for _ in range(4))
    for k, fk in enumerate(f):
        M = 2j * np.pi * fk * np.eye(n) - A
        X = np.linalg.solve(M, np.column_stack([b_core, b_boost]))
        L[k] = -(C @ X[:, 0] + C @ X[:, 1])
        Lb[k] = -(C @ X[:, 1])
        eng[k] = ss.C[o("theta_rad")] @ X[:, 0]
        pis[k] = ss.C[o("x_p_m")] @ X[:, 0]
    return LoopPrediction(f, L, Lb, eng, pis, g, float(t_s))


def describing_engine(model: TvcModel, axis: str, amplitude_rad: float, freq_hz) -> tuple[np.ndarray, np.ndarray, dict]:
    """(engine N(A, w) [-], piston x_p / theta_c [m/rad], solver provenance) of ``model`` (friction
    and avionics) by settled sine dwells at ``amplitude_rad`` [rad] and each of ``freq_hz`` [Hz]
    (:func:`taos.planar.freqresp.sine_dwell_points`, one settling cycle, one measured)."""
    from taos.planar.freqresp import sine_dwell_points

    f = np.atleast_1d(np.asarray(freq_hz, float))
    pts = sine_dwell_points(model, np.full(f.size, float(amplitude_rad)), f, axis, settle_cycles=2, measure_cycles=1)
    return pts.engine, pts.piston * model.actuator.moment_arm_m, pts.solver
