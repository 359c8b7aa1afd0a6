"""The exponential (ETDRK4) sine dwell of taos.planar._expstep against independent references.

* phi-functions against their recurrences phi_{k+1}(X) = X^-1 (phi_k(X) - I / k!) (a different
  formula from the augmented exponential the module uses);
* step refinement against the exact solution of the linear block (friction off, no
  quantiser: x = orbit + e^{At} (x0 - orbit(0)), from the complex steady orbit), fourth order;
* the exact staircase of a quantised command against the same exact solution summed over the
  quantiser's steps (closed form per constant piece);
* with LuGre friction, the limits and the 12-bit avionics: refinement against the fine RK4
  reference (dt = 2.5e-5 s), and the physics-chosen step at least as accurate as the RK4 kernel
  at its default step 2e-4 s;
* the parallel batch bit for bit equal to each dwell alone (serial), on one and two threads;
* gain and phase of settled exponential dwells against long-settled RK4 dwells (4 s here).
"""

from __future__ import annotations

import math

import numba
import numpy as np
import pytest
from scipy.linalg import expm

from taos.linear import gain_db
from taos.model import load_model
from taos.planar import _expplan as P
from taos.planar import _expstep as X
from taos.planar import dynamics as _ig
from taos.planar.freqresp import sine_dwell_points
from taos.planar.simplex import simplex_plant
from taos.planar.simulate import kernel_args

from .conftest import MODELS

DEG = math.pi / 180


@pytest.fixture(scope="module")
def flight():
    m = load_model(MODELS / "rs25_flight.toml", friction="lugre")
    p = simplex_plant(m)
    o = p.ss.output_index
    Cy = np.ascontiguousarray(p.ss.C[[o("x_p_m"), o("theta_rad")]])
    return m, kernel_args(p, m), Cy


def _exp_run(args, Cy, fid, fp, avp, amp, npc, dt, n_steps, every=1):
    """Engine angle [rad] every ``every`` ETDRK4 steps from rest (r = amp sin(2 pi k / npc))."""
    A, bc = args.A, args.bc
    co = X.etd_coefficients(A, dt)
    G, D = X.command_table(A, bc, 0.5 * dt, X.table_nodes(A, 0.5 * dt))
    x = np.zeros(A.shape[0])
    z = 0.0
    out = np.zeros((Cy.shape[0], 3))
    th = [Cy[1] @ x]
    for k in range(0, n_steps, every):
        z, st, _ = X.sine_steps_exp(*args, Cy, fid, fp, avp, *co, G, D, 0, amp, npc, dt, x, z, k, every, False, out)
        assert st < 0
        th.append(Cy[1] @ x)
    return np.array(th)


def _rk4_run(args, Cy, fid, fp, avp, amp, npc, dt, n_steps, every):
    """The same with the fixed-step RK4 kernel on the sampled sine
    (taos.planar.dynamics.integrate_samples; linear interpolation between samples, 1e-8 of the
    amplitude at the reference step)."""
    nr = args.Br.shape[1]
    k = np.arange(n_steps + 1)
    r = np.ascontiguousarray(np.repeat((amp * np.sin(2 * math.pi * k / npc))[:, None], nr, axis=1))
    nrec = n_steps // every + 1
    y = np.empty((nrec, Cy.shape[0]))
    aux = np.empty((nrec, _ig.N_AUX))
    st = _ig.integrate_samples(*args, Cy, fid, fp, avp, np.zeros(args.A.shape[0]), 0.0, r, dt, every, y, aux)
    assert st < 0
    return y[:, 1]


def test_phi_functions_match_their_recurrences(flight):
    _, args, _ = flight
    A = args.A
    for h in (1e-4, 3e-3, 1e-2):
        E, p1, p2, p3 = X.phi_functions(A, h)
        Xh = h * A
        Xi = np.linalg.inv(Xh)
        I = np.eye(A.shape[0])
        assert np.allclose(E, expm(Xh), rtol=1e-10, atol=1e-12 * np.abs(E).max())
        for lo, hi, k in ((E, p1, 1.0), (p1, p2, 1.0), (p2, p3, 2.0)):
            ref = Xi @ (lo - I / k)
            assert np.max(np.abs(hi - ref)) <= 1e-9 * np.max(np.abs(ref))


def _engine_exact(args, Cy, amp, f, ts):
    """Exact engine angle [rad] at times ``ts`` of the linear block driven by b_c u(t), u = amp
    sin(2 pi f t), from rest: the steady orbit minus the free response that cancels its initial
    state, expm(A t) x_orbit(0)."""
    A, bc = args.A, args.bc
    Xc = P.orbit(A, bc, amp, f)
    x0o = np.imag(Xc)
    return np.array([Cy[1] @ (np.imag(Xc * np.exp(2j * math.pi * f * t)) - expm(A * t) @ x0o) for t in ts])


