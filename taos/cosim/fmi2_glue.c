/* FMI 2.0 co-simulation interface of the standalone taos TVC FMU (taos fmu --standalone).

   Hand-written and model-independent: the FMI life cycle, the variables, the communication
   step and the FMU state. It holds no dynamics. The state equations and the RK4 step are
   taos_kernels.c, which taos emits from the compiled kernels' own Python definitions
   (taos.cosim._ccode); the model's numbers are the defaults of the parameter block TaosParams
   in taos_model.h, written from the loaded model, and taos_params.c recomputes what depends on
   a parameter (taos_derive; taos.cosim._standalone_params). Each instance owns its block:
   parameters are set with fmi2SetReal (the fixed ones until initialisation ends, the tunable
   ones also between steps), every setting checked and derived on a copy, taken whole or not.

   Per axis (pitch, yaw; each its own planar plant, as taos simulate): a communication step of
   n internal steps of dt runs taos_rk4_step n times with the command given by command_mode:
   0 (exact, the default) the command set for this step, entering over the first internal step
   as taos simulate's linear interpolation of its samples enters a step change (the samples of
   a command held over each communication step: the one at a communication point is the
   command in force before it); 1 (ramp) linear from the previous communication point's command
   over the whole step; 2 (hold) a pure staircase, switching at the communication point. The
   outputs are read at the step's end: y = Cy x, the friction torque and post-avionics command
   of taos_rates there, and the engine force and moment on the vehicle:
   F = T d (d the thrust direction, T the thrust input) and M = r x F with r = (0, 0, -l) the
   gimbal point from the vehicle reference point, l = vehicle_moment_arm_m: M = (l F_y, -l F_x, 0).

   Statuses: a host mistake (a call in the wrong state, an unknown value reference, a fixed
   parameter set after initialisation, a NaN or out-of-range input, a communication point
   that is not the FMU's time, a step that is not a whole multiple of the internal step) is
   fmi2Error with one log line, and changes nothing. A step whose state becomes non-finite or
   leaves the physical envelope is fmi2Discard: the FMU stays at the step's start
   (fmi2LastSuccessfulTime) and reports fmi2Terminated = true (the run cannot go on).
   Memory comes from the host's allocateMemory/freeMemory; nothing is global but constants. */

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "fmi2Functions.h"
#include "taos_kernels.h"
#include "taos_model.h"

#define N_AX 2
#define N_BLOCK 17                  /* the block's outputs (taos.cosim.BlockOutputs) */
#define N_OUT (N_BLOCK + TAOS_N_VEHICLE)
#define VR_OUT0 2                   /* Real value references: 0, 1 the commands, 2..18 the block's outputs */
#define VR_DT TAOS_VR_DT            /* internal_step_s (19) */
#define VR_MODE 0                   /* Integer value reference of command_mode */
#define TIME_TOL (1e-3 * s->d.p.dt) /* a communication point is the FMU's time within this [s] */
#define STEP_TOL (1e-6 * s->d.p.dt) /* a step is a whole multiple of dt within this [s] */

enum { ST_INSTANTIATED, ST_INIT, ST_STEP, ST_TERMINATED };
static const char *const STATE_NAME[] = {"instantiated", "initialization mode", "stepping", "terminated"};

/* Everything an FMU state (fmi2GetFMUstate) holds. */
typedef struct {
    double x[N_AX][TAOS_NX];  /* linear states per axis [SI] */
    double z[N_AX];           /* friction states [rad] */
    long k;                   /* internal steps since the start */
    double cmd_prev[N_AX];    /* commands at the last communication point [rad] (a ramp's start) */
    double in[N_AX];          /* the inputs as set [rad] */
    double thrust;            /* the thrust input [N] */
    double out[N_OUT];        /* outputs at the last communication point [SI] */
    TaosParams p;             /* the parameter block and its derived numbers */
    int mode;                 /* command_mode: 0 exact, 1 ramp, 2 hold */
    int terminated;           /* fmi2Terminated */
    double t0;                /* start time [s] */
} Dyn;

typedef struct {
    Dyn d;
    int state;
    int logging;
    char *name;
    fmi2CallbackLogger logger;
    fmi2CallbackAllocateMemory alloc;
    fmi2CallbackFreeMemory dealloc;
    fmi2ComponentEnvironment env;
    double k1[TAOS_NX], k2[TAOS_NX], k3[TAOS_NX], k4[TAOS_NX], xt[TAOS_NX];
} Inst;

#define SER_MAGIC "taos-fmu-state-1"

#include "fmi2_glue_common.h"   /* logging, state checks, FMU state, unsupported calls */

