"""The standalone FMU's parameter block (``sources/taos_model.h``, ``sources/taos_params.c``;
:mod:`taos.cosim._standalone`).

The model's numbers are a C struct ``TaosParams`` in each FMU instance, filled from the build's
defaults (``taos_defaults``) at instantiation and by ``fmi2SetReal``; ``taos_derive`` then
recomputes, in C, every number the kernels take that depends on a parameter:

* ``load_stiffness_N_per_m`` K_L [N/m] (fixed: set before initialisation ends): the state
  matrix A, the applied-torque row ca and the load-force output row of each axis, from
  :func:`taos.planar.simplex.simplex_state_space` evaluated on a CasADi symbol K_L and emitted
  by CasADi's C code generator (the same expression graph as the Python matrices, including
  the load-path damping c_L = 2 zeta sqrt(K_L R^2 J_n) / R^2); at the build's K_L the build's
  own arrays are used (bit for bit those of ``taos simulate``). Range [K_L / 4, k K_L] with k
  the largest of 4, 2, 1.5, 1.25, 1 at which the build's internal step keeps
  dt |lambda|max <= :data:`taos.bounds.RK4_STEP_LIMIT`.
* ``avionics_gain`` k [-] (tunable): the crossover gain table's gains times k, or a one-entry
  table of gain k when the model has none (as the fits' ``avionics_gain``,
  :mod:`taos.identify.surrogate`): u = k g(|c|) c.
* friction levels ``friction_<key>`` (tunable): the law's torque-like packed slots
  (:mod:`taos.friction._slots`; torque levels, bristle stiffness and damping, viscous and stick
  damping) in SI units; positive where the model's value is (the laws' own validation), else
  >= 0. A law without a static-torque field keeps slot T_s = T_c (``FrictionLaw.pack``).
* ``internal_step_s`` dt [s] (fixed): within (0, dt_max], dt_max the RK4 limit of the stiffest
  K_L allowed; with K_L and the friction levels it must pass the law's explicit-step rule
  (:meth:`taos.friction.FrictionLaw.check_step`, :data:`STEP_RULES` in C, for both axes'
  inertia) whenever any of them is set, or the setting is refused (fmi2Error).
* ``vehicle_moment_arm_m`` l [m] (tunable): the gimbal point's distance behind the vehicle's
  reference point along -z (moment outputs).

A plug-in law with its own step rule but none in :data:`STEP_RULES` keeps its friction levels
and the internal step compiled in (constants).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from ..friction import _slots as K
from ..planar._avionics_slots import AV_NTAB, AV_TABLE

#: the explicit-step rules of the built-in laws with one (FrictionLaw.check_step), in C over
#: fp (packed slots), dt [s] and J [kg m^2]: each (refusal condition, what the law needs)
STEP_RULES = {
    "coulomb-smooth": [(f"dt * fp[{K.SLOT_TC}] / (fp[{K.SLOT_VEPS}] * J) > 2.0",
                        "dt T_c / (v_eps J) at most 2 (friction.regularization_velocity)")],
    "coulomb-switching": [(f"dt * (fmax(fp[{K.SLOT_TS}], fp[{K.SLOT_TC}]) + fp[{K.SLOT_TC}]) / J >= fp[{K.SLOT_VEPS}]",
                           ("a stick band above one step's rate change dt (max(T_s, T_c) + T_c) / J "
                            "(friction.stick_velocity)")),
                          (f"fp[{K.SLOT_CSTICK}] * dt / J > 1.0", "c_stick dt / J at most 1 (friction.stick_damping)")],
}
#: (value reference, name) of the Real variables after the block's outputs (2..18)
VR_DT, VR_THRUST = 19, 20
VEHICLE_OUTPUTS = ("vehicle_force_x_N", "vehicle_force_y_N", "vehicle_force_z_N",
                   "vehicle_moment_x_Nm", "vehicle_moment_y_Nm", "vehicle_moment_z_Nm")
VR_VEHICLE0 = 21
VR_PAR0 = VR_VEHICLE0 + len(VEHICLE_OUTPUTS)
KL_FACTORS = (4.0, 2.0, 1.5, 1.25, 1.0)
#: friction parameter kind -> (FMI unit, name suffix)
_KIND_UNIT = {"torque": ("N.m", "_Nm"), "rotational_stiffness": ("N.m/rad", "_Nm_per_rad"),
              "rotational_damping": ("N.m.s/rad", "_Nms_per_rad")}


@dataclasses.dataclass(frozen=True)
class Param:
    """One parameter of the FMU: FMI name, value reference, the C lvalue in ``TaosParams``,
    unit, tunable (else fixed), start, bounds and whether it must be positive."""

    name: str
    vr: int
    field: str
    unit: str
    tunable: bool
    start: float
    lo: float
    hi: float
    positive: bool
    description: str


def _with_kl(model, kl):
    return dataclasses.replace(model, structure=dataclasses.replace(model.structure, load_stiffness_N_per_m=kl))


def step_bounds(model, dt_s: float) -> tuple[float, float]:
    """(largest K_L [N/m] allowed, largest internal step [s]): module docstring."""
    from ..bounds import RK4_STEP_LIMIT
    from ..planar.envelope import fastest_mode_rad_s

    k0 = model.structure.load_stiffness_N_per_m
    for f in KL_FACTORS:
        lam = fastest_mode_rad_s(_with_kl(model, f * k0))
        if dt_s * lam <= RK4_STEP_LIMIT or f == 1.0:
            return f * k0, RK4_STEP_LIMIT / lam
    raise AssertionError


def friction_tunable(model) -> bool:
    """Whether the law's levels and the internal step can be parameters (its step rule, if it
    has one, is in :data:`STEP_RULES`)."""
    from ..friction import FrictionLaw

    law = model.friction
    return type(law).check_step is FrictionLaw.check_step or law.name in STEP_RULES


def parameters(model, dt_s: float) -> list[Param]:
    """The FMU's Real parameters (module docstring), internal_step_s first."""
    k0 = model.structure.load_stiffness_N_per_m
    kmax, dtmax = step_bounds(model, dt_s)
    tun = friction_tunable(model)
    out = []
    if tun:
        out.append(Param("internal_step_s", VR_DT, "dt", "s", False, dt_s, 0.0, dtmax, True,
                         f"the kernel's fixed RK4 step; communication steps are whole multiples of it; at most "
                         f"{dtmax:.4g} s (RK4 limit at the stiffest load stiffness allowed) and the friction law's "
                         f"explicit-step rule"))
    vr = VR_PAR0
    out.append(Param("load_stiffness_N_per_m", vr, "KL", "N/m", False, k0, k0 / 4, kmax, True,
                     "load-path stiffness K_L (structure, engine, gimbal, actuator case); the linear plant is "
                     "recomputed from it (CasADi-generated C of taos's simplex_state_space)"))
    out.append(Param("avionics_gain", vr + 1, "avionics_gain", "", True, 1.0, 0.5, 1.5, True,
                     "servo-amplifier gain factor k on the crossover gain table (u = k g(|c|) c)"))
    out.append(Param("vehicle_moment_arm_m", vr + 2, "arm", "m", True, 0.0, 0.0, math.inf, False,
                     "distance l of the gimbal point behind the vehicle reference point (along -z of the gimbal "
                     "frame) for the vehicle moment outputs"))
    vr += 3
    if tun:
        law = model.friction
        for f in dataclasses.fields(law):
            md = f.metadata
            if md.get("slot") is None or not md.get("torque_like"):
                continue
            v = float(getattr(law, f.name))
            unit, suffix = _KIND_UNIT.get(md["kind"], ("", ""))
            out.append(Param(f"friction_{md['key']}{suffix}", vr, f"fp[{md['slot']}]", unit, True,
                             v, 0.0, math.inf, v > 0, f"{law.name} friction: {md.get('meaning') or md['key']} "
                             f"(packed slot {md['slot']})"))
            vr += 1
    return out


