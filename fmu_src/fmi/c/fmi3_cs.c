/*
 * fmi3_cs.c: the FMI 3.0 co-simulation interface around a model (fmu_model.h), the same model, values and rules
 * as the FMI 2.0 wrapper (fmi2_cs.c): both are thin layers over fmu_core.c. What FMI 3.0 adds here:
 *   - arrays: an FMI 3.0 variable is a run of the model's FMI 2.0 value slots (fmi3_vars.h), its size fixed by
 *     the build (a structural parameter, or a number); nValues must be the number of elements of the value
 *     references given, or the call is refused with nothing stored;
 *   - Enumerations are read and written with fmi3GetInt64 / fmi3SetInt64, as the standard says;
 *   - early return: instantiated with earlyReturnAllowed, fmi3DoStep ends at the model's first event inside the
 *     step (model_step_to_event: the first internal substep at which one of its event indicators crosses 0),
 *     with earlyReturn = true and lastSuccessfulTime that substep's end; without
 *     it, every step is the FMI 2.0 FMU's, bit for bit. No event mode (hasEventMode = false): the models' events
 *     change no discrete state, there is nothing for an event mode to update;
 *   - the divergence rule in FMI 3.0's terms: the step that diverges (or finds no balanced solution) returns fmi3OK
 *     with terminateSimulation = true, lastSuccessfulTime the time the model reached and, when early return is
 *     allowed and that time is before the communication point, earlyReturn = true; its outputs are those of the
 *     state reached. FMI 3.0's fmi3Discard would say "nothing changed, the output arguments are undefined", which
 *     is not what happened, and fmpy's FMI 3.0 loop raises on it (the user loses every row). fmi3SetFMUState to an
 *     earlier state (or fmi3Reset) goes on; a further step without that is fmi3Error. (The FMI 2.0 FMU keeps
 *     fmi2Discard, then fmi2Terminated, as FMI 2.0 asks.)
 * Every misuse is fmi3Error with a logged message naming the variable, the value and the accepted range or
 * the rule, the instance left as it was.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi3Functions.h"
#include "fmi3_vars.h"
#include "fmu_core.h"

typedef struct {
    fmu_core core; /* first: an inst_t is its core */
    fmi3InstanceEnvironment env;
    fmi3LogMessageCallback log_message;
    int early_return;
    int configuring; /* configuration mode (from the instantiated state): structural parameters only */
} inst_t;

static const core_dialect FMI3 = {0x52524633u /* "RRF3" */, "fmi3SetFMUState", "fmi3Reset", "fmi3Terminate",
                                  "fmi3FreeInstance", "fmi3EnterInitializationMode", "fmi3ExitInitializationMode",
                                  "terminateSimulation", 1, 1};

static const char *const TYPE_NAME[] = {"Float64", "Int32", "UInt64", "Enumeration", "String"};
static const char *const ACCESS[] = {"fmi3GetFloat64/fmi3SetFloat64", "fmi3GetInt32/fmi3SetInt32",
                                     "fmi3GetUInt64/fmi3SetUInt64", "fmi3GetInt64/fmi3SetInt64",
                                     "fmi3GetString/fmi3SetString"};

static void log_fmi3(fmu_core *core, model_status status, const char *category, const char *text)
{
    inst_t *c = (inst_t *)core;
    if (c->log_message) c->log_message(c->env, (fmi3Status)status, category, text);
}

#define INST(c) ((inst_t *)(c))
#define CORE(c) (&INST(c)->core)
#define CHECK_INSTANCE(c, fn)                                                                                          \
    do {                                                                                                               \
        if (!(c)) return fmi3Error;                                                                                    \
        if (CORE(c)->phase > PH_TERMINATED)                                                                            \
            return (fmi3Status)core_fail(CORE(c), MODEL_ERROR, "%s: invalid instance", fn);                            \
    } while (0)
#define FAIL(c, ...) ((fmi3Status)core_fail(CORE(c), MODEL_ERROR, __VA_ARGS__))
#define UNUSED(x) (void)(x)

/* ------------------------------------------------------------------ variables */

static const fmi3_var *lookup(inst_t *c, const char *fn, fmi3ValueReference vr)
{
    int k = vr <= FMI3_INFO.max_vr ? FMI3_INFO.by_vr[vr] : -1;
    if (k < 0) {
        core_fail(&c->core, MODEL_ERROR, "%s: unknown value reference %u (not a variable of this FMU: see its "
                  "modelDescription.xml)", fn, vr);
        return NULL;
    }
    return &FMI3_INFO.vars[k];
}

/* Check that every value reference is a variable of type want and that their elements add up to nValues;
 * the variables in out (nvr of them). Nothing is read or stored unless every one passes. */
static fmi3Status resolve(inst_t *c, const char *fn, v3_type want, const fmi3ValueReference vr[], size_t nvr,
                          const void *values, size_t n_values, const fmi3_var **out)
{
    size_t k, total = 0;
    if (nvr && !vr) return FAIL(c, "%s: valueReferences is NULL", fn);
    if (n_values && !values) return FAIL(c, "%s: values is NULL", fn);
    for (k = 0; k < nvr; ++k) {
        const fmi3_var *v = lookup(c, fn, vr[k]);
        if (!v) return fmi3Error;
        if (v->type != want)
            return FAIL(c, "%s: %s (value reference %u) is of type %s: use %s", fn, v->name, vr[k], TYPE_NAME[v->type],
                        ACCESS[v->type]);
        out[k] = v;
        total += (size_t)v->n;
    }
    if (total != n_values)
        return FAIL(c, "%s: nValues = %zu, but the %zu value reference(s) given have %zu element(s) (an array of "
                    "its size counts each element)", fn, n_values, nvr, total);
    return fmi3OK;
}

