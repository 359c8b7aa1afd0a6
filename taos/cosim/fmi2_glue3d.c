/* FMI 2.0 co-simulation interface of the standalone 3-D taos TVC FMU (taos fmu --engine taos).

   Hand-written FMI interface, no dynamics: the whole 3-D step (RK4 of the engine body and the
   two actuators, the bearing's BDF2 substeps with the friction law's implicit solve, the
   trapezoidal torque kick, the records) is taos3d_steps in taos_kernels.c, which taos emits
   from the compiled kernels' own Python (taos.taos3d.dynamics._steps; taos.cosim._ccode); the
   model's packed numbers (taos.taos3d.simulate.pack) are constants in taos_model.h.

   A communication step of n internal steps of dt runs taos3d_steps over n + 1 command samples,
   pitch and yaw: the first the command in force before the communication point, the others the
   command set for this step (a command held over each communication step, as taos simulate
   of its samples; exact at every communication point). The outputs are the record at the
   step's end (engine angles, pistons, load forces and pressures, friction torques,
   post-avionics commands, bearing slips).

   Statuses as fmi2_glue.c: a host mistake is fmi2Error with one log line and changes nothing;
   a step whose state becomes non-finite or leaves the envelope is fmi2Discard, the FMU stays
   at the step's start and reports fmi2Terminated = true. The internal step is a fixed
   parameter (set before initialisation ends, within (0, TAOS_DT_MAX]). */

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "fmi2Functions.h"
#include "taos_kernels.h"
#include "taos_model.h"

#define N_AX 2
#define VR_OUT0 2                   /* Real value references: 0, 1 the commands, 2.. the outputs */
#define VR_DT (VR_OUT0 + TAOS_NOUT) /* internal_step_s */
#define TIME_TOL (1e-3 * s->d.dt)   /* a communication point is the FMU's time within this [s] */
#define STEP_TOL (1e-6 * s->d.dt)   /* a step is a whole multiple of dt within this [s] */

enum { ST_INSTANTIATED, ST_INIT, ST_STEP, ST_TERMINATED };
static const char *const STATE_NAME[] = {"instantiated", "initialization mode", "stepping", "terminated"};

/* Everything an FMU state (fmi2GetFMUstate) holds. */
typedef struct {
    double x[TAOS_NX];        /* engine body and actuators (taos.taos3d.dynamics X_*) [SI] */
    double bs[TAOS_NBS];      /* bearing state (BS_*) */
    long k;                   /* internal steps since the start */
    double cmd_prev[N_AX];    /* commands at the last communication point [rad] */
    double in[N_AX];          /* the inputs as set [rad] */
    double out[TAOS_NOUT];    /* outputs at the last communication point [SI] */
    double dt;                /* internal step [s] */
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
    taos_nt_TaosParams P;
    double ks[5][TAOS_NX], aux[TAOS_NAUX], cs[4][2], kc[2][2], rec[2][TAOS_NREC];
    double *r;                /* command samples (n + 1, 2), grown with the host's memory */
    long r_rows;
} Inst;

#define SER_MAGIC "taos-fmu-state-1"

#include "fmi2_glue_common.h"   /* logging, state checks, FMU state, unsupported calls */


/* Run n internal steps from the state with samples r (n + 1 rows); the record at the end into
   s->rec[n > 0]; returns -1 or the failing step. */
static long run(Inst *s, long n) {
    return taos3d_steps(&s->P, (double *)taos_fp, TAOS_NFP, (double *)taos_avp, TAOS_NAVP, s->d.x, TAOS_NX,
                        s->d.bs, TAOS_NBS, s->r, n + 1, 2, s->d.dt, n > 0 ? n : 1, &s->rec[0][0], n > 0 ? 2 : 1,
                        TAOS_NREC, &s->ks[0][0], 5, TAOS_NX, s->aux, TAOS_NAUX, &s->cs[0][0], 4, 2, &s->kc[0][0], 2, 2);
}

static int grow(Inst *s, long n) {
    if (s->r_rows >= n + 1) return 1;
    double *r = (double *)s->alloc((size_t)(n + 1) * 2, sizeof(double));
    if (r == NULL) return 0;
    if (s->r) s->dealloc(s->r);
    s->r = r;
    s->r_rows = n + 1;
    return 1;
}

static void take_outputs(Inst *s, int row) {
    for (int o = 0; o < TAOS_NOUT; o++) s->d.out[o] = s->rec[row][taos_out_col[o]];
}

/* Outputs at rest (before and at the end of initialisation): the record with no step. */
static void outputs_at_rest(Inst *s) {
    Dyn save = s->d;
    s->r[0] = s->d.in[0];
    s->r[1] = s->d.in[1];
    (void)run(s, 0);
    s->d = save;
    take_outputs(s, 0);
}

static void defaults(Inst *s) {
    memset(&s->d, 0, sizeof s->d);
    s->d.dt = TAOS_DT;
}

static void rest(Inst *s) {
    memset(s->d.x, 0, sizeof s->d.x);
    s->d.x[TAOS_XQW] = 1.0;   /* identity quaternion */
    memset(s->d.bs, 0, sizeof s->d.bs);
    s->d.k = 0;
    s->d.terminated = 0;
}

