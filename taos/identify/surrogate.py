"""What a fit can change, and the CasADi describing-function surrogate it is fitted through.

Free parameters (:data:`PARAMETERS`, names for ``taos fit --free``): load stiffness, friction
levels, servo gains, engine properties and the avionics gain. Each maps to one field of the
model dataclasses (SI) and one key of the model file (written back with its unit).

Surrogate of the amplitude-dependent sine-dwell response (one point: axis, frequency w,
command amplitude A). The linear simplex block (:func:`taos.planar.simplex.simplex_state_space`,
built with CasADi SX parameters, the one definition of the dynamics) gives, exactly and
differentiably (:func:`taos.linear.freqresp_symbolic`), the four responses from command c and
friction torque T to piston x_p and engine rate omega: G_xc, G_xT, G_wc, G_wT. The command
path is the describing function of the avionics (quantiser and crossover gain, a static map:
its fundamental computed numerically from :class:`taos.planar.avionics.Avionics` itself), times the
free ``avionics_gain`` k: C = k N_av(A) A. The friction element is replaced by the describing
function its registry entry gives the fit (``fit_describing_function``, from engine rate to
torque, T = N Omega; :mod:`taos.friction.registry`). Two loop solutions:

* a relay (the entry gives ``fit_relay_level`` a; Coulomb, both forms: N = a / V,
  a = 4 T_c / pi). The loop Omega = G_wc C + G_wT N Omega gives
  |V - a G_wT| = |G_wc C| with a = 4 T_c / pi, solved in closed form:
  V = a Re G_wT + sqrt(|G_wc C|^2 - a^2 (Im G_wT)^2), and V = 0 (engine held, the load path
  takes the whole piston motion) when that is not positive: smoothed for the NLP.
* any other describing function N(X, w) of the engine angle amplitude X (Dahl with exponent
  1: the exact hysteresis loop, :func:`taos.descfcn.dahl_angle_df`; LuGre/modified LuGre
  through their Dahl core plus sigma_2): the amplitude X solves the implicit loop equation
  ln(w X) + ln|1 - G_wT N| - ln|G_wc C| = 0, which the NLP carries as constraints with
  u = ln(X / X_lin) as variables.

Then Omega = G_wc C / (1 - G_wT N), x_p = G_xc C + G_xT N Omega, theta = Omega / (j w), and the
responses are x_p / (A) [m/rad] and theta / A. The DF neglects harmonics (the engine rate is
not sinusoidal while friction holds it), and the surrogate's valve is the linear one (the
null-load-pressure linearisation of the square-root valve law and relief of
:mod:`taos.planar.saturation`); :mod:`taos.identify.fit` removes both biases by defect
correction against the time-domain sine dwell of the full nonlinear model.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Callable

import numpy as np

from taos.descfcn import static_describing_function
from taos.errors import InputError
from taos.model import TvcModel
from taos.linear import freqresp_symbolic


@dataclass(frozen=True)
class FitParam:
    """A fittable model value: CLI name, model-file place, unit, accessor and setter."""

    name: str
    section: str
    toml_key: str
    kind: str
    unit: str
    get: Callable[[TvcModel], float]
    set: Callable[[TvcModel, object], TvcModel]
    lo: float = 0.05   # bounds: [lo, hi] times the start value, for parameters without a physical
    #                    range (taos.identify.physbounds)
    hi: float = 20.0


def _rep(part: str, fieldname: str):
    def setter(m, v):
        return dataclasses.replace(m, **{part: dataclasses.replace(getattr(m, part), **{fieldname: v})})
    return setter


def _get(part: str, fieldname: str):
    return lambda m: float(getattr(getattr(m, part), fieldname))


def _avionics_set(m, k):
    av = m.avionics
    if isinstance(k, (int, float)):
        if av.gain_table:
            av = dataclasses.replace(av, gain_table=tuple(g * k for g in av.gain_table))
        else:
            av = dataclasses.replace(av, gain_table_rad=(0.0,), gain_table=(float(k),))
        return dataclasses.replace(m, avionics=av)
    return m  # symbolic: applied in the surrogate's command path


def _p(name, section, key, part, fld, kind, unit, **kw):
    return FitParam(name, section, key, kind, unit, _get(part, fld), _rep(part, fld), **kw)


def _friction_level_set(m, v):
    """Set the friction LEVEL T_c = ``v``: every torque-like parameter of the law (static
    torque, bristle stiffness and damping, viscous and stick damping) scales with it
    (:meth:`taos.friction.FrictionLaw.scaled`), as friction proportional to the bearing normal
    load does and as the model file's parameter set is scaled to its ``coulomb_torque``
    (``reference_torque``): the pre-sliding angle T_c / sigma_0, the Stribeck ratio T_s / T_c
    and the LuGre passivity ratios (:meth:`taos.friction.LuGre.passivity_ratios`, homogeneous
    of degree 0 in these) stay the hardware's at every level the fit tries. A torque-like
    parameter that is itself free is set after this (:func:`apply_values`)."""
    law = m.friction
    tc = law.coulomb_torque_Nm
    if isinstance(tc, (int, float)) and tc > 0:
        return dataclasses.replace(m, friction=law.scaled(v / tc))
    return dataclasses.replace(m, friction=dataclasses.replace(law, coulomb_torque_Nm=v))


def variant_values(model: TvcModel, names, values) -> dict:
    """The model-file keys and values (SI) of free parameters ``names`` at ``values`` (floats),
    for :meth:`~taos.model.TvcModel.with_values`: each parameter's own key, the avionics gain
    as the crossover gain table times the factor."""
    out = {}
    for n, v in zip(names, values):
        p = PARAMETERS[n]
        if n == "avionics_gain":
            av = model.avionics
            if av.gain_table:
                out["avionics.crossover_gain"] = [float(g * v) for g in av.gain_table]
            else:
                out["avionics.crossover_command"] = ["0 deg"]
                out["avionics.crossover_gain"] = [float(v)]
        else:
            out[f"{p.section}.{p.toml_key}"] = float(v)
    return out


def apply_values(model: TvcModel, names, values) -> TvcModel:
    """``model`` with parameters ``names`` set to ``values`` (SI). Floats: the model variant
    through the loader (:mod:`taos.variants`; ``coulomb_torque`` is the friction level, the law's
    other torque-like parameters following it, a free one among them set as given). CasADi SX
    values (the surrogate's symbols): the same meaning on the dataclasses, the friction level
    first (it scales the law's other torque-like parameters, which a free one then overrides),
    so the result does not depend on the order of ``--free``."""
    if all(isinstance(v, (int, float, np.floating)) for v in values):
        names, values = list(names), [float(v) for v in values]
        if "avionics_gain" in names and any(k == "code.avionics" for k, _ in model.overrides):
            # avionics set in code (e.g. the bounding gain): the factor scales that table, in code
            g = values.pop(names.index("avionics_gain"))
            names.remove("avionics_gain")
            model = model.with_values(variant_values(model, names, values)) if names else model
            return model.replace(avionics=_avionics_set(model, g).avionics)
        return model.with_values(variant_values(model, names, values))
    pairs = sorted(zip(names, values), key=lambda nv: nv[0] != "coulomb_torque")
    for n, v in pairs:
        model = PARAMETERS[n].set(model, v)
    return model


#: name -> FitParam
PARAMETERS: dict[str, FitParam] = {p.name: p for p in (
    _p("load_stiffness", "structure", "load_stiffness", "structure", "load_stiffness_N_per_m", "stiffness", "lbf/in"),
    _p("load_damping_ratio", "structure", "load_damping_ratio", "structure", "load_damping_ratio", "dimensionless",
       "", lo=1e-2, hi=1e2),
    FitParam("coulomb_torque", "friction", "coulomb_torque", "torque", "in*lbf", _get("friction", "coulomb_torque_Nm"),
             _friction_level_set),
    _p("bristle_stiffness", "friction", "bristle_stiffness", "friction", "bristle_stiffness_Nm_per_rad",
       "rotational_stiffness", "N*m/rad", lo=1e-3, hi=1e3),
    _p("viscous_damping", "friction", "viscous_damping", "friction", "viscous_damping_Nms_per_rad",
       "rotational_damping", "N*m*s/rad", lo=1e-3, hi=1e3),
    _p("loop_gain", "actuator", "loop_gain", "actuator", "loop_gain_per_s", "rate", "1/s"),
    _p("pressure_feedback_gain", "actuator", "pressure_feedback_gain", "actuator",
       "pressure_feedback_gain_m_per_s_Pa", "velocity_per_pressure", "m/s/Pa"),
    _p("valve_natural_frequency", "actuator", "valve_natural_frequency", "actuator", "valve_natural_frequency_hz",
       "frequency", "Hz"),
    _p("piston_damping", "actuator", "piston_damping", "actuator", "piston_damping_Ns_per_m", "damping", "N*s/m"),
    _p("rotational_stiffness", "engine", "rotational_stiffness", "engine", "rotational_stiffness_Nm_per_rad",
       "rotational_stiffness", "N*m/rad", lo=1e-3, hi=1e3),
    _p("inertia_pitch", "engine", "inertia_pitch", "engine", "inertia_pitch_kgm2", "inertia", "kg*m**2", lo=0.2, hi=5),
    _p("inertia_yaw", "engine", "inertia_yaw", "engine", "inertia_yaw_kgm2", "inertia", "kg*m**2", lo=0.2, hi=5),
    FitParam("avionics_gain", "avionics", "crossover_gain", "dimensionless", "", lambda m: 1.0, _avionics_set,
             lo=0.5, hi=1.5),
)}


def friction_family(model: TvcModel) -> str:
    """How the surrogate treats the model's friction law, asked of its registry entry: 'none'
    (no friction), 'relay' (closed-form loop) or 'implicit' (amplitude unknowns)."""
    law = model.friction
    if not law.has_friction:
        return "none"
    e = law.entry
    if e.fit_describing_function is None and e.fit_relay_level is None:
        raise InputError(model.source, "friction.model", "a law the fit supports (one whose registry entry "
                         "gives a fit describing function)", got=law.name)
    if e.fit_check is not None:
        e.fit_check(law, model.source)
    return "relay" if e.fit_relay_level is not None else "implicit"


def check_free(model: TvcModel, names) -> list[FitParam]:
    """Validate ``--free`` names against the model; returns the FitParams."""
    fam = friction_family(model)
    out = []
    for n in names:
        if n not in PARAMETERS:
            raise InputError("command line", "--free", "names from " + ", ".join(PARAMETERS), got=repr(n))
        p = PARAMETERS[n]
        if p.section == "friction":
            ok = () if fam == "none" else model.friction.entry.fit_parameters
            if n not in ok:
                raise InputError("command line", "--free", f"friction parameters of the {model.friction.name} law "
                                 f"({', '.join(ok) or 'none: choose --friction'})", got=repr(n))
        if n == "pressure_feedback_gain" and model.actuator.pressure_feedback_time_constant_s <= 0:
            raise InputError(model.source, "actuator.pressure_feedback_time_constant",
                             "a positive time constant to fit pressure_feedback_gain")
        if n in [q.name for q in out]:
            raise InputError("command line", "--free", "each name once", got=repr(n))
        out.append(p)
    if not out:
        raise InputError("command line", "--free", "at least one parameter name", got="none")
    return out


def avionics_df(model: TvcModel, amplitude_rad: float, n: int = 4096) -> complex:
    """Describing function of the command avionics at ``amplitude_rad`` (fundamental of
    avionics(A sin psi) over A sin psi, from the avionics kernel itself,
    :func:`taos.descfcn.static_describing_function`); 1 for no amplitude."""
    if amplitude_rad <= 0 or not math.isfinite(amplitude_rad):
        return 1.0 + 0j
    return static_describing_function(model.avionics, amplitude_rad, n)


# -- complex arithmetic on (re, im) pairs of SX ------------------------------------------------
def _cm(a, b):
    return (a[0] * b[0] - a[1] * b[1], a[0] * b[1] + a[1] * b[0])


def _cd(a, b):
    d = b[0] * b[0] + b[1] * b[1]
    return ((a[0] * b[0] + a[1] * b[1]) / d, (a[1] * b[0] - a[0] * b[1]) / d)


def _ca(a, b):
    return (a[0] + b[0], a[1] + b[1])


@dataclass(frozen=True, eq=False)
class Surrogate:
    """CasADi function ``fn(s, u) -> (hx_re, hx_im, he_re, he_im, g)`` over the points.

    ``s`` are the free parameters over their reference values (p = p_ref s); ``u`` the
    implicit amplitude variables (ln(X / X_lin), 'implicit' family only; empty otherwise); ``g`` the
    implicit loop residuals. hx is x_p / theta_c [m/rad], he theta / theta_c."""

    fn: object
    g_fn: object
    params: tuple[FitParam, ...]
    p_ref: np.ndarray
    n_u: int
    family: str
    axes: np.ndarray
    freq_hz: np.ndarray
    amp_rad: np.ndarray


def build_surrogate(model: TvcModel, params, axes, freq_hz, amp_rad) -> Surrogate:
    """Symbolic surrogate responses at points (axes[k], freq_hz[k], amp_rad[k])."""
    import casadi as ca

    from taos.linear import balancing_scale
    from taos.planar.simplex import simplex_state_space

    params = tuple(params)
    fam = friction_family(model)
    p_ref = np.array([p.get(model) for p in params])
    s = ca.SX.sym("s", len(params))
    kav = 1.0
    names, vals = [], []
    for i, p in enumerate(params):
        if p.name == "avionics_gain":
            kav = s[i]
        else:
            names.append(p.name)
            vals.append(p_ref[i] * s[i])
    msym = apply_values(model, names, vals)
    law = msym.friction
    entry = model.friction.entry
    axes = np.asarray(axes)
    f = np.asarray(freq_hz, float)
    A = np.asarray(amp_rad, float)
    m = f.size
    n_u = m if fam == "implicit" else 0
    u = ca.SX.sym("u", n_u)
    out = {k: [] for k in ("xr", "xi", "er", "ei", "g")}
    cache = {}
    lin = {}
    if fam == "implicit":  # numeric linear command -> rate at the start values (amplitude scale)
        for ax in set(map(str, axes)):
            lin[ax] = simplex_state_space(model, ax).freqresp(f, "command_rad", "omega_rad_s")
    for k in range(m):
        ax = str(axes[k])
        if ax not in cache:
            cache[ax] = (simplex_state_space(msym, ax), balancing_scale(simplex_state_space(model, ax)))
        ss, sc = cache[ax]
        w = 2 * math.pi * f[k]
        G = freqresp_symbolic_2x2(ss, w, sc)
        Gxc, Gxt = G["command_rad", "x_p_m"], G["friction_torque_Nm", "x_p_m"]
        Gwc, Gwt = G["command_rad", "omega_rad_s"], G["friction_torque_Nm", "omega_rad_s"]
        nav = avionics_df(model, A[k]) if math.isfinite(A[k]) else 1.0 + 0j
        C = (kav * nav.real, kav * nav.imag)  # command phasor per unit A
        Aeff = A[k] if math.isfinite(A[k]) else 1e-2
        if fam == "none":
            N = (0.0, 0.0)
            Om = _cm(Gwc, C)
        elif fam == "relay":
            a = entry.fit_relay_level(law) / Aeff   # per unit A (phasors per unit command)
            gc2 = (Gwc[0] ** 2 + Gwc[1] ** 2) * (C[0] ** 2 + C[1] ** 2)
            disc = gc2 - a * a * Gwt[1] ** 2
            dsm = 1e-8 * gc2
            root = ca.sqrt(0.5 * (disc + ca.sqrt(disc * disc + dsm * dsm)))
            raw = a * Gwt[0] + root
            eps = 1e-4 * ca.sqrt(gc2)
            V = 0.5 * (raw + ca.sqrt(raw * raw + eps * eps))
            den = (V - a * Gwt[0], -a * Gwt[1])
            Om = _cd(_cm((V, 0.0), _cm(Gwc, C)), den)
            N = (a / V, 0.0)
        else:  # implicit: the law's describing function at engine angle amplitude X
            Xlin = Aeff * abs(lin[ax][k] * nav) / w
            X = Xlin * ca.exp(u[k])
            N = tuple(entry.fit_describing_function(law, X, w))   # rate form [N m s/rad]
            one_m = (1 - (Gwt[0] * N[0] - Gwt[1] * N[1]), -(Gwt[0] * N[1] + Gwt[1] * N[0]))
            Om = _cd(_cm(Gwc, C), one_m)
            # per unit A: Omega amplitude w X / Aeff
            lhs = ca.log(w * X / Aeff) + 0.5 * ca.log(one_m[0] ** 2 + one_m[1] ** 2)
            rhs = 0.5 * ca.log((Gwc[0] ** 2 + Gwc[1] ** 2) * (C[0] ** 2 + C[1] ** 2))
            out["g"].append(lhs - rhs)
        Hx = _ca(_cm(Gxc, C), _cm(Gxt, _cm(N, Om)))
        He = (Om[1] / w, -Om[0] / w)
        out["xr"].append(Hx[0])
        out["xi"].append(Hx[1])
        out["er"].append(He[0])
        out["ei"].append(He[1])
    vc = lambda L: ca.vertcat(*L) if L else ca.SX(0, 1)  # noqa: E731
    fn = ca.Function("surrogate", [s, u], [vc(out["xr"]), vc(out["xi"]), vc(out["er"]), vc(out["ei"]), vc(out["g"])],
                     ["s", "u"], ["hx_re", "hx_im", "he_re", "he_im", "g"])
    g_fn = ca.Function("g", [s, u], [vc(out["g"])])
    return Surrogate(fn, g_fn, params, p_ref, n_u, fam, axes, f, A)


def freqresp_symbolic_2x2(ss, w_rad_s: float, scale):
    """(re, im) of the four responses {command_rad, friction_torque_Nm} -> {x_p_m,
    omega_rad_s} at w from one balanced real solve with two right-hand sides
    (:func:`taos.linear.freqresp_symbolic`), which quarters the expression graph of the fit."""
    ins = ("command_rad", "friction_torque_Nm")
    outs = ("x_p_m", "omega_rad_s")
    re, im = freqresp_symbolic(ss, w_rad_s, list(ins), list(outs), scale=scale)
    return {(i, o): (re[b, a], im[b, a]) for a, i in enumerate(ins) for b, o in enumerate(outs)}


def solve_implicit(sur: Surrogate, s, u0=None, iters: int = 60) -> np.ndarray:
    """Solve g(s, u) = 0 for u (each g_k depends on u_k only), by safeguarded bisection in
    u over [-30, 6] refined by Newton steps. Returns u."""
    if sur.n_u == 0:
        return np.zeros(0)
    G = sur.g_fn
    lo = np.full(sur.n_u, -30.0)
    hi = np.full(sur.n_u, 6.0)
    glo = np.asarray(G(s, lo)).ravel()
    for _ in range(iters):
        mid = 0.5 * (lo + hi)
        gm = np.asarray(G(s, mid)).ravel()
        same = np.sign(gm) == np.sign(glo)
        lo = np.where(same, mid, lo)
        glo = np.where(same, gm, glo)
        hi = np.where(same, hi, mid)
    return 0.5 * (lo + hi)
