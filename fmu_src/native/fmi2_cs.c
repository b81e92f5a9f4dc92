/*
 * fmi2_cs.c: the FMI 2.0 co-simulation interface around a model (fmu_model.h), model-agnostic: the same
 * file builds RotorCasingContact and LPSpool.
 *
 * What a system simulator can rely on:
 *   - every misuse is fmi2Error with a logged message that names the variable, the value and the
 *     accepted range or the rule (never a silent fmi2OK, never fmi2Fatal, never a crash): an unknown
 *     value reference, a type mismatch, setting an output, a fixed parameter after initialisation, a
 *     value outside its declared [min, max] or not finite, or one that breaks a rule of the model
 *     (refused at the fmi2Set call, the old value kept), a communication point that is not the FMU's
 *     time, fmi2DoStep before initialisation or after fmi2Terminate, a bad or foreign FMU state;
 *   - configuration errors are reported by fmi2ExitInitializationMode (fmi2Error; the parameters can
 *     be corrected and the call repeated);
 *   - a step the model cannot complete (a divergence, a spool that stops, no balanced solution) is
 *     fmi2Discard with the reason in the log and in 'message'; from then on
 *     fmi2GetBooleanStatus(fmi2Terminated) is fmi2True and fmi2GetRealStatus(fmi2LastSuccessfulTime)
 *     the time the model reached, so that every master ends the run cleanly with what it has. The flag
 *     belongs to the FMU state: fmi2SetFMUstate to a state saved before the step (or fmi2Reset) clears
 *     it and the run goes on; a further fmi2DoStep without that is fmi2Error;
 *   - fmi2SetFMUstate works in every state FMI 2.0 allows it, the instantiated one included: a state
 *     saved during a run is restored with its model (configured from the state's own parameters);
 *   - errors and warnings reach the logger whether or not logging was switched on (debug messages only
 *     when it was), and the last message is in the 'message' output. Numbers in messages are written as
 *     the shortest decimal that reads back to the same double.
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"
#include "fmu_model.h"

typedef enum { PH_INSTANTIATED, PH_INITIALIZATION, PH_STEP, PH_TERMINATED } phase_t;
static const char *PHASE_NAME[] = {"instantiated", "initialization mode", "step mode", "terminated"};

#define MSG_LEN 1024
#define STATE_MAGIC 0x52524632u /* "RRF2" */

typedef struct {
    char *name;
    fmi2CallbackFunctions cb;
    int logging;
    phase_t phase;
    double time;
    double last_good;
    double *r;
    int *i;
    char message[MSG_LEN];
    int stopped; /* the model ended the run (a discarded step): fmi2Terminated */
    char stop_reason[MSG_LEN];
    model_values v;
    model_runtime *m;
    int inputs_changed; /* feedthrough: outputs to recompute before a read */
} inst_t;

typedef struct {
    unsigned magic;
    const model_info *info; /* &MODEL_INFO of the binary that made it: another FMU's (or build's) is refused */
    const inst_t *owner;
    phase_t phase;
    double time, last_good;
    double *r;
    int *i;
    char message[MSG_LEN];
    int stopped;
    char stop_reason[MSG_LEN];
    size_t n_model;
    double *model;
} snapshot_t;

#define N_VARS ((size_t)MODEL_INFO.n_vars)
/* a snapshot this binary made: every FMU built on this wrapper shares STATE_MAGIC, and the model state's
 * size alone does not tell two builds of one model apart */
#define IS_OURS(p) ((p) && (p)->magic == STATE_MAGIC && (p)->info == &MODEL_INFO)
#define VAR(vr) (&MODEL_INFO.vars[vr])

/* the shortest decimal that reads back as x (%.17g writes 640.8 as 640.79999999999995) */
static const char *num(double x, char *buf, size_t len)
{
    int p;
    for (p = 1; p <= 17; ++p) {
        snprintf(buf, len, "%.*g", p, x);
        if (strtod(buf, NULL) == x) break;
    }
    return buf;
}

/* ------------------------------------------------------------------ logging and errors */

/* Hand a formatted message to the host's logger. The message is passed as the format: loggers that do not
 * format (fmpy's) see it as it is, and a '%' is doubled for those that do. */
static void emit(const fmi2CallbackFunctions *cb, const char *name, fmi2Status status, const char *category,
                 const char *text)
{
    char fmt_buf[2 * MSG_LEN];
    size_t k, j = 0;
    for (k = 0; text[k] && j + 2 < sizeof fmt_buf; ++k) {
        fmt_buf[j++] = text[k];
        if (text[k] == '%') fmt_buf[j++] = '%';
    }
    fmt_buf[j] = '\0';
    cb->logger(cb->componentEnvironment, name, status, category, fmt_buf);
}

static void logv(inst_t *c, fmi2Status status, const char *category, const char *fmt, va_list ap)
{
    char buf[MSG_LEN];
    vsnprintf(buf, sizeof buf, fmt, ap);
    if (status >= fmi2Discard) {
        memcpy(c->message, buf, sizeof buf);
        c->message[MSG_LEN - 1] = '\0';
    }
    if (c->cb.logger && (status >= fmi2Warning || c->logging)) emit(&c->cb, c->name, status, category, buf);
}

/* A refused call: logged (status fmi2Error or fmi2Discard), its cause in 'message', and for an
 * error the 'status' output says bad input or configuration. */
static fmi2Status fail(inst_t *c, fmi2Status status, const char *fmt, ...)
{
    va_list ap;
    if (status == fmi2Error) c->i[MODEL_INFO.vr_status] = STATUS_BAD_INPUT;
    va_start(ap, fmt);
    logv(c, status, status == fmi2Error ? "logStatusError" : "logStatusDiscard", fmt, ap);
    va_end(ap);
    return status;
}