/* the plant arrays of axis ax in the order of the kernels' arguments (taos.planar.simulate.PlantArrays) */
#define PLANT(ax) P->A[ax], (long)TAOS_NX, (long)TAOS_NX, P->Br[ax], (long)TAOS_NX, (long)TAOS_NR, \
    P->bc[ax], (long)TAOS_NX, P->bf[ax], (long)TAOS_NX, P->cc[ax], (long)TAOS_NX, P->dc[ax], (long)TAOS_NR, \
    P->cw[ax], (long)TAOS_NX, P->ca[ax], (long)TAOS_NX, P->lim[ax], (long)TAOS_NLIM, \
    P->fp, (long)TAOS_NFP, P->avp, (long)TAOS_NAVP

/* Outputs at the current state with the commands cmd [rad] (taos.cosim._cores.SIGNALS order:
   each per-axis signal pitch then yaw, then the thrust direction). */
static void outputs(Inst *s, const double cmd[N_AX]) {
    TaosParams *P = &s->d.p;
    double th[N_AX];
    for (int ax = 0; ax < N_AX; ax++) {
        double r[TAOS_NR];
        for (int j = 0; j < TAOS_NR; j++) r[j] = cmd[ax];
        taos_tup3 q = taos_rates(s->d.x[ax], TAOS_NX, s->d.z[ax], r, TAOS_NR, PLANT(ax), s->k1, TAOS_NX);
        double y[TAOS_NY];
        for (int o = 0; o < TAOS_NY; o++) {
            double acc = 0.0;
            for (int i = 0; i < TAOS_NX; i++) acc += P->cy[ax][o][i] * s->d.x[ax][i];
            y[o] = acc;
        }
        /* TAOS_NY rows: engine angle, engine rate, piston, load force, load pressure */
        for (int o = 0; o < TAOS_NY; o++) s->d.out[2 * o + ax] = y[o];
        s->d.out[2 * TAOS_NY + ax] = q.v[1];       /* friction torque [N m] */
        s->d.out[2 * TAOS_NY + 2 + ax] = q.v[2];   /* command after the avionics [rad] */
        th[ax] = y[0];
    }
    taos_tup3 d = taos_thrust_direction(th[0], th[1]);
    double *v = s->d.out + N_BLOCK, T = s->d.thrust, l = P->arm;
    for (int i = 0; i < 3; i++) {
        s->d.out[2 * TAOS_NY + 4 + i] = d.v[i];
        v[i] = T * d.v[i];                     /* engine force on the vehicle [N] */
    }
    v[3] = l * v[1];                           /* moment about the reference point [N m] */
    v[4] = -l * v[0];
    v[5] = 0.0;
}

static void defaults(Inst *s) {
    memset(&s->d, 0, sizeof s->d);
    s->d.p = taos_defaults;
    s->d.thrust = TAOS_THRUST_N;
    s->d.mode = 0;
}

static void rest(Inst *s) {
    memset(s->d.x, 0, sizeof s->d.x);
    memset(s->d.z, 0, sizeof s->d.z);
    s->d.k = 0;
    s->d.terminated = 0;
}

static double now(const Inst *s) { return s->d.t0 + s->d.k * s->d.p.dt; }

/* -- common functions ------------------------------------------------------------------- */
const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }
const char *fmi2GetVersion(void) { return fmi2Version; }

fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean on, size_t n, const fmi2String cats[]) {
    Inst *s = (Inst *)c;
    if (s == NULL) return fmi2Error;
    for (size_t i = 0; i < n; i++)
        if (cats == NULL || cats[i] == NULL || (strcmp(cats[i], "logStatusError") && strcmp(cats[i], "logStatusDiscard")
                                                && strcmp(cats[i], "logAll")))
            return ERR(s, "fmi2SetDebugLogging: unknown log category %s (logStatusError, logStatusDiscard, logAll)",
                       cats && cats[i] ? cats[i] : "(null)");
    s->logging = on ? 1 : 0;
    return fmi2OK;
}