def _c_float(v: float) -> str:
    v = float(v)
    if math.isinf(v):
        return "INFINITY" if v > 0 else "-INFINITY"
    if math.isnan(v):
        raise ValueError("NaN in the model's arrays")
    r = repr(v)
    return r if any(c in r for c in ".e") else r + ".0"


def _c_array(values) -> str:
    a = np.asarray(values, dtype=float)
    if a.ndim == 1:
        return "{" + ", ".join(_c_float(v) for v in a) + "}"
    return "{" + ", ".join(_c_array(row) for row in a) + "}"


def kl_functions(model):
    """CasADi functions ``taos_kl_pitch``/``taos_kl_yaw``: K_L -> (A row-major (n n,), applied
    row ca (n,), load-force row (n,)) of the simplex block (module docstring)."""
    import casadi as ca

    from ..planar.simplex import simplex_state_space

    kl = ca.SX.sym("K_L")
    fns = []
    for ax in ("pitch", "yaw"):
        ss = simplex_state_space(_with_kl(model, kl), ax)
        rows = [ss.C[ss.output_index(k), :] for k in ("applied_torque_Nm", "load_force_N")]
        fns.append(ca.Function(f"taos_kl_{ax}", [kl], [ca.vec(ss.A.T), *(ca.vec(r) for r in rows)]))
    return fns