static void debug(inst_t *c, const char *fmt, ...)
{
    va_list ap;
    if (!c->logging) return;
    va_start(ap, fmt);
    logv(c, fmi2OK, "logAll", fmt, ap);
    va_end(ap);
}

#define INST(c) ((inst_t *)(c))
#define CHECK_INSTANCE(c, fn)                                                                                          \
    do {                                                                                                               \
        if (!(c)) return fmi2Error;                                                                                    \
        if (INST(c)->phase > PH_TERMINATED) return fail(INST(c), fmi2Error, "%s: invalid instance", fn);             \
    } while (0)

/* ------------------------------------------------------------------ values */

/* FMI 2.0 co-simulation: values are read from fmi2EnterInitializationMode on (the start values before that are
 * the model description's) */
static fmi2Status check_readable(inst_t *c, const char *fn)
{
    if (c->phase == PH_INSTANTIATED)
        return fail(c, fmi2Error, "%s: the instance is instantiated: values are read from "
                    "fmi2EnterInitializationMode on (the start values are in modelDescription.xml)", fn);
    return fmi2OK;
}

/* the only String a model has is its 'message' output (the build refuses any other) */
static void set_starts(inst_t *c)
{
    size_t k;
    for (k = 0; k < N_VARS; ++k) {
        const model_var *v = VAR(k);
        c->r[k] = v->name && v->type == VT_REAL ? v->start : 0.0;
        c->i[k] = v->name && (v->type == VT_INTEGER || v->type == VT_ENUM) ? (int)v->start : 0;
    }
    c->message[0] = '\0';
    c->stopped = 0;
    c->stop_reason[0] = '\0';
}

static fmi2Status check_vr(inst_t *c, const char *fn, fmi2ValueReference vr, int want_real, int want_int,
                           int want_str)
{
    const model_var *v;
    if (vr >= (fmi2ValueReference)MODEL_INFO.n_vars || !VAR(vr)->name)
        return fail(c, fmi2Error, "%s: unknown value reference %u (not a variable of this FMU: see its "
                    "modelDescription.xml)", fn, vr);
    v = VAR(vr);
    if ((want_real && v->type != VT_REAL) || (want_int && v->type != VT_INTEGER && v->type != VT_ENUM) ||
        (want_str && v->type != VT_STRING)) {
        static const char *TYPE[] = {"Real", "Integer", "Enumeration", "String"};
        return fail(c, fmi2Error, "%s: %s (value reference %u) is of type %s", fn, v->name, vr, TYPE[v->type]);
    }
    return fmi2OK;
}

/* may variable vr be set now? */
static fmi2Status check_settable(inst_t *c, const char *fn, fmi2ValueReference vr)
{
    const model_var *v = VAR(vr);
    if (v->causality == VC_OUTPUT)
        return fail(c, fmi2Error, "%s: %s is an output and cannot be set", fn, v->name);
    if (c->phase == PH_TERMINATED)
        return fail(c, fmi2Error, "%s: %s: the instance is terminated (fmi2Reset or fmi2FreeInstance)", fn, v->name);
    if (c->stopped) /* FMI 2.0: no inputs in stepFailed (after fmi2Discard): the master rolls back or ends */
        return fail(c, fmi2Error, "%s: %s: the FMU ended this simulation (fmi2Terminated is true): %s; roll back with "
                    "fmi2SetFMUstate first, or fmi2Terminate / fmi2Reset", fn, v->name, c->stop_reason);
    if (v->variability == VV_FIXED && c->phase == PH_STEP)
        return fail(c, fmi2Error, "%s: %s is a fixed parameter: it cannot change after initialisation (fmi2Reset "
                    "first)", fn, v->name);
    return fmi2OK;
}

static fmi2Status check_range(inst_t *c, const char *fn, fmi2ValueReference vr, double x)
{
    const model_var *v = VAR(vr);
    char bx[32], blo[32], bhi[32], msg[MSG_LEN];
    if (!isfinite(x))
        return fail(c, fmi2Error, "%s: %s = %g is not finite; accepted range [%s, %s]", fn, v->name, x,
                    num(v->min, blo, sizeof blo), num(v->max, bhi, sizeof bhi));
    if (v->has_range && (x < v->min || x > v->max))
        return fail(c, fmi2Error, "%s: %s = %s out of range; accepted range [%s, %s]", fn, v->name,
                    num(x, bx, sizeof bx), num(v->min, blo, sizeof blo), num(v->max, bhi, sizeof bhi));
    /* a rule of the model between this variable and the fixed ones, once they are fixed */
    if (c->m && c->phase == PH_STEP && v->causality != VC_OUTPUT &&
        model_check_set(c->m, &c->v, (int)vr, x, msg, sizeof msg) != fmi2OK)
        return fail(c, fmi2Error, "%s: %s", fn, msg);
    return fmi2OK;
}

static void after_set(inst_t *c, fmi2ValueReference vr)
{
    if (VAR(vr)->causality == VC_INPUT || VAR(vr)->variability == VV_TUNABLE) c->inputs_changed = 1;
}

/* feedthrough build: the outputs are the model's at the current inputs */
static fmi2Status refresh_outputs(inst_t *c)
{
    char msg[MSG_LEN];
    fmi2Status s;
    if (!MODEL_INFO.feedthrough || !c->inputs_changed || !c->m || c->phase != PH_STEP) return fmi2OK;
    c->inputs_changed = 0;
    s = model_solve_now(c->m, &c->v, c->time, msg, sizeof msg);
    if (s != fmi2OK) {
        c->i[MODEL_INFO.vr_status] = STATUS_DIVERGED;
        return fail(c, s, "%s", msg);
    }
    return fmi2OK;
}