static double now(const Inst *s) { return s->d.t0 + s->d.k * s->d.dt; }

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
    taos_bind(&s->P);
    defaults(s);
    rest(s);
    if (!grow(s, 1)) {
        f->freeMemory(nm);
        f->freeMemory(s);
        logmsg(&tmp, fmi2Error, "logStatusError", "fmi2Instantiate: out of memory");
        return NULL;
    }
    s->state = ST_INSTANTIATED;
    return s;
}

void fmi2FreeInstance(fmi2Component c) {
    Inst *s = (Inst *)c;
    if (s == NULL) return;
    fmi2CallbackFreeMemory dealloc = s->dealloc;
    if (s->r) dealloc(s->r);
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
    outputs_at_rest(s);
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
    rest(s);
    s->state = ST_INSTANTIATED;
    return fmi2OK;
}

/* -- variables -------------------------------------------------------------------------- */

fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Real v[]) {
    CHECK(c, "fmi2GetReal", ALL);
    if (n > 0 && (vr == NULL || v == NULL)) return ERR(s, "fmi2GetReal: no value references or no values");
    if (s->state == ST_INSTANTIATED || s->state == ST_INIT) outputs_at_rest(s);   /* the initial values */
    for (size_t i = 0; i < n; i++) {
        if (vr[i] < VR_OUT0) v[i] = s->d.in[vr[i]];
        else if (vr[i] < VR_OUT0 + TAOS_NOUT) v[i] = s->d.out[vr[i] - VR_OUT0];
        else if (vr[i] == VR_DT) v[i] = s->d.dt;
        else return ERR(s, "fmi2GetReal: no Real with value reference %u", vr[i]);
    }
    return fmi2OK;
}

fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Real v[]) {
    CHECK(c, "fmi2SetReal", M(ST_INSTANTIATED) | M(ST_INIT) | M(ST_STEP));
    if (n > 0 && (vr == NULL || v == NULL)) return ERR(s, "fmi2SetReal: no value references or no values");
    for (size_t i = 0; i < n; i++) {   /* every value checked before any is taken */
        if (vr[i] == VR_DT) {
            if (s->state == ST_STEP) return ERR(s, "internal_step_s: a fixed parameter, set only before initialisation ends");
            if (!(v[i] > 0 && v[i] <= TAOS_DT_MAX))
                return ERR(s, "internal_step_s: expected a step above 0 and at most %g s, got %g", TAOS_DT_MAX, v[i]);
        } else if (vr[i] >= VR_OUT0) {
            return ERR(s, "fmi2SetReal: value reference %u is an output or no Real, which cannot be set", vr[i]);
        } else if (!(fabs(v[i]) <= TAOS_COMMAND_RANGE_RAD)) {
            return ERR(s, "%s_command_rad: expected a command within the gimbal range +-%g rad, got %g",
                       vr[i] == 0 ? "pitch" : "yaw", TAOS_COMMAND_RANGE_RAD, v[i]);
        }
    }
    for (size_t i = 0; i < n; i++) {
        if (vr[i] < VR_OUT0) s->d.in[vr[i]] = v[i];
        else s->d.dt = v[i];
    }
    return fmi2OK;
}

fmi2Status fmi2GetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Integer v[]) {
    (void)vr; (void)v; return no_vars(c, "fmi2GetInteger", n);
}
fmi2Status fmi2SetInteger(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Integer v[]) {
    (void)vr; (void)v; return no_vars(c, "fmi2SetInteger", n);
}

fmi2Status fmi2DoStep(fmi2Component c, fmi2Real t, fmi2Real h, fmi2Boolean noSetPrior) {
    CHECK(c, "fmi2DoStep", M(ST_STEP));
    (void)noSetPrior;
    if (s->d.terminated)
        return ERR(s, "fmi2DoStep: the FMU reported fmi2Terminated at t = %.9g s; reset it or set an earlier state", now(s));
    if (!(fabs(t - now(s)) <= TIME_TOL))
        return ERR(s, "fmi2DoStep: currentCommunicationPoint %.12g s is not the FMU's time %.12g s", t, now(s));
    double dt = s->d.dt;
    double nd = isfinite(h) && h > 0 ? floor(h / dt + 0.5) : 0.0;
    if (nd < 1 || nd > 1e9 || fabs(h - nd * dt) > STEP_TOL)
        return ERR(s, "fmi2DoStep: communication step %.12g s: expected a positive whole multiple of the internal "
                   "step %g s (set internal_step_s to divide the host's step)", h, dt);
    long n = (long)nd;
    if (!grow(s, n)) return ERR(s, "fmi2DoStep: out of memory for %ld command samples", n + 1);
    Dyn save = s->d;
    for (long k = 0; k <= n; k++)
        for (int ax = 0; ax < N_AX; ax++) s->r[2 * k + ax] = k == 0 ? s->d.cmd_prev[ax] : s->d.in[ax];
    long bad = run(s, n);
    if (bad >= 0) {
        double tk = now(s) + bad * dt;
        s->d = save;
        s->d.terminated = 1;
        logmsg(s, fmi2Discard, "logStatusDiscard", "t = %.9g s: state not finite at %.9g s (unstable; " TAOS_LABEL
               ", dt = %g s); the FMU stays at %.9g s", t, tk, dt, now(s));
        return fmi2Discard;
    }
    s->d.k += n;
    memcpy(s->d.cmd_prev, s->d.in, sizeof s->d.in);
    take_outputs(s, 1);
    for (int ax = 0; ax < N_AX; ax++) {
        double th = s->d.out[TAOS_OUT_THETA + ax], fl = s->d.out[TAOS_OUT_FL + ax];
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