/* the refusal of a getter or setter of a type this FMU has no variable of */
static fmi3Status no_such_type(fmi3Instance inst, const char *fn, const char *type, const fmi3ValueReference vr[],
                               size_t nvr)
{
    const fmi3_var *v;
    CHECK_INSTANCE(inst, fn);
    if (nvr == 0) return fmi3OK;
    if (!vr) return FAIL(inst, "%s: valueReferences is NULL", fn);
    if (!(v = lookup(INST(inst), fn, vr[0]))) return fmi3Error;
    return FAIL(inst, "%s: %s (value reference %u) is of type %s, not %s (this FMU has no %s variable): use %s", fn,
                v->name, vr[0], TYPE_NAME[v->type], type, type, ACCESS[v->type]);
}

/* Each getter: resolve every variable first, then a feedthrough model's outputs follow the inputs. */
#define BEGIN_GET(fn, want)                                                                                            \
    inst_t *c = INST(instance);                                                                                        \
    const fmi3_var *stackv[64], **vars = stackv;                                                                       \
    size_t k, at = 0;                                                                                                  \
    fmi3Status s;                                                                                                      \
    CHECK_INSTANCE(instance, fn);                                                                                      \
    if ((s = (fmi3Status)core_check_readable(&c->core, fn)) != fmi3OK) return s;                                      \
    if (nValueReferences > 64 && !(vars = (const fmi3_var **)malloc(nValueReferences * sizeof *vars)))               \
        return FAIL(c, "%s: out of memory", fn);                                                                       \
    s = resolve(c, fn, want, valueReferences, nValueReferences, values, nValues, vars);                               \
    if (s == fmi3OK) s = (fmi3Status)core_refresh_outputs(&c->core);                                                   \
    if (s <= fmi3Warning)                                                                                              \
        for (k = 0; k < nValueReferences; ++k) {                                                                       \
            const fmi3_var *v = vars[k];                                                                               \
            int e;                                                                                                     \
            for (e = 0; e < v->n; ++e, ++at)
#define END_GET                                                                                                        \
    }                                                                                                                  \
    if (vars != stackv) free((void *)vars);                                                                            \
    return s > fmi3Warning ? s : fmi3OK;

static double float_of(const fmu_core *c, const fmi3_var *v, int e)
{
    if (v->kind == K3_TIME) return c->time;
    if (v->kind == K3_SUM) return c->r[v->slots[0]] + c->r[v->slots[1]];
    return c->r[v->slots[e]];
}

fmi3Status fmi3GetFloat64(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                          fmi3Float64 values[], size_t nValues)
{
    BEGIN_GET("fmi3GetFloat64", V3_FLOAT64)
    values[at] = float_of(&c->core, v, e);
    END_GET
}

fmi3Status fmi3GetInt32(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                        fmi3Int32 values[], size_t nValues)
{
    BEGIN_GET("fmi3GetInt32", V3_INT32)
    values[at] = c->core.i[v->slots[e]];
    END_GET
}

/* Enumerations (FMI 3.0 reads and writes them as Int64) */
fmi3Status fmi3GetInt64(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                        fmi3Int64 values[], size_t nValues)
{
    BEGIN_GET("fmi3GetInt64", V3_ENUM)
    values[at] = c->core.i[v->slots[e]];
    END_GET
}

fmi3Status fmi3GetUInt64(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                         fmi3UInt64 values[], size_t nValues)
{
    BEGIN_GET("fmi3GetUInt64", V3_UINT64)
    values[at] = v->fixed;
    END_GET
}

fmi3Status fmi3GetString(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                         fmi3String values[], size_t nValues)
{
    BEGIN_GET("fmi3GetString", V3_STRING)
    values[at] = c->core.message; /* the only String is the 'message' output */
    (void)e;
    END_GET
}

/* may every element of v be set now, to these values? (all or nothing) */
static fmi3Status check_set(inst_t *c, const char *fn, const fmi3_var *v, const double *x)
{
    int e;
    fmi3Status s;
    if (v->kind == K3_TIME)
        return FAIL(c, "%s: %s is the independent variable: it advances with fmi3DoStep and cannot be set", fn,
                    v->name);
    if (v->kind == K3_SUM) return FAIL(c, "%s: %s is a local variable (computed) and cannot be set", fn, v->name);
    if (v->kind == K3_STRUCTURAL) {
        char b[32];
        if (!c->configuring)
            return FAIL(c, "%s: %s is a structural parameter: set only in configuration mode "
                        "(fmi3EnterConfigurationMode from the instantiated state)", fn, v->name);
        if (x[0] != (double)v->fixed)
            return FAIL(c, "%s: %s = %s out of range; accepted range [%llu, %llu] (fixed when the FMU was built: "
                        "rebuild it for another value, as its manual documentation/FMU.md says)", fn,
                        v->name, core_num(x[0], b, sizeof b), v->fixed, v->fixed);
        return fmi3OK;
    }
    if (c->configuring && CORE_VAR(v->slots[0])->causality != VC_OUTPUT)
        return FAIL(c, "%s: %s: in configuration mode only structural parameters are set (fmi3ExitConfigurationMode "
                    "first)", fn, v->name);
    for (e = 0; e < v->n; ++e) {
        if ((s = (fmi3Status)core_check_settable(&c->core, fn, v->slots[e], v->name)) != fmi3OK) return s;
        if ((s = (fmi3Status)core_check_range(&c->core, fn, v->slots[e], v->name, x[e])) != fmi3OK) return s;
    }
    return fmi3OK;
}

