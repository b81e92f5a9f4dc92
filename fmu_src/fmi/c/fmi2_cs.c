/*
 * fmi2_cs.c: the FMI 2.0 co-simulation interface around a model (fmu_model.h), model-agnostic: the same file
 * builds every model of fmu_src/models/. A thin layer over fmu_core.c (shared with the FMI 3.0
 * wrapper, fmi3_cs.c): FMI 2.0's names, callbacks and types, and its calling sequence.
 *
 * What a system simulator can rely on (fmu_core.c says the rest):
 *   - every misuse is fmi2Error with a logged message that names the variable, the value and the accepted
 *     range or the rule: an unknown value reference, a type mismatch, setting an output, a fixed parameter
 *     after initialisation, a value outside its declared [min, max] or not finite, or one that breaks a rule
 *     of the model (refused at the fmi2Set call, the old value kept), a communication point that is not the
 *     FMU's time, fmi2DoStep before initialisation or after fmi2Terminate, a bad or foreign FMU state;
 *   - a step the model cannot complete is fmi2Discard; from then on fmi2GetBooleanStatus(fmi2Terminated) is
 *     fmi2True and fmi2GetRealStatus(fmi2LastSuccessfulTime) the time the model reached;
 *   - FMI 2.0 loggers may format their message: the text is passed as the format, with every '%' doubled.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"
#include "fmu_core.h"

/* A host reads the same outputs after every step: the value references fmi2GetReal last validated are kept, and
 * a call with the same list (compared element by element, not by address: the host may refill its array) skips
 * the walk through the variable table. */
#define REAL_MEMO 256

typedef struct {
    fmu_core core; /* first: an inst_t is its core */
    fmi2CallbackFunctions cb;
    size_t real_memo_n; /* 0: nothing validated yet */
    fmi2ValueReference real_memo[REAL_MEMO];
} inst_t;

static const core_dialect FMI2 = {0x52524632u /* "RRF2" */, "fmi2SetFMUstate", "fmi2Reset", "fmi2Terminate",
                                  "fmi2FreeInstance", "fmi2EnterInitializationMode", "fmi2ExitInitializationMode",
                                  "fmi2Terminated", 0, 0};

#define MSG_LEN CORE_MSG_LEN
#define VAR(vr) CORE_VAR(vr)

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

static void log_fmi2(fmu_core *core, model_status status, const char *category, const char *text)
{
    inst_t *c = (inst_t *)core;
    if (c->cb.logger) emit(&c->cb, core->name, (fmi2Status)status, category, text);
}

#define INST(c) ((inst_t *)(c))
#define CORE(c) (&INST(c)->core)
#define CHECK_INSTANCE(c, fn)                                                                                          \
    do {                                                                                                               \
        if (!(c)) return fmi2Error;                                                                                    \
        if (CORE(c)->phase > PH_TERMINATED)                                                                            \
            return (fmi2Status)core_fail(CORE(c), MODEL_ERROR, "%s: invalid instance", fn);                            \
    } while (0)
#define FAIL(c, ...) ((fmi2Status)core_fail(CORE(c), MODEL_ERROR, __VA_ARGS__))

static fmi2Status check_vr(fmu_core *c, const char *fn, fmi2ValueReference vr, int want_real, int want_int,
                           int want_str)
{
    const model_var *v;
    if (vr >= (fmi2ValueReference)MODEL_INFO.n_vars || !VAR(vr)->name)
        return (fmi2Status)core_fail(c, MODEL_ERROR, "%s: unknown value reference %u (not a variable of this FMU: "
                                     "see its modelDescription.xml)", fn, vr);
    v = VAR(vr);
    if ((want_real && v->type != VT_REAL) || (want_int && v->type != VT_INTEGER && v->type != VT_ENUM) ||
        (want_str && v->type != VT_STRING)) {
        static const char *TYPE[] = {"Real", "Integer", "Enumeration", "String"};
        return (fmi2Status)core_fail(c, MODEL_ERROR, "%s: %s (value reference %u) is of type %s", fn, v->name, vr,
                                     TYPE[v->type]);
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
    size_t k, j;
    CHECK_INSTANCE(comp, "fmi2SetDebugLogging");
    for (k = 0; k < nCategories; ++k) {
        int found = 0;
        for (j = 0; j < sizeof KNOWN / sizeof KNOWN[0]; ++j)
            if (categories && categories[k] && strcmp(categories[k], KNOWN[j]) == 0) found = 1;
        if (!found)
            return FAIL(comp, "fmi2SetDebugLogging: unknown log category '%s'; accepted: logStatusWarning, "
                        "logStatusDiscard, logStatusError, logStatusFatal, logAll",
                        categories && categories[k] ? categories[k] : "(null)");
    }
    CORE(comp)->logging = loggingOn ? 1 : 0;
    return fmi2OK;
}

fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType, fmi2String fmuGUID,
                              fmi2String fmuResourceLocation, const fmi2CallbackFunctions *functions,
                              fmi2Boolean visible, fmi2Boolean loggingOn)
{
    inst_t *c;
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
    if (!c || core_init(&c->core, &FMI2, log_fmi2, instanceName, loggingOn ? 1 : 0) != 0) {
        free(c);
        functions->logger(functions->componentEnvironment, instanceName, fmi2Error, "logStatusError",
                          "fmi2Instantiate: out of memory");
        return NULL;
    }
    c->cb = *functions;
    core_debug(&c->core, "fmi2Instantiate: %s", instanceName);
    return c;
}