/* ------------------------------------------------------------------ FMI: common functions */

const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }

const char *fmi2GetVersion(void) { return fmi2Version; }

fmi2Status fmi2SetDebugLogging(fmi2Component comp, fmi2Boolean loggingOn, size_t nCategories,
                               const fmi2String categories[])
{
    static const char *KNOWN[] = {"logStatusWarning", "logStatusDiscard", "logStatusError", "logStatusFatal",
                                  "logAll"};
    inst_t *c = INST(comp);
    size_t k, j;
    CHECK_INSTANCE(comp, "fmi2SetDebugLogging");
    for (k = 0; k < nCategories; ++k) {
        int found = 0;
        for (j = 0; j < sizeof KNOWN / sizeof KNOWN[0]; ++j)
            if (categories && categories[k] && strcmp(categories[k], KNOWN[j]) == 0) found = 1;
        if (!found)
            return fail(c, fmi2Error, "fmi2SetDebugLogging: unknown log category '%s'; accepted: logStatusWarning, "
                        "logStatusDiscard, logStatusError, logStatusFatal, logAll",
                        categories && categories[k] ? categories[k] : "(null)");
    }
    c->logging = loggingOn ? 1 : 0;
    return fmi2OK;
}

fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType, fmi2String fmuGUID,
                              fmi2String fmuResourceLocation, const fmi2CallbackFunctions *functions,
                              fmi2Boolean visible, fmi2Boolean loggingOn)
{
    inst_t *c;
    int n = MODEL_INFO.n_vars;
    (void)fmuResourceLocation;
    (void)visible;
    if (!functions || !functions->logger) return NULL; /* FMI 2.0: the logger is mandatory */
    if (!instanceName || !instanceName[0]) {
        functions->logger(functions->componentEnvironment, "?", fmi2Error, "logStatusError",
                          "fmi2Instantiate: missing instance name");
        return NULL;
    }
    if (fmuType != fmi2CoSimulation) {
        functions->logger(functions->componentEnvironment, instanceName, fmi2Error, "logStatusError",
                          "fmi2Instantiate: this FMU supports co-simulation only (fmuType = fmi2CoSimulation)");
        return NULL;
    }
    if (!fmuGUID || strcmp(fmuGUID, MODEL_INFO.guid) != 0) {
        char buf[MSG_LEN];
        snprintf(buf, sizeof buf, "fmi2Instantiate: GUID '%s' is not this FMU's (%s): modelDescription.xml and the "
                 "binary come from different builds", fmuGUID ? fmuGUID : "(null)", MODEL_INFO.guid);
        emit(functions, instanceName, fmi2Error, "logStatusError", buf);
        return NULL;
    }
    c = (inst_t *)calloc(1, sizeof *c);
    if (!c) return NULL;
    c->name = (char *)malloc(strlen(instanceName) + 1);
    c->r = (double *)calloc((size_t)n, sizeof(double));
    c->i = (int *)calloc((size_t)n, sizeof(int));
    if (!c->name || !c->r || !c->i) {
        free(c->name);
        free(c->r);
        free(c->i);
        free(c);
        functions->logger(functions->componentEnvironment, instanceName, fmi2Error, "logStatusError",
                          "fmi2Instantiate: out of memory");
        return NULL;
    }
    strcpy(c->name, instanceName);
    c->cb = *functions;
    c->logging = loggingOn ? 1 : 0;
    c->phase = PH_INSTANTIATED;
    c->v.r = c->r;
    c->v.i = c->i;
    set_starts(c);
    debug(c, "fmi2Instantiate: %s", instanceName);
    return c;
}

void fmi2FreeInstance(fmi2Component comp)
{
    inst_t *c = INST(comp);
    if (!c) return;
    model_free(c->m);
    free(c->name);
    free(c->r);
    free(c->i);
    free(c);
}

fmi2Status fmi2SetupExperiment(fmi2Component comp, fmi2Boolean toleranceDefined, fmi2Real tolerance,
                               fmi2Real startTime, fmi2Boolean stopTimeDefined, fmi2Real stopTime)
{
    inst_t *c = INST(comp);
    CHECK_INSTANCE(comp, "fmi2SetupExperiment");
    (void)toleranceDefined;
    (void)tolerance;
    if (c->phase != PH_INSTANTIATED)
        return fail(c, fmi2Error, "fmi2SetupExperiment: allowed only before fmi2EnterInitializationMode (the "
                    "instance is in %s)", PHASE_NAME[c->phase]);
    if (!isfinite(startTime))
        return fail(c, fmi2Error, "fmi2SetupExperiment: startTime = %g is not finite", startTime);
    if (stopTimeDefined && !(stopTime >= startTime))
        return fail(c, fmi2Error, "fmi2SetupExperiment: stopTime = %g is before startTime = %g", stopTime, startTime);
    c->time = c->last_good = startTime;
    return fmi2OK;
}

fmi2Status fmi2EnterInitializationMode(fmi2Component comp)
{
    inst_t *c = INST(comp);
    CHECK_INSTANCE(comp, "fmi2EnterInitializationMode");
    if (c->phase != PH_INSTANTIATED)
        return fail(c, fmi2Error, "fmi2EnterInitializationMode: the instance is in %s", PHASE_NAME[c->phase]);
    c->phase = PH_INITIALIZATION;
    return fmi2OK;
}