/* Each setter: resolve, check every element of every variable, then store them all. The values are handed to
 * the checks as doubles: every Int32 and every enumeration value this FMU declares is exact in a double, and
 * an Int64 beyond 2^53 is far out of any declared range either way. */
#define SET_VALUES(fn, want, store)                                                                                    \
    inst_t *c = INST(instance);                                                                                        \
    const fmi3_var *stackv[64], **vars = stackv;                                                                       \
    size_t k, at;                                                                                                      \
    int e;                                                                                                             \
    fmi3Status s;                                                                                                      \
    CHECK_INSTANCE(instance, fn);                                                                                      \
    if (nValueReferences > 64 && !(vars = (const fmi3_var **)malloc(nValueReferences * sizeof *vars)))               \
        return FAIL(c, "%s: out of memory", fn);                                                                       \
    s = resolve(c, fn, want, valueReferences, nValueReferences, values, nValues, vars);                               \
    for (k = 0, at = 0; s == fmi3OK && k < nValueReferences; at += (size_t)vars[k]->n, ++k) {                         \
        double x[64];                                                                                                  \
        for (e = 0; e < vars[k]->n && e < 64; ++e) x[e] = (double)values[at + (size_t)e];                             \
        s = vars[k]->n > 64 ? FAIL(c, "%s: %s: more than 64 elements", fn, vars[k]->name)                              \
                            : check_set(c, fn, vars[k], x);                                                            \
    }                                                                                                                  \
    for (k = 0, at = 0; s == fmi3OK && k < nValueReferences; at += (size_t)vars[k]->n, ++k)                           \
        if (vars[k]->kind == K3_SLOTS)                                                                                 \
            for (e = 0; e < vars[k]->n; ++e) store(&c->core, vars[k]->slots[e], values[at + (size_t)e]);             \
    if (vars != stackv) free((void *)vars);                                                                            \
    return s;

static void store_int(fmu_core *c, int slot, double x) { core_store_int(c, slot, (int)x); }

fmi3Status fmi3SetFloat64(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                          const fmi3Float64 values[], size_t nValues)
{
    SET_VALUES("fmi3SetFloat64", V3_FLOAT64, core_store_real)
}

fmi3Status fmi3SetInt32(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                        const fmi3Int32 values[], size_t nValues)
{
    SET_VALUES("fmi3SetInt32", V3_INT32, store_int)
}

fmi3Status fmi3SetInt64(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                        const fmi3Int64 values[], size_t nValues)
{
    SET_VALUES("fmi3SetInt64", V3_ENUM, store_int)
}

fmi3Status fmi3SetUInt64(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                         const fmi3UInt64 values[], size_t nValues)
{
    SET_VALUES("fmi3SetUInt64", V3_UINT64, store_int) /* nothing is stored: a UInt64 is a structural parameter, fixed */
}

fmi3Status fmi3SetString(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                         const fmi3String values[], size_t nValues)
{
    inst_t *c = INST(instance);
    const fmi3_var *vars[64];
    size_t k;
    fmi3Status s;
    CHECK_INSTANCE(instance, "fmi3SetString");
    if (nValueReferences > 64) return FAIL(c, "fmi3SetString: more than 64 value references");
    if ((s = resolve(c, "fmi3SetString", V3_STRING, valueReferences, nValueReferences, values, nValues, vars)))
        return s;
    for (k = 0; k < nValueReferences; ++k) /* every String is an output: refused here */
        if ((s = (fmi3Status)core_check_settable(&c->core, "fmi3SetString", vars[k]->slots[0], vars[k]->name)))
            return s;
    return fmi3OK;
}