fmi2Component fmi2Instantiate(fmi2String name, fmi2Type type, fmi2String guid, fmi2String resources,
                              const fmi2CallbackFunctions *f, fmi2Boolean visible, fmi2Boolean loggingOn) {
    Inst tmp;
    (void)resources; (void)visible;
    if (f == NULL || f->allocateMemory == NULL || f->freeMemory == NULL) return NULL;
    memset(&tmp, 0, sizeof tmp);
    tmp.logger = f->logger;
    tmp.env = f->componentEnvironment;
    tmp.name = (char *)(name ? name : "?");
    if (name == NULL || !*name) { logmsg(&tmp, fmi2Error, "logStatusError", "fmi2Instantiate: no instance name"); return NULL; }
    if (type != fmi2CoSimulation) {
        logmsg(&tmp, fmi2Error, "logStatusError", "fmi2Instantiate: this FMU is for co-simulation only");
        return NULL;
    }
    if (guid == NULL || strcmp(guid, TAOS_GUID)) {
        logmsg(&tmp, fmi2Error, "logStatusError", "fmi2Instantiate: GUID %s is not this FMU's %s", guid ? guid : "(null)",
               TAOS_GUID);
        return NULL;
    }
    Inst *s = (Inst *)f->allocateMemory(1, sizeof(Inst));
    char *nm = (char *)f->allocateMemory(strlen(name) + 1, 1);
    if (s == NULL || nm == NULL) {
        if (s) f->freeMemory(s);
        if (nm) f->freeMemory(nm);
        logmsg(&tmp, fmi2Error, "logStatusError", "fmi2Instantiate: out of memory");
        return NULL;
    }
    memset(s, 0, sizeof *s);
    strcpy(nm, name);
    s->name = nm;
    s->logger = f->logger;
    s->alloc = f->allocateMemory;
    s->dealloc = f->freeMemory;
    s->env = f->componentEnvironment;
    s->logging = loggingOn ? 1 : 0;
    defaults(s);
    s->state = ST_INSTANTIATED;
    return s;
}

void fmi2FreeInstance(fmi2Component c) {
    Inst *s = (Inst *)c;
    if (s == NULL) return;
    fmi2CallbackFreeMemory dealloc = s->dealloc;
    dealloc(s->name);
    dealloc(s);
}

fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean tolDefined, fmi2Real tol, fmi2Real start,
                               fmi2Boolean stopDefined, fmi2Real stop) {
    CHECK(c, "fmi2SetupExperiment", M(ST_INSTANTIATED));
    (void)tolDefined; (void)tol;
    if (!isfinite(start) || (stopDefined && !(stop >= start)))
        return ERR(s, "fmi2SetupExperiment: start time %g s and stop time %g s: expected a finite start before the stop",
                   start, stop);
    s->d.t0 = start;
    return fmi2OK;
}

fmi2Status fmi2EnterInitializationMode(fmi2Component c) {
    CHECK(c, "fmi2EnterInitializationMode", M(ST_INSTANTIATED));
    s->state = ST_INIT;
    return fmi2OK;
}

fmi2Status fmi2ExitInitializationMode(fmi2Component c) {
    CHECK(c, "fmi2ExitInitializationMode", M(ST_INIT));
    rest(s);
    memcpy(s->d.cmd_prev, s->d.in, sizeof s->d.in);
    outputs(s, s->d.in);
    s->state = ST_STEP;
    return fmi2OK;
}

fmi2Status fmi2Terminate(fmi2Component c) {
    CHECK(c, "fmi2Terminate", M(ST_STEP));
    s->state = ST_TERMINATED;
    return fmi2OK;
}

fmi2Status fmi2Reset(fmi2Component c) {
    CHECK(c, "fmi2Reset", M(ST_INSTANTIATED) | M(ST_INIT) | M(ST_STEP) | M(ST_TERMINATED));
    defaults(s);
    s->state = ST_INSTANTIATED;
    return fmi2OK;
}

/* -- variables -------------------------------------------------------------------------- */

static const TaosPar *param(fmi2ValueReference vr) {
    for (int i = 0; i < TAOS_NPAR; i++) if (taos_par[i].vr == vr) return &taos_par[i];
    return NULL;
}
#define PAR(s, q) ((double *)((char *)&(s)->d.p + (q)->off))

fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Real v[]) {
    CHECK(c, "fmi2GetReal", ALL);
    if (n > 0 && (vr == NULL || v == NULL)) return ERR(s, "fmi2GetReal: no value references or no values");
    if (s->state == ST_INSTANTIATED || s->state == ST_INIT) outputs(s, s->d.in);   /* at rest: the initial values */
    for (size_t i = 0; i < n; i++) {
        const TaosPar *q = param(vr[i]);
        if (vr[i] < VR_OUT0) v[i] = s->d.in[vr[i]];
        else if (vr[i] < VR_OUT0 + N_BLOCK) v[i] = s->d.out[vr[i] - VR_OUT0];
        else if (vr[i] == TAOS_VR_THRUST) v[i] = s->d.thrust;
        else if (vr[i] >= TAOS_VR_VEHICLE0 && vr[i] < TAOS_VR_VEHICLE0 + TAOS_N_VEHICLE)
            v[i] = s->d.out[N_BLOCK + vr[i] - TAOS_VR_VEHICLE0];
        else if (vr[i] == VR_DT) v[i] = s->d.p.dt;
        else if (q) v[i] = *PAR(s, q);
        else return ERR(s, "fmi2GetReal: no Real with value reference %u", vr[i]);
    }
    return fmi2OK;
}

fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Real v[]) {
    CHECK(c, "fmi2SetReal", M(ST_INSTANTIATED) | M(ST_INIT) | M(ST_STEP));
    if (n > 0 && (vr == NULL || v == NULL)) return ERR(s, "fmi2SetReal: no value references or no values");
    int pars = 0;
    for (size_t i = 0; i < n; i++) {   /* every value checked before any is taken */
        const TaosPar *q = param(vr[i]);
        if (q) {
            if (!q->tunable && s->state == ST_STEP)
                return ERR(s, "%s: a fixed parameter, set only before initialisation ends", q->name);
            if (!(v[i] >= q->lo && v[i] <= q->hi) || (q->positive && !(v[i] > 0)))
                return ERR(s, "%s: expected a value %s %g and at most %g, got %g", q->name, q->positive ? "above" : "from",
                           q->lo, q->hi, v[i]);
            pars = 1;
        } else if (vr[i] == TAOS_VR_THRUST) {
            if (!(v[i] >= 0 && isfinite(v[i]))) return ERR(s, "thrust_N: expected a finite thrust >= 0 N, got %g", v[i]);
        } else if (vr[i] >= VR_OUT0) {
            return ERR(s, "fmi2SetReal: value reference %u is %s, which cannot be set", vr[i],
                       vr[i] == VR_DT ? "the constant internal_step_s" : "an output or no Real");
        } else if (!(fabs(v[i]) <= TAOS_COMMAND_RANGE_RAD)) {
            return ERR(s, "%s_command_rad: expected a command within the gimbal range +-%g rad, got %g",
                       vr[i] == 0 ? "pitch" : "yaw", TAOS_COMMAND_RANGE_RAD, v[i]);
        }
    }
    if (pars) {   /* the parameters on a copy, derived and checked, taken whole or not at all */
        TaosParams trial = s->d.p;
        char why[400];
        for (size_t i = 0; i < n; i++) {
            const TaosPar *q = param(vr[i]);
            if (q) *(double *)((char *)&trial + q->off) = v[i];
        }
        if (taos_derive(&trial, why, sizeof why)) return ERR(s, "fmi2SetReal: %s; nothing set", why);
        s->d.p = trial;
    }
    for (size_t i = 0; i < n; i++) {
        if (vr[i] < VR_OUT0) s->d.in[vr[i]] = v[i];
        else if (vr[i] == TAOS_VR_THRUST) s->d.thrust = v[i];
    }
    return fmi2OK;
}

fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Integer v[]) {
    CHECK(c, "fmi2GetInteger", ALL);
    for (size_t i = 0; i < n; i++) {
        if (vr[i] != VR_MODE) return ERR(s, "fmi2GetInteger: no Integer with value reference %u", vr[i]);
        v[i] = s->d.mode;
    }
    return fmi2OK;
}

fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Integer v[]) {
    CHECK(c, "fmi2SetInteger", M(ST_INSTANTIATED) | M(ST_INIT) | M(ST_STEP));
    for (size_t i = 0; i < n; i++) {
        if (vr[i] != VR_MODE) return ERR(s, "fmi2SetInteger: no Integer with value reference %u", vr[i]);
        if (s->state == ST_STEP)
            return ERR(s, "command_mode: a fixed parameter, set only before initialisation ends");
        if (v[i] < 0 || v[i] > 2) return ERR(s, "command_mode: expected 0 (exact), 1 (ramp) or 2 (hold), got %d", v[i]);
    }
    for (size_t i = 0; i < n; i++) s->d.mode = v[i];
    return fmi2OK;
}