def params_source(model) -> str:
    """``taos_params.c``: CasADi's C of :func:`kl_functions` and ``taos_derive``, ``taos_check``."""
    import casadi as ca

    fns = kl_functions(model)
    cg = ca.CodeGenerator("taos_params_kl", {"with_header": False, "with_export": False, "casadi_int": "long",
                                             "verbose": False})
    for f in fns:
        cg.add(f)
    casadi_c = cg.dump()
    sz_w = max(f.sz_w() for f in fns)
    sz_iw = max(f.sz_iw() for f in fns) + 1
    law = model.friction
    slots = {f.metadata.get("slot") for f in dataclasses.fields(law)}
    ts_line = "" if K.SLOT_TS in slots else f"    p->fp[{K.SLOT_TS}] = p->fp[{K.SLOT_TC}];   /* FrictionLaw.pack: T_s = T_c */\n"
    rules = "".join(f'        if ({cond}) {{ snprintf(why, n, "internal step %g s, %s axis: the {law.name} law needs '
                    f'{need}", dt, ax ? "yaw" : "pitch"); return 1; }}\n'
                    for cond, need in STEP_RULES.get(law.name, []))
    return f"""/* Generated by taos fmu --standalone: the parameter block's derived numbers (taos.cosim._standalone_params).
   Do not edit. The functions taos_kl_pitch and taos_kl_yaw below are CasADi's C code generation of
   taos.planar.simplex.simplex_state_space with a symbolic load stiffness. */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include "taos_model.h"

{casadi_c}

static int plant_of_kl(TaosParams *p, int ax) {{
    const double *arg[1];
    double *res[3];
    long iw[{sz_iw}];
    double w[{sz_w + 1}];
    arg[0] = &p->KL;
    res[0] = p->A[ax];
    res[1] = p->ca[ax];
    res[2] = p->cy[ax][TAOS_ROW_LOAD];
    return ax ? taos_kl_yaw(arg, res, iw, w, 0) : taos_kl_pitch(arg, res, iw, w, 0);
}}

int taos_derive(TaosParams *p, char *why, size_t n) {{
    const TaosParams *d = &taos_defaults;
    double dt = p->dt;
    int ntab = (int)d->avp[{AV_NTAB}];
    /* avionics gain: the table's gains times k, or a one-entry table of gain k */
    memcpy(p->avp, d->avp, sizeof p->avp);
    if (ntab > 0) {{
        for (int i = 0; i < ntab; i++) p->avp[{AV_TABLE} + ntab + i] = d->avp[{AV_TABLE} + ntab + i] * p->avionics_gain;
    }} else if (p->avionics_gain != 1.0) {{
        p->avp[{AV_NTAB}] = 1.0;
        p->avp[{AV_TABLE}] = 0.0;
        p->avp[{AV_TABLE} + 1] = p->avionics_gain;
    }}
{ts_line}    /* the linear plant of K_L: the build's arrays at its own K_L, CasADi's C elsewhere */
    for (int ax = 0; ax < 2; ax++) {{
        if (p->KL == d->KL) {{
            memcpy(p->A[ax], d->A[ax], sizeof p->A[ax]);
            memcpy(p->ca[ax], d->ca[ax], sizeof p->ca[ax]);
            memcpy(p->cy[ax][TAOS_ROW_LOAD], d->cy[ax][TAOS_ROW_LOAD], sizeof p->cy[ax][TAOS_ROW_LOAD]);
        }} else if (plant_of_kl(p, ax)) {{
            snprintf(why, n, "load stiffness %g N/m: the plant's code failed", p->KL);
            return 1;
        }}
    }}
    for (int ax = 0; ax < 2; ax++) {{
        double J = taos_inertia[ax];
        const double *fp = p->fp;
        (void)J; (void)fp;
{rules}    }}
    (void)dt;
    return 0;
}}
"""


