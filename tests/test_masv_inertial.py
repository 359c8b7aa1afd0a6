"""MASV couplings checked against hand calculations on one-mode structures: the gimbals'
rotational coupling (K_n between the engine and the structure's rotation at the gimbal), the
engines' centre-of-mass offset (tail wags dog / dog wags tail) and the TVSE loop break (paper
sec. 3.3). Each reference is a 2-DOF system written out here from m_e, l_e, J_n, K_n, K_L R^2
and the mode shape, not from the MASV assembly."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest

from masv import analysis as an
from masv.config import ActuatorSpec, EngineSpec, make_config
from masv.structure import NODE_NAMES, ModalStructure, rigid_structure
from masv.system import build_system
from taos.model import Structure, load_model
from taos.planar.simplex import simplex_state_space

ROOT = Path(__file__).resolve().parents[1]
L_E = 1.5          # gimbal -> engine c.g. [m] (the shipped files' [geometry] engine_cg)


@pytest.fixture(scope="module")
def hotfire():
    m = load_model(ROOT / "models" / "rs25_hotfire.toml")   # MASV's structural damping is modal:
    return m.replace(structure=dataclasses.replace(m.structure, load_damping_ratio=0.0))  # no load-path damper


def one_mode(freq_hz, dof, value, zeta=0.0, node="gimbal_1"):
    """One mode with a single non-zero shape entry ``value`` at (node, dof)."""
    phi = np.zeros((1, 12, 6))
    phi[0, NODE_NAMES.index(node), dof] = value
    return ModalStructure(np.array([float(freq_hz)]), np.array([float(zeta)]), NODE_NAMES, np.zeros((12, 3)), phi)


def pitch_engine(model, structure, cg=(-L_E, 0.0, 0.0)):
    """One engine, its pitch actuator: line of action -x, rotation axis +y, c.g. at ``cg``
    (vehicle frame): a theta about +y moves the c.g. along +y x cg = +z by l_e theta."""
    e = EngineSpec("engine_1", model, "gimbal_1", cg)
    a = ActuatorSpec("actuator_1_pitch", "engine_1", "pitch", "actuator_1_pitch", (-1.0, 0.0, 0.0),
                     (0.0, 1.0, 0.0))
    return build_system(make_config([e], [a], structure))


def quadratic_roots(a, b, c):
    d = math.sqrt(b * b - 4 * a * c)
    return sorted([(-b - d) / (2 * a), (-b + d) / (2 * a)])


def two_dof_frequencies_hz(M, K):
    """Natural frequencies of the undamped 2-DOF system (M, K) from det(K - lam M) = 0."""
    a = M[0][0] * M[1][1] - M[0][1] ** 2
    b = -(K[0][0] * M[1][1] + K[1][1] * M[0][0] - 2 * K[0][1] * M[0][1])
    c = K[0][0] * K[1][1] - K[0][1] ** 2
    return [math.sqrt(lam) / (2 * math.pi) for lam in quadratic_roots(a, b, c)]


def notch_near(system, f0, span=0.3):
    """Frequency [Hz] of the minimum of |x_p / theta_c| near f0 (dense grid + bounded search)."""
    import scipy.optimize
    f = np.linspace(f0 * (1 - span), f0 * (1 + span), 4001)
    g = np.abs(system.frf(f)[0][:, 0, 0])
    i = int(np.argmin(g))
    r = scipy.optimize.minimize_scalar(lambda x: abs(system.frf([x])[0][0, 0, 0]),
                                       bounds=(f[max(i - 1, 0)], f[min(i + 1, f.size - 1)]), method="bounded",
                                       options={"xatol": 1e-10})
    return float(r.x)


# -- the gimbal's rotational coupling (issue 11: dropping it passed every test) ------------------
def test_rotational_mode_at_the_gimbal_shifts_the_piston_notch(hotfire):
    """A structure mode that only rotates the gimbal about the pitch axis (shape phi_r
    [rad/sqrt(kg)], w_m) couples to the engine only through K_n (theta - r). The command ->
    piston notch is where the piston-blocked load has a resonance (its impedance is infinite),
    here the 2-DOF system [theta, q]:
        M = diag(J, 1),  K = [[K_L R^2 + K_n, -K_n phi_r], [-K_n phi_r, w_m^2 + K_n phi_r^2]]."""
    Kn = 6.0e6        # a stiff feedline/gravity spring (about 20 % of K_L R^2) makes the coupling large
    model = hotfire.replace(engine=dataclasses.replace(hotfire.engine, rotational_stiffness_Nm_per_rad=Kn))
    J = model.engine.inertia_pitch_kgm2
    KLR2 = model.structure.load_stiffness_N_per_m * model.actuator.moment_arm_m ** 2
    f_l = math.sqrt((KLR2 + Kn) / J) / (2 * math.pi)            # simplex notch (paper eq. 1)
    f_m = 1.05 * f_l                                             # the mode near the notch
    phi_r = 2 * math.pi * f_m / math.sqrt(Kn)                    # structure rotational stiffness = K_n
    w_m = 2 * math.pi * f_m
    hand = two_dof_frequencies_hz([[J, 0.0], [0.0, 1.0]],
                                  [[KLR2 + Kn, -Kn * phi_r], [-Kn * phi_r, w_m ** 2 + Kn * phi_r ** 2]])
    s = pitch_engine(model, one_mode(f_m, 4, phi_r), cg=(0.0, 0.0, 0.0))   # dof 4: rotation about y
    found = [notch_near(s, fh, 0.02) for fh in hand]
    for fh, fn in zip(hand, found):
        assert fn == pytest.approx(fh, rel=2e-4)
    assert abs(hand[0] / f_l - 1) > 0.03 and abs(hand[1] / f_l - 1) > 0.03   # far from the simplex notch


def test_quasi_static_rotational_mode_is_a_spring_in_series_with_kn(hotfire):
    """Kept only as static flexibility, the rotational mode is a spring k_r = w_m^2 / phi_r^2 in
    series with K_n: the response is the simplex's with K_n k_r / (K_n + k_r)."""
    Kn = 6.0e6
    model = hotfire.replace(engine=dataclasses.replace(hotfire.engine, rotational_stiffness_Nm_per_rad=Kn))
    kr = 1.5 * Kn
    f_m = 50.0
    st = one_mode(f_m, 4, 2 * math.pi * f_m / math.sqrt(kr), zeta=0.005)
    series = model.replace(engine=dataclasses.replace(model.engine,
                                                      rotational_stiffness_Nm_per_rad=Kn * kr / (Kn + kr)))
    f = np.logspace(-1, 1.5, 100)
    ref = simplex_state_space(series, "pitch").freqresp(f, "command_rad", ["x_p_m", "theta_rad"])
    xp, th = pitch_engine(model, st.truncated(0.0), cg=(0.0, 0.0, 0.0)).frf(f)
    assert np.max(np.abs(xp[:, 0, 0] / ref[:, 0] - 1)) < 1e-9
    assert np.max(np.abs(th[:, 0, 0] / ref[:, 1] - 1)) < 1e-9
    plain = simplex_state_space(model, "pitch").freqresp(f, "command_rad", "x_p_m")
    assert np.max(np.abs(xp[:, 0, 0] / plain - 1)) > 0.05                      # the coupling matters


