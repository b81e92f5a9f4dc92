/*
 * fmi2_cs.c: the FMI 2.0 co-simulation interface around a model (fmu_model.h), model-agnostic.
 *
 * What a system simulator can rely on:
 *   - every misuse is fmi2Error with a logged message that names the variable, the value and
 *     the accepted range or the rule (never a silent fmi2OK, never fmi2Fatal, never a crash):
 *     an unknown value reference, a type mismatch, setting an output, a fixed parameter after
 *     initialisation, a value outside its declared [min, max] or not finite (refused at the
 *     fmi2Set call, the old value kept), a communication point that is not the FMU's time,
 *     fmi2DoStep before initialisation or after fmi2Terminate, a bad or foreign FMU state;
 *   - configuration errors are reported by fmi2ExitInitializationMode (fmi2Error; the
 *     parameters can be corrected and the call repeated);
 *   - a step the model cannot complete (divergence, no balanced solution) is fmi2Discard; the
 *     instance stays usable: fmi2SetFMUstate to a saved state and a retry succeed, and
 *     fmi2GetBooleanStatus(fmi2Terminated) stays fmi2False;
 *   - errors and warnings reach the logger whether or not logging was switched on (debug
 *     messages only when it was), and the last message is in the 'message' output.
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
#define STATE_MAGIC 0x52524655u /* "RRFU" */

typedef struct {
    char *name;
    fmi2CallbackFunctions cb;
    int logging;
    phase_t phase;
    double time;
    double last_good;
    double *r;
    int *i;
    char *param_file;
    char message[MSG_LEN];
    model_values v;
    model_runtime *m;
    int inputs_changed; /* quasi-static feedthrough: outputs to recompute before a read */
} inst_t;

typedef struct {
    unsigned magic;
    const inst_t *owner;
    phase_t phase;
    double time, last_good;
    double *r;
    int *i;
    char message[MSG_LEN];
    size_t n_model;
    double *model;
} snapshot_t;

/* ------------------------------------------------------------------ logging and errors */

static void logv(inst_t *c, fmi2Status status, const char *category, const char *fmt, va_list ap)
{
    char buf[MSG_LEN];
    vsnprintf(buf, sizeof buf, fmt, ap);
    if (status >= fmi2Discard) {
        memcpy(c->message, buf, sizeof buf);
        c->message[MSG_LEN - 1] = '\0';
    }
    if (c->cb.logger && (status >= fmi2Warning || c->logging)) {
        /* the message is the format: loggers that do not format (fmpy's) see it as it is, and a
         * '%' is doubled for those that do */
        char fmt_buf[2 * MSG_LEN];
        size_t k, j = 0;
        for (k = 0; buf[k] && j + 2 < sizeof fmt_buf; ++k) {
            fmt_buf[j++] = buf[k];
            if (buf[k] == '%') fmt_buf[j++] = '%';
        }
        fmt_buf[j] = '\0';
        c->cb.logger(c->cb.componentEnvironment, c->name, status, category, fmt_buf);
    }
}

/* A refused call: logged (status fmi2Error or fmi2Discard), its cause in 'message', and for an
 * error the 'status' output says bad input or configuration. */
