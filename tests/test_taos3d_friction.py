"""Spherical-bearing friction: the planar laws are the 1-D special case of the vector laws,
and the implicit bearing step solves its own equations. Parametrised over the friction
registry: a registered law is checked here by being registered."""

from __future__ import annotations

import math

import numpy as np
import pytest

from taos import friction
from taos.model import load_model

LAWS = friction.ids()


@pytest.fixture(scope="module")
def base():
    return load_model("models/rs25_hotfire.toml")


@pytest.mark.parametrize("name", LAWS)
def test_vector_law_reduces_to_planar_law_on_one_axis(base, name):
    law = base.with_friction(name).friction
    e = law.entry
    p = law.pack()
    rng = np.random.default_rng(1)
    tc = law.coulomb_torque_Nm
    for _ in range(200):
        v = rng.normal() * 10 ** rng.uniform(-5, 0)
        z = rng.uniform(-1.2, 1.2) * tc / 1.3e7
        ta = rng.normal() * tc
        dz, t = e.rates(v, z, ta, p)
        for sgn_axis in (0, 1):  # along pitch and along yaw
            w = [0.0, 0.0]
            zz = [0.0, 0.0]
            tt = [0.0, 0.0]
            w[sgn_axis], zz[sgn_axis], tt[sgn_axis] = v, z, ta
            d3 = e.zdot3(w[0], w[1], zz[0], zz[1], p)
            t3 = e.torque3(w[0], w[1], zz[0], zz[1], d3[0], d3[1], tt[0], tt[1], p)
            assert d3[sgn_axis] == pytest.approx(dz, rel=1e-12, abs=1e-300)
            assert d3[1 - sgn_axis] == 0.0
            assert t3[sgn_axis] == pytest.approx(t, rel=1e-12, abs=1e-9)
            assert t3[1 - sgn_axis] == 0.0


# every law but the ones without torque or with a stick band (isotropy of the stuck state is
# the saturation of the applied torque, tested by the bearing step below)
@pytest.mark.parametrize("name", [n for n in LAWS if n not in ("none", "coulomb-switching")])
def test_vector_law_is_isotropic_and_opposes_relative_rotation(base, name):
    law = base.with_friction(name).friction
    e = law.entry
    p = law.pack()
    rng = np.random.default_rng(2)
    for _ in range(100):
        a = rng.uniform(0, 2 * math.pi)
        v = rng.uniform(1e-4, 0.3)
        z = rng.uniform(-1, 1) * law.coulomb_torque_Nm / 1.3e7
        c, s = math.cos(a), math.sin(a)
        d = e.zdot3(v * c, v * s, z * c, z * s, p)
        t = e.torque3(v * c, v * s, z * c, z * s, d[0], d[1], 0.0, 0.0, p)
        d1, t1 = e.rates(v, z, 0.0, p)
        np.testing.assert_allclose(t, (t1 * c, t1 * s), rtol=1e-10, atol=1e-9)
    # steady sliding: torque along the rate, magnitude the planar steady state
    for v in (1e-3, 0.05):
        w = np.array([0.6, -0.8]) * v
        tq, _ = law.response(np.full(4000, v), 1e-3)
        zz = np.zeros(2)
        for _ in range(4000):  # same explicit march in 2-D, for the direction
            d = e.zdot3(w[0], w[1], zz[0], zz[1], p)
            zz += 1e-3 * np.array(d)
        d = e.zdot3(w[0], w[1], zz[0], zz[1], p)
        t = np.array(e.torque3(w[0], w[1], zz[0], zz[1], d[0], d[1], 0, 0, p))
        assert np.dot(t, w) > 0
        assert abs(t[0] * w[1] - t[1] * w[0]) < 1e-9 * np.linalg.norm(t) * v
        assert np.linalg.norm(t) == pytest.approx(abs(tq[-1]), rel=2e-3)


@pytest.mark.parametrize("name", LAWS)
def test_torque_levels_scale_with_normal_load(base, name):
    law = base.with_friction(name).friction
    e = law.entry
    p = law.pack()
    q = law.scaled(0.25).pack()
    w, z = (0.01, -0.002), (1e-4, 2e-4)
    d = e.zdot3(*w, *z, p)
    dq = e.zdot3(*w, *z, q)
    assert dq == pytest.approx(d, rel=1e-14)  # same bristle dynamics (pre-sliding angle unchanged)
    t = e.torque3(*w, *z, *d, 0, 0, p)
    tq = e.torque3(*w, *z, *dq, 0, 0, q)
    np.testing.assert_allclose(tq, 0.25 * np.array(t), rtol=1e-12)


