"""Load-path structural damping (issue 12.6): a finite command -> piston notch for the shipped
models, the damped zero against its hand calculation, and ``taos fit`` freeing it."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
import scipy.signal

from taos.model import load_model
from taos.planar.simplex import load_resonance_from_notch, simplex_state_space

from .conftest import MODELS

DEG = math.pi / 180


@pytest.mark.parametrize("name", ["rs25_ambient", "rs25_hotfire", "rs25_flight"])
def test_shipped_notch_depth_is_finite(name):
    """The linear command -> piston notch (x_p / (R theta_c)) is between -30 and -80 dB deep
    (undamped it was -155 dB ambient, -178 dB hot fire)."""
    m = load_model(MODELS / f"{name}.toml")
    assert m.structure.load_damping_ratio == pytest.approx(0.005)
    fn = load_resonance_from_notch(m)
    g = abs(simplex_state_space(m).freqresp([fn], "command_rad", "x_p_m")[0]) / m.actuator.moment_arm_m
    assert -80.0 < 20 * math.log10(g) < -30.0


def test_notch_zero_damping_matches_hand_calculation(ambient):
    """The notch is the engine on the load spring with the piston held: the zero pair of
    command -> piston solves J s^2 + c_L R^2 s + K_L R^2 + K_n = 0, so its damping ratio is
    zeta_L sqrt(K_L R^2 / (K_L R^2 + K_n)) and its frequency sqrt((K_L R^2 + K_n) / J)."""
    m = ambient.replace(structure=dataclasses.replace(ambient.structure, load_damping_ratio=0.03))
    ss = simplex_state_space(m)
    i, o = ss.input_index("command_rad"), ss.output_index("x_p_m")
    z, _, _ = scipy.signal.ss2zpk(ss.A, ss.B[:, [i]], ss.C[[o]], ss.D[[o]][:, [i]])
    R, J, KL, Kn = (m.actuator.moment_arm_m, m.engine.inertia("pitch"), m.structure.load_stiffness_N_per_m,
                    m.engine.rotational_stiffness_Nm_per_rad)
    wz = math.sqrt((KL * R * R + Kn) / J)
    zz = z[np.argmin(np.abs(np.abs(z) - wz))]
    assert abs(zz) == pytest.approx(wz, rel=1e-6)
    assert -zz.real / abs(zz) == pytest.approx(0.03 * math.sqrt(KL * R * R / (KL * R * R + Kn)), rel=1e-6)


def test_fit_frees_the_load_damping(ambient):
    """``taos fit --free load_damping_ratio``: from sine-dwell data around the notch made with
    zeta_L = 0.03, a start at 0.01 recovers it within 5 %."""
    from taos.identify.estimation import MeasuredResponse
    from taos.identify.fit import fit_frequency_response
    truth = ambient.with_friction("none")
    truth = truth.replace(structure=dataclasses.replace(truth.structure, load_damping_ratio=0.03))
    f = np.array([2.0, 4.0, 4.8, 5.0, 5.1, 5.2, 5.3, 5.4, 5.6, 6.0, 8.0])
    from taos.planar.freqresp import sine_dwell_grid
    p, e = sine_dwell_grid(truth, [0.4 * DEG], f)  # the full model (avionics in the path)
    ones = np.ones(f.size)
    data = [MeasuredResponse("pitch", f, np.full(f.size, 0.4 * DEG), p[0] * truth.actuator.moment_arm_m, e[0],
                             ones, ones, np.full(f.size, 0.003), np.full(f.size, 0.003))]
    r = fit_frequency_response(truth, data, ["load_damping_ratio"], start={"load_damping_ratio": 0.01})
    assert r.values[0] == pytest.approx(0.03, rel=0.05)
