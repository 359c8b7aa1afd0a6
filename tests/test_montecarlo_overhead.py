"""The Monte Carlo run's work outside the kernel, made cheaper without changing a bit (issue 44
point 4): the turbulence recursion as one compiled call (no scipy.signal in a worker), the segment flights interpolated at
once, a model's base variant loaded once a process. Each against the previous way of computing
it, written out here, and a small campaign's store against the same campaign flown the previous
way."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest

from taos.flight import ascent_lanes, ascent_sim
from taos.flight.ascent import load_ascent, wind_speed
from taos.montecarlo import load_campaign, open_store, run_campaign

DATA = Path(__file__).resolve().parent / "data"


def wind_loop(ascent, t_s, rng, dt_s):
    """The previous wind: the Ornstein-Uhlenbeck turbulence w_k = phi w_(k-1) + s xi_k as a
    Python loop on the coarse grid (tau / 20), interpolated onto ``t_s``."""
    w = ascent.wind
    t = np.asarray(t_s, float)
    steady = ascent.trajectory.at("wind_speed_m_s", t)
    g = (t - w.gust_time_s) / w.gust_duration_s
    gust = np.where((g >= 0) & (g <= 1), 0.5 * w.gust_amplitude_m_s * (1 - np.cos(2 * np.pi * g)), 0.0)
    h = w.turbulence_time_constant_s / 20.0
    tc = np.arange(t[0], t[-1] + 2 * h, h)
    phi = math.exp(-h / w.turbulence_time_constant_s)
    xi = rng.standard_normal(tc.size)
    turb = np.empty(tc.size)
    turb[0] = w.turbulence_intensity_m_s * xi[0]
    s = w.turbulence_intensity_m_s * math.sqrt(1 - phi * phi)
    for k in range(1, tc.size):
        turb[k] = phi * turb[k - 1] + s * xi[k]
    return w.scale * (steady + gust + np.interp(t, tc, turb))


def flight_at_scalar(ascent, t_s, axis):
    """The previous frozen flight: the trajectory interpolated at one time."""
    from taos.flight.ascent import aero_instability, control_acceleration
    fl, tr = ascent.flight, ascent.trajectory
    core, boost = (float(v) for v in control_acceleration(ascent, t_s))
    k = fl.vehicle.control_acceleration_per_s2(axis) / (core + boost)
    inertia = float(tr.at("inertia_kgm2", t_s))
    veh = dataclasses.replace(fl.vehicle, mass_kg=float(tr.at("mass_kg", t_s)), pitch_inertia_kgm2=inertia,
                              yaw_inertia_kgm2=inertia, thrust_per_engine_N=float(tr.at("core_thrust_per_engine_N", t_s)),
                              gimbal_arm_m=float(tr.at("gimbal_arm_m", t_s)),
                              aero_instability_per_s2=float(aero_instability(ascent, t_s)))
    fcs = dataclasses.replace(fl.fcs, attitude_gain=fl.fcs.attitude_gain * k,
                              integral_gain_per_s=fl.fcs.integral_gain_per_s * k, rate_gain_s=fl.fcs.rate_gain_s * k)
    return dataclasses.replace(fl, vehicle=veh, fcs=fcs), boost


def recorded_by_segment(plants, bounds, rec, Xq):
    """The previous recorded outputs: y = C x term by term, segment by segment."""
    from taos.flight.ascent_sim import _RECORDED
    Y = np.empty((Xq.shape[0], 8))
    for p, k0, k1 in zip(plants, bounds[:-1], bounds[1:]):
        sl = slice(k0 // rec, k1 // rec + (1 if k1 == bounds[-1] else 0))
        for j, name in enumerate(_RECORDED):
            if name is not None:
                row = p.ss.C[p.ss.output_index(name)]
                y = np.zeros(sl.stop - sl.start)
                for i in np.flatnonzero(row):
                    y += row[i] * Xq[sl, i]
                Y[sl, j] = y
    return Y


@pytest.fixture(scope="module")
def ascent():
    return load_ascent("ascent")


@pytest.mark.parametrize("seed,scale", [(1, 1.0), (20221116, 1.7), (5, 0.0)])
def test_turbulence_kernel_gives_the_loops_bits(ascent, seed, scale):
    asc = dataclasses.replace(ascent, wind=dataclasses.replace(ascent.wind, scale=scale))
    t = 120.0 + np.arange(200_001) * 1e-3
    got = wind_speed(asc, t, np.random.default_rng(seed), 1e-3)
    ref = wind_loop(asc, t, np.random.default_rng(seed), 1e-3)
    assert np.array_equal(got, ref)
    # the turbulence is there: its RMS about the steady wind and gust is the file's sigma (a 200 s
    # record of a process with tau = h 20: about 200 / (2 tau) independent samples)
    if scale:
        w = asc.wind
        steady = wind_loop(dataclasses.replace(asc, wind=dataclasses.replace(w, turbulence_intensity_m_s=0.0)), t,
                           np.random.default_rng(seed), 1e-3)
        rms = np.std(got - steady) / scale
        n_ind = 200.0 / (2 * w.turbulence_time_constant_s)
        assert abs(rms / w.turbulence_intensity_m_s - 1) < 4 / math.sqrt(n_ind)


def test_segment_flights_at_once_equal_one_at_a_time(ascent):
    times = 120.0 + 5.0 * np.arange(41) + 2.5   # the campaign's segment middles, and separation
    for axis in ("pitch", "yaw"):
        got = ascent_lanes.flights_at(ascent, times, axis)
        for t, (fl, b) in zip(times, got):
            ref, rb = flight_at_scalar(ascent, float(t), axis)
            assert fl == ref and b == rb
        assert ascent_lanes.flight_at(ascent, float(times[0]), axis) == got[0]


def test_base_variant_loaded_once_is_the_loaded_one():
    from taos import variants
    from taos.flight.lco import with_bounding_avionics
    from taos.model import load_model
    m = with_bounding_avionics(load_model("rs25_flight", friction="dahl"))  # a change made in code
    variants._BASES.clear()
    a = m.with_values({"friction.coulomb_torque": 9000.0, "structure.load_stiffness": "110000 lbf/in"})
    assert len(variants._BASES) == 1
    b = m.with_values({"friction.coulomb_torque": 9100.0})
    assert len(variants._BASES) == 1   # the same base for every variant of m
    variants._BASES.clear()
    b2 = m.with_values({"friction.coulomb_torque": 9100.0})
    assert b2 == b and b2.sha256 == b.sha256 and b.avionics == m.avionics
    assert a.friction.coulomb_torque_Nm == 9000.0 and a.avionics == m.avionics


def test_small_campaign_store_equals_the_previous_way(tmp_path, monkeypatch):
    """The short campaign (4 runs and the nominal, in process) stored the same, array for array,
    as with the turbulence loop, the segment flights one at a time, every variant loading its
    base again and the recorded outputs summed segment by segment."""
    from taos import variants
    c = load_campaign(DATA / "mc_short.toml")
    run_campaign(c, tmp_path / "new", runs=4, workers=0)
    monkeypatch.setattr(ascent_lanes, "wind_speed", wind_loop)
    monkeypatch.setattr(ascent_lanes, "flights_at",
                        lambda asc, ts, axis: [flight_at_scalar(asc, float(t), axis) for t in np.atleast_1d(ts)])
    monkeypatch.setattr(variants, "base_variant", lambda model, old, load: load(old))
    monkeypatch.setattr(ascent_sim, "_recorded", recorded_by_segment)
    run_campaign(c, tmp_path / "old", runs=4, workers=0)
    for group in (None, "nominal"):
        new, old = open_store(tmp_path / "new" / "campaign.zarr", group), open_store(tmp_path / "old" / "campaign.zarr", group)
        assert set(new.data_vars) == set(old.data_vars)
        for k in new.data_vars:
            a, b = np.asarray(new[k].values), np.asarray(old[k].values)
            assert np.array_equal(a, b, equal_nan=a.dtype.kind == "f"), (group, k)
    st = np.asarray(open_store(tmp_path / "new" / "campaign.zarr")["status"].values)
    assert np.all(st == 1)