# -- the engine's c.g. offset: tail wags dog ---------------------------------------------------
def twd_hand_frequencies_hz(m, l, J, Kn, w_m, phi):
    """Engine (theta) on the gimbal of a one-mode structure (q, gimbal translation phi q along
    the direction the c.g. moves): kinetic energy 1/2 (q')^2 + 1/2 m (phi q' + l theta')^2
    + 1/2 (J - m l^2) theta'^2, potential 1/2 w_m^2 q^2 + 1/2 K_n theta^2."""
    return two_dof_frequencies_hz([[1.0 + m * phi ** 2, m * l * phi], [m * l * phi, J]], [[w_m ** 2, 0.0], [0.0, Kn]])


def test_tail_wags_dog_frequencies_of_one_mode_structure(hotfire):
    """With the actuator's load path cut (K_L = 0) the engine hangs on K_n alone, and MASV's
    eigenvalues must contain the hand 2-DOF frequencies of engine + structure mode, where the
    modal force per unit engine angular acceleration is m_e l_e phi."""
    model = hotfire.replace(structure=Structure(0.0))
    m, J, Kn = model.engine.mass_kg, model.engine.inertia_pitch_kgm2, model.engine.rotational_stiffness_Nm_per_rad
    f_m, phi = 3.0, 1.0 / math.sqrt(4000.0)       # a 4,000 kg modal mass moving the gimbal along z
    hand = twd_hand_frequencies_hz(m, L_E, J, Kn, 2 * math.pi * f_m, phi)
    s = pitch_engine(model, one_mode(f_m, 2, phi))
    p = s.state_space().poles()
    for fh in hand:
        k = np.argmin(np.abs(p - 2j * math.pi * fh))
        assert abs(p[k].real) < 1e-9 * abs(p[k])
        assert abs(p[k].imag) / (2 * math.pi) == pytest.approx(fh, rel=1e-10)
    # without the c.g. offset the engine is only a point mass m_e on the mode, and K_n alone
    point = [math.sqrt(Kn / J) / (2 * math.pi), f_m / math.sqrt(1 + m * phi ** 2)]
    assert min(abs(h / q - 1) for h, q in zip(hand, point)) > 0.03
    p0 = pitch_engine(model, one_mode(f_m, 2, phi), cg=(0.0, 0.0, 0.0)).state_space().poles()
    for fq in point:
        assert np.min(np.abs(np.abs(p0.imag) / (2 * math.pi) - fq)) < 1e-9 * fq


