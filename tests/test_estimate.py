"""Frequency-response estimation: H1 on a known linear system, two axes excited at once,
the unknown engine-angle offset, and dwell detection on the Green Run profile."""

from __future__ import annotations

import math

import numpy as np
import scipy.signal as ss

from taos.identify.data import TestData
from taos.identify.estimation import detect_dwells, estimate_dwells, estimate_h1

from .conftest import MODELS

DEG = math.pi / 180
FS = 200.0


def _sys(wn_hz, zeta, k=1.0):
    w = 2 * np.pi * wn_hz
    return ss.lti([k * w * w], [1, 2 * zeta * w, w * w])


def _exact(sys_, f):
    return ss.freqresp(sys_, 2 * np.pi * np.asarray(f))[1]


def _lsim(sys_, u, t, up=5):
    """lsim on a grid ``up`` times finer (its linear interpolation of the input is then exact
    to ~1e-4 at 14 Hz), sampled back on t. ``u`` is a function of time."""
    tf = np.arange(t.size * up) * (t[1] - t[0]) / up
    return ss.lsim(sys_, u(tf), tf)[1][::up]


def _multisine(t, freqs, amp, ph):
    return amp * sum(np.cos(2 * np.pi * f * t + p) for f, p in zip(freqs, ph)) / math.sqrt(len(freqs))


def test_h1_matches_exact_response_within_0p2_db_and_2_deg_where_coherent():
    """Random (band-limited) command through a known 2nd-order system plus output noise:
    H1 within 0.2 dB and 2 deg of the exact response wherever coherence > 0.9."""
    rng = np.random.default_rng(3)
    n = 2 ** 16
    up = 5
    tf = np.arange(n * up) / (FS * up)
    b, a = ss.butter(4, 20.0, fs=FS * up)
    uf = ss.lfilter(b, a, rng.standard_normal(n * up)) * DEG
    plant = _sys(6.0, 0.15, 0.02)
    y = ss.lsim(plant, uf, tf)[1][::up]
    u = uf[::up]
    t = tf[::up]
    y = y + 0.01 * np.std(y) * rng.standard_normal(n)
    d = TestData("synthetic", t, ("pitch",), u[None], y[None], None)
    r = estimate_h1(d, nperseg=2048)[0]
    ok = (r.coherence_piston > 0.9) & (r.freq_hz > 0.3) & (r.freq_hz < 18)
    assert ok.sum() > 40
    h = _exact(plant, r.freq_hz[ok])
    err_db = 20 * np.log10(np.abs(r.piston_m_per_rad[ok] / h))
    err_deg = np.degrees(np.angle(r.piston_m_per_rad[ok] / h))
    assert np.max(np.abs(err_db)) < 0.2 and np.max(np.abs(err_deg)) < 2.0


def test_two_axis_multisine_h1_separates_the_axes():
    """Pitch and yaw excited at once with disjoint multisine lines through a coupled 2x2
    system: each axis' H1 at its own lines equals its direct response."""
    rng = np.random.default_rng(4)
    nper = 2000                       # one multisine period: 10 s at 200 Hz, 0.1 Hz bins
    t = np.arange(5 * nper) / FS
    fp = np.arange(5, 140, 10) * 0.1  # 0.5, 1.5, ... Hz
    fy = fp + 0.5                     # 1.0, 2.0, ... Hz
    php, phy = rng.uniform(0, 2 * np.pi, fp.size), rng.uniform(0, 2 * np.pi, fy.size)
    fu_p = lambda tt: _multisine(tt, fp, 0.4 * DEG, php)  # noqa: E731
    fu_y = lambda tt: _multisine(tt, fy, 0.4 * DEG, phy)  # noqa: E731
    up, uy = fu_p(t), fu_y(t)
    Hpp, Hyy, Hpy = _sys(5.0, 0.2), _sys(7.0, 0.1), _sys(3.0, 0.5, 0.3)
    yp = _lsim(Hpp, fu_p, t) + _lsim(Hpy, fu_y, t)
    yy = _lsim(Hyy, fu_y, t) + _lsim(Hpy, fu_p, t)
    d = TestData("synthetic", t[nper:], ("pitch", "yaw"), np.vstack([up, uy])[:, nper:],
                 np.vstack([yp, yy])[:, nper:], None)
    rp, ry = estimate_h1(d, nperseg=nper, window="boxcar")
    np.testing.assert_allclose(rp.freq_hz, fp, atol=1e-9)
    np.testing.assert_allclose(ry.freq_hz, fy, atol=1e-9)
    assert np.max(np.abs(rp.piston_m_per_rad / _exact(Hpp, fp) - 1)) < 1e-3
    assert np.max(np.abs(ry.piston_m_per_rad / _exact(Hyy, fy) - 1)) < 1e-3


def test_two_axis_dwells_are_separated_and_engine_offset_is_ignored():
    """Simultaneous dwells at different frequencies through a coupled system, engine angles
    with a constant unknown offset: the dwell estimate returns the direct responses and
    flags the engine DC level unobservable."""
    t = np.arange(int(12 * FS)) / FS
    up = 0.4 * DEG * np.sin(2 * np.pi * 1.0 * t)
    uy = 0.4 * DEG * np.sin(2 * np.pi * 1.5 * t)
    Hpp, Hyy, Hpy = _sys(5.0, 0.2), _sys(7.0, 0.1), _sys(3.0, 0.5, 0.3)
    yp = ss.lsim(Hpp, up, t)[1] + ss.lsim(Hpy, uy, t)[1]
    yy = ss.lsim(Hyy, uy, t)[1] + ss.lsim(Hpy, up, t)[1]
    eng = np.vstack([yp, yy]) + np.array([[0.03 * DEG], [-0.05 * DEG]])
    d = TestData("synthetic", t, ("pitch", "yaw"), np.vstack([up, uy]), np.vstack([yp, yy]), eng,
                 engine_absolute=False)
    rp, ry = estimate_dwells(d)
    assert rp.freq_hz == np.array([1.0]) or abs(rp.freq_hz[0] - 1.0) < 1e-3
    assert abs(rp.piston_m_per_rad[0] / _exact(Hpp, [1.0])[0] - 1) < 2e-3
    assert abs(ry.piston_m_per_rad[0] / _exact(Hyy, [1.5])[0] - 1) < 2e-3
    assert abs(rp.engine[0] / _exact(Hpp, [1.0])[0] - 1) < 2e-3
    assert not rp.engine_dc_observable and np.all(rp.freq_hz > 0)
    assert abs(math.degrees(rp.amplitude_rad[0]) - 0.4) < 1e-3


def test_dwell_detection_finds_the_green_run_segments():
    from taos.profiles import load_profile
    prof = load_profile(MODELS / "profiles" / "greenrun_two_axis.toml")
    t = np.arange(0, prof.duration_s, 1 / 250)
    cmd = prof(t)
    fp = [s.freq_hz for s in detect_dwells(t, cmd[0])]
    fy = [s.freq_hz for s in detect_dwells(t, cmd[1])]
    np.testing.assert_allclose(fp, [0.5, 1, 2, 4, 7, 10, 14], rtol=2e-3)
    np.testing.assert_allclose(fy, [0.75, 1.5, 3, 5, 12], rtol=2e-3)