fmi2Status fmi2ExitInitializationMode(fmi2Component comp)
{
    inst_t *c = INST(comp);
    char msg[MSG_LEN];
    fmi2Status s;
    CHECK_INSTANCE(comp, "fmi2ExitInitializationMode");
    if (c->phase != PH_INITIALIZATION)
        return fail(c, fmi2Error, "fmi2ExitInitializationMode: the instance is in %s", PHASE_NAME[c->phase]);
    model_free(c->m);
    c->m = model_configure(&c->v, c->time, msg, sizeof msg);
    if (!c->m) return fail(c, fmi2Error, "fmi2ExitInitializationMode: %s", msg);
    c->phase = PH_STEP;
    c->i[MODEL_INFO.vr_status] = STATUS_OK;
    c->message[0] = '\0';
    c->stopped = 0;
    c->stop_reason[0] = '\0';
    c->inputs_changed = 0;
    s = model_solve_now(c->m, &c->v, c->time, msg, sizeof msg);
    if (s != fmi2OK) {
        /* quasi-static: no balanced solution at the initial inputs; the first step reports it again */
        c->i[MODEL_INFO.vr_status] = STATUS_DIVERGED;
        fail(c, fmi2Warning, "fmi2ExitInitializationMode: %s", msg);
        return fmi2Warning;
    }
    return fmi2OK;
}

fmi2Status fmi2Terminate(fmi2Component comp)
{
    inst_t *c = INST(comp);
    CHECK_INSTANCE(comp, "fmi2Terminate");
    if (c->phase != PH_STEP) /* FMI 2.0 co-simulation: after initialisation only (fmi2Reset ends the others) */
        return fail(c, fmi2Error, "fmi2Terminate: the instance is in %s (a simulation ends with fmi2Terminate "
                    "once it is initialised; fmi2Reset or fmi2FreeInstance end it in any state)", PHASE_NAME[c->phase]);
    c->phase = PH_TERMINATED;
    return fmi2OK;
}

fmi2Status fmi2Reset(fmi2Component comp)
{
    inst_t *c = INST(comp);
    CHECK_INSTANCE(comp, "fmi2Reset");
    model_free(c->m);
    c->m = NULL;
    c->phase = PH_INSTANTIATED;
    c->time = c->last_good = 0.0;
    c->inputs_changed = 0;
    set_starts(c);
    return fmi2OK;
}

fmi2Status fmi2GetReal(fmi2Component comp, const fmi2ValueReference vr[], size_t nvr, fmi2Real value[])
{
    inst_t *c = INST(comp);
    size_t k;
    fmi2Status s;
    CHECK_INSTANCE(comp, "fmi2GetReal");
    if ((s = check_readable(c, "fmi2GetReal")) != fmi2OK) return s;
    if (nvr && (!vr || !value)) return fail(c, fmi2Error, "fmi2GetReal: NULL array");
    for (k = 0; k < nvr; ++k)
        if ((s = check_vr(c, "fmi2GetReal", vr[k], 1, 0, 0)) != fmi2OK) return s;
    if ((s = refresh_outputs(c)) > fmi2Warning) return s;
    for (k = 0; k < nvr; ++k) value[k] = c->r[vr[k]];
    return fmi2OK;
}

fmi2Status fmi2GetInteger(fmi2Component comp, const fmi2ValueReference vr[], size_t nvr, fmi2Integer value[])
{
    inst_t *c = INST(comp);
    size_t k;
    fmi2Status s;
    CHECK_INSTANCE(comp, "fmi2GetInteger");
    if ((s = check_readable(c, "fmi2GetInteger")) != fmi2OK) return s;
    if (nvr && (!vr || !value)) return fail(c, fmi2Error, "fmi2GetInteger: NULL array");
    for (k = 0; k < nvr; ++k)
        if ((s = check_vr(c, "fmi2GetInteger", vr[k], 0, 1, 0)) != fmi2OK) return s;
    if ((s = refresh_outputs(c)) > fmi2Warning) return s;
    for (k = 0; k < nvr; ++k) value[k] = c->i[vr[k]];
    return fmi2OK;
}

fmi2Status fmi2GetBoolean(fmi2Component comp, const fmi2ValueReference vr[], size_t nvr, fmi2Boolean value[])
{
    inst_t *c = INST(comp);
    (void)value;
    CHECK_INSTANCE(comp, "fmi2GetBoolean");
    if (nvr == 0) return fmi2OK;
    if (!vr) return fail(c, fmi2Error, "fmi2GetBoolean: NULL array");
    if (check_vr(c, "fmi2GetBoolean", vr[0], 0, 0, 0) != fmi2OK) return fmi2Error;
    return fail(c, fmi2Error, "fmi2GetBoolean: %s is not a Boolean (this FMU has no Boolean variable)",
                VAR(vr[0])->name);
}

fmi2Status fmi2GetString(fmi2Component comp, const fmi2ValueReference vr[], size_t nvr, fmi2String value[])
{
    inst_t *c = INST(comp);
    size_t k;
    fmi2Status s;
    CHECK_INSTANCE(comp, "fmi2GetString");
    if ((s = check_readable(c, "fmi2GetString")) != fmi2OK) return s;
    if (nvr && (!vr || !value)) return fail(c, fmi2Error, "fmi2GetString: NULL array");
    for (k = 0; k < nvr; ++k)
        if ((s = check_vr(c, "fmi2GetString", vr[k], 0, 0, 1)) != fmi2OK) return s;
    for (k = 0; k < nvr; ++k) value[k] = c->message;
    return fmi2OK;
}

