"""The LCO verdict map with its time-domain confirmation (issue 28 point 3, issue 26 point 5):
the confirmation starts on the describing function's periodic solution and still decides; the
map's points run on both cores bit for bit as in series; the map runs as a stored, resumable
campaign on the Monte Carlo engine."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from taos.flight.lco import describing_function_map_for, flown_model, measure_oscillation, predict_lco, \
    simulate_flight
from taos.flight.lco_confirm import confirm, periodic_start
from taos.flight.vehicle import flight_plant, load_flight
from taos.model import Structure, load_model

from .conftest import MODELS, run_cli
from .inprocess import taos_json

DEG = math.pi / 180
LBF_IN = 4.4482216152605 / 0.0254
FLIGHT = MODELS / "flight" / "core_stage.toml"
AMPS = np.logspace(np.log10(0.01), 0.0, 8) * DEG
FREQ = np.logspace(np.log10(0.06), np.log10(0.5), 6)


class _Dahl(dict):
    """Dahl at 115,000 (soft: a cycle) and 205,000 lbf/in (stiff: none), bounding avionics, made
    on first use: {name: (flight, flown model, plant, describing-function map, prediction)}."""

    def __missing__(self, name):
        fl = load_flight(FLIGHT)
        kl = {"soft": 115000, "stiff": 205000}[name]
        m = flown_model(load_model(MODELS / "rs25_flight.toml", friction="dahl").replace(
            structure=Structure(kl * LBF_IN)))
        df = describing_function_map_for(m, fl.axis, amplitudes_rad=AMPS, freq_hz=FREQ, flown=True)
        self[name] = (fl, m, flight_plant(fl, m, fl.axis), df, predict_lco(fl, df))
        return self[name]


@pytest.fixture(scope="module")
def dahl():
    return _Dahl()


@pytest.fixture(scope="module")
def soft_confirmed(dahl):
    """The soft loop's start on the predicted cycle and its confirmation (the reference of both
    confirmation tests below: the same run on the same inputs, made once for the module)."""
    fl, m, plant, df, pred = dahl["soft"]
    c = pred.stable_cycle
    s = periodic_start(plant, m, df, c.amplitude_rad, c.freq_hz, "predicted cycle")
    return s, confirm(plant, m, s)


def test_start_is_the_harmonic_balance_state_of_the_whole_loop(dahl):
    """The start solves the plant's linear block for the avionics and friction fundamentals that
    give the describing function's engine and piston phasors; the FCS command it then carries,
    computed through the vehicle and FCS (an independent route to L0 N = -1), is the predicted
    amplitude A: |c - A| / A below 1e-6 (achieved ~1e-15 at the refined root)."""
    fl, m, plant, df, pred = dahl["soft"]
    c = pred.stable_cycle
    s = periodic_start(plant, m, df, c.amplitude_rad, c.freq_hz, "predicted cycle")
    assert s.command_residual < 1e-6
    # the engine state at the start lies on the engine phasor N A (amplitude bound)
    theta0 = plant.ss.C[plant.ss.output_index("theta_rad")] @ s.x0
    assert abs(theta0) <= abs(df(c.amplitude_rad, c.freq_hz)) * c.amplitude_rad * (1 + 1e-9)
    assert s.z0 != 0.0   # the bristle state pre-rolled on its hysteresis loop


@pytest.mark.slow
def test_confirmation_from_the_predicted_cycle_agrees_with_the_run_from_rest(dahl, soft_confirmed):
    """Soft: the run started on the predicted cycle settles within 2 % in command and engine
    amplitude and 1 % in frequency of the 300 s run from rest (achieved 0.4 %, 0.5 %, 0.1 %) in
    at most a third of its simulated time; its first cycle is already within 5 % of its last (a
    start on the cycle, not a transient). Stiff: no cycle in either (the start at the nearest
    margin decays)."""
    for name in ("soft", "stiff"):
        fl, m, plant, df, pred = dahl[name]
        c = pred.stable_cycle
        if name == "soft":
            s, r = soft_confirmed
        else:
            from taos.flight.lco_verdict import nearest_margin
            assert c is None
            near = nearest_margin(pred)
            s = periodic_start(plant, m, df, near.amplitude_rad, near.freq_hz, "nearest margin")
            r = confirm(plant, m, s)
        ref = measure_oscillation(simulate_flight(fl, m, 300.0), 120.0)
        print(name, r.outcome, r.simulated_s, np.degrees(r.cycle_amplitudes_rad), ref)
        assert r.lco == ref.lco == (name == "soft")
        assert r.simulated_s <= 100.0
        if name == "soft":
            assert r.outcome == "sustained"
            assert r.amplitude_rad == pytest.approx(ref.amplitude_rad, rel=0.02)
            assert r.engine_amplitude_rad == pytest.approx(ref.engine_amplitude_rad, rel=0.02)
            assert r.freq_hz == pytest.approx(ref.freq_hz, rel=0.01)
            assert r.cycle_amplitudes_rad[0] == pytest.approx(r.cycle_amplitudes_rad[-1], rel=0.05)
        else:
            assert r.outcome == "decays"


@pytest.mark.slow
def test_the_confirmation_decides_rather_than_echoes_its_start(dahl, soft_confirmed):
    """Started at a quarter of the soft cycle the motion grows into the cycle (the settled
    amplitude is the cycle's, 2 %, not the start's); started at 0.3 deg in the stiff loop, which
    has no cycle, it decays and is reported so."""
    fl, m, plant, df, pred = dahl["soft"]
    c = pred.stable_cycle
    ref = soft_confirmed[1]   # the run started on the predicted cycle
    low = confirm(plant, m, periodic_start(plant, m, df, 0.25 * c.amplitude_rad, c.freq_hz, "probe"))
    print(np.degrees(low.cycle_amplitudes_rad))
    assert low.lco and low.outcome == "sustained"
    assert low.amplitude_rad == pytest.approx(ref.amplitude_rad, rel=0.02)
    assert low.cycle_amplitudes_rad[-1] > 2 * low.cycle_amplitudes_rad[0]
    fl, m, plant, df, pred = dahl["stiff"]
    hi = confirm(plant, m, periodic_start(plant, m, df, 0.3 * DEG, 0.12, "probe"))
    print(np.degrees(hi.cycle_amplitudes_rad))
    assert not hi.lco and hi.outcome == "decays"


def _small_map(threads):
    from taos.flight.lco_map import SweepAxis, lco_map
    fl = load_flight(FLIGHT)
    m = load_model(MODELS / "rs25_flight.toml", friction="dahl")
    axes = (SweepAxis("integral_gain", (0.6, 0.78)),)
    return lco_map(fl, m, axes, amplitudes_rad=AMPS, freq_hz=FREQ, time_domain=True, threads=threads)


@pytest.mark.slow
def test_map_on_both_cores_equals_the_serial_map_bit_for_bit():
    """Issue 28.1: the map's dwells and confirmation runs in parallel give the serial result
    exactly (every array, NaN where NaN); and the verdicts are the documented flip (soft Dahl:
    none at K_i 0.6, a cycle at 0.78)."""
    import numba
    par = _small_map(None)
    n = numba.get_num_threads()
    numba.set_num_threads(1)
    try:
        ser = _small_map(1)
    finally:
        numba.set_num_threads(n)
    for k in ("lco", "prediction_lco", "amplitude_deg", "engine_amplitude_deg", "frequency_hz", "margin_db"):
        np.testing.assert_array_equal(getattr(par, k), getattr(ser, k))
    for k in par.td:
        np.testing.assert_array_equal(par.td[k], ser.td[k])
    assert par.lco.tolist() == [False, True] and par.prediction_lco.tolist() == [False, True]


LCO = ("lco", MODELS / "rs25_flight.toml", "--flight", FLIGHT, "--friction", "dahl",
       "--amplitudes-deg", ",".join(f"{a:.4g}" for a in np.degrees(AMPS)),
       "--freq-hz", ",".join(f"{f:.4g}" for f in FREQ), "--sweep", "integral_gain=0.6,0.78")


@pytest.fixture(scope="module")
def map_json(tmp_path_factory):
    """``taos lco`` LCO's map with no store, the JSON (the reference of both campaign tests below:
    the same command on the same inputs, run once for the module). The commands whose subject is
    the map's figures and files run in this process (:mod:`tests.inprocess`); the refusals run the
    console script."""
    return taos_json(tmp_path_factory.mktemp("lco_map") / "inproc.json", *LCO)


@pytest.mark.slow
def test_map_as_a_stored_resumable_campaign(tmp_path, map_json):
    """Issue 26.5: ``--out DIR`` runs the map on the Monte Carlo engine: DIR/map.zarr in the
    campaign store's layout (xarray-readable, one row per point), the same map as in process; a
    second run without --resume is refused (exit 2, nothing written); a point lost (its status
    reset) is run again by --resume and the map comes out the same."""
    import xarray as xr
    out = tmp_path / "map"
    a = map_json["sweep"]
    b = taos_json(tmp_path / "stored.json", *LCO, "--out", out)["sweep"]
    assert a == b
    ds = xr.open_zarr(out / "map.zarr", zarr_format=2, chunks=None)   # (no Dask: never a task of a stale client)
    assert ds.sizes["run"] == 2 and list(ds["status"].values) == [1, 1]
    assert ds["td_lco"].values.tolist() == [False, True]
    man = json.loads((out / "map.json").read_text())
    assert man["format"] == "taos-lco-map-2" and len(man["inputs_sha256"]) == 64
    assert any(f["file"].endswith("rs25_flight.toml") for f in man["input_files"])
    again = run_cli(*LCO, "--out", out, "--json", tmp_path / "x.json")
    assert again.returncode == 2 and "--resume" in again.stderr and not (tmp_path / "x.json").exists()
    other = run_cli(*LCO[:-1], "integral_gain=0.6,0.9", "--out", out, "--resume", "--json", tmp_path / "x.json")
    assert other.returncode == 2 and "design_sha256" in other.stderr
    xr.Dataset({"status": (("run",), np.array([1, 0], np.int8))}).to_zarr(out / "map.zarr", region={"run": slice(0, 2)},
                                                                         zarr_format=2)
    assert taos_json(tmp_path / "resumed.json", *LCO, "--out", out, "--resume")["sweep"] == a


@pytest.mark.slow
def test_map_on_dask_workers_equals_the_map_in_process(tmp_path, map_json):
    """``--workers 2`` (a local Dask cluster, one batch per TVC variant) stores the same map."""
    assert map_json == taos_json(tmp_path / "dask.json", *LCO, "--out", tmp_path / "map", "--workers", "2")


def test_map_campaign_options_need_a_sweep_and_a_folder(tmp_path):
    r = run_cli("lco", MODELS / "rs25_flight.toml", "--flight", FLIGHT, "--out", tmp_path / "m", "--no-time-domain")
    assert r.returncode == 2 and "--out" in r.stderr and len(r.stderr.strip().splitlines()) == 1
    r = run_cli(*LCO, "--resume", "--no-time-domain")
    assert r.returncode == 2 and "--resume" in r.stderr
    assert not (tmp_path / "m").exists()
