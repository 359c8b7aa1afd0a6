/* FMI 2.0 functions shared by the standalone FMUs' interfaces (fmi2_glue.c, planar; fmi2_glue3d.c,
   3-D): the log line, the state-machine check, the variable types an FMU does not have, the FMU
   state (get/set/free/serialise, a copy of the glue's Dyn struct behind SER_MAGIC and the GUID),
   and the calls the FMUs refuse (directional and input/output derivatives, cancel step).

   Included once by each glue, after it defines Inst (with the members d, state, logging, name,
   logger, alloc, dealloc, env), Dyn (everything a state holds), the ST_* states and
   STATE_NAME, SER_MAGIC, and taos_model.h's TAOS_GUID. Not a translation unit of its own. */

#ifndef TAOS_FMI2_GLUE_COMMON_H
#define TAOS_FMI2_GLUE_COMMON_H

static void logmsg(Inst *s, fmi2Status st, const char *cat, const char *fmt, ...) {
    char buf[512];
    va_list ap;
    if (s == NULL || s->logger == NULL || (st == fmi2OK && !s->logging)) return;
    va_start(ap, fmt);
    vsnprintf(buf, sizeof buf, fmt, ap);
    va_end(ap);
    for (char *p = buf; *p; p++) if (*p == '%') *p = ' ';   /* the host may read it as a format */
    s->logger(s->env, s->name, st, cat, buf);
}

#define ERR(s, ...) (logmsg((s), fmi2Error, "logStatusError", __VA_ARGS__), fmi2Error)

static int allowed(Inst *s, const char *fn, unsigned mask) {
    if (mask & (1u << s->state)) return 1;
    logmsg(s, fmi2Error, "logStatusError", "%s: not allowed in state %s", fn, STATE_NAME[s->state]);
    return 0;
}
#define M(st) (1u << (st))
#define CHECK(c, fn, mask) Inst *s = (Inst *)(c); if (s == NULL) return fmi2Error; if (!allowed(s, fn, (mask))) return fmi2Error
#define ALL (M(ST_INSTANTIATED) | M(ST_INIT) | M(ST_STEP) | M(ST_TERMINATED))   /* any state */

static fmi2Status no_vars(fmi2Component c, const char *fn, size_t n) {
    CHECK(c, fn, ALL);
    return n ? ERR(s, "%s: the FMU has no variable of that type", fn) : fmi2OK;
}
fmi2Status fmi2GetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2Boolean v[]) {
    (void)vr; (void)v; return no_vars(c, "fmi2GetBoolean", n);
}
fmi2Status fmi2SetBoolean(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Boolean v[]) {
    (void)vr; (void)v; return no_vars(c, "fmi2SetBoolean", n);
}
fmi2Status fmi2GetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, fmi2String v[]) {
    (void)vr; (void)v; return no_vars(c, "fmi2GetString", n);
}
fmi2Status fmi2SetString(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2String v[]) {
    (void)vr; (void)v; return no_vars(c, "fmi2SetString", n);
}


/* -- FMU state -------------------------------------------------------------------------- */
fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *st) {
    CHECK(c, "fmi2GetFMUstate", ALL);
    if (st == NULL) return ERR(s, "fmi2GetFMUstate: no state pointer");
    if (*st == NULL) *st = s->alloc(1, sizeof(Dyn));
    if (*st == NULL) return ERR(s, "fmi2GetFMUstate: out of memory");
    memcpy(*st, &s->d, sizeof(Dyn));
    return fmi2OK;
}

fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate st) {
    CHECK(c, "fmi2SetFMUstate", ALL);
    if (st == NULL) return ERR(s, "fmi2SetFMUstate: no state");
    memcpy(&s->d, st, sizeof(Dyn));
    return fmi2OK;
}

fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *st) {
    CHECK(c, "fmi2FreeFMUstate", ALL);
    if (st != NULL && *st != NULL) { s->dealloc(*st); *st = NULL; }
    return fmi2OK;
}

#define SER_HEAD (sizeof SER_MAGIC + sizeof TAOS_GUID)

fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate st, size_t *size) {
    CHECK(c, "fmi2SerializedFMUstateSize", ALL);
    (void)st;
    *size = SER_HEAD + sizeof(Dyn);
    return fmi2OK;
}

fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate st, fmi2Byte out[], size_t size) {
    CHECK(c, "fmi2SerializeFMUstate", ALL);
    if (st == NULL || out == NULL || size < SER_HEAD + sizeof(Dyn))
        return ERR(s, "fmi2SerializeFMUstate: no state, or a buffer shorter than fmi2SerializedFMUstateSize");
    memcpy(out, SER_MAGIC, sizeof SER_MAGIC);
    memcpy(out + sizeof SER_MAGIC, TAOS_GUID, sizeof TAOS_GUID);
    memcpy(out + SER_HEAD, st, sizeof(Dyn));
    return fmi2OK;
}

fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte in[], size_t size, fmi2FMUstate *st) {
    CHECK(c, "fmi2DeSerializeFMUstate", ALL);
    if (in == NULL || st == NULL || size != SER_HEAD + sizeof(Dyn) || memcmp(in, SER_MAGIC, sizeof SER_MAGIC)
        || memcmp(in + sizeof SER_MAGIC, TAOS_GUID, sizeof TAOS_GUID))
        return ERR(s, "fmi2DeSerializeFMUstate: not a state serialised by this FMU (size, format or GUID)");
    if (*st == NULL) *st = s->alloc(1, sizeof(Dyn));
    if (*st == NULL) return ERR(s, "fmi2DeSerializeFMUstate: out of memory");
    memcpy(*st, in + SER_HEAD, sizeof(Dyn));
    return fmi2OK;
}

fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference u[], size_t nu,
                                        const fmi2ValueReference z[], size_t nz, const fmi2Real dv[], fmi2Real dz[]) {
    CHECK(c, "fmi2GetDirectionalDerivative", ALL);
    (void)u; (void)nu; (void)z; (void)nz; (void)dv; (void)dz;
    return ERR(s, "fmi2GetDirectionalDerivative: not provided (providesDirectionalDerivative=false)");
}

/* -- co-simulation ---------------------------------------------------------------------- */
fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Integer o[],
                                       const fmi2Real v[]) {
    CHECK(c, "fmi2SetRealInputDerivatives", ALL);
    (void)vr; (void)n; (void)o; (void)v;
    return ERR(s, "fmi2SetRealInputDerivatives: not supported (canInterpolateInputs=false)");
}

fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t n, const fmi2Integer o[],
                                        fmi2Real v[]) {
    CHECK(c, "fmi2GetRealOutputDerivatives", ALL);
    (void)vr; (void)n; (void)o; (void)v;
    return ERR(s, "fmi2GetRealOutputDerivatives: not supported (maxOutputDerivativeOrder=0)");
}

fmi2Status fmi2CancelStep(fmi2Component c) {
    CHECK(c, "fmi2CancelStep", ALL);
    return ERR(s, "fmi2CancelStep: the FMU never runs asynchronously");
}


#endif