fmi2Status fmi2SetReal(fmi2Component comp, const fmi2ValueReference vr[], size_t nvr, const fmi2Real value[])
{
    inst_t *c = INST(comp);
    size_t k;
    fmi2Status s;
    CHECK_INSTANCE(comp, "fmi2SetReal");
    if (nvr && (!vr || !value)) return fail(c, fmi2Error, "fmi2SetReal: NULL array");
    /* all or nothing: check every value before storing any */
    for (k = 0; k < nvr; ++k) {
        if ((s = check_vr(c, "fmi2SetReal", vr[k], 1, 0, 0)) != fmi2OK) return s;
        if ((s = check_settable(c, "fmi2SetReal", vr[k])) != fmi2OK) return s;
        if ((s = check_range(c, "fmi2SetReal", vr[k], value[k])) != fmi2OK) return s;
    }
    for (k = 0; k < nvr; ++k) {
        if (c->r[vr[k]] != value[k]) after_set(c, vr[k]);
        c->r[vr[k]] = value[k];
    }
    return fmi2OK;
}

fmi2Status fmi2SetInteger(fmi2Component comp, const fmi2ValueReference vr[], size_t nvr, const fmi2Integer value[])
{
    inst_t *c = INST(comp);
    size_t k;
    fmi2Status s;
    CHECK_INSTANCE(comp, "fmi2SetInteger");
    if (nvr && (!vr || !value)) return fail(c, fmi2Error, "fmi2SetInteger: NULL array");
    for (k = 0; k < nvr; ++k) {
        if ((s = check_vr(c, "fmi2SetInteger", vr[k], 0, 1, 0)) != fmi2OK) return s;
        if ((s = check_settable(c, "fmi2SetInteger", vr[k])) != fmi2OK) return s;
        if ((s = check_range(c, "fmi2SetInteger", vr[k], (double)value[k])) != fmi2OK) return s;
    }
    for (k = 0; k < nvr; ++k) c->i[vr[k]] = value[k];
    return fmi2OK;
}

fmi2Status fmi2SetBoolean(fmi2Component comp, const fmi2ValueReference vr[], size_t nvr, const fmi2Boolean value[])
{
    inst_t *c = INST(comp);
    (void)value;
    CHECK_INSTANCE(comp, "fmi2SetBoolean");
    if (nvr == 0) return fmi2OK;
    if (!vr) return fail(c, fmi2Error, "fmi2SetBoolean: NULL array");
    if (check_vr(c, "fmi2SetBoolean", vr[0], 0, 0, 0) != fmi2OK) return fmi2Error;
    return fail(c, fmi2Error, "fmi2SetBoolean: %s is not a Boolean (this FMU has no Boolean variable)",
                VAR(vr[0])->name);
}

fmi2Status fmi2SetString(fmi2Component comp, const fmi2ValueReference vr[], size_t nvr, const fmi2String value[])
{
    inst_t *c = INST(comp);
    size_t k;
    fmi2Status s;
    CHECK_INSTANCE(comp, "fmi2SetString");
    if (nvr && (!vr || !value)) return fail(c, fmi2Error, "fmi2SetString: NULL array");
    for (k = 0; k < nvr; ++k) {
        if ((s = check_vr(c, "fmi2SetString", vr[k], 0, 0, 1)) != fmi2OK) return s;
        if ((s = check_settable(c, "fmi2SetString", vr[k])) != fmi2OK) return s;
        if (!value[k]) return fail(c, fmi2Error, "fmi2SetString: %s: NULL string", VAR(vr[k])->name);
    }
    return fmi2OK; /* unreachable: every String is an output, refused by check_settable */
}

/* ------------------------------------------------------------------ FMI: co-simulation */

fmi2Status fmi2SetRealInputDerivatives(fmi2Component comp, const fmi2ValueReference vr[], size_t nvr,
                                       const fmi2Integer order[], const fmi2Real value[])
{
    (void)vr;
    (void)nvr;
    (void)order;
    (void)value;
    CHECK_INSTANCE(comp, "fmi2SetRealInputDerivatives");
    return fail(INST(comp), fmi2Error, "fmi2SetRealInputDerivatives: the inputs are held over each step "
                "(canInterpolateInputs = false)");
}

fmi2Status fmi2GetRealOutputDerivatives(fmi2Component comp, const fmi2ValueReference vr[], size_t nvr,
                                        const fmi2Integer order[], fmi2Real value[])
{
    (void)vr;
    (void)nvr;
    (void)order;
    (void)value;
    CHECK_INSTANCE(comp, "fmi2GetRealOutputDerivatives");
    return fail(INST(comp), fmi2Error, "fmi2GetRealOutputDerivatives: not provided (maxOutputDerivativeOrder = 0)");
}