def _assert_series_balance(e, p, law, Kc, d, z, dt, w, T, zn, dmag, tc):
    """w dt + Kc T = d, and for a law with state the backward-Euler bristle update with T the
    law's torque there (its zdot3 and torque3 kernels)."""
    np.testing.assert_allclose(w * dt + Kc @ T, d, rtol=1e-7, atol=1e-9 * dmag + 1e-18)
    if law.has_state:
        dz = np.array(e.zdot3(w[0], w[1], zn[0], zn[1], p))
        np.testing.assert_allclose(zn, z + dt * dz, rtol=1e-7, atol=1e-9 * np.abs(z).max() + 1e-15)
        tq = e.torque3(w[0], w[1], zn[0], zn[1], dz[0], dz[1], 0, 0, p)
        np.testing.assert_allclose(T, tq, rtol=1e-6, atol=1e-6 * tc)


def _sweep(law, Kc, dt, u, z, dmags, tc):
    """Slip speeds of bearing steps for trial increments d = u dmag, swept up and back down,
    each step continued from the previous slip speed; every result satisfies the balance."""
    e, p = law.entry, law.pack()
    sweeps = []
    for order in (dmags, dmags[::-1]):
        s0, slips = 0.0, {}
        for dmag in order:
            d = u * dmag
            w0, w1, z0, z1, t0, t1 = e.bearing_step(p, Kc, d[0], d[1], z[0], z[1], dt, s0)
            _assert_series_balance(e, p, law, Kc, d, z, dt, np.array([w0, w1]), np.array([t0, t1]),
                                   np.array([z0, z1]), dmag, tc)
            s0 = slips[dmag] = np.hypot(w0, w1)
        sweeps.append(np.array([slips[m] for m in dmags]))
    return sweeps


def test_bearing_step_keeps_the_branch_it_continues_from(base):
    """A Stribeck law whose static level is twice the Coulomb level (T_s = 2 T_c, v_s
    0.3 deg/s; the torque falls with the slip speed) with its bristles loaded to the static
    level makes the backward-Euler bearing equation w dt + Kc T(w) = d multi-valued where
    Kc |dT/ds| > dt: a slow (sticking) and a fast (sliding) root. Each step continues from
    the previous slip speed, so a slow sweep of the trial increment d up and back down shows
    stick-slip hysteresis in one band: up, the bearing stays on the slow branch past the
    point where the fast one appears; down, on the fast branch past where the slow one
    reappears. The shipped law (T_s = T_c, rational bristle-damping decay: the torque
    rises with the slip speed) has one root: up and down sweeps agree."""
    import dataclasses

    shipped = base.with_friction("modified-lugre").friction
    tc = shipped.coulomb_torque_Nm
    Kc = np.array([[5.3e-8, 3e-10], [3e-10, 5.0e-8]])  # the hot-fire model's chain compliance
    dt = 2e-4
    u = np.array([0.6, 0.8])
    up, down = _sweep(shipped, Kc, dt, u, np.zeros(2), np.geomspace(1e-5, 1e-3, 300), tc)
    np.testing.assert_allclose(up, down, rtol=1e-9, atol=1e-12)
    law = dataclasses.replace(shipped, static_torque_Nm=2 * tc,
                              stribeck_velocity_rad_s=3 * shipped.stribeck_velocity_rad_s)
    dmags = np.geomspace(3e-4, 1.5e-3, 300)
    up, down = _sweep(law, Kc, dt, u, law.static_torque_Nm / law.bristle_stiffness_Nm_per_rad * u, dmags, tc)
    assert np.all(up <= down * (1 + 1e-9))
    apart = up < 0.2 * down  # slow on the way up, fast on the way down
    print("hysteresis over d =", dmags[apart].min(), "-", dmags[apart].max(), "rad,", apart.sum(), "of", dmags.size)
    assert apart.sum() >= 0.3 * dmags.size
    assert np.all(np.diff(np.flatnonzero(apart)) == 1)  # one band