void fmi2FreeInstance(fmi2Component comp)
{
    if (!comp) return;
    core_release(CORE(comp));
    free(comp);
}

fmi2Status fmi2SetupExperiment(fmi2Component comp, fmi2Boolean toleranceDefined, fmi2Real tolerance,
                               fmi2Real startTime, fmi2Boolean stopTimeDefined, fmi2Real stopTime)
{
    fmu_core *c = CORE(comp);
    CHECK_INSTANCE(comp, "fmi2SetupExperiment");
    (void)toleranceDefined;
    (void)tolerance;
    if (c->phase != PH_INSTANTIATED)
        return FAIL(comp, "fmi2SetupExperiment: allowed only before fmi2EnterInitializationMode (the "
                    "instance is in %s)", CORE_PHASE_NAME[c->phase]);
    if (!isfinite(startTime)) return FAIL(comp, "fmi2SetupExperiment: startTime = %g is not finite", startTime);
    if (stopTimeDefined && !(stopTime >= startTime))
        return FAIL(comp, "fmi2SetupExperiment: stopTime = %g is before startTime = %g", stopTime, startTime);
    c->time = c->last_good = startTime;
    return fmi2OK;
}

fmi2Status fmi2EnterInitializationMode(fmi2Component comp)
{
    CHECK_INSTANCE(comp, "fmi2EnterInitializationMode");
    return (fmi2Status)core_enter_init(CORE(comp), "fmi2EnterInitializationMode");
}

fmi2Status fmi2ExitInitializationMode(fmi2Component comp)
{
    CHECK_INSTANCE(comp, "fmi2ExitInitializationMode");
    return (fmi2Status)core_exit_init(CORE(comp), "fmi2ExitInitializationMode");
}

fmi2Status fmi2Terminate(fmi2Component comp)
{
    CHECK_INSTANCE(comp, "fmi2Terminate");
    return (fmi2Status)core_terminate(CORE(comp), "fmi2Terminate");
}

fmi2Status fmi2Reset(fmi2Component comp)
{
    CHECK_INSTANCE(comp, "fmi2Reset");
    core_reset(CORE(comp));
    return fmi2OK;
}

/* ------------------------------------------------------------------ values */

fmi2Status fmi2GetReal(fmi2Component comp, const fmi2ValueReference vr[], size_t nvr, fmi2Real value[])
{
    fmu_core *c = CORE(comp);
    size_t k;
    fmi2Status s;
    CHECK_INSTANCE(comp, "fmi2GetReal");
    if ((s = (fmi2Status)core_check_readable(c, "fmi2GetReal")) != fmi2OK) return s;
    if (nvr && (!vr || !value)) return FAIL(comp, "fmi2GetReal: NULL array");
    if (nvr && (nvr != INST(comp)->real_memo_n || memcmp(vr, INST(comp)->real_memo, nvr * sizeof *vr) != 0)) {
        for (k = 0; k < nvr; ++k)
            if ((s = check_vr(c, "fmi2GetReal", vr[k], 1, 0, 0)) != fmi2OK) return s;
        if (nvr && nvr <= REAL_MEMO) {
            memcpy(INST(comp)->real_memo, vr, nvr * sizeof *vr);
            INST(comp)->real_memo_n = nvr;
        }
    }
    if ((s = (fmi2Status)core_refresh_outputs(c)) > fmi2Warning) return s;
    for (k = 0; k < nvr; ++k) value[k] = c->r[vr[k]];
    return fmi2OK;
}