def test_engine_mass_already_in_modes_is_not_added_twice(hotfire):
    """With ``engine_mass_in_modes`` the mode's own mass stands for m_e at the gimbal: the
    same physics is a mode of modal mass M_s + m_e in which MASV adds only the rotation."""
    model = hotfire.replace(structure=Structure(0.0))
    m, J, Kn = model.engine.mass_kg, model.engine.inertia_pitch_kgm2, model.engine.rotational_stiffness_Nm_per_rad
    f_m, phi = 3.0, 1.0 / math.sqrt(4000.0)
    hand = twd_hand_frequencies_hz(m, L_E, J, Kn, 2 * math.pi * f_m, phi)
    # the same structure with the engine mass lumped in: modal mass 1 + m phi^2, renormalised
    scale = 1.0 / math.sqrt(1.0 + m * phi ** 2)
    st = dataclasses.replace(one_mode(f_m * scale, 2, phi * scale), engine_mass_in_modes=True)
    p = pitch_engine(model, st).state_space().poles()
    for fh in hand:
        assert np.min(np.abs(np.abs(p.imag) / (2 * math.pi) - fh)) < 1e-9 * fh


# -- the TVSE loop break ----------------------------------------------------------------------
def test_tvse_loop_is_zero_on_a_rigid_structure(hotfire):
    s = pitch_engine(hotfire, rigid_structure())
    (res,) = an.tvse_loops(s, np.logspace(-1, 2, 50))
    assert np.all(res.loop == 0)
    assert math.isinf(res.margin.gain_margin_db) and res.margin.gain_crossover_hz is None


def test_tvse_loop_of_one_mode_structure_against_hand(hotfire):
    """Loop broken at the engine's inertial force on the gimbal (paper sec. 3.3):
        structure  (f -> gimbal accel)  P(s) = s^2 phi^2 / ((1 + m_e phi^2) s^2 + 2 zeta w s + w^2)
        engine     (accel -> f_twd)     G(s) = -m_e^2 l_e^2 s^2 H(s),  H = theta / T_f of the
                                        planar simplex (the gimbal acceleration enters the engine
                                        as a torque -m_e l_e a, like friction)
        L = -G P;  closing the loop gives the tail-wags-dog poles."""
    m = hotfire.engine.mass_kg
    f_m, zeta, phi = 9.0, 0.005, 1.0 / math.sqrt(6000.0)
    s_sys = pitch_engine(hotfire, one_mode(f_m, 2, phi, zeta=zeta))
    f = np.logspace(0, 1.7, 600)
    (res,) = an.tvse_loops(s_sys, f)
    s = 2j * np.pi * f
    w = 2 * math.pi * f_m
    H = simplex_state_space(hotfire, "pitch").freqresp(f, "friction_torque_Nm", "theta_rad")
    P = s ** 2 * phi ** 2 / ((1 + m * phi ** 2) * s ** 2 + 2 * zeta * w * s + w ** 2)
    L = m ** 2 * L_E ** 2 * s ** 2 * H * P
    assert np.max(np.abs(res.loop - L)) < 1e-10 * np.max(np.abs(L))
    # the peak sits at the structure mode carrying the engine mass, its height set by 0.5 % damping
    k = int(np.argmax(np.abs(L)))
    assert res.peak_hz == pytest.approx(f[k]) and res.peak_db == pytest.approx(20 * math.log10(abs(L[k])))
    assert f[k] == pytest.approx(f_m / math.sqrt(1 + m * phi ** 2), rel=0.02)
    ref = an.margins_from_loop("actuator_1_pitch", f, L)
    for key in ("gain_margin_db", "phase_crossover_hz", "phase_margin_deg", "gain_crossover_hz"):
        assert getattr(res.margin, key) == pytest.approx(getattr(ref, key), rel=1e-9)
    # closing the TVSE loop gives the coupled system's poles: 1 + L = 0 at an eigenvalue of MASV
    poles = s_sys.state_space().poles()
    lam = poles[np.argmin(np.abs(poles - 1j * w / math.sqrt(1 + m * phi ** 2)))]
    ss = simplex_state_space(hotfire, "pitch")
    Hs = (ss.C[ss.output_index("theta_rad")] @ np.linalg.solve(lam * np.eye(ss.A.shape[0]) - ss.A,
                                                                 ss.B[:, ss.input_index("friction_torque_Nm")]))
    Ll = m ** 2 * L_E ** 2 * lam ** 2 * Hs * lam ** 2 * phi ** 2 / ((1 + m * phi ** 2) * lam ** 2 + 2 * zeta * w * lam
                                                                   + w ** 2)
    assert abs(1 + Ll) < 1e-6


def test_engine_mass_in_modes_needs_the_mass_at_the_gimbal(hotfire):
    """A mode claiming to hold the engine mass but lumping less than m_e^2 l_e^2 / J_n at the
    gimbal would give the engine's free rotation a negative mass: one-line InputError."""
    from taos.errors import InputError
    m, J = hotfire.engine.mass_kg, hotfire.engine.inertia_pitch_kgm2
    phi = 1.0 / math.sqrt(0.5 * m ** 2 * L_E ** 2 / J)      # modal mass half the needed amount
    st = dataclasses.replace(one_mode(10.0, 2, phi), engine_mass_in_modes=True)
    with pytest.raises(InputError) as e:
        pitch_engine(hotfire, st)
    assert e.value.field == "structure.engine_mass_in_modes" and "\n" not in str(e.value)