def test_linear_block_fourth_order_against_exact_solution(flight):
    """Friction off, no quantiser, no limits: ETDRK4 converges to the exact solution at
    fourth order (error ratio ~16 per halving); the linear block itself is exact, so the
    error is the sine command's quadrature only."""
    m, args, Cy = flight
    args = args._replace(lim=np.zeros(0))
    none = load_model(MODELS / "rs25_flight.toml", friction="none")
    fid, fp = none.friction.entry.rates, none.friction.pack()
    avp = np.zeros(4)
    amp, f = 0.5 * DEG, 2.0
    T = 1.0
    errs = []
    for npc in (16, 32, 64, 128):
        dt = 1.0 / (f * npc)
        n = int(round(T / dt))
        th = _exp_run(args, Cy, fid, fp, avp, amp, npc, dt, n, every=n // 4)
        ex = _engine_exact(args, Cy, amp, f, np.arange(5) * (n // 4) * dt)
        errs.append(np.max(np.abs(th - ex)))
    errs = np.array(errs)
    ratios = errs[:-1] / errs[1:]
    # measured ratios 16.5, 16.1, 16.0; the error at 128 steps a cycle 7.7e-9 of the amplitude
    assert np.all(ratios > 14) and np.all(ratios < 19), (errs, ratios)
    assert errs[-1] < 3e-8 * amp


def test_quantised_command_is_exact_in_the_linear_block(flight):
    """12-bit avionics, friction and limits off: the staircase's response is exact (crossing
    times and the tabulated command response), so a coarse step (8 steps a quarter cycle, far
    too few for the sine's quadrature) matches a 4x finer one to the table's interpolation
    error, and both match a fine RK4 run to its own time-discretisation error."""
    m, args, Cy = flight
    args = args._replace(lim=np.zeros(0))
    none = load_model(MODELS / "rs25_flight.toml", friction="none")
    fid, fp = none.friction.entry.rates, none.friction.pack()
    avp = m.avionics.pack()
    amp, f = 0.02 * DEG, 1.0
    npc = 32
    th1 = _exp_run(args, Cy, fid, fp, avp, amp, npc, 1 / (f * npc), 2 * npc, every=npc // 4)
    th4 = _exp_run(args, Cy, fid, fp, avp, amp, 4 * npc, 1 / (4 * f * npc), 8 * npc, every=npc)
    scale = np.max(np.abs(th4))
    assert np.max(np.abs(th1 - th4)) < 1e-10 * scale   # measured 2.6e-12
    ref = _rk4_run(args, Cy, fid, fp, avp, amp, 1280 * npc, 1 / (1280 * f * npc), 2 * 1280 * npc, 1280 * npc // 4)
    # RK4 at dt = 2.4e-5 s samples the staircase's steps at its stage times: measured 3.3e-5 of
    # full scale
    assert np.max(np.abs(th1 - ref)) < 1e-4 * scale


def test_lugre_refinement_and_default_step_accuracy(flight):
    """LuGre, 12-bit avionics, the limits: the ETDRK4 error against the fine RK4 reference
    (dt = 2.5e-5 s) falls as the step is refined, and at the step the physics chooses it is no
    larger than the RK4 kernel's at its default 2e-4 s (issue 28: accuracy at least as good)."""
    m, args, Cy = flight
    fid, fp, avp = m.friction.entry.rates, m.friction.pack(), m.avionics.pack()
    amp, f = 0.1 * DEG, 1.0
    h, why = P.dwell_step_s(args, m, amp, f, 2e-4)
    npc0 = P.steps_per_cycle(h, f, 64)
    ncyc = 2
    ref_npc = 40000
    ref = _rk4_run(args, Cy, fid, fp, avp, amp, ref_npc, 1 / (f * ref_npc), ncyc * ref_npc, ref_npc // 4)
    rk = _rk4_run(args, Cy, fid, fp, avp, amp, 5000, 1 / (f * 5000), ncyc * 5000, 5000 // 4)
    e_rk4 = np.max(np.abs(rk - ref))
    errs = []
    for npc in (npc0 // 4, npc0 // 2, npc0, 2 * npc0):
        npc = 4 * (npc // 4)
        th = _exp_run(args, Cy, fid, fp, avp, amp, npc, 1 / (f * npc), ncyc * npc, npc // 4)
        errs.append(np.max(np.abs(th - ref)))
    # measured (deg): 1.0e-4, 7.4e-6, 7.9e-7, 3.1e-7 at 24, 48, 100 (chosen: h = 0.01 s, the
    # sampling bound), 200 steps a cycle; RK4 at 2e-4 s 1.13e-6
    assert errs[2] <= e_rk4, (errs, e_rk4, h, why)
    assert errs[0] > 50 * errs[2] and errs[1] > 4 * errs[2]


def test_parallel_batch_is_bit_identical_to_serial(flight):
    m, _, _ = flight
    amps = np.array([0.02, 0.1, 0.5, 1.0, 0.05, 0.3]) * DEG
    freqs = np.array([0.3, 1.0, 2.0, 7.0, 12.0, 4.0])
    nt = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        one = [sine_dwell_points(m, amps[i:i + 1], freqs[i:i + 1], settle_s=1.0) for i in range(amps.size)]
        numba.set_num_threads(min(2, numba.config.NUMBA_NUM_THREADS))
        batch = sine_dwell_points(m, amps, freqs, settle_s=1.0)
    finally:
        numba.set_num_threads(nt)
    for i, o in enumerate(one):
        assert o.engine[0] == batch.engine[i] and o.piston[0] == batch.piston[i]


def test_settled_dwells_against_long_settled_rk4(flight):
    """Gain and phase of the default (settled, exponential) dwell within what the default RK4
    dwell achieves against 60 s of RK4 settling (bench_maps: 0.028 dB / 0.08 deg)."""
    m, _, _ = flight
    amps = np.array([0.02, 0.1, 0.4, 1.0]) * DEG
    freqs = np.array([0.5, 2.0, 5.0, 12.0])
    e = sine_dwell_points(m, amps, freqs)
    ref = sine_dwell_points(m, amps, freqs, settle_s=60.0, measure_cycles=1, integrator="rk4")
    for h, r in ((e.engine, ref.engine), (e.piston, ref.piston)):
        assert np.max(np.abs(gain_db(h) - gain_db(r))) < 0.03
        assert np.max(np.abs(np.degrees(np.angle(h / r)))) < 0.1


@pytest.mark.parametrize("kl_lbf_in", [115000, 205000])
def test_switching_law_step_is_its_stick_band_rate_not_its_jump(kl_lbf_in):
    """Karnopp's switching law: inside the stick band |w| < v_s, T_f = t_app + c_stick w (a rate
    c_stick / J on the planar joint: M = [[T_w c_w.b_f + T_a c_a.b_f, 0], [0, 0]]), outside it
    T_c sign(w) (no rate); at |w| = v_s the torque jumps, which the law's own explicit-step rule
    covers. So every dwell's friction step is KAPPA / |c_stick c_w.b_f + c_a.b_f|, on the paper's
    soft and stiff structures alike, including orbit samples within a quotient's stencil of the
    band's edge: a central quotient across the jump had made the 0.037-deg 0.5-Hz dwell's step
    3.3e-7 s on the stiff structure (six million steps a cycle, 80 % of the LCO map's work)."""
    from taos.model import Structure

    m = load_model(MODELS / "rs25_flight.toml", friction="coulomb-switching")
    m = m.replace(structure=Structure(kl_lbf_in * 4.4482216152605 / 0.0254))
    args = kernel_args(simplex_plant(m), m)
    cw, ca, bf = args.cw, args.ca, args.bf
    law = m.friction
    rate = abs(law.stick_damping_Nms_per_rad * float(cw @ bf) + float(ca @ bf))
    amps = np.logspace(np.log10(0.01), 0.0, 8) * DEG          # the LCO tests' map (tests/test_lco.py)
    freqs = np.logspace(np.log10(0.06), np.log10(0.5), 6)
    steps = np.array([P.dwell_step_s(args, m, a, f, 2e-4)[0] for a in amps for f in freqs])
    assert np.allclose(steps, P.KAPPA / rate, rtol=1e-9, atol=0)
    # samples a fraction of the quotient's stencil (1e-7 rad/s) inside and outside the edge
    fid, fp, vs = law.entry.rates, law.pack(), law.stick_velocity_rad_s
    for w, want in ((vs - 2e-8, rate), (-vs + 3e-8, rate), (vs + 2e-8, 0.0), (-vs - 6e-8, 0.0)):
        got = P._friction_rate(fid, fp, np.array([w]), np.zeros(1), np.zeros(1), float(cw @ bf), float(ca @ bf))
        assert got == pytest.approx(want, rel=1e-6, abs=1e-9 * rate)