fmi2Status fmi2GetInteger(fmi2Component comp, const fmi2ValueReference vr[], size_t nvr, fmi2Integer value[])
{
    fmu_core *c = CORE(comp);
    size_t k;
    fmi2Status s;
    CHECK_INSTANCE(comp, "fmi2GetInteger");
    if ((s = (fmi2Status)core_check_readable(c, "fmi2GetInteger")) != fmi2OK) return s;
    if (nvr && (!vr || !value)) return FAIL(comp, "fmi2GetInteger: NULL array");
    for (k = 0; k < nvr; ++k)
        if ((s = check_vr(c, "fmi2GetInteger", vr[k], 0, 1, 0)) != fmi2OK) return s;
    if ((s = (fmi2Status)core_refresh_outputs(c)) > fmi2Warning) return s;
    for (k = 0; k < nvr; ++k) value[k] = c->i[vr[k]];
    return fmi2OK;
}

fmi2Status fmi2GetBoolean(fmi2Component comp, const fmi2ValueReference vr[], size_t nvr, fmi2Boolean value[])
{
    (void)value;
    CHECK_INSTANCE(comp, "fmi2GetBoolean");
    if (nvr == 0) return fmi2OK;
    if (!vr) return FAIL(comp, "fmi2GetBoolean: NULL array");
    if (check_vr(CORE(comp), "fmi2GetBoolean", vr[0], 0, 0, 0) != fmi2OK) return fmi2Error;
    return FAIL(comp, "fmi2GetBoolean: %s is not a Boolean (this FMU has no Boolean variable)", VAR(vr[0])->name);
}

fmi2Status fmi2GetString(fmi2Component comp, const fmi2ValueReference vr[], size_t nvr, fmi2String value[])
{
    fmu_core *c = CORE(comp);
    size_t k;
    fmi2Status s;
    CHECK_INSTANCE(comp, "fmi2GetString");
    if ((s = (fmi2Status)core_check_readable(c, "fmi2GetString")) != fmi2OK) return s;
    if (nvr && (!vr || !value)) return FAIL(comp, "fmi2GetString: NULL array");
    for (k = 0; k < nvr; ++k)
        if ((s = check_vr(c, "fmi2GetString", vr[k], 0, 0, 1)) != fmi2OK) return s;
    for (k = 0; k < nvr; ++k) value[k] = c->message;
    return fmi2OK;
}

fmi2Status fmi2SetReal(fmi2Component comp, const fmi2ValueReference vr[], size_t nvr, const fmi2Real value[])
{
    fmu_core *c = CORE(comp);
    size_t k;
    fmi2Status s;
    CHECK_INSTANCE(comp, "fmi2SetReal");
    if (nvr && (!vr || !value)) return FAIL(comp, "fmi2SetReal: NULL array");
    /* all or nothing: check every value before storing any */
    for (k = 0; k < nvr; ++k) {
        if ((s = check_vr(c, "fmi2SetReal", vr[k], 1, 0, 0)) != fmi2OK) return s;
        if ((s = (fmi2Status)core_check_settable(c, "fmi2SetReal", (int)vr[k], NULL)) != fmi2OK) return s;
        if ((s = (fmi2Status)core_check_range(c, "fmi2SetReal", (int)vr[k], NULL, value[k])) != fmi2OK) return s;
    }
    for (k = 0; k < nvr; ++k) core_store_real(c, (int)vr[k], value[k]);
    return fmi2OK;
}

fmi2Status fmi2SetInteger(fmi2Component comp, const fmi2ValueReference vr[], size_t nvr, const fmi2Integer value[])
{
    fmu_core *c = CORE(comp);
    size_t k;
    fmi2Status s;
    CHECK_INSTANCE(comp, "fmi2SetInteger");
    if (nvr && (!vr || !value)) return FAIL(comp, "fmi2SetInteger: NULL array");
    for (k = 0; k < nvr; ++k) {
        if ((s = check_vr(c, "fmi2SetInteger", vr[k], 0, 1, 0)) != fmi2OK) return s;
        if ((s = (fmi2Status)core_check_settable(c, "fmi2SetInteger", (int)vr[k], NULL)) != fmi2OK) return s;
        if ((s = (fmi2Status)core_check_range(c, "fmi2SetInteger", (int)vr[k], NULL, (double)value[k])) != fmi2OK)
            return s;
    }
    for (k = 0; k < nvr; ++k) core_store_int(c, (int)vr[k], value[k]);
    return fmi2OK;
}

fmi2Status fmi2SetBoolean(fmi2Component comp, const fmi2ValueReference vr[], size_t nvr, const fmi2Boolean value[])
{
    (void)value;
    CHECK_INSTANCE(comp, "fmi2SetBoolean");
    if (nvr == 0) return fmi2OK;
    if (!vr) return FAIL(comp, "fmi2SetBoolean: NULL array");
    if (check_vr(CORE(comp), "fmi2SetBoolean", vr[0], 0, 0, 0) != fmi2OK) return fmi2Error;
    return FAIL(comp, "fmi2SetBoolean: %s is not a Boolean (this FMU has no Boolean variable)", VAR(vr[0])->name);
}

