"""The friction registry: a law added through the registry alone (inside the test) runs in the
planar simulation, the 3-D simulation, the describing-function map and the fit; an
unregistered id stops with a clear InputError.

The toy law is viscous plus smooth Coulomb friction, T = c v + T_c v / sqrt(v^2 + v_eps^2)
(memoryless). Physics references: with T_c = 0 it is a linear damper c at the gimbal, so its
sine-dwell response equals the linear simplex model with the loop closed through c (a
state-space closed loop, A + b_T c c_w, not the surrogate's phasor algebra); with c = 0 it is
exactly the built-in ``coulomb-smooth`` law, so the 3-D run must reproduce that law's run;
in the 3-D run every recorded bearing torque must equal the law at the recorded slip rate.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from pathlib import Path
from typing import ClassVar

import numpy as np
import pytest
from numba import njit

from taos import friction
from taos.errors import InputError
from taos.flight.describing import describing_function_map, rigid_engine_response, rigid_limit_model
from taos.friction import _kernels as K
from taos.friction import coeff_bearing_step
from taos.identify.fit import fit_frequency_response
from taos.identify.surrogate import build_surrogate, check_free, solve_implicit, PARAMETERS
from taos.model import load_model
from taos.profiles import SineDwell
from taos.planar.simplex import simplex_state_space
from taos.planar.simulate import simulate
from taos.taos3d import load_taos_model, simulate_taos

from .conftest import MODELS

DEG = math.pi / 180
TOY = "toy-viscous-coulomb"


# -- the toy law: everything about it, written here ------------------------------------------------
@dataclass(frozen=True)
class ViscousCoulomb(friction.FrictionLaw):
    """T = c v + T_c v / sqrt(v^2 + v_eps^2): viscous damping c [N m s/rad] plus smooth Coulomb."""

    name: ClassVar[str] = TOY

    viscous_damping_Nms_per_rad: float = friction.param(0.0, "viscous_damping", "rotational_damping",
                                                        K.SLOT_SIGMA2, torque_like=True)
    regularization_velocity_rad_s: float = friction.param(1e-3, "regularization_velocity", "angular_velocity",
                                                          K.SLOT_VEPS)

    def steady_state(self, v):
        v = np.asarray(v, float)
        e = self.regularization_velocity_rad_s
        return self.viscous_damping_Nms_per_rad * v + self.coulomb_torque_Nm * v / np.sqrt(v * v + e * e)

    def describing_function(self, rate_amplitude, omega_rad_s=None):
        return complex(self.viscous_damping_Nms_per_rad + 4 * self.coulomb_torque_Nm / (math.pi * rate_amplitude))

    def check_step(self, inertia_kgm2, dt_s, source, section="friction"):
        slope = self.viscous_damping_Nms_per_rad + self.coulomb_torque_Nm / self.regularization_velocity_rad_s
        if dt_s * slope / inertia_kgm2 > 2.0:
            raise InputError(source, f"{section}.viscous_damping", "dt (c + T_c / v_eps) / J below 2")


def toy_rates(v, z, t_app, p):
    e = p[K.SLOT_VEPS]
    return 0.0, p[K.SLOT_SIGMA2] * v + p[K.SLOT_TC] * v / math.sqrt(v * v + e * e)


def toy_zdot3(w0, w1, z0, z1, p):
    return 0.0, 0.0


def toy_torque3(w0, w1, z0, z1, dz0, dz1, t0, t1, p):
    s = math.sqrt(w0 * w0 + w1 * w1)
    e = p[K.SLOT_VEPS]
    a = p[K.SLOT_SIGMA2] + p[K.SLOT_TC] / math.sqrt(s * s + e * e)
    return a * w0, a * w1


@njit
def _toy_coeffs(s, p, dt, kappa):  # T = a(|w|) w (memoryless)
    e = p[K.SLOT_VEPS]
    return p[K.SLOT_SIGMA2] + p[K.SLOT_TC] / math.sqrt(s * s + e * e), 0.0


def toy_bearing(p, Kc, d0, d1, z0, z1, dt, s0):
    return coeff_bearing_step(_toy_coeffs, _toy_coeffs, False, 1.0, p, Kc, d0, d1, z0, z1, dt, s0)


def toy_fit_df(law, X, w):
    return law.viscous_damping_Nms_per_rad + 4 * law.coulomb_torque_Nm / (math.pi * w * X), 0.0


@pytest.fixture(scope="module")
def toy():
    entry = friction.register(friction.FrictionLawEntry(
        TOY, ViscousCoulomb, toy_rates, toy_zdot3, toy_torque3, toy_bearing,
        fit_describing_function=toy_fit_df, fit_parameters=("coulomb_torque", "viscous_damping")))
    yield entry
    friction.unregister(TOY)


@pytest.fixture(scope="module")
def flight():
    return load_model(MODELS / "rs25_flight.toml")


def damping(model, zeta=0.2):
    """c [N m s/rad] giving damping ratio ``zeta`` on the engine-on-load-path mode."""
    J = model.engine.inertia_pitch_kgm2
    R = model.actuator.moment_arm_m
    wl = math.sqrt((model.structure.load_stiffness_N_per_m * R * R + model.engine.rotational_stiffness_Nm_per_rad) / J)
    return 2 * zeta * J * wl


def linear_with_damper(model, c, f):
    """theta / theta_c and x_p / theta_c [m/rad] of the linear simplex model with the loop
    closed through a gimbal damper T_f = c omega (state-space closed loop)."""
    ss = simplex_state_space(model, "pitch")
    ic, it = ss.input_index("command_rad"), ss.input_index("friction_torque_Nm")
    iw, ith, ix = (ss.output_index(k) for k in ("omega_rad_s", "theta_rad", "x_p_m"))
    assert np.all(ss.D[iw] == 0)
    A = ss.A + c * np.outer(ss.B[:, it], ss.C[iw])
    out = []
    for fk in f:
        x = np.linalg.solve(2j * math.pi * fk * np.eye(A.shape[0]) - A, ss.B[:, ic])
        out.append((ss.C[ith] @ x + ss.D[ith, ic], ss.C[ix] @ x + ss.D[ix, ic]))
    return np.array(out).T


# -- the acceptance test -----------------------------------------------------------------------------------
def test_toy_law_is_found_by_id_everywhere(toy, flight):
    assert TOY in friction.ids() and friction.get(TOY) is toy
    m = flight.with_friction(TOY)  # the model-file path: [friction] table + --friction override
    assert isinstance(m.friction, ViscousCoulomb) and m.friction.entry is toy
    law = ViscousCoulomb(coulomb_torque_Nm=100.0, viscous_damping_Nms_per_rad=7.0)
    v = np.array([-0.3, -1e-3, 2e-4, 0.05])
    np.testing.assert_allclose([law(x) for x in v], law.steady_state(v), rtol=1e-13)
    tq, _ = law.response(v, 1e-3)
    np.testing.assert_allclose(tq, law.steady_state(v), rtol=1e-13)


def test_toy_viscous_law_dwell_equals_linear_model_with_that_damping(toy, flight):
    """Planar simulation (the DF map's sine dwell and taos.planar.simulate) of the pure viscous toy law
    (T_c = 0) equals the linear model with the damper in the loop."""
    c = damping(flight)
    # the ideal valve: the square-root valve law is a nonlinearity of its own, not the law's
    m = flight.replace(friction=ViscousCoulomb(coulomb_torque_Nm=0.0, viscous_damping_Nms_per_rad=c),
                       avionics=flight.avionics.ideal(),
                       actuator=dataclasses.replace(flight.actuator, pressure_limited=False))
    f = np.array([0.5, 2.0, 5.0, 8.0])
    dfm = describing_function_map(m, [0.2 * DEG], f)
    eng, pis = linear_with_damper(m, c, f)
    R = m.actuator.moment_arm_m
    np.testing.assert_allclose(dfm.engine[0], eng, rtol=2e-4)
    np.testing.assert_allclose(dfm.piston[0], pis / R, rtol=2e-4)
    # the damper visibly changes the response (not a no-op law)
    undamped, _ = linear_with_damper(m, 0.0, f)
    assert np.max(np.abs(eng / undamped - 1)) > 0.05
    # time domain: the steady dwell's engine amplitude at 2 Hz
    th = simulate(m, SineDwell(0.2 * DEG, 2.0, 20), dt_s=2e-4, record_every=1, duration_s=10.0)
    last = th.t_s >= 9.0  # two whole cycles after ~60 time constants of the slowest mode
    amp = 0.5 * (th.engine_rad[0, last].max() - th.engine_rad[0, last].min())
    assert amp == pytest.approx(0.2 * DEG * abs(eng[1]), rel=2e-3)


def test_toy_law_describing_function_in_the_rigid_loop(toy, flight):
    """Viscous + Coulomb in the rigid-load limit: the DF map (sine dwell) equals the analytic
    friction-in-loop response from the toy's describing function c + 4 T_c / (pi V) within 3 %
    (the first-harmonic approximation: as in tests/test_describing.py's relay case, the servo's
    dynamic pressure feedback passes the friction torque's odd harmonics to the engine angle);
    ideal valve (the square-root valve law is a nonlinearity of its own against a stiff load)."""
    c = 0.2 * damping(flight)
    law = ViscousCoulomb(coulomb_torque_Nm=flight.friction.coulomb_torque_Nm, viscous_damping_Nms_per_rad=c,
                         regularization_velocity_rad_s=1e-3)
    m = rigid_limit_model(flight.replace(friction=law, actuator=dataclasses.replace(flight.actuator, pressure_limited=False)), 100.0)
    f = np.array([2.0, 5.0, 8.0])
    dfm = describing_function_map(m, [0.4 * DEG], f)
    for j, fj in enumerate(f):
        ana = rigid_engine_response(m, 0.4 * DEG, fj)
        assert abs(dfm.engine[0, j] / ana - 1) < 0.03, (fj, dfm.engine[0, j], ana)


def test_toy_law_runs_in_the_3d_model(toy):
    """3-D run (taos.taos3d.simulate_taos): with c = 0 the toy reproduces the built-in
    coulomb-smooth run; with c > 0 every bearing torque is the law at the slip rate."""
    tm = load_taos_model(MODELS / "rs25_hotfire.toml", friction="coulomb-smooth")
    base = tm.base.friction
    prof = SineDwell(0.1 * DEG, 3.0, 0.3)
    ref = simulate_taos(tm, prof, record_every=1, duration_s=0.3)
    same = ViscousCoulomb(coulomb_torque_Nm=base.coulomb_torque_Nm,
                          regularization_velocity_rad_s=base.regularization_velocity_rad_s)
    run = simulate_taos(tm.replace(base=tm.base.replace(friction=same)), prof, record_every=1, duration_s=0.3)
    for k in ("engine_rad", "piston_m", "friction_torque_Nm"):
        a, b = getattr(ref, k), getattr(run, k)
        assert np.max(np.abs(a - b)) <= 1e-12 * np.max(np.abs(a)), k
    c = damping(tm.base)
    law = dataclasses.replace(same, viscous_damping_Nms_per_rad=c)
    tmc = tm.replace(base=tm.base.replace(friction=law))
    run = simulate_taos(tmc, prof, record_every=1, duration_s=0.3)
    dt = run.t_s[1] - run.t_s[0]
    ph = run.extra["bearing_slip_rad"]
    ph = np.hstack([ph[:, :1], ph])  # at rest before the start: phi_{-1} = phi_0
    w = (3 * ph[:, 2:] - 4 * ph[:, 1:-1] + ph[:, :-2]) / (2 * dt)  # the BDF2 slip rate of each step
    T = run.friction_torque_Nm[:, 1:]
    scaled = law.scaled(tmc.friction_scale)
    s = np.hypot(w[0], w[1])
    a = scaled.viscous_damping_Nms_per_rad + scaled.coulomb_torque_Nm / np.sqrt(
        s * s + scaled.regularization_velocity_rad_s ** 2)
    np.testing.assert_allclose(T, a * w, rtol=1e-6, atol=1e-9 * np.abs(T).max())
    assert np.abs(T).max() > 0.1 * scaled.coulomb_torque_Nm
    assert np.max(np.abs(run.engine_rad - ref.engine_rad)) > 0  # the damper acts


def test_toy_law_fit_surrogate_and_fit(toy, flight):
    """Fit surrogate: for the pure viscous toy its describing function is exact, so the
    surrogate equals the linear model with the damper; the fit recovers c from sine-dwell data."""
    from taos.planar.freqresp import sine_dwell_grid
    from taos.identify.estimation import MeasuredResponse

    c = damping(flight)
    m = flight.replace(friction=ViscousCoulomb(coulomb_torque_Nm=0.0, viscous_damping_Nms_per_rad=c),
                       avionics=flight.avionics.ideal())
    params = check_free(m, ["viscous_damping"])
    with pytest.raises(InputError, match="bristle_stiffness"):
        check_free(m, ["bristle_stiffness"])
    f = np.array([1.0, 3.0, 6.0, 9.0])
    sur = build_surrogate(m, params, ["pitch"] * f.size, f, np.full(f.size, 0.3 * DEG))
    assert sur.family == "implicit"
    s = np.ones(1)
    u = solve_implicit(sur, s)
    hx_re, hx_im, he_re, he_im, g = (np.asarray(v).ravel() for v in sur.fn(s, u))
    eng, pis = linear_with_damper(m, c, f)
    np.testing.assert_allclose(he_re + 1j * he_im, eng, rtol=1e-9)
    np.testing.assert_allclose(hx_re + 1j * hx_im, pis, rtol=1e-9)
    # fit c from the model's own sine dwells, starting 2x off
    p, e = sine_dwell_grid(m, [0.3 * DEG], f, "pitch")
    n = f.size
    data = [MeasuredResponse("pitch", f, np.full(n, 0.3 * DEG), p[0] * m.actuator.moment_arm_m, e[0],
                             np.ones(n), np.ones(n), np.full(n, 1e-3), np.full(n, 1e-3))]
    r = fit_frequency_response(m, data, ["viscous_damping"], start={"viscous_damping": 2 * c}, starts=1)
    assert r.values[0] == pytest.approx(c, rel=1e-3)
    assert PARAMETERS["viscous_damping"].get(m) == c


def test_registered_step_rule_is_asked(toy, flight):
    c = 1e3 * damping(flight)  # dt c / J far above 2
    m = flight.replace(friction=ViscousCoulomb(coulomb_torque_Nm=0.0, viscous_damping_Nms_per_rad=c))
    with pytest.raises(InputError, match="friction.viscous_damping"):
        simulate(m, SineDwell(0.2 * DEG, 2.0, 1), duration_s=0.1)


def test_unregistered_id_stops_with_a_clear_error(flight):
    with pytest.raises(InputError) as err:
        friction.get("stiction-magic")
    msg = str(err.value)
    assert "'stiction-magic'" in msg and all(i in msg for i in ("none", "lugre", "modified-lugre", "dahl"))
    with pytest.raises(InputError, match="--friction.*stiction-magic"):
        load_model(MODELS / "rs25_flight.toml", friction="stiction-magic")
    with pytest.raises(InputError, match="stiction-magic"):
        flight.with_friction("stiction-magic")


def test_unregister_removes_a_run_time_law_and_keeps_builtins(flight):
    @dataclass(frozen=True)
    class Temp(ViscousCoulomb):
        name: ClassVar[str] = "temp-law"

    friction.register(friction.FrictionLawEntry("temp-law", Temp, toy_rates, toy_zdot3, toy_torque3,
                                                toy_bearing))
    m = flight.with_friction("temp-law")
    friction.unregister("temp-law")
    with pytest.raises(InputError, match="temp-law"):
        m.friction.entry
    with pytest.raises(InputError):
        friction.unregister("lugre")
    with pytest.raises(InputError):  # a built-in id cannot be taken over
        friction.register(dataclasses.replace(friction.get("lugre")), replace_existing=True)


@pytest.mark.parametrize("bad", [{"a": 1}, 3, ["dahl"]])
def test_a_law_name_that_is_not_a_string_is_bad_input(bad):
    """``[friction] model = {a = 1}`` (a table, a number, a list where a law id belongs) is one
    InputError naming friction.model, not an internal TypeError (found by the model-file fuzzing)."""
    from taos.friction import registry

    with pytest.raises(InputError, match="friction.model"):
        registry.params_of(bad, "m.toml")


LAZY_PROBE = """
import json, sys
from taos import friction
from taos.friction import registry
before = [m for m in sys.modules if m.startswith("taos.friction._law_")]
friction.get("dahl")
one = sorted(m for m in sys.modules if m.startswith("taos.friction._law_"))
ids = list(friction.ids())
try:   # a run-time law cannot take a built-in id, whose kernels are not loaded
    registry.register(registry.FrictionLawEntry("lugre", friction.LuGre, *[None] * 4))
    taken = False
except Exception as e:
    taken = "duplicate" in str(e)
unloaded = "taos.friction._law_lugre" not in sys.modules
entries = {i: e.id for i, e in friction.LAWS.items()}
print(json.dumps({"before": before, "one": one, "ids": ids, "taken": taken, "unloaded": unloaded,
                  "entries": entries, "all": sorted(m for m in sys.modules if m.startswith("taos.friction._law_"))}))
"""


def test_a_law_lookup_loads_that_laws_kernels_only():
    """Built-in laws register one at a time (their kernels' modules imported on first lookup):
    ``get('dahl')`` loads the Dahl kernels only, the ids stay complete and in order, a built-in
    id stays reserved before its kernels are loaded, and iterating ``LAWS`` loads every law."""
    import json
    import subprocess
    import sys

    r = subprocess.run([sys.executable, "-c", LAZY_PROBE], capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    d = json.loads(r.stdout.strip().splitlines()[-1])
    assert d["before"] == [] and d["one"] == ["taos.friction._law_dahl"]
    assert d["ids"][:6] == ["none", "coulomb-switching", "coulomb-smooth", "dahl", "lugre", "modified-lugre"]
    assert d["taken"] and d["unloaded"]
    assert all(d["entries"][i] == i for i in d["ids"][:6])
    assert set(d["all"]) == {f"taos.friction.{p.stem}" for p in Path(friction.__file__).parent.glob("_law_*.py")}