fmi2Status fmi2DoStep(fmi2Component c, fmi2Real t, fmi2Real h, fmi2Boolean noSetPrior) {
    CHECK(c, "fmi2DoStep", M(ST_STEP));
    (void)noSetPrior;
    if (s->d.terminated)
        return ERR(s, "fmi2DoStep: the FMU reported fmi2Terminated at t = %.9g s; reset it or set an earlier state", now(s));
    if (!(fabs(t - now(s)) <= TIME_TOL))
        return ERR(s, "fmi2DoStep: currentCommunicationPoint %.12g s is not the FMU's time %.12g s", t, now(s));
    TaosParams *P = &s->d.p;
    double dt = P->dt;
    double nd = isfinite(h) && h > 0 ? floor(h / dt + 0.5) : 0.0;
    if (nd < 1 || nd > 1e12 || fabs(h - nd * dt) > STEP_TOL)
        return ERR(s, "fmi2DoStep: communication step %.12g s: expected a positive whole multiple of the internal "
                   "step %g s (set internal_step_s to divide the host's step)", h, dt);
    long n = (long)nd;
    Dyn save = s->d;
    double r0[TAOS_NR], rm[TAOS_NR], r1[TAOS_NR];
    for (int ax = 0; ax < N_AX; ax++) {
        double c0 = s->d.cmd_prev[ax], c1 = s->d.in[ax];
        for (long k = 0; k < n; k++) {
            double a = c1, b = c1;
            if (s->d.mode == 1) {   /* taos simulate's linear interpolation: c0 + (k / n) (c1 - c0), end points exact */
                a = k == 0 ? c0 : ((double)k / (double)n) * (c1 - c0) + c0;
                b = k + 1 == n ? c1 : ((double)(k + 1) / (double)n) * (c1 - c0) + c0;
            } else if (s->d.mode == 0 && k == 0) {   /* exact: the held command's samples, c0 at the point */
                a = c0;
            }
            for (int j = 0; j < TAOS_NR; j++) { r0[j] = a; r1[j] = b; rm[j] = 0.5 * (a + b); }
            taos_tup3 q = taos_rk4_step(s->d.x[ax], TAOS_NX, s->d.z[ax], r0, TAOS_NR, rm, TAOS_NR, r1, TAOS_NR, dt,
                                        PLANT(ax), s->k1, TAOS_NX, s->k2, TAOS_NX, s->k3, TAOS_NX, s->k4, TAOS_NX,
                                        s->xt, TAOS_NX);
            s->d.z[ax] = q.v[0];
            if (!taos_finite(s->d.x[ax], TAOS_NX, s->d.z[ax])) {
                double tk = now(s) + (k + 1) * dt;
                s->d = save;
                s->d.terminated = 1;
                logmsg(s, fmi2Discard, "logStatusDiscard", "t = %.9g s: %s: state not finite at %.9g s (unstable; "
                       TAOS_LABEL ", dt = %g s); the FMU stays at %.9g s", t, ax ? "yaw" : "pitch", tk, dt, now(s));
                return fmi2Discard;
            }
        }
    }
    s->d.k += n;
    memcpy(s->d.cmd_prev, s->d.in, sizeof s->d.in);
    outputs(s, s->d.in);
#if TAOS_CHECK_ENVELOPE
    for (int ax = 0; ax < N_AX; ax++) {
        double th = s->d.out[ax], fl = s->d.out[6 + ax];
        const char *what = !(fabs(th) <= TAOS_HARD_STOP_RAD) ? "engine angle beyond the hard stops"
                         : !(fabs(fl) <= TAOS_FORCE_LIMIT_N) ? "load force beyond 3 x the stall force" : NULL;
        if (what) {
            double tk = now(s);
            s->d = save;
            s->d.terminated = 1;
            logmsg(s, fmi2Discard, "logStatusDiscard", "t = %.9g s: %s %s at %.9g s (envelope: +-%g rad, +-%g N); the "
                   "FMU stays at %.9g s", t, ax ? "yaw" : "pitch", what, tk, TAOS_HARD_STOP_RAD, TAOS_FORCE_LIMIT_N, now(s));
            return fmi2Discard;
        }
    }
#endif
    return fmi2OK;
}

fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind k, fmi2Status *v) {
    CHECK(c, "fmi2GetStatus", ALL);
    (void)k; (void)v;
    return fmi2Discard;   /* fmi2DoStepStatus and fmi2PendingStatus: the FMU never runs asynchronously */
}

fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind k, fmi2Real *v) {
    CHECK(c, "fmi2GetRealStatus", ALL);
    if (k != fmi2LastSuccessfulTime || v == NULL) return fmi2Discard;
    *v = now(s);
    return fmi2OK;
}

fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind k, fmi2Integer *v) {
    CHECK(c, "fmi2GetIntegerStatus", ALL);
    (void)k; (void)v;
    return fmi2Discard;
}

fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind k, fmi2Boolean *v) {
    CHECK(c, "fmi2GetBooleanStatus", ALL);
    if (k != fmi2Terminated || v == NULL) return fmi2Discard;
    *v = s->d.terminated ? fmi2True : fmi2False;
    return fmi2OK;
}

fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind k, fmi2String *v) {
    CHECK(c, "fmi2GetStringStatus", ALL);
    (void)k; (void)v;
    return fmi2Discard;
}

/* Model-exchange functions are not part of a co-simulation FMU: none is exported. */