fmi2Status fmi2DoStep(fmi2Component comp, fmi2Real t, fmi2Real h, fmi2Boolean noSetFMUStatePriorToCurrentPoint)
{
    inst_t *c = INST(comp);
    char msg[MSG_LEN], bt[32], bc[32];
    fmi2Status s;
    double tol;
    (void)noSetFMUStatePriorToCurrentPoint;
    CHECK_INSTANCE(comp, "fmi2DoStep");
    if (c->phase != PH_STEP)
        return fail(c, fmi2Error, "fmi2DoStep: the instance is in %s (steps are taken after "
                    "fmi2ExitInitializationMode and before fmi2Terminate)", PHASE_NAME[c->phase]);
    if (c->stopped)
        return fail(c, fmi2Error, "fmi2DoStep: the FMU ended this simulation at t = %s s (fmi2Terminated is true): "
                    "%s; call fmi2Terminate, or roll back with fmi2SetFMUstate to a state saved before, or "
                    "fmi2Reset", num(c->last_good, bt, sizeof bt), c->stop_reason);
    if (!isfinite(h) || !(h > 0.0))
        return fail(c, fmi2Error, "fmi2DoStep: communicationStepSize = %g: must be finite and > 0", h);
    tol = 1e-9 * (fabs(c->time) > h ? fabs(c->time) : h);
    if (!isfinite(t) || fabs(t - c->time) > tol)
        return fail(c, fmi2Error, "fmi2DoStep: currentCommunicationPoint = %s does not match the FMU's time "
                    "%s (steps must follow each other; to go back, use fmi2SetFMUstate)", num(t, bt, sizeof bt),
                    num(c->time, bc, sizeof bc));
    s = model_step(c->m, &c->v, c->time, h, msg, sizeof msg);
    c->inputs_changed = 0;
    if (s == fmi2OK) {
        c->time = c->time + h;
        c->last_good = c->time;
        c->message[0] = '\0';
        return fmi2OK;
    }
    c->last_good = c->time + model_time_advanced(c->m);
    if (s == fmi2Discard) {
        /* the model cannot go on from here: the run ends (fmi2Terminated), unless the master rolls back; the
         * status says so whatever the last good step reported (quasi_static: 3, unstable) */
        c->i[MODEL_INFO.vr_status] = STATUS_DIVERGED;
        c->stopped = 1;
        snprintf(c->stop_reason, sizeof c->stop_reason, "%s", msg);
        return fail(c, s, "fmi2DoStep at t = %s s: %s (fmi2Terminated = true: the run ends at the last successful "
                    "time %s s; fmi2SetFMUstate to an earlier state to go on)", num(t, bt, sizeof bt), msg,
                    num(c->last_good, bc, sizeof bc));
    }
    return fail(c, s, "fmi2DoStep at t = %s s: %s", num(t, bt, sizeof bt), msg);
}

fmi2Status fmi2CancelStep(fmi2Component comp)
{
    CHECK_INSTANCE(comp, "fmi2CancelStep");
    return fail(INST(comp), fmi2Error, "fmi2CancelStep: steps are synchronous (canRunAsynchronuously = false)");
}

fmi2Status fmi2GetStatus(fmi2Component comp, const fmi2StatusKind s, fmi2Status *value)
{
    (void)s;
    (void)value;
    CHECK_INSTANCE(comp, "fmi2GetStatus");
    return fmi2Discard; /* only meaningful for asynchronous steps */
}

fmi2Status fmi2GetRealStatus(fmi2Component comp, const fmi2StatusKind s, fmi2Real *value)
{
    CHECK_INSTANCE(comp, "fmi2GetRealStatus");
    if (s != fmi2LastSuccessfulTime || !value) return fmi2Discard;
    *value = INST(comp)->last_good;
    return fmi2OK;
}

fmi2Status fmi2GetIntegerStatus(fmi2Component comp, const fmi2StatusKind s, fmi2Integer *value)
{
    (void)s;
    (void)value;
    CHECK_INSTANCE(comp, "fmi2GetIntegerStatus");
    return fmi2Discard;
}

fmi2Status fmi2GetBooleanStatus(fmi2Component comp, const fmi2StatusKind s, fmi2Boolean *value)
{
    CHECK_INSTANCE(comp, "fmi2GetBooleanStatus");
    if (s != fmi2Terminated || !value) return fmi2Discard;
    *value = INST(comp)->stopped ? fmi2True : fmi2False; /* the model ended the run (a discarded step) */
    return fmi2OK;
}

fmi2Status fmi2GetStringStatus(fmi2Component comp, const fmi2StatusKind s, fmi2String *value)
{
    (void)s;
    (void)value;
    CHECK_INSTANCE(comp, "fmi2GetStringStatus");
    return fmi2Discard;
}

/* ------------------------------------------------------------------ FMU state */

static void free_snapshot(snapshot_t *p)
{
    if (!p) return;
    free(p->r);
    free(p->i);
    free(p->model);
    free(p);
}

fmi2Status fmi2GetFMUstate(fmi2Component comp, fmi2FMUstate *state)
{
    inst_t *c = INST(comp);
    snapshot_t *p;
    CHECK_INSTANCE(comp, "fmi2GetFMUstate");
    if (!state) return fail(c, fmi2Error, "fmi2GetFMUstate: NULL pointer");
    p = (snapshot_t *)*state;
    if (p && !IS_OURS(p)) return fail(c, fmi2Error, "fmi2GetFMUstate: *FMUstate is not a state of this FMU");
    if (!p) {
        p = (snapshot_t *)calloc(1, sizeof *p);
        if (!p) return fail(c, fmi2Error, "fmi2GetFMUstate: out of memory");
        p->r = (double *)calloc(N_VARS, sizeof(double));
        p->i = (int *)calloc(N_VARS, sizeof(int));
        if (!p->r || !p->i) {
            free_snapshot(p);
            return fail(c, fmi2Error, "fmi2GetFMUstate: out of memory");
        }
    }
    p->magic = STATE_MAGIC;
    p->info = &MODEL_INFO;
    p->owner = c;
    p->phase = c->phase;
    p->time = c->time;
    p->last_good = c->last_good;
    memcpy(p->r, c->r, N_VARS * sizeof(double));
    memcpy(p->i, c->i, N_VARS * sizeof(int));
    memcpy(p->message, c->message, MSG_LEN);
    p->stopped = c->stopped;
    memcpy(p->stop_reason, c->stop_reason, MSG_LEN);
    free(p->model);
    p->model = NULL;
    p->n_model = c->m ? model_state_size(c->m) : 0;
    if (p->n_model) {
        p->model = (double *)malloc(p->n_model * sizeof(double));
        if (!p->model) {
            free_snapshot(p);
            *state = NULL;
            return fail(c, fmi2Error, "fmi2GetFMUstate: out of memory");
        }
        model_state_save(c->m, p->model);
    }
    *state = p;
    return fmi2OK;
}