def params_header(model, dt_s: float, guid: str, allow_unstable: bool, axes, output_rows, envelope) -> str:
    """``taos_model.h``: sizes, the ``TaosParams`` struct and its defaults, the parameter table.
    ``axes`` [(PlantArrays, Cy rows)] per axis (pitch, yaw); ``output_rows`` the names of the
    rows of Cy; ``envelope`` (command range [rad], hard stops [rad], load-force bound [N])."""
    (p0, _), _ = axes
    n, nr = p0.A.shape[0], p0.Br.shape[1]
    rng, stop, force = envelope
    fp, avp = model.friction.pack(), model.avionics.pack()
    navp = max(avp.size, AV_TABLE + 2)
    avp = np.concatenate([avp, np.zeros(navp - avp.size)])
    pars = parameters(model, dt_s)
    lines = [(f"/* Generated by taos fmu --standalone: the numbers of model {model.name!r} (model_sha256 "
              f"{model.sha256}) as the defaults of the parameter block (taos.cosim._standalone_params). Do not edit. */"),
             "#ifndef TAOS_MODEL_H", "#define TAOS_MODEL_H", "#include <math.h>", "#include <stddef.h>",
             f"#define TAOS_NX {n}", f"#define TAOS_NR {nr}", f"#define TAOS_NY {len(output_rows)}",
             f"#define TAOS_ROW_LOAD {output_rows.index('load_force_N')}",
             f"#define TAOS_NLIM {p0.lim.size}", f"#define TAOS_NFP {fp.size}", f"#define TAOS_NAVP {navp}",
             f'#define TAOS_GUID "{guid}"',
             f"#define TAOS_COMMAND_RANGE_RAD {_c_float(rng * (1 + 1e-12))}",
             f"#define TAOS_HARD_STOP_RAD {_c_float(stop)}", f"#define TAOS_FORCE_LIMIT_N {_c_float(force)}",
             f"#define TAOS_CHECK_ENVELOPE {0 if allow_unstable else 1}",
             f'#define TAOS_LABEL "{model.friction.name} friction"',
             f"#define TAOS_THRUST_N {_c_float(model.engine.thrust_N)}",
             f"#define TAOS_VR_DT {VR_DT}", f"#define TAOS_VR_THRUST {VR_THRUST}",
             f"#define TAOS_VR_VEHICLE0 {VR_VEHICLE0}", f"#define TAOS_N_VEHICLE {len(VEHICLE_OUTPUTS)}",
             "typedef struct {",
             "    double A[2][TAOS_NX * TAOS_NX], Br[2][TAOS_NX * TAOS_NR], bc[2][TAOS_NX], bf[2][TAOS_NX];",
             "    double cc[2][TAOS_NX], dc[2][TAOS_NR], cw[2][TAOS_NX], ca[2][TAOS_NX], lim[2][TAOS_NLIM];",
             "    double cy[2][TAOS_NY][TAOS_NX];   /* output rows (y = Cy x) per axis */",
             "    double fp[TAOS_NFP], avp[TAOS_NAVP];   /* packed friction and avionics */",
             "    double dt, KL, avionics_gain, arm;   /* internal step [s], K_L [N/m], k [-], l [m] */",
             "} TaosParams;",
             "/* one parameter: value reference, name, place in TaosParams, tunable, bounds, positive */",
             ("typedef struct { unsigned vr; const char *name; size_t off; int tunable; double lo, hi; int positive; } "
              "TaosPar;"),
             f"#define TAOS_NPAR {len(pars)}",
             "int taos_derive(TaosParams *p, char *why, size_t n);"]
    init = []
    for name in ("A", "Br", "bc", "bf", "cc", "dc", "cw", "ca", "lim"):
        init.append(f"    .{name} = {_c_array([getattr(pa, name).reshape(-1) for pa, _ in axes])},")
    init.append(f"    .cy = {_c_array([cy for _, cy in axes])},")
    init.append(f"    .fp = {_c_array(fp)}, .avp = {_c_array(avp)},")
    init.append(f"    .dt = {_c_float(dt_s)}, .KL = {_c_float(model.structure.load_stiffness_N_per_m)}, "
                f".avionics_gain = 1.0, .arm = 0.0")
    lines += ["static const TaosParams taos_defaults = {", *init, "};"]
    lines.append(f"static const double taos_inertia[2] = {_c_array([model.engine.inertia(a) for a in ('pitch', 'yaw')])};")
    rows = ",\n".join(f'    {{{p.vr}, "{p.name}", offsetof(TaosParams, {p.field}), {int(p.tunable)}, {_c_float(p.lo)}, '
                      f"{_c_float(p.hi)}, {int(p.positive)}}}" for p in pars)
    lines += [f"static const TaosPar taos_par[TAOS_NPAR] = {{\n{rows}\n}};"]
    lines.append(f"#define TAOS_DT_PARAM {int(any(p.vr == VR_DT for p in pars))}")
    return "\n".join(lines + ["#endif", ""])