#define NO_SUCH_TYPE(T, CT, CONST)                                                                                     \
    fmi3Status fmi3Get##T(fmi3Instance instance, const fmi3ValueReference valueReferences[],                           \
                          size_t nValueReferences, CT values[], size_t nValues)                                        \
    {                                                                                                                  \
        UNUSED(values);                                                                                                \
        UNUSED(nValues);                                                                                               \
        return no_such_type(instance, "fmi3Get" #T, #T, valueReferences, nValueReferences);                           \
    }                                                                                                                  \
    fmi3Status fmi3Set##T(fmi3Instance instance, const fmi3ValueReference valueReferences[],                           \
                          size_t nValueReferences, CONST CT values[], size_t nValues)                                  \
    {                                                                                                                  \
        UNUSED(values);                                                                                                \
        UNUSED(nValues);                                                                                               \
        return no_such_type(instance, "fmi3Set" #T, #T, valueReferences, nValueReferences);                           \
    }
NO_SUCH_TYPE(Float32, fmi3Float32, const)
NO_SUCH_TYPE(Int8, fmi3Int8, const)
NO_SUCH_TYPE(UInt8, fmi3UInt8, const)
NO_SUCH_TYPE(Int16, fmi3Int16, const)
NO_SUCH_TYPE(UInt16, fmi3UInt16, const)
NO_SUCH_TYPE(UInt32, fmi3UInt32, const)
NO_SUCH_TYPE(Boolean, fmi3Boolean, const)

fmi3Status fmi3GetBinary(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                         size_t valueSizes[], fmi3Binary values[], size_t nValues)
{
    UNUSED(valueSizes);
    UNUSED(values);
    UNUSED(nValues);
    return no_such_type(instance, "fmi3GetBinary", "Binary", valueReferences, nValueReferences);
}

fmi3Status fmi3SetBinary(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                         const size_t valueSizes[], const fmi3Binary values[], size_t nValues)
{
    UNUSED(valueSizes);
    UNUSED(values);
    UNUSED(nValues);
    return no_such_type(instance, "fmi3SetBinary", "Binary", valueReferences, nValueReferences);
}

fmi3Status fmi3GetClock(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                        fmi3Clock values[])
{
    UNUSED(values);
    return no_such_type(instance, "fmi3GetClock", "Clock", valueReferences, nValueReferences);
}

fmi3Status fmi3SetClock(fmi3Instance instance, const fmi3ValueReference valueReferences[], size_t nValueReferences,
                        const fmi3Clock values[])
{
    UNUSED(values);
    return no_such_type(instance, "fmi3SetClock", "Clock", valueReferences, nValueReferences);
}

/* ------------------------------------------------------------------ common functions */

const char *fmi3GetVersion(void) { return fmi3Version; }

fmi3Status fmi3SetDebugLogging(fmi3Instance instance, fmi3Boolean loggingOn, size_t nCategories,
                               const fmi3String categories[])
{
    static const char *KNOWN[] = {"logStatusWarning", "logStatusDiscard", "logStatusError", "logStatusFatal",
                                  "logAll"};
    size_t k, j;
    CHECK_INSTANCE(instance, "fmi3SetDebugLogging");
    for (k = 0; k < nCategories; ++k) {
        int found = 0;
        for (j = 0; j < sizeof KNOWN / sizeof KNOWN[0]; ++j)
            if (categories && categories[k] && strcmp(categories[k], KNOWN[j]) == 0) found = 1;
        if (!found)
            return FAIL(instance, "fmi3SetDebugLogging: unknown log category '%s'; accepted: logStatusWarning, "
                        "logStatusDiscard, logStatusError, logStatusFatal, logAll",
                        categories && categories[k] ? categories[k] : "(null)");
    }
    CORE(instance)->logging = loggingOn ? 1 : 0;
    return fmi3OK;
}

static void refuse_instance(fmi3LogMessageCallback log, fmi3InstanceEnvironment env, const char *text)
{
    if (log) log(env, fmi3Error, "logStatusError", text);
}

fmi3Instance fmi3InstantiateModelExchange(fmi3String instanceName, fmi3String instantiationToken,
                                          fmi3String resourcePath, fmi3Boolean visible, fmi3Boolean loggingOn,
                                          fmi3InstanceEnvironment instanceEnvironment,
                                          fmi3LogMessageCallback logMessage)
{
    UNUSED(instanceName);
    UNUSED(instantiationToken);
    UNUSED(resourcePath);
    UNUSED(visible);
    UNUSED(loggingOn);
    refuse_instance(logMessage, instanceEnvironment, "fmi3InstantiateModelExchange: this FMU supports "
                    "co-simulation only (fmi3InstantiateCoSimulation)");
    return NULL;
}

fmi3Instance fmi3InstantiateCoSimulation(fmi3String instanceName, fmi3String instantiationToken,
                                         fmi3String resourcePath, fmi3Boolean visible, fmi3Boolean loggingOn,
                                         fmi3Boolean eventModeUsed, fmi3Boolean earlyReturnAllowed,
                                         const fmi3ValueReference requiredIntermediateVariables[],
                                         size_t nRequiredIntermediateVariables,
                                         fmi3InstanceEnvironment instanceEnvironment,
                                         fmi3LogMessageCallback logMessage,
                                         fmi3IntermediateUpdateCallback intermediateUpdate)
{
    inst_t *c;
    char buf[CORE_MSG_LEN];
    UNUSED(resourcePath);
    UNUSED(visible);
    UNUSED(requiredIntermediateVariables);
    UNUSED(intermediateUpdate); /* providesIntermediateUpdate = false: never called */
    if (!instanceName || !instanceName[0]) {
        refuse_instance(logMessage, instanceEnvironment, "fmi3InstantiateCoSimulation: missing instance name");
        return NULL;
    }
    if (!instantiationToken || strcmp(instantiationToken, MODEL_INFO.guid) != 0) {
        snprintf(buf, sizeof buf, "fmi3InstantiateCoSimulation: instantiationToken '%s' is not this FMU's (%s): "
                 "modelDescription.xml and the binary come from different builds",
                 instantiationToken ? instantiationToken : "(null)", MODEL_INFO.guid);
        refuse_instance(logMessage, instanceEnvironment, buf);
        return NULL;
    }
    if (eventModeUsed) {
        refuse_instance(logMessage, instanceEnvironment, "fmi3InstantiateCoSimulation: eventModeUsed = true, but this "
                        "FMU has no event mode (hasEventMode = false: its events change no discrete state); "
                        "instantiate with eventModeUsed = false, and earlyReturnAllowed = true to land on its events");
        return NULL;
    }
    c = (inst_t *)calloc(1, sizeof *c);
    if (!c || core_init(&c->core, &FMI3, log_fmi3, instanceName, loggingOn ? 1 : 0) != 0) {
        free(c);
        refuse_instance(logMessage, instanceEnvironment, "fmi3InstantiateCoSimulation: out of memory");
        return NULL;
    }
    c->env = instanceEnvironment;
    c->log_message = logMessage;
    c->early_return = earlyReturnAllowed ? 1 : 0;
    if (nRequiredIntermediateVariables)
        core_warn(&c->core, "fmi3InstantiateCoSimulation: %zu required intermediate variable(s) ignored: this FMU "
                  "provides no intermediate update (providesIntermediateUpdate = false)",
                  nRequiredIntermediateVariables);
    core_debug(&c->core, "fmi3InstantiateCoSimulation: %s (early return %s)", instanceName,
               c->early_return ? "allowed" : "not allowed");
    return c;
}

fmi3Instance fmi3InstantiateScheduledExecution(fmi3String instanceName, fmi3String instantiationToken,
                                               fmi3String resourcePath, fmi3Boolean visible, fmi3Boolean loggingOn,
                                               fmi3InstanceEnvironment instanceEnvironment,
                                               fmi3LogMessageCallback logMessage, fmi3ClockUpdateCallback clockUpdate,
                                               fmi3LockPreemptionCallback lockPreemption,
                                               fmi3UnlockPreemptionCallback unlockPreemption)
{
    UNUSED(instanceName);
    UNUSED(instantiationToken);
    UNUSED(resourcePath);
    UNUSED(visible);
    UNUSED(loggingOn);
    UNUSED(clockUpdate);
    UNUSED(lockPreemption);
    UNUSED(unlockPreemption);
    refuse_instance(logMessage, instanceEnvironment, "fmi3InstantiateScheduledExecution: this FMU supports "
                    "co-simulation only (fmi3InstantiateCoSimulation)");
    return NULL;
}

void fmi3FreeInstance(fmi3Instance instance)
{
    if (!instance) return;
    core_release(CORE(instance));
    free(instance);
}

static fmi3Status not_configuring(fmi3Instance instance, const char *fn)
{
    if (INST(instance)->configuring)
        return FAIL(instance, "%s: the instance is in configuration mode (fmi3ExitConfigurationMode first)", fn);
    return fmi3OK;
}

fmi3Status fmi3EnterInitializationMode(fmi3Instance instance, fmi3Boolean toleranceDefined, fmi3Float64 tolerance,
                                       fmi3Float64 startTime, fmi3Boolean stopTimeDefined, fmi3Float64 stopTime)
{
    fmu_core *c = CORE(instance);
    fmi3Status s;
    char b0[32], b1[32];
    UNUSED(toleranceDefined);
    UNUSED(tolerance);
    CHECK_INSTANCE(instance, "fmi3EnterInitializationMode");
    if ((s = not_configuring(instance, "fmi3EnterInitializationMode")) != fmi3OK) return s;
    if (c->phase != PH_INSTANTIATED)
        return FAIL(instance, "fmi3EnterInitializationMode: the instance is in %s", CORE_PHASE_NAME[c->phase]);
    if (!isfinite(startTime))
        return FAIL(instance, "fmi3EnterInitializationMode: startTime = %g is not finite", startTime);
    if (stopTimeDefined && !(stopTime >= startTime))
        return FAIL(instance, "fmi3EnterInitializationMode: stopTime = %s is before startTime = %s",
                    core_num(stopTime, b1, sizeof b1), core_num(startTime, b0, sizeof b0));
    c->time = c->last_good = startTime;
    return (fmi3Status)core_enter_init(c, "fmi3EnterInitializationMode");
}

fmi3Status fmi3ExitInitializationMode(fmi3Instance instance)
{
    CHECK_INSTANCE(instance, "fmi3ExitInitializationMode");
    return (fmi3Status)core_exit_init(CORE(instance), "fmi3ExitInitializationMode");
}

fmi3Status fmi3EnterEventMode(fmi3Instance instance)
{
    CHECK_INSTANCE(instance, "fmi3EnterEventMode");
    return FAIL(instance, "fmi3EnterEventMode: this FMU has no event mode (hasEventMode = false); with "
                "earlyReturnAllowed, fmi3DoStep returns early at the model's events instead");
}

fmi3Status fmi3Terminate(fmi3Instance instance)
{
    fmi3Status s;
    CHECK_INSTANCE(instance, "fmi3Terminate");
    if ((s = not_configuring(instance, "fmi3Terminate")) != fmi3OK) return s;
    return (fmi3Status)core_terminate(CORE(instance), "fmi3Terminate");
}

fmi3Status fmi3Reset(fmi3Instance instance)
{
    CHECK_INSTANCE(instance, "fmi3Reset");
    core_reset(CORE(instance));
    INST(instance)->configuring = 0;
    return fmi3OK;
}

fmi3Status fmi3GetNumberOfVariableDependencies(fmi3Instance instance, fmi3ValueReference valueReference,
                                               size_t *nDependencies)
{
    UNUSED(valueReference);
    UNUSED(nDependencies);
    CHECK_INSTANCE(instance, "fmi3GetNumberOfVariableDependencies");
    return FAIL(instance, "fmi3GetNumberOfVariableDependencies: not provided (the dependencies are in "
                "modelDescription.xml; providesPerElementDependencies = false)");
}

fmi3Status fmi3GetVariableDependencies(fmi3Instance instance, fmi3ValueReference dependent,
                                       size_t elementIndicesOfDependent[], fmi3ValueReference independents[],
                                       size_t elementIndicesOfIndependents[], fmi3DependencyKind dependencyKinds[],
                                       size_t nDependencies)
{
    UNUSED(dependent);
    UNUSED(elementIndicesOfDependent);
    UNUSED(independents);
    UNUSED(elementIndicesOfIndependents);
    UNUSED(dependencyKinds);
    UNUSED(nDependencies);
    CHECK_INSTANCE(instance, "fmi3GetVariableDependencies");
    return FAIL(instance, "fmi3GetVariableDependencies: not provided (the dependencies are in modelDescription.xml; "
                "providesPerElementDependencies = false)");
}

/* ------------------------------------------------------------------ FMU state */

fmi3Status fmi3GetFMUState(fmi3Instance instance, fmi3FMUState *FMUState)
{
    CHECK_INSTANCE(instance, "fmi3GetFMUState");
    return (fmi3Status)core_get_state(CORE(instance), "fmi3GetFMUState", FMUState);
}

fmi3Status fmi3SetFMUState(fmi3Instance instance, fmi3FMUState FMUState)
{
    fmi3Status s;
    CHECK_INSTANCE(instance, "fmi3SetFMUState");
    s = (fmi3Status)core_set_state(CORE(instance), "fmi3SetFMUState", FMUState);
    if (s == fmi3OK) INST(instance)->configuring = 0;
    return s;
}

fmi3Status fmi3FreeFMUState(fmi3Instance instance, fmi3FMUState *FMUState)
{
    CHECK_INSTANCE(instance, "fmi3FreeFMUState");
    return (fmi3Status)core_free_state(CORE(instance), "fmi3FreeFMUState", FMUState);
}

fmi3Status fmi3SerializedFMUStateSize(fmi3Instance instance, fmi3FMUState FMUState, size_t *size)
{
    CHECK_INSTANCE(instance, "fmi3SerializedFMUStateSize");
    return (fmi3Status)core_serialized_size(CORE(instance), "fmi3SerializedFMUStateSize", FMUState, size);
}

fmi3Status fmi3SerializeFMUState(fmi3Instance instance, fmi3FMUState FMUState, fmi3Byte serializedState[],
                                 size_t size)
{
    CHECK_INSTANCE(instance, "fmi3SerializeFMUState");
    return (fmi3Status)core_serialize(CORE(instance), "fmi3SerializeFMUState", FMUState, serializedState, size);
}

fmi3Status fmi3DeserializeFMUState(fmi3Instance instance, const fmi3Byte serializedState[], size_t size,
                                   fmi3FMUState *FMUState)
{
    CHECK_INSTANCE(instance, "fmi3DeserializeFMUState");
    return (fmi3Status)core_deserialize(CORE(instance), "fmi3DeserializeFMUState", serializedState, size, FMUState);
}

/* ------------------------------------------------------------------ derivatives, configuration, clocks */

fmi3Status fmi3GetDirectionalDerivative(fmi3Instance instance, const fmi3ValueReference unknowns[],
                                        size_t nUnknowns, const fmi3ValueReference knowns[], size_t nKnowns,
                                        const fmi3Float64 seed[], size_t nSeed, fmi3Float64 sensitivity[],
                                        size_t nSensitivity)
{
    UNUSED(unknowns);
    UNUSED(nUnknowns);
    UNUSED(knowns);
    UNUSED(nKnowns);
    UNUSED(seed);
    UNUSED(nSeed);
    UNUSED(sensitivity);
    UNUSED(nSensitivity);
    CHECK_INSTANCE(instance, "fmi3GetDirectionalDerivative");
    return FAIL(instance, "fmi3GetDirectionalDerivative: not provided (providesDirectionalDerivatives = false)");
}

fmi3Status fmi3GetAdjointDerivative(fmi3Instance instance, const fmi3ValueReference unknowns[], size_t nUnknowns,
                                    const fmi3ValueReference knowns[], size_t nKnowns, const fmi3Float64 seed[],
                                    size_t nSeed, fmi3Float64 sensitivity[], size_t nSensitivity)
{
    UNUSED(unknowns);
    UNUSED(nUnknowns);
    UNUSED(knowns);
    UNUSED(nKnowns);
    UNUSED(seed);
    UNUSED(nSeed);
    UNUSED(sensitivity);
    UNUSED(nSensitivity);
    CHECK_INSTANCE(instance, "fmi3GetAdjointDerivative");
    return FAIL(instance, "fmi3GetAdjointDerivative: not provided (providesAdjointDerivatives = false)");
}

/* Configuration mode exists for the structural parameters (an array's size), which the build fixes: one may be set to its
 * one value there (a master that sets every structural parameter it reads goes through), nothing else. */
fmi3Status fmi3EnterConfigurationMode(fmi3Instance instance)
{
    fmi3Status s;
    CHECK_INSTANCE(instance, "fmi3EnterConfigurationMode");
    if ((s = not_configuring(instance, "fmi3EnterConfigurationMode")) != fmi3OK) return s;
    if (CORE(instance)->phase != PH_INSTANTIATED)
        return FAIL(instance, "fmi3EnterConfigurationMode: the instance is in %s (configuration mode is entered from "
                    "the instantiated state; no structural parameter is tunable, so there is no reconfiguration "
                    "mode)", CORE_PHASE_NAME[CORE(instance)->phase]);
    INST(instance)->configuring = 1;
    return fmi3OK;
}

fmi3Status fmi3ExitConfigurationMode(fmi3Instance instance)
{
    CHECK_INSTANCE(instance, "fmi3ExitConfigurationMode");
    if (!INST(instance)->configuring)
        return FAIL(instance, "fmi3ExitConfigurationMode: the instance is not in configuration mode (it is in %s)",
                    CORE_PHASE_NAME[CORE(instance)->phase]);
    INST(instance)->configuring = 0;
    return fmi3OK;
}

#define NO_CLOCKS(fn)                                                                                                  \
    CHECK_INSTANCE(instance, fn);                                                                                      \
    return FAIL(instance, "%s: this FMU has no clocks", fn)

fmi3Status fmi3GetIntervalDecimal(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                  size_t nValueReferences, fmi3Float64 intervals[],
                                  fmi3IntervalQualifier qualifiers[])
{
    UNUSED(valueReferences);
    UNUSED(nValueReferences);
    UNUSED(intervals);
    UNUSED(qualifiers);
    NO_CLOCKS("fmi3GetIntervalDecimal");
}

fmi3Status fmi3GetIntervalFraction(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                   size_t nValueReferences, fmi3UInt64 counters[], fmi3UInt64 resolutions[],
                                   fmi3IntervalQualifier qualifiers[])
{
    UNUSED(valueReferences);
    UNUSED(nValueReferences);
    UNUSED(counters);
    UNUSED(resolutions);
    UNUSED(qualifiers);
    NO_CLOCKS("fmi3GetIntervalFraction");
}

fmi3Status fmi3GetShiftDecimal(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                               size_t nValueReferences, fmi3Float64 shifts[])
{
    UNUSED(valueReferences);
    UNUSED(nValueReferences);
    UNUSED(shifts);
    NO_CLOCKS("fmi3GetShiftDecimal");
}

fmi3Status fmi3GetShiftFraction(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                size_t nValueReferences, fmi3UInt64 counters[], fmi3UInt64 resolutions[])
{
    UNUSED(valueReferences);
    UNUSED(nValueReferences);
    UNUSED(counters);
    UNUSED(resolutions);
    NO_CLOCKS("fmi3GetShiftFraction");
}

fmi3Status fmi3SetIntervalDecimal(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                  size_t nValueReferences, const fmi3Float64 intervals[])
{
    UNUSED(valueReferences);
    UNUSED(nValueReferences);
    UNUSED(intervals);
    NO_CLOCKS("fmi3SetIntervalDecimal");
}

fmi3Status fmi3SetIntervalFraction(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                   size_t nValueReferences, const fmi3UInt64 counters[],
                                   const fmi3UInt64 resolutions[])
{
    UNUSED(valueReferences);
    UNUSED(nValueReferences);
    UNUSED(counters);
    UNUSED(resolutions);
    NO_CLOCKS("fmi3SetIntervalFraction");
}

fmi3Status fmi3SetShiftDecimal(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                               size_t nValueReferences, const fmi3Float64 shifts[])
{
    UNUSED(valueReferences);
    UNUSED(nValueReferences);
    UNUSED(shifts);
    NO_CLOCKS("fmi3SetShiftDecimal");
}

fmi3Status fmi3SetShiftFraction(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                size_t nValueReferences, const fmi3UInt64 counters[], const fmi3UInt64 resolutions[])
{
    UNUSED(valueReferences);
    UNUSED(nValueReferences);
    UNUSED(counters);
    UNUSED(resolutions);
    NO_CLOCKS("fmi3SetShiftFraction");
}

fmi3Status fmi3EvaluateDiscreteStates(fmi3Instance instance)
{
    CHECK_INSTANCE(instance, "fmi3EvaluateDiscreteStates");
    return FAIL(instance, "fmi3EvaluateDiscreteStates: not provided (providesEvaluateDiscreteStates = false)");
}

fmi3Status fmi3UpdateDiscreteStates(fmi3Instance instance, fmi3Boolean *discreteStatesNeedUpdate,
                                    fmi3Boolean *terminateSimulation, fmi3Boolean *nominalsOfContinuousStatesChanged,
                                    fmi3Boolean *valuesOfContinuousStatesChanged, fmi3Boolean *nextEventTimeDefined,
                                    fmi3Float64 *nextEventTime)
{
    UNUSED(discreteStatesNeedUpdate);
    UNUSED(terminateSimulation);
    UNUSED(nominalsOfContinuousStatesChanged);
    UNUSED(valuesOfContinuousStatesChanged);
    UNUSED(nextEventTimeDefined);
    UNUSED(nextEventTime);
    CHECK_INSTANCE(instance, "fmi3UpdateDiscreteStates");
    return FAIL(instance, "fmi3UpdateDiscreteStates: this FMU has no event mode (hasEventMode = false)");
}

/* ------------------------------------------------------------------ model exchange: not this FMU */

#define NOT_ME(fn)                                                                                                     \
    CHECK_INSTANCE(instance, fn);                                                                                      \
    return FAIL(instance, "%s: a model-exchange function; this FMU is co-simulation only", fn)

fmi3Status fmi3EnterContinuousTimeMode(fmi3Instance instance) { NOT_ME("fmi3EnterContinuousTimeMode"); }

fmi3Status fmi3CompletedIntegratorStep(fmi3Instance instance, fmi3Boolean noSetFMUStatePriorToCurrentPoint,
                                       fmi3Boolean *enterEventMode, fmi3Boolean *terminateSimulation)
{
    UNUSED(noSetFMUStatePriorToCurrentPoint);
    UNUSED(enterEventMode);
    UNUSED(terminateSimulation);
    NOT_ME("fmi3CompletedIntegratorStep");
}

fmi3Status fmi3SetTime(fmi3Instance instance, fmi3Float64 time)
{
    UNUSED(time);
    NOT_ME("fmi3SetTime");
}

fmi3Status fmi3SetContinuousStates(fmi3Instance instance, const fmi3Float64 continuousStates[],
                                   size_t nContinuousStates)
{
    UNUSED(continuousStates);
    UNUSED(nContinuousStates);
    NOT_ME("fmi3SetContinuousStates");
}

fmi3Status fmi3GetContinuousStateDerivatives(fmi3Instance instance, fmi3Float64 derivatives[],
                                             size_t nContinuousStates)
{
    UNUSED(derivatives);
    UNUSED(nContinuousStates);
    NOT_ME("fmi3GetContinuousStateDerivatives");
}

fmi3Status fmi3GetEventIndicators(fmi3Instance instance, fmi3Float64 eventIndicators[], size_t nEventIndicators)
{
    UNUSED(eventIndicators);
    UNUSED(nEventIndicators);
    NOT_ME("fmi3GetEventIndicators");
}

fmi3Status fmi3GetContinuousStates(fmi3Instance instance, fmi3Float64 continuousStates[], size_t nContinuousStates)
{
    UNUSED(continuousStates);
    UNUSED(nContinuousStates);
    NOT_ME("fmi3GetContinuousStates");
}

fmi3Status fmi3GetNominalsOfContinuousStates(fmi3Instance instance, fmi3Float64 nominals[],
                                             size_t nContinuousStates)
{
    UNUSED(nominals);
    UNUSED(nContinuousStates);
    NOT_ME("fmi3GetNominalsOfContinuousStates");
}

fmi3Status fmi3GetNumberOfEventIndicators(fmi3Instance instance, size_t *nEventIndicators)
{
    UNUSED(nEventIndicators);
    NOT_ME("fmi3GetNumberOfEventIndicators");
}

fmi3Status fmi3GetNumberOfContinuousStates(fmi3Instance instance, size_t *nContinuousStates)
{
    UNUSED(nContinuousStates);
    NOT_ME("fmi3GetNumberOfContinuousStates");
}

/* ------------------------------------------------------------------ co-simulation */

fmi3Status fmi3EnterStepMode(fmi3Instance instance)
{
    CHECK_INSTANCE(instance, "fmi3EnterStepMode");
    return FAIL(instance, "fmi3EnterStepMode: this FMU has no event mode (hasEventMode = false): "
                "fmi3ExitInitializationMode enters step mode");
}

fmi3Status fmi3GetOutputDerivatives(fmi3Instance instance, const fmi3ValueReference valueReferences[],
                                    size_t nValueReferences, const fmi3Int32 orders[], fmi3Float64 values[],
                                    size_t nValues)
{
    UNUSED(valueReferences);
    UNUSED(nValueReferences);
    UNUSED(orders);
    UNUSED(values);
    UNUSED(nValues);
    CHECK_INSTANCE(instance, "fmi3GetOutputDerivatives");
    return FAIL(instance, "fmi3GetOutputDerivatives: not provided (maxOutputDerivativeOrder = 0)");
}

fmi3Status fmi3DoStep(fmi3Instance instance, fmi3Float64 currentCommunicationPoint,
                      fmi3Float64 communicationStepSize, fmi3Boolean noSetFMUStatePriorToCurrentPoint,
                      fmi3Boolean *eventHandlingNeeded, fmi3Boolean *terminateSimulation, fmi3Boolean *earlyReturn,
                      fmi3Float64 *lastSuccessfulTime)
{
    inst_t *c = INST(instance);
    fmi3Status s;
    int early = 0;
    UNUSED(noSetFMUStatePriorToCurrentPoint);
    CHECK_INSTANCE(instance, "fmi3DoStep");
    if (!eventHandlingNeeded || !terminateSimulation || !earlyReturn || !lastSuccessfulTime)
        return FAIL(instance, "fmi3DoStep: NULL pointer among eventHandlingNeeded, terminateSimulation, earlyReturn, "
                    "lastSuccessfulTime");
    if ((s = not_configuring(instance, "fmi3DoStep")) == fmi3OK)
        s = (fmi3Status)core_step(&c->core, "fmi3DoStep", currentCommunicationPoint, communicationStepSize,
                                  c->early_return ? model_step_to_event : NULL, &early);
    *eventHandlingNeeded = fmi3False; /* no event mode: nothing to update */
    *terminateSimulation = c->core.stopped ? fmi3True : fmi3False;
    *lastSuccessfulTime = c->core.last_good;
    /* an early return at the model's event, or one that ends the run before the communication point (FMI 3.0 names
     * terminateSimulation among the reasons for an early return; without it allowed, the master stamps the row) */
    if (s == fmi3OK && c->core.stopped && c->early_return &&
        c->core.last_good < currentCommunicationPoint + communicationStepSize)
        early = 1;
    *earlyReturn = early ? fmi3True : fmi3False;
    if (early && !c->core.stopped) {
        char bt[32];
        core_debug(&c->core, "fmi3DoStep: the model's event at t = %s s: early return", core_num(c->core.time, bt, sizeof bt));
    }
    return s;
}

fmi3Status fmi3ActivateModelPartition(fmi3Instance instance, fmi3ValueReference clockReference,
                                      fmi3Float64 activationTime)
{
    UNUSED(clockReference);
    UNUSED(activationTime);
    CHECK_INSTANCE(instance, "fmi3ActivateModelPartition");
    return FAIL(instance, "fmi3ActivateModelPartition: scheduled execution is not supported");
}