/* the fixed parameters of a snapshot are those this instance's model was configured with */
static int same_configuration(const inst_t *c, const snapshot_t *p)
{
    size_t k;
    for (k = 0; k < N_VARS; ++k) {
        const model_var *v = VAR(k);
        if (!v->name || v->causality != VC_PARAMETER || v->variability != VV_FIXED) continue;
        if (v->type == VT_REAL ? c->r[k] != p->r[k] : c->i[k] != p->i[k]) return 0;
    }
    return 1;
}

/* Restore a snapshot in any phase. A state saved during a run brings its model: this instance's when it
 * was configured with the same fixed parameters, otherwise one configured from the state's own values (a
 * state restored right after fmi2Instantiate, as fmusim's --initial-fmu-state-file does). A state saved
 * before initialisation leaves no model. Nothing changes when the state is refused. */
static fmi2Status restore(inst_t *c, const snapshot_t *p, const char *fn)
{
    char msg[MSG_LEN];
    model_runtime *m = NULL;
    int fresh = 0;
    if (!IS_OURS(p)) return fail(c, fmi2Error, "%s: not a state of this FMU (another FMU's or build's)", fn);
    if (p->phase > PH_TERMINATED || (p->phase == PH_STEP && !p->n_model))
        return fail(c, fmi2Error, "%s: corrupt state (phase)", fn);
    if (p->n_model) {
        if (c->m && same_configuration(c, p)) {
            m = c->m;
        } else {
            model_values pv;
            pv.r = p->r;
            pv.i = p->i;
            m = model_configure(&pv, p->time, msg, sizeof msg);
            if (!m) return fail(c, fmi2Error, "%s: the state's parameters do not make a model (%s); nothing restored",
                                fn, msg);
            fresh = 1;
        }
        if (model_state_restore(m, p->model, p->n_model) != 0) {
            if (fresh) model_free(m);
            return fail(c, fmi2Error, "%s: the state was saved with another configuration or is corrupt; nothing "
                        "restored", fn);
        }
    }
    if (m != c->m) {
        model_free(c->m);
        c->m = m;
    }
    c->phase = p->phase;
    c->time = p->time;
    c->last_good = p->last_good;
    memcpy(c->r, p->r, N_VARS * sizeof(double));
    memcpy(c->i, p->i, N_VARS * sizeof(int));
    memcpy(c->message, p->message, MSG_LEN);
    c->stopped = p->stopped;
    memcpy(c->stop_reason, p->stop_reason, MSG_LEN);
    c->inputs_changed = 0;
    return fmi2OK;
}

fmi2Status fmi2SetFMUstate(fmi2Component comp, fmi2FMUstate state)
{
    CHECK_INSTANCE(comp, "fmi2SetFMUstate");
    return restore(INST(comp), (const snapshot_t *)state, "fmi2SetFMUstate");
}

fmi2Status fmi2FreeFMUstate(fmi2Component comp, fmi2FMUstate *state)
{
    CHECK_INSTANCE(comp, "fmi2FreeFMUstate");
    if (!state || !*state) return fmi2OK;
    if (!IS_OURS((snapshot_t *)*state))
        return fail(INST(comp), fmi2Error, "fmi2FreeFMUstate: not a state of this FMU");
    free_snapshot((snapshot_t *)*state);
    *state = NULL;
    return fmi2OK;
}

/* serialised: magic, guid (64 bytes), phase, n_vars, n_model, stopped (8 bytes each), time, last_good, r[], i[],
 * message, stop_reason, model[] */
#define GUID_BYTES 64
#define HEAD_BYTES (4 + GUID_BYTES + 4 * 8 + 2 * 8)
static size_t serialized_size_of(size_t n_model)
{
    return HEAD_BYTES + N_VARS * 8 + N_VARS * 4 + 2 * MSG_LEN + n_model * 8;
}

fmi2Status fmi2SerializedFMUstateSize(fmi2Component comp, fmi2FMUstate state, size_t *size)
{
    CHECK_INSTANCE(comp, "fmi2SerializedFMUstateSize");
    if (!IS_OURS((snapshot_t *)state) || !size)
        return fail(INST(comp), fmi2Error, "fmi2SerializedFMUstateSize: not a state of this FMU");
    *size = serialized_size_of(((const snapshot_t *)state)->n_model);
    return fmi2OK;
}