fmi2Status fmi2SetString(fmi2Component comp, const fmi2ValueReference vr[], size_t nvr, const fmi2String value[])
{
    fmu_core *c = CORE(comp);
    size_t k;
    fmi2Status s;
    CHECK_INSTANCE(comp, "fmi2SetString");
    if (nvr && (!vr || !value)) return FAIL(comp, "fmi2SetString: NULL array");
    for (k = 0; k < nvr; ++k) {
        if ((s = check_vr(c, "fmi2SetString", vr[k], 0, 0, 1)) != fmi2OK) return s;
        if ((s = (fmi2Status)core_check_settable(c, "fmi2SetString", (int)vr[k], NULL)) != fmi2OK) return s;
        if (!value[k]) return FAIL(comp, "fmi2SetString: %s: NULL string", VAR(vr[k])->name);
    }
    return fmi2OK; /* unreachable: every String is an output, refused by core_check_settable */
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
    return FAIL(comp, "fmi2SetRealInputDerivatives: the inputs are held over each step (canInterpolateInputs = "
                "false)");
}

fmi2Status fmi2GetRealOutputDerivatives(fmi2Component comp, const fmi2ValueReference vr[], size_t nvr,
                                        const fmi2Integer order[], fmi2Real value[])
{
    (void)vr;
    (void)nvr;
    (void)order;
    (void)value;
    CHECK_INSTANCE(comp, "fmi2GetRealOutputDerivatives");
    return FAIL(comp, "fmi2GetRealOutputDerivatives: not provided (maxOutputDerivativeOrder = 0)");
}

fmi2Status fmi2DoStep(fmi2Component comp, fmi2Real t, fmi2Real h, fmi2Boolean noSetFMUStatePriorToCurrentPoint)
{
    int early;
    (void)noSetFMUStatePriorToCurrentPoint;
    CHECK_INSTANCE(comp, "fmi2DoStep");
    return (fmi2Status)core_step(CORE(comp), "fmi2DoStep", t, h, NULL, &early);
}

fmi2Status fmi2CancelStep(fmi2Component comp)
{
    CHECK_INSTANCE(comp, "fmi2CancelStep");
    return FAIL(comp, "fmi2CancelStep: steps are synchronous (canRunAsynchronuously = false)");
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
    *value = CORE(comp)->last_good;
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
    *value = CORE(comp)->stopped ? fmi2True : fmi2False; /* the model ended the run (a discarded step) */
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

fmi2Status fmi2GetFMUstate(fmi2Component comp, fmi2FMUstate *state)
{
    CHECK_INSTANCE(comp, "fmi2GetFMUstate");
    return (fmi2Status)core_get_state(CORE(comp), "fmi2GetFMUstate", state);
}

fmi2Status fmi2SetFMUstate(fmi2Component comp, fmi2FMUstate state)
{
    CHECK_INSTANCE(comp, "fmi2SetFMUstate");
    return (fmi2Status)core_set_state(CORE(comp), "fmi2SetFMUstate", state);
}

fmi2Status fmi2FreeFMUstate(fmi2Component comp, fmi2FMUstate *state)
{
    CHECK_INSTANCE(comp, "fmi2FreeFMUstate");
    return (fmi2Status)core_free_state(CORE(comp), "fmi2FreeFMUstate", state);
}

fmi2Status fmi2SerializedFMUstateSize(fmi2Component comp, fmi2FMUstate state, size_t *size)
{
    CHECK_INSTANCE(comp, "fmi2SerializedFMUstateSize");
    return (fmi2Status)core_serialized_size(CORE(comp), "fmi2SerializedFMUstateSize", state, size);
}

fmi2Status fmi2SerializeFMUstate(fmi2Component comp, fmi2FMUstate state, fmi2Byte bytes[], size_t size)
{
    CHECK_INSTANCE(comp, "fmi2SerializeFMUstate");
    return (fmi2Status)core_serialize(CORE(comp), "fmi2SerializeFMUstate", state, (unsigned char *)bytes, size);
}

fmi2Status fmi2DeSerializeFMUstate(fmi2Component comp, const fmi2Byte bytes[], size_t size, fmi2FMUstate *state)
{
    CHECK_INSTANCE(comp, "fmi2DeSerializeFMUstate");
    return (fmi2Status)core_deserialize(CORE(comp), "fmi2DeSerializeFMUstate", (const unsigned char *)bytes, size,
                                        state);
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
    return FAIL(comp, "fmi2GetDirectionalDerivative: not provided (providesDirectionalDerivative = false)");
}