@pytest.mark.parametrize("name", LAWS)
def test_bearing_step_solves_the_series_balance(base, name):
    """w dt + Kc T = d, with T the law's torque at the backward-Euler state."""
    law = base.with_friction(name).friction
    e = law.entry
    p = law.pack()
    rng = np.random.default_rng(3)
    Kc = np.array([[2e-9, 3e-10], [3e-10, 1.5e-9]])
    dt = 2e-4
    tc = law.coulomb_torque_Nm
    for _ in range(300):
        dmag = 10 ** rng.uniform(-9, -4)
        d = rng.normal(size=2) * dmag
        z = rng.uniform(-1, 1, 2) * tc / 1.3e7
        s0 = 0.0 if rng.uniform() < 0.3 else 10 ** rng.uniform(-8, 1)  # the continuation start [rad/s]
        w0, w1, z0, z1, t0, t1 = e.bearing_step(p, Kc, d[0], d[1], z[0], z[1], dt, s0)
        w, T, zn = np.array([w0, w1]), np.array([t0, t1]), np.array([z0, z1])
        _assert_series_balance(e, p, law, Kc, d, z, dt, w, T, zn, dmag, tc)
        if name == "coulomb-switching":  # stick: |T| within breakaway; slide: |T| = T_c along w
            if np.linalg.norm(w) == 0:
                assert np.linalg.norm(T) <= max(law.static_torque_Nm, tc) * (1 + 1e-12)
            else:
                assert np.linalg.norm(T) == pytest.approx(tc, rel=1e-9)
                assert abs(T[0] * w[1] - T[1] * w[0]) < 1e-7 * tc * np.linalg.norm(w)
        elif not law.has_state:  # memoryless: the torque at the slip rate
            np.testing.assert_allclose(T, e.torque3(w0, w1, 0, 0, 0, 0, 0, 0, p), rtol=1e-8, atol=1e-300)


@pytest.mark.parametrize("name", ["lugre", "modified-lugre"])
def test_bearing_torque_rises_with_the_slip_rate_at_a_frozen_bristle_state(base, name):
    """The incremental condition of the massless bearing (docs/theory/taos3d.md, why the decay
    is rational): with the shipped rational decay, along any slip direction u the vector
    kernels' torque component T.u at a frozen bristle state z (|z| <= T_c / sigma_0, any
    direction relative to u) does not fall as the slip speed s grows, by finite differences
    over 1e-7-1e3 rad/s from V_d up (h = 1), and equals the closed form (T_s = T_c,
    sigma_2 = 0 as shipped) sigma_0 z.u + sigma_1 v_1 s / (v_1 + s) (1 - sigma_0 z.u / T_c).
    So the balance Kc T(w, z) = psi - phi has its root on one rising branch: no impasse,
    which the former exponential decay (torque peaking at v_1 / sqrt 2 and falling back to
    sigma_0 z) had. The law is passive (its documented condition) at the same rates."""
    law = base.with_friction(name).friction
    e, p = law.entry, law.pack()
    s0, s1, v1, tc = (law.bristle_stiffness_Nm_per_rad, law.bristle_damping_Nms_per_rad,
                      law.damping_decay_velocity_rad_s, law.coulomb_torque_Nm)
    assert law.viscous_damping_Nms_per_rad == 0 and law.static_torque_Nm == tc
    vd = getattr(law, "vibration_velocity_rad_s", 0.0)
    s = np.geomspace(max(vd, 1e-7), 1e3, 3001)
    rng = np.random.default_rng(5)
    for _ in range(12):
        a, b = rng.uniform(0, 2 * math.pi, 2)
        u = np.array([math.cos(a), math.sin(a)])
        z = rng.uniform(0, 1) * tc / s0 * np.array([math.cos(b), math.sin(b)])
        T = np.array([e.torque3(*(x * u), *z, *e.zdot3(*(x * u), *z, p), 0.0, 0.0, p) for x in s])
        Tu = T @ u
        assert np.all(np.diff(Tu) >= -1e-12 * tc)
        zu = s0 * (z @ u)
        np.testing.assert_allclose(Tu, zu + s1 * v1 * s / (v1 + s) * (1 - zu / tc), rtol=1e-12, atol=1e-9 * tc)
    v = np.geomspace(1e-7, 1e3, 2001)
    assert law.passive_at(v).all()