fmi2Status fmi2SerializeFMUstate(fmi2Component comp, fmi2FMUstate state, fmi2Byte bytes[], size_t size)
{
    const snapshot_t *p = (const snapshot_t *)state;
    size_t at = 0;
    unsigned long long u;
    char guid[GUID_BYTES];
    CHECK_INSTANCE(comp, "fmi2SerializeFMUstate");
    if (!IS_OURS(p)) return fail(INST(comp), fmi2Error, "fmi2SerializeFMUstate: not a state of this FMU");
    if (!bytes || size != serialized_size_of(p->n_model))
        return fail(INST(comp), fmi2Error, "fmi2SerializeFMUstate: the buffer has %zu bytes, the state needs %zu", size,
                    serialized_size_of(p->n_model));
    memset(guid, 0, sizeof guid);
    strncpy(guid, MODEL_INFO.guid, GUID_BYTES - 1);
#define PUT(src, nbytes) (memcpy(bytes + at, (src), (nbytes)), at += (nbytes))
    PUT(&p->magic, 4);
    PUT(guid, GUID_BYTES);
    u = (unsigned long long)p->phase;
    PUT(&u, 8);
    u = (unsigned long long)N_VARS;
    PUT(&u, 8);
    u = (unsigned long long)p->n_model;
    PUT(&u, 8);
    u = (unsigned long long)p->stopped;
    PUT(&u, 8);
    PUT(&p->time, 8);
    PUT(&p->last_good, 8);
    PUT(p->r, N_VARS * 8);
    PUT(p->i, N_VARS * 4);
    PUT(p->message, MSG_LEN);
    PUT(p->stop_reason, MSG_LEN);
    if (p->n_model) PUT(p->model, p->n_model * 8);
#undef PUT
    return fmi2OK;
}

fmi2Status fmi2DeSerializeFMUstate(fmi2Component comp, const fmi2Byte bytes[], size_t size, fmi2FMUstate *state)
{
    inst_t *c = INST(comp);
    size_t at = 0, k;
    unsigned long long phase, nv, nm, stopped;
    unsigned magic;
    char guid[GUID_BYTES];
    snapshot_t *p;
    CHECK_INSTANCE(comp, "fmi2DeSerializeFMUstate");
    if (!bytes || !state) return fail(c, fmi2Error, "fmi2DeSerializeFMUstate: NULL pointer");
    if (size < HEAD_BYTES) return fail(c, fmi2Error, "fmi2DeSerializeFMUstate: %zu bytes: too short to be a state of "
                                       "this FMU", size);
#define GET(dst, nbytes) (memcpy((dst), bytes + at, (nbytes)), at += (nbytes))
    GET(&magic, 4);
    GET(guid, GUID_BYTES);
    guid[GUID_BYTES - 1] = '\0';
    if (magic != STATE_MAGIC || strcmp(guid, MODEL_INFO.guid) != 0)
        return fail(c, fmi2Error, "fmi2DeSerializeFMUstate: not a state of this FMU (wrong magic or GUID)");
    GET(&phase, 8);
    GET(&nv, 8);
    GET(&nm, 8);
    GET(&stopped, 8);
    if (phase > PH_TERMINATED || nv != N_VARS || nm > 100000 || stopped > 1 || size != serialized_size_of((size_t)nm))
        return fail(c, fmi2Error, "fmi2DeSerializeFMUstate: corrupt state (sizes do not match this FMU)");
    p = (snapshot_t *)calloc(1, sizeof *p);
    if (!p) return fail(c, fmi2Error, "fmi2DeSerializeFMUstate: out of memory");
    p->r = (double *)calloc(N_VARS, sizeof(double));
    p->i = (int *)calloc(N_VARS, sizeof(int));
    p->model = nm ? (double *)calloc((size_t)nm, sizeof(double)) : NULL;
    if (!p->r || !p->i || (nm && !p->model)) {
        free_snapshot(p);
        return fail(c, fmi2Error, "fmi2DeSerializeFMUstate: out of memory");
    }
    p->magic = STATE_MAGIC;
    p->info = &MODEL_INFO;
    p->owner = c;
    p->phase = (phase_t)phase;
    p->n_model = (size_t)nm;
    p->stopped = (int)stopped;
    GET(&p->time, 8);
    GET(&p->last_good, 8);
    GET(p->r, N_VARS * 8);
    GET(p->i, N_VARS * 4);
    GET(p->message, MSG_LEN);
    p->message[MSG_LEN - 1] = '\0';
    GET(p->stop_reason, MSG_LEN);
    p->stop_reason[MSG_LEN - 1] = '\0';
    if (nm) GET(p->model, (size_t)nm * 8);
#undef GET
    if (!isfinite(p->time) || !isfinite(p->last_good)) {
        free_snapshot(p);
        return fail(c, fmi2Error, "fmi2DeSerializeFMUstate: corrupt state (time)");
    }
    for (k = 0; k < N_VARS; ++k) {
        const model_var *v = VAR(k);
        if (!v->name) continue;
        if ((v->type == VT_REAL && v->causality != VC_OUTPUT &&
             (!isfinite(p->r[k]) || (v->has_range && (p->r[k] < v->min || p->r[k] > v->max)))) ||
            (v->type == VT_ENUM && (p->i[k] < v->min || p->i[k] > v->max))) {
            free_snapshot(p);
            return fail(c, fmi2Error, "fmi2DeSerializeFMUstate: corrupt state (%s out of range)", v->name);
        }
    }
    *state = p;
    return fmi2OK;
}

/* ------------------------------------------------------------------ not a model-exchange FMU, no derivatives */

fmi2Status fmi2GetDirectionalDerivative(fmi2Component comp, const fmi2ValueReference vUnknown_ref[],
                                        size_t nUnknown, const fmi2ValueReference vKnown_ref[], size_t nKnown,
                                        const fmi2Real dvKnown[], fmi2Real dvUnknown[])
{
    (void)vUnknown_ref;
    (void)nUnknown;
    (void)vKnown_ref;
    (void)nKnown;
    (void)dvKnown;
    (void)dvUnknown;
    CHECK_INSTANCE(comp, "fmi2GetDirectionalDerivative");
    return fail(INST(comp), fmi2Error, "fmi2GetDirectionalDerivative: not provided "
                "(providesDirectionalDerivative = false)");
}
