"""TVC describing function N(A, w) (seed paper sec. 3.1, figs. 4-5): the analytic Coulomb
checks in the rigid-load limit, the paper's ordering of amplitude dependence, and the map's
interpolation and export."""

from __future__ import annotations

import dataclasses

import math

import numpy as np
import pytest

from taos.flight.describing import (DescribingFunctionMap, describing_function_map, rigid_engine_response,
                             rigid_limit_model)
from taos.planar.freqresp import linear_freqresp
from taos.model import load_model

from .conftest import MODELS

DEG = math.pi / 180
FLIGHT = MODELS / "rs25_flight.toml"


@pytest.mark.parametrize("law", ["coulomb-switching", "coulomb-smooth"])
def test_coulomb_numeric_describing_function_is_4Tc_over_pi_V(law):
    """Numeric DF of Coulomb friction (rate sine V sin wt -> torque fundamental) = 4 T_c/(pi V)
    within 2 %, over two decades of rate amplitude."""
    f = load_model(FLIGHT, friction=law).friction
    for V in (0.02, 0.1, 1.0):
        num = f.numeric_describing_function(V, 1.0)
        ana = 4 * f.coulomb_torque_Nm / (math.pi * V)
        assert abs(num - ana) / ana < 0.02, (V, num, ana)
        assert f.describing_function(V).real == pytest.approx(ana, rel=1e-12)


def test_rigid_limit_engine_response_matches_relay_in_loop_describing_function():
    """Very stiff load path (100 x), ideal avionics, Coulomb friction at the Green Run
    amplitude 0.4 deg: the sine-dwell engine response equals the analytic relay-in-loop
    prediction G_c / (1 + j w G_f 4 T_c/(pi w |theta|)) within 3 % while friction moves it
    more than 10 % from the linear response (23-26 %).

    Measured: 1.9, 2.7, 2.2, 2.2 % at 2, 5, 8, 12 Hz (the same to 0.02 % with the periodic
    orbit by shooting or dt 2.5e-5 s: not numerics). It was within 2 % (0.2-0.8 %) with the previous
    notional servo (K_v 40 1/s); the difference is the first-harmonic approximation itself: the
    recalibrated servo's dynamic pressure feedback makes it a damper in series with the load path
    between its 1.06 Hz washout corner and the loop bandwidth, so more of the relay torque's
    odd harmonics reach the engine angle (its 3rd harmonic 1.6 % / 1.3 % of the fundamental at
    5 / 8 Hz, against 0.8 % / 0.5 % before), and the describing function neglects them."""
    m = load_model(FLIGHT, friction="coulomb-switching")
    # the ideal valve: against a 100 x stiffer load the square-root valve law of the pressure-limited
    # servo is a nonlinearity of its own (3-12 % at these points), which the relay DF does not model
    m = rigid_limit_model(m.replace(actuator=dataclasses.replace(m.actuator, pressure_limited=False)), 100.0)
    f = np.array([2.0, 5.0, 8.0, 12.0])
    dfm = describing_function_map(m, [0.4 * DEG], f)
    lin = linear_freqresp(m, f).engine
    for j, fj in enumerate(f):
        ana = rigid_engine_response(m, 0.4 * DEG, fj)
        num = dfm.engine[0, j]
        assert abs(num / ana - 1) < 0.03, (fj, num, ana)
        assert abs(num / lin[j] - 1) > 0.10


def test_amplitude_dependence_ordering_coulomb_dahl_modified_lugre():
    """Paper sec. 3.2: at low frequency Coulomb shows the strongest amplitude dependence,
    Dahl less, modified LuGre the least (same torque level). Measured as the engine-gain
    change from 1 deg to 0.1 deg command at 0.1 Hz."""
    spread = {}
    for law in ("coulomb-switching", "dahl", "modified-lugre"):
        m = load_model(FLIGHT, friction=law)
        d = describing_function_map(m, [0.1 * DEG, 1.0 * DEG], [0.1], settle_cycles=1, measure_cycles=1)
        g = d.gain_db()
        spread[law] = g[1, 0] - g[0, 0]
    assert spread["coulomb-switching"] > spread["dahl"] > spread["modified-lugre"] > 0, spread
    assert spread["modified-lugre"] < 1.0


def test_df_map_interpolates_nodes_and_round_trips(tmp_path):
    """The map returns its own nodes exactly, interpolates between them in log-log, holds
    edge values, and survives JSON and HDF5 export; its plot saves as PNG."""
    m = load_model(FLIGHT, friction="dahl")
    amps = np.array([0.05, 0.2, 1.0]) * DEG
    f = np.array([0.1, 0.3, 1.0])
    d = describing_function_map(m, amps, f, settle_cycles=1, measure_cycles=1)
    assert np.allclose(d(amps[:, None], f[None, :]), d.engine, rtol=1e-9)
    mid = d(math.sqrt(amps[0] * amps[1]), math.sqrt(f[0] * f[1]))
    gm = np.mean(d.gain_db()[:2, :2])
    assert 20 * math.log10(abs(mid)) == pytest.approx(gm, abs=1e-9)
    assert d(amps[-1] * 10, f[-1] * 10) == pytest.approx(d.engine[-1, -1], rel=1e-9)
    d.to_hdf5(tmp_path / "df.h5")
    e = DescribingFunctionMap.from_hdf5(tmp_path / "df.h5")
    assert np.array_equal(e.engine, d.engine) and e.friction_model == "dahl"
    d.to_json(tmp_path / "df.json")
    import json
    j = json.loads((tmp_path / "df.json").read_text())
    assert j["amplitude_deg"][0] == pytest.approx(0.05) and len(j["engine"]["gain_db"]) == 3
    from taos.plotting import save
    from taos.plotting.describing import plot_df_map
    save(plot_df_map(d), tmp_path / "df.png")
    assert (tmp_path / "df.png").stat().st_size > 1000