static fmi2Status fail(inst_t *c, fmi2Status status, const char *fmt, ...)
{
    va_list ap;
    if (status == fmi2Error) c->i[VR_STATUS] = STATUS_BAD_INPUT;
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

static void set_starts(inst_t *c)
{
    int k;
    for (k = 0; k < MODEL_DATA.n_vars; ++k) {
        const model_var *v = &MODEL_DATA.vars[k];
        c->r[k] = v->type == VT_REAL ? v->start : 0.0;
        c->i[k] = v->type == VT_INTEGER || v->type == VT_ENUM ? (int)v->start : 0;
    }
    c->param_file[0] = '\0';
    c->message[0] = '\0';
}

static fmi2Status check_vr(inst_t *c, const char *fn, fmi2ValueReference vr, int want_real, int want_int,
                           int want_str)
{
    const model_var *v;
    if (vr >= (fmi2ValueReference)MODEL_DATA.n_vars)
        return fail(c, fmi2Error, "%s: unknown value reference %u (this FMU has 0..%d)", fn, vr, MODEL_DATA.n_vars - 1);
    v = &MODEL_DATA.vars[vr];
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
    const model_var *v = &MODEL_DATA.vars[vr];
    if (v->causality == VC_OUTPUT)
        return fail(c, fmi2Error, "%s: %s is an output and cannot be set", fn, v->name);
    if (c->phase == PH_TERMINATED)
        return fail(c, fmi2Error, "%s: %s: the instance is terminated (fmi2Reset or fmi2FreeInstance)", fn, v->name);
    if (v->variability == VV_FIXED && c->phase == PH_STEP)
        return fail(c, fmi2Error, "%s: %s is a fixed parameter: it cannot change after initialisation (fmi2Reset "
                    "first)", fn, v->name);
    return fmi2OK;
}

static fmi2Status check_range(inst_t *c, const char *fn, fmi2ValueReference vr, double x)
{
    const model_var *v = &MODEL_DATA.vars[vr];
    if (!isfinite(x))
        return fail(c, fmi2Error, "%s: %s = %g is not finite; accepted range [%.17g, %.17g]", fn, v->name, x, v->min,
                    v->max);
    if (v->has_range && (x < v->min || x > v->max))
        return fail(c, fmi2Error, "%s: %s = %.17g out of range; accepted range [%.17g, %.17g]", fn, v->name, x,
                    v->min, v->max);
    return fmi2OK;
}

static void after_set(inst_t *c, fmi2ValueReference vr)
{
    if (MODEL_DATA.vars[vr].causality == VC_INPUT || MODEL_DATA.vars[vr].variability == VV_TUNABLE)
        c->inputs_changed = 1;
}

/* quasi-static feedthrough build: the outputs are the solution at the current inputs */
static fmi2Status refresh_outputs(inst_t *c)
{
    char msg[MSG_LEN];
    fmi2Status s;
    if (!MODEL_DATA.feedthrough || !c->inputs_changed || !c->m || c->phase != PH_STEP) return fmi2OK;
    c->inputs_changed = 0;
    s = model_solve_now(c->m, &c->v, msg, sizeof msg);
    if (s != fmi2OK) {
        c->i[VR_STATUS] = STATUS_DIVERGED;
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
    int n = MODEL_DATA.n_vars;
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
    if (!fmuGUID || strcmp(fmuGUID, MODEL_DATA.guid) != 0) {
        functions->logger(functions->componentEnvironment, instanceName, fmi2Error, "logStatusError",
                          "fmi2Instantiate: GUID '%s' is not this FMU's (%s): modelDescription.xml and the binary "
                          "come from different builds", fmuGUID ? fmuGUID : "(null)", MODEL_DATA.guid);
        return NULL;
    }
    c = (inst_t *)calloc(1, sizeof *c);
    if (!c) return NULL;
    c->name = (char *)malloc(strlen(instanceName) + 1);
    c->r = (double *)calloc((size_t)n, sizeof(double));
    c->i = (int *)calloc((size_t)n, sizeof(int));
    c->param_file = (char *)calloc(1, 1);
    if (!c->name || !c->r || !c->i || !c->param_file) {
        free(c->name);
        free(c->r);
        free(c->i);
        free(c->param_file);
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
    free(c->param_file);
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
    if (c->param_file[0]) {
        c->i[VR_STATUS] = STATUS_BAD_INPUT;
        return fail(c, fmi2Error, "fmi2ExitInitializationMode: param_file = '%s': this native FMU carries its model "
                    "built in and reads no parameter file; rebuild it with `rotorub build-fmu --native --params "
                    "FILE`, or use the pythonfmu FMU", c->param_file);
    }
    model_free(c->m);
    c->m = model_configure(&c->v, msg, sizeof msg);
    if (!c->m) {
        c->i[VR_STATUS] = STATUS_BAD_INPUT;
        return fail(c, fmi2Error, "fmi2ExitInitializationMode: %s", msg);
    }
    c->phase = PH_STEP;
    c->i[VR_STATUS] = STATUS_OK;
    c->message[0] = '\0';
    c->inputs_changed = 0;
    s = model_solve_now(c->m, &c->v, msg, sizeof msg);
    if (s != fmi2OK) {
        /* quasi-static: no balanced solution at the initial inputs; the first step reports it again */
        c->i[VR_STATUS] = STATUS_DIVERGED;
        fail(c, fmi2Warning, "fmi2ExitInitializationMode: %s", msg);
        return fmi2Warning;
    }
    return fmi2OK;
}

fmi2Status fmi2Terminate(fmi2Component comp)
{
    inst_t *c = INST(comp);
    CHECK_INSTANCE(comp, "fmi2Terminate");
    if (c->phase != PH_STEP && c->phase != PH_INITIALIZATION)
        return fail(c, fmi2Error, "fmi2Terminate: the instance is in %s", PHASE_NAME[c->phase]);
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
    if (vr[0] >= (fmi2ValueReference)MODEL_DATA.n_vars)
        return fail(c, fmi2Error, "fmi2GetBoolean: unknown value reference %u", vr[0]);
    return fail(c, fmi2Error, "fmi2GetBoolean: %s is not a Boolean (this FMU has no Boolean variable)",
                MODEL_DATA.vars[vr[0]].name);
}

fmi2Status fmi2GetString(fmi2Component comp, const fmi2ValueReference vr[], size_t nvr, fmi2String value[])
{
    inst_t *c = INST(comp);
    size_t k;
    fmi2Status s;
    CHECK_INSTANCE(comp, "fmi2GetString");
    if (nvr && (!vr || !value)) return fail(c, fmi2Error, "fmi2GetString: NULL array");
    for (k = 0; k < nvr; ++k)
        if ((s = check_vr(c, "fmi2GetString", vr[k], 0, 0, 1)) != fmi2OK) return s;
    for (k = 0; k < nvr; ++k) value[k] = (int)vr[k] == VR_PARAM_FILE ? c->param_file : c->message;
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
    if (vr[0] >= (fmi2ValueReference)MODEL_DATA.n_vars)
        return fail(c, fmi2Error, "fmi2SetBoolean: unknown value reference %u", vr[0]);
    return fail(c, fmi2Error, "fmi2SetBoolean: %s is not a Boolean (this FMU has no Boolean variable)",
                MODEL_DATA.vars[vr[0]].name);
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
        if (!value[k]) return fail(c, fmi2Error, "fmi2SetString: %s: NULL string", MODEL_DATA.vars[vr[k]].name);
        if ((int)vr[k] == VR_PARAM_FILE && value[k][0])
            return fail(c, fmi2Error, "fmi2SetString: param_file = '%s': this native FMU carries its model built in "
                        "and reads no parameter file; rebuild it with `rotorub build-fmu --native --params FILE`, "
                        "or use the pythonfmu FMU", value[k]);
    }
    for (k = 0; k < nvr; ++k) {
        char *copy = (char *)malloc(strlen(value[k]) + 1);
        if (!copy) return fail(c, fmi2Error, "fmi2SetString: out of memory");
        strcpy(copy, value[k]);
        free(c->param_file);
        c->param_file = copy;
    }
    return fmi2OK;
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
    char msg[MSG_LEN];
    fmi2Status s;
    double tol;
    (void)noSetFMUStatePriorToCurrentPoint;
    CHECK_INSTANCE(comp, "fmi2DoStep");
    if (c->phase != PH_STEP)
        return fail(c, fmi2Error, "fmi2DoStep: the instance is in %s (steps are taken after "
                    "fmi2ExitInitializationMode and before fmi2Terminate)", PHASE_NAME[c->phase]);
    if (!isfinite(h) || !(h > 0.0))
        return fail(c, fmi2Error, "fmi2DoStep: communicationStepSize = %g: must be finite and > 0", h);
    tol = 1e-9 * (fabs(c->time) > h ? fabs(c->time) : h);
    if (!isfinite(t) || fabs(t - c->time) > tol)
        return fail(c, fmi2Error, "fmi2DoStep: currentCommunicationPoint = %.17g does not match the FMU's time "
                    "%.17g (steps must follow each other; to go back, use fmi2SetFMUstate)", t, c->time);
    s = model_step(c->m, &c->v, h, msg, sizeof msg);
    c->inputs_changed = 0;
    if (s == fmi2OK) {
        c->time = c->time + h;
        c->last_good = c->time;
        c->message[0] = '\0';
        return fmi2OK;
    }
    c->last_good = c->time + model_time_advanced(c->m);
    c->i[VR_STATUS] = s == fmi2Discard ? STATUS_DIVERGED : STATUS_BAD_INPUT;
    return fail(c, s, "fmi2DoStep at t = %g s: %s", t, msg);
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
    *value = fmi2False; /* a refused step is recoverable: roll back, change the input, retry */
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
    size_t n = (size_t)MODEL_DATA.n_vars;
    CHECK_INSTANCE(comp, "fmi2GetFMUstate");
    if (!state) return fail(c, fmi2Error, "fmi2GetFMUstate: NULL pointer");
    p = (snapshot_t *)*state;
    if (p && p->magic != STATE_MAGIC) return fail(c, fmi2Error, "fmi2GetFMUstate: *FMUstate is not a state of this FMU");
    if (!p) {
        p = (snapshot_t *)calloc(1, sizeof *p);
        if (!p) return fail(c, fmi2Error, "fmi2GetFMUstate: out of memory");
        p->r = (double *)calloc(n, sizeof(double));
        p->i = (int *)calloc(n, sizeof(int));
        if (!p->r || !p->i) {
            free_snapshot(p);
            return fail(c, fmi2Error, "fmi2GetFMUstate: out of memory");
        }
    }
    p->magic = STATE_MAGIC;
    p->owner = c;
    p->phase = c->phase;
    p->time = c->time;
    p->last_good = c->last_good;
    memcpy(p->r, c->r, n * sizeof(double));
    memcpy(p->i, c->i, n * sizeof(int));
    memcpy(p->message, c->message, MSG_LEN);
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

/* Restore a snapshot; a state of another configuration (or no model when one is needed) is refused. */
static fmi2Status restore(inst_t *c, const snapshot_t *p, const char *fn)
{
    size_t n = (size_t)MODEL_DATA.n_vars;
    if (!p || p->magic != STATE_MAGIC) return fail(c, fmi2Error, "%s: not a state of this FMU", fn);
    if (p->phase > PH_TERMINATED) return fail(c, fmi2Error, "%s: corrupt state (phase)", fn);
    if (p->n_model) {
        if (!c->m)
            return fail(c, fmi2Error, "%s: the state holds a running simulation; this instance is not initialised "
                        "(restore after fmi2ExitInitializationMode)", fn);
        if (p->i[VR_FORMULATION] != c->i[VR_FORMULATION] || p->i[VR_MODE] != c->i[VR_MODE] ||
            model_state_restore(c->m, p->model, p->n_model) != 0)
            return fail(c, fmi2Error, "%s: the state was saved with another configuration (formulation, mode or "
                        "model) or is corrupt; nothing restored", fn);
    }
    c->phase = p->phase == PH_STEP && !c->m ? PH_INITIALIZATION : p->phase;
    c->time = p->time;
    c->last_good = p->last_good;
    memcpy(c->r, p->r, n * sizeof(double));
    memcpy(c->i, p->i, n * sizeof(int));
    memcpy(c->message, p->message, MSG_LEN);
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
    if (((snapshot_t *)*state)->magic != STATE_MAGIC)
        return fail(INST(comp), fmi2Error, "fmi2FreeFMUstate: not a state of this FMU");
    free_snapshot((snapshot_t *)*state);
    *state = NULL;
    return fmi2OK;
}

/* serialised: magic, guid (64 bytes), phase, n_vars, n_model, time, last_good, r[], i[], message, model[] */
#define GUID_BYTES 64
static size_t serialized_size(const snapshot_t *p)
{
    size_t n = (size_t)MODEL_DATA.n_vars;
    return 4 + GUID_BYTES + 3 * 8 + 2 * 8 + n * 8 + n * 4 + MSG_LEN + p->n_model * 8;
}

fmi2Status fmi2SerializedFMUstateSize(fmi2Component comp, fmi2FMUstate state, size_t *size)
{
    CHECK_INSTANCE(comp, "fmi2SerializedFMUstateSize");
    if (!state || ((snapshot_t *)state)->magic != STATE_MAGIC || !size)
        return fail(INST(comp), fmi2Error, "fmi2SerializedFMUstateSize: not a state of this FMU");
    *size = serialized_size((const snapshot_t *)state);
    return fmi2OK;
}

fmi2Status fmi2SerializeFMUstate(fmi2Component comp, fmi2FMUstate state, fmi2Byte bytes[], size_t size)
{
    const snapshot_t *p = (const snapshot_t *)state;
    size_t n = (size_t)MODEL_DATA.n_vars, at = 0;
    unsigned long long u;
    char guid[GUID_BYTES];
    CHECK_INSTANCE(comp, "fmi2SerializeFMUstate");
    if (!p || p->magic != STATE_MAGIC) return fail(INST(comp), fmi2Error, "fmi2SerializeFMUstate: not a state of this FMU");
    if (!bytes || size != serialized_size(p))
        return fail(INST(comp), fmi2Error, "fmi2SerializeFMUstate: the buffer has %zu bytes, the state needs %zu", size,
                    serialized_size(p));
    memset(guid, 0, sizeof guid);
    strncpy(guid, MODEL_DATA.guid, GUID_BYTES - 1);
#define PUT(src, nbytes) (memcpy(bytes + at, (src), (nbytes)), at += (nbytes))
    PUT(&p->magic, 4);
    PUT(guid, GUID_BYTES);
    u = (unsigned long long)p->phase;
    PUT(&u, 8);
    u = (unsigned long long)n;
    PUT(&u, 8);
    u = (unsigned long long)p->n_model;
    PUT(&u, 8);
    PUT(&p->time, 8);
    PUT(&p->last_good, 8);
    PUT(p->r, n * 8);
    PUT(p->i, n * 4);
    PUT(p->message, MSG_LEN);
    if (p->n_model) PUT(p->model, p->n_model * 8);
#undef PUT
    return fmi2OK;
}

fmi2Status fmi2DeSerializeFMUstate(fmi2Component comp, const fmi2Byte bytes[], size_t size, fmi2FMUstate *state)
{
    inst_t *c = INST(comp);
    size_t n = (size_t)MODEL_DATA.n_vars, at = 0, k;
    unsigned long long phase, nv, nm;
    unsigned magic;
    char guid[GUID_BYTES];
    snapshot_t *p;
    CHECK_INSTANCE(comp, "fmi2DeSerializeFMUstate");
    if (!bytes || !state) return fail(c, fmi2Error, "fmi2DeSerializeFMUstate: NULL pointer");
    if (size < 4 + GUID_BYTES + 5 * 8) return fail(c, fmi2Error, "fmi2DeSerializeFMUstate: %zu bytes: too short to "
                                                   "be a state of this FMU", size);
#define GET(dst, nbytes) (memcpy((dst), bytes + at, (nbytes)), at += (nbytes))
    GET(&magic, 4);
    GET(guid, GUID_BYTES);
    guid[GUID_BYTES - 1] = '\0';
    if (magic != STATE_MAGIC || strcmp(guid, MODEL_DATA.guid) != 0)
        return fail(c, fmi2Error, "fmi2DeSerializeFMUstate: not a state of this FMU (wrong magic or GUID)");
    GET(&phase, 8);
    GET(&nv, 8);
    GET(&nm, 8);
    if (phase > PH_TERMINATED || nv != n || nm > 100000 ||
        size != 4 + GUID_BYTES + 3 * 8 + 2 * 8 + n * 8 + n * 4 + MSG_LEN + nm * 8)
        return fail(c, fmi2Error, "fmi2DeSerializeFMUstate: corrupt state (sizes do not match this FMU)");
    p = (snapshot_t *)calloc(1, sizeof *p);
    if (!p) return fail(c, fmi2Error, "fmi2DeSerializeFMUstate: out of memory");
    p->r = (double *)calloc(n, sizeof(double));
    p->i = (int *)calloc(n, sizeof(int));
    p->model = nm ? (double *)calloc((size_t)nm, sizeof(double)) : NULL;
    if (!p->r || !p->i || (nm && !p->model)) {
        free_snapshot(p);
        return fail(c, fmi2Error, "fmi2DeSerializeFMUstate: out of memory");
    }
    p->magic = STATE_MAGIC;
    p->owner = c;
    p->phase = (phase_t)phase;
    p->n_model = (size_t)nm;
    GET(&p->time, 8);
    GET(&p->last_good, 8);
    GET(p->r, n * 8);
    GET(p->i, n * 4);
    GET(p->message, MSG_LEN);
    p->message[MSG_LEN - 1] = '\0';
    if (nm) GET(p->model, (size_t)nm * 8);
#undef GET
    if (!isfinite(p->time) || !isfinite(p->last_good)) {
        free_snapshot(p);
        return fail(c, fmi2Error, "fmi2DeSerializeFMUstate: corrupt state (time)");
    }
    for (k = 0; k < n; ++k) {
        const model_var *v = &MODEL_DATA.vars[k];
        if ((v->type == VT_REAL && v->causality != VC_OUTPUT && check_range(c, "fmi2DeSerializeFMUstate", (unsigned)k,
                                                                           p->r[k]) != fmi2OK) ||
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
