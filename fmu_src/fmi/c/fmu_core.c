/*
 * fmu_core.c: the half of the FMI wrappers that does not depend on the standard's version (fmu_core.h).
 *
 * What a system simulator can rely on, in FMI 2.0 and FMI 3.0 alike:
 *   - every misuse is an error with a logged message that names the variable, the value and the accepted
 *     range or the rule (never a silent OK, never Fatal, never a crash), and leaves the instance as it was;
 *   - configuration errors are reported when initialisation ends (the parameters can be corrected and the
 *     call repeated);
 *   - a step the model cannot complete (a divergence, a speed that would fall below 0, no balanced solution) ends the run at
 *     the last successful time, with the reason in the log and in 'message': FMI 2.0 fmi2Discard then
 *     fmi2Terminated; FMI 3.0 fmi3OK with terminateSimulation (the dialect's end_run_with_ok), so that every
 *     master ends it cleanly with what it has. The flag belongs to the FMU state: restoring a state saved
 *     before the step (or a reset) clears it; a further step without that is an error;
 *   - a serialized state carries a checksum of every byte: a state changed anywhere after serialisation is
 *     refused, as a state of another FMU or build is;
 *   - a state can be restored in every phase, the instantiated one included: a state saved during a run is
 *     restored with its model (configured from the state's own parameters);
 *   - errors and warnings reach the logger whether or not logging was switched on (debug messages only when
 *     it was), and the last message is in the 'message' output.
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmu_core.h"
#include "model.h"

/* ------------------------------------------------------------------ what a model need not write */

#ifndef MODEL_HAS_CHECK_SET
model_status model_check_set(const model_runtime *m, const model_values *v, int vr, double x, char *msg, size_t len)
{
    (void)m;
    (void)v;
    (void)vr;
    (void)x;
    (void)msg;
    (void)len;
    return MODEL_OK; /* the declared ranges are the only rules */
}
#endif

#ifndef MODEL_HAS_STEP_TO_EVENT
model_status model_step_to_event(model_runtime *m, model_values *v, double t, double h, int *event, char *msg,
                                 size_t len)
{
    *event = 0; /* a model without events: every step is model_step's */
    return model_step(m, v, t, h, msg, len);
}
#endif

#ifndef MODEL_HAS_TIME_ADVANCED
double model_time_advanced(const model_runtime *m)
{
    (void)m;
    return 0.0; /* a refused step leaves the state as it was */
}
#endif

const char *const CORE_PHASE_NAME[] = {"instantiated", "initialization mode", "step mode", "terminated"};

typedef struct {
    void *self;             /* the snapshot's own address: tells a state passed by value from a pointer to one */
    unsigned magic;
    const model_info *info; /* &MODEL_INFO of the binary that made it: another FMU's (or build's) is refused */
    const fmu_core *owner;
    core_phase phase;
    double time, last_good;
    double *r;
    int *i;
    char message[CORE_MSG_LEN];
    int stopped;
    char stop_reason[CORE_MSG_LEN];
    size_t n_model;
    double *model;
} snapshot_t;

/* a snapshot this binary made: every FMU built on these wrappers shares the magic of its FMI version, and the
 * model state's size alone does not tell two builds of one model apart */
#define IS_OURS(c, p) ((p) && (p)->magic == (c)->d->state_magic && (p)->info == &MODEL_INFO)

const char *core_num(double x, char *buf, size_t len)
{
    int p, e;
    const char *exp_at;
    double a = fabs(x);
    for (p = 1; p <= 17; ++p) {
        snprintf(buf, len, "%.*g", p, x);
        if (strtod(buf, NULL) == x) break;
    }
    if (p > 17) p = 17;
    /* %g writes 20 as 2e+01 with one digit: the same digits without an exponent where a person expects none (the
     * exponent read from the text itself: no libm, the native FMU links none) */
    if (isfinite(x) && a >= 1e-4 && a < 1e16 && (exp_at = strchr(buf, 'e')) != NULL) {
        e = atoi(exp_at + 1);
        snprintf(buf, len, "%.*f", p - 1 - e > 0 ? p - 1 - e : 0, x);
    }
    return buf;
}

/* ------------------------------------------------------------------ logging */

static void logv(fmu_core *c, model_status status, const char *category, const char *fmt, va_list ap)
{
    char buf[CORE_MSG_LEN];
    vsnprintf(buf, sizeof buf, fmt, ap);
    if (status >= MODEL_DISCARD) {
        memcpy(c->message, buf, sizeof buf);
        c->message[CORE_MSG_LEN - 1] = '\0';
    }
    if (c->log && (status >= MODEL_WARNING || c->logging)) c->log(c, status, category, buf);
}

model_status core_fail(fmu_core *c, model_status status, const char *fmt, ...)
{
    va_list ap;
    /* a refusal after a divergence leaves status at 1: the run ended diverged, whatever the master tries next */
    if (status == MODEL_ERROR && !c->stopped) c->i[MODEL_INFO.vr_status] = STATUS_BAD_INPUT;
    va_start(ap, fmt);
    logv(c, status, status == MODEL_ERROR ? "logStatusError" : "logStatusDiscard", fmt, ap);
    va_end(ap);
    return status;
}

void core_warn(fmu_core *c, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    logv(c, MODEL_WARNING, "logStatusWarning", fmt, ap);
    va_end(ap);
}

void core_debug(fmu_core *c, const char *fmt, ...)
{
    va_list ap;
    if (!c->logging) return;
    va_start(ap, fmt);
    logv(c, MODEL_OK, "logAll", fmt, ap);
    va_end(ap);
}

/* ------------------------------------------------------------------ an instance's values */

/* the only String a model has is its 'message' output (the build refuses any other) */
static void set_starts(fmu_core *c)
{
    size_t k;
    for (k = 0; k < CORE_N_VARS; ++k) {
        const model_var *v = CORE_VAR(k);
        c->r[k] = v->name && v->type == VT_REAL ? v->start : 0.0;
        c->i[k] = v->name && (v->type == VT_INTEGER || v->type == VT_ENUM) ? (int)v->start : 0;
    }
    c->message[0] = '\0';
    c->stopped = 0;
    c->stop_reason[0] = '\0';
}

int core_init(fmu_core *c, const core_dialect *d, core_log_fn log, const char *name, int logging)
{
    size_t n = CORE_N_VARS;
    memset(c, 0, sizeof *c);
    c->name = (char *)malloc(strlen(name) + 1);
    c->r = (double *)calloc(n, sizeof(double));
    c->i = (int *)calloc(n, sizeof(int));
    if (!c->name || !c->r || !c->i) {
        core_release(c);
        return -1;
    }
    strcpy(c->name, name);
    c->d = d;
    c->log = log;
    c->logging = logging;
    c->phase = PH_INSTANTIATED;
    c->v.r = c->r;
    c->v.i = c->i;
    set_starts(c);
    return 0;
}

void core_release(fmu_core *c)
{
    model_free(c->m);
    free(c->name);
    free(c->r);
    free(c->i);
    c->m = NULL;
    c->name = NULL;
    c->r = NULL;
    c->i = NULL;
}

model_status core_check_readable(fmu_core *c, const char *fn)
{
    if (c->phase == PH_INSTANTIATED && !c->d->read_before_init)
        return core_fail(c, MODEL_ERROR, "%s: the instance is instantiated: values are read from %s on (the start "
                         "values are in modelDescription.xml)", fn, c->d->enter_init);
    return MODEL_OK;
}

model_status core_check_settable(fmu_core *c, const char *fn, int slot, const char *name)
{
    const model_var *v = CORE_VAR(slot);
    const char *d_reset = c->d->reset;
    if (!name) name = v->name;
    if (v->causality == VC_OUTPUT) return core_fail(c, MODEL_ERROR, "%s: %s is an output and cannot be set", fn, name);
    if (c->phase == PH_TERMINATED)
        return core_fail(c, MODEL_ERROR, "%s: %s: the instance is terminated (%s or %s)", fn, name, d_reset,
                         c->d->free_instance);
    if (c->stopped) /* no inputs after a discarded step: the master rolls back or ends */
        return core_fail(c, MODEL_ERROR, "%s: %s: the FMU ended this simulation (%s is true): %s; roll back with %s "
                         "first, or %s / %s", fn, name, c->d->terminated, c->stop_reason, c->d->set_state,
                         c->d->terminate, d_reset);
    if (v->variability == VV_FIXED && c->phase == PH_STEP)
        return core_fail(c, MODEL_ERROR, "%s: %s is a fixed parameter: it cannot change after initialisation (%s "
                         "first)", fn, name, d_reset);
    return MODEL_OK;
}

model_status core_check_range(fmu_core *c, const char *fn, int slot, const char *name, double x)
{
    const model_var *v = CORE_VAR(slot);
    char bx[32], blo[32], bhi[32], msg[CORE_MSG_LEN];
    const char *unit = v->unit && v->unit[0] ? v->unit : NULL;
    if (!name) name = v->name;
    if (!isfinite(x))
        return core_fail(c, MODEL_ERROR, "%s: %s = %g is not finite; accepted range [%s, %s]%s%s", fn, name, x,
                         core_num(v->min, blo, sizeof blo), core_num(v->max, bhi, sizeof bhi), unit ? " " : "",
                         unit ? unit : "");
    if (v->has_range && (x < v->min || x > v->max))
        return core_fail(c, MODEL_ERROR, "%s: %s = %s%s%s out of range; accepted range [%s, %s]%s%s", fn, name,
                         core_num(x, bx, sizeof bx), unit ? " " : "", unit ? unit : "",
                         core_num(v->min, blo, sizeof blo), core_num(v->max, bhi, sizeof bhi), unit ? " " : "",
                         unit ? unit : "");
    /* a rule of the model between this variable and the fixed ones, once they are fixed */
    if (c->m && c->phase == PH_STEP && v->causality != VC_OUTPUT &&
        model_check_set(c->m, &c->v, slot, x, msg, sizeof msg) != MODEL_OK)
        return core_fail(c, MODEL_ERROR, "%s: %s", fn, msg);
    return MODEL_OK;
}

static void after_set(fmu_core *c, int slot)
{
    if (CORE_VAR(slot)->causality == VC_INPUT || CORE_VAR(slot)->variability == VV_TUNABLE) c->inputs_changed = 1;
}

void core_store_real(fmu_core *c, int slot, double x)
{
    if (c->r[slot] != x) after_set(c, slot);
    c->r[slot] = x;
    c->initial_stale = 1;
}

void core_store_int(fmu_core *c, int slot, int x)
{
    c->i[slot] = x;
    c->initial_stale = 1;
}

/* FMI lets a master read the outputs in initialization mode, and masters that propagate their connections
 * before the first step (libcosim, OMSimulator) pass them on: they are those of a model configured from the
 * values set so far, redone after any value changes. A configuration that does not hold yet is no error
 * here (the master may still be setting values): exit from initialization mode reports it. */
static model_status initial_outputs(fmu_core *c)
{
    char msg[CORE_MSG_LEN];
    if (!c->initial_stale && c->m) return MODEL_OK;
    c->initial_stale = 0;
    model_free(c->m);
    c->m = model_configure(&c->v, c->time, msg, sizeof msg);
    if (c->m) (void)model_solve_now(c->m, &c->v, c->time, msg, sizeof msg);
    return MODEL_OK;
}

model_status core_refresh_outputs(fmu_core *c)
{
    char msg[CORE_MSG_LEN];
    model_status s;
    if (c->phase == PH_INITIALIZATION) return initial_outputs(c);
    if (!MODEL_INFO.feedthrough || !c->inputs_changed || !c->m || c->phase != PH_STEP) return MODEL_OK;
    c->inputs_changed = 0;
    s = model_solve_now(c->m, &c->v, c->time, msg, sizeof msg);
    if (s != MODEL_OK) {
        c->i[MODEL_INFO.vr_status] = STATUS_DIVERGED;
        return core_fail(c, s, "%s", msg);
    }
    return MODEL_OK;
}

/* ------------------------------------------------------------------ phases */

model_status core_enter_init(fmu_core *c, const char *fn)
{
    if (c->phase != PH_INSTANTIATED)
        return core_fail(c, MODEL_ERROR, "%s: the instance is in %s", fn, CORE_PHASE_NAME[c->phase]);
    c->phase = PH_INITIALIZATION;
    c->initial_stale = 1;
    return MODEL_OK;
}

model_status core_exit_init(fmu_core *c, const char *fn)
{
    char msg[CORE_MSG_LEN];
    model_status s;
    if (c->phase != PH_INITIALIZATION)
        return core_fail(c, MODEL_ERROR, "%s: the instance is in %s", fn, CORE_PHASE_NAME[c->phase]);
    model_free(c->m);
    c->m = model_configure(&c->v, c->time, msg, sizeof msg);
    if (!c->m) return core_fail(c, MODEL_ERROR, "%s: %s", fn, msg);
    c->phase = PH_STEP;
    c->i[MODEL_INFO.vr_status] = STATUS_OK;
    c->message[0] = '\0';
    c->stopped = 0;
    c->stop_reason[0] = '\0';
    c->inputs_changed = 0;
    s = model_solve_now(c->m, &c->v, c->time, msg, sizeof msg);
    if (s != MODEL_OK) {
        /* quasi-static: no balanced solution at the initial inputs (or one deeper than the divergence depth). Not
         * a refused call: the model is configured, the outputs are those the model wrote (the state at rest, or
         * that solution), 'status' says 1 and 'message' why, and the first step tries again at its inputs (a sweep
         * that starts outside goes on). OK, logged as a warning: a master that stops on any status above OK
         * (fmusim) still records the initial row and reads the status there; the first step that cannot solve
         * ends the run as any divergence does */
        c->i[MODEL_INFO.vr_status] = STATUS_DIVERGED;
        core_warn(c, "%s: %s (status = 1; the first step tries again at its inputs)", fn, msg);
        snprintf(c->message, sizeof c->message, "%s: %s", fn, msg);
    }
    return MODEL_OK;
}

model_status core_terminate(fmu_core *c, const char *fn)
{
    if (c->phase != PH_STEP) /* after initialisation only (a reset ends the others) */
        return core_fail(c, MODEL_ERROR, "%s: the instance is in %s (a simulation ends with %s once it is "
                         "initialised; %s or %s end it in any state)", fn, CORE_PHASE_NAME[c->phase], c->d->terminate,
                         c->d->reset, c->d->free_instance);
    c->phase = PH_TERMINATED;
    return MODEL_OK;
}

void core_reset(fmu_core *c)
{
    model_free(c->m);
    c->m = NULL;
    c->phase = PH_INSTANTIATED;
    c->time = c->last_good = 0.0;
    c->inputs_changed = 0;
    set_starts(c);
}

/* ------------------------------------------------------------------ the communication step */

model_status core_step(fmu_core *c, const char *fn, double t, double h, core_event_step to_event,
                       int *early)
{
    char msg[CORE_MSG_LEN], bt[32], bc[32];
    model_status s;
    double tol;
    int event = 0;
    *early = 0;
    if (c->phase != PH_STEP)
        return core_fail(c, MODEL_ERROR, "%s: the instance is in %s (steps are taken after %s and before %s)", fn,
                         CORE_PHASE_NAME[c->phase], c->d->exit_init, c->d->terminate);
    if (c->stopped)
        return core_fail(c, MODEL_ERROR, "%s: the FMU ended this simulation at t = %s s (%s is true): %s; call %s, "
                         "or roll back with %s to a state saved before, or %s", fn,
                         core_num(c->last_good, bt, sizeof bt), c->d->terminated, c->stop_reason, c->d->terminate,
                         c->d->set_state, c->d->reset);
    if (!isfinite(h) || !(h > 0.0))
        return core_fail(c, MODEL_ERROR, "%s: communicationStepSize = %g: must be finite and > 0", fn, h);
    tol = 1e-9 * (fabs(c->time) > h ? fabs(c->time) : h);
    if (!isfinite(t) || fabs(t - c->time) > tol)
        return core_fail(c, MODEL_ERROR, "%s: currentCommunicationPoint = %s does not match the FMU's time %s (steps "
                         "must follow each other; to go back, use %s)", fn, core_num(t, bt, sizeof bt),
                         core_num(c->time, bc, sizeof bc), c->d->set_state);
    s = to_event ? to_event(c->m, &c->v, c->time, h, &event, msg, sizeof msg)
                 : model_step(c->m, &c->v, c->time, h, msg, sizeof msg);
    c->inputs_changed = 0;
    if (s == MODEL_OK) {
        /* an early return ends at the time the model reached; the full step at t + h exactly, as the master
         * computes its next communication point */
        c->time = event ? c->time + model_time_advanced(c->m) : c->time + h;
        c->last_good = c->time;
        c->message[0] = '\0';
        *early = event;
        return MODEL_OK;
    }
    c->last_good = c->time + model_time_advanced(c->m);
    if (s == MODEL_DISCARD) {
        /* the model cannot go on from here: the run ends, unless the master rolls back; the status says so
         * whatever the last good step reported (quasi_static: 3, unstable) */
        c->i[MODEL_INFO.vr_status] = STATUS_DIVERGED;
        c->stopped = 1;
        snprintf(c->stop_reason, sizeof c->stop_reason, "%s", msg);
        if (c->d->end_run_with_ok) {
            /* FMI 3.0: the step ends at the last successful time with its outputs, terminateSimulation says the
             * run is over; a master records the row and stops (fmpy, fmusim), or rolls back */
            c->time = c->last_good;
            core_warn(c, "%s at t = %s s: %s (%s = true: the run ends at t = %s s; %s to an earlier state to go on)",
                      fn, core_num(t, bt, sizeof bt), msg, c->d->terminated, core_num(c->last_good, bc, sizeof bc),
                      c->d->set_state);
            snprintf(c->message, sizeof c->message, "%s at t = %s s: %s", fn, bt, msg);
            return MODEL_OK;
        }
        return core_fail(c, s, "%s at t = %s s: %s (%s = true: the run ends at the last successful time %s s; %s to "
                         "an earlier state to go on)", fn, core_num(t, bt, sizeof bt), msg, c->d->terminated,
                         core_num(c->last_good, bc, sizeof bc), c->d->set_state);
    }
    return core_fail(c, s, "%s at t = %s s: %s", fn, core_num(t, bt, sizeof bt), msg);
}

/* ------------------------------------------------------------------ FMU states */

static void free_snapshot(snapshot_t *p)
{
    if (!p) return;
    free(p->r);
    free(p->i);
    free(p->model);
    free(p);
}

/* a snapshot with room for every variable (and n_model model values), marked as this binary's */
static snapshot_t *new_snapshot(fmu_core *c, size_t n_model)
{
    snapshot_t *p = (snapshot_t *)calloc(1, sizeof *p);
    if (!p) return NULL;
    p->r = (double *)calloc(CORE_N_VARS, sizeof(double));
    p->i = (int *)calloc(CORE_N_VARS, sizeof(int));
    p->model = n_model ? (double *)calloc(n_model, sizeof(double)) : NULL;
    if (!p->r || !p->i || (n_model && !p->model)) {
        free_snapshot(p);
        return NULL;
    }
    p->self = p;
    p->magic = c->d->state_magic;
    p->info = &MODEL_INFO;
    p->owner = c;
    p->n_model = n_model;
    return p;
}

model_status core_get_state(fmu_core *c, const char *fn, void **state)
{
    snapshot_t *p;
    if (!state) return core_fail(c, MODEL_ERROR, "%s: NULL pointer", fn);
    p = (snapshot_t *)*state;
    if (p && !IS_OURS(c, p)) return core_fail(c, MODEL_ERROR, "%s: *FMUstate is not a state of this FMU", fn);
    if (!p && !(p = new_snapshot(c, 0))) return core_fail(c, MODEL_ERROR, "%s: out of memory", fn);
    p->owner = c;
    p->phase = c->phase;
    p->time = c->time;
    p->last_good = c->last_good;
    memcpy(p->r, c->r, CORE_N_VARS * sizeof(double));
    memcpy(p->i, c->i, CORE_N_VARS * sizeof(int));
    memcpy(p->message, c->message, CORE_MSG_LEN);
    p->stopped = c->stopped;
    memcpy(p->stop_reason, c->stop_reason, CORE_MSG_LEN);
    free(p->model);
    p->model = NULL;
    p->n_model = c->m ? model_state_size(c->m) : 0;
    if (p->n_model) {
        p->model = (double *)malloc(p->n_model * sizeof(double));
        if (!p->model) {
            free_snapshot(p);
            *state = NULL;
            return core_fail(c, MODEL_ERROR, "%s: out of memory", fn);
        }
        model_state_save(c->m, p->model);
    }
    *state = p;
    return MODEL_OK;
}

/* the fixed parameters of a snapshot are those this instance's model was configured with */
static int same_configuration(const fmu_core *c, const snapshot_t *p)
{
    size_t k;
    for (k = 0; k < CORE_N_VARS; ++k) {
        const model_var *v = CORE_VAR(k);
        if (!v->name || v->causality != VC_PARAMETER || v->variability != VV_FIXED) continue;
        if (v->type == VT_REAL ? c->r[k] != p->r[k] : c->i[k] != p->i[k]) return 0;
    }
    return 1;
}

/* Restore a snapshot in any phase. A state saved during a run brings its model: this instance's when it was
 * configured with the same fixed parameters, otherwise one configured from the state's own values (a state
 * restored right after instantiation, as fmusim's --initial-fmu-state-file does). A state saved before
 * initialisation leaves no model. Nothing changes when the state is refused. */
model_status core_set_state(fmu_core *c, const char *fn, const void *state)
{
    const snapshot_t *p = (const snapshot_t *)state;
    char msg[CORE_MSG_LEN];
    model_runtime *m = NULL;
    int fresh = 0;
    if (!IS_OURS(c, p)) return core_fail(c, MODEL_ERROR, "%s: not a state of this FMU (another FMU's or build's)", fn);
    if (p->phase > PH_TERMINATED || (p->phase == PH_STEP && !p->n_model))
        return core_fail(c, MODEL_ERROR, "%s: corrupt state (phase)", fn);
    if (p->n_model) {
        if (c->m && same_configuration(c, p)) {
            m = c->m;
        } else {
            model_values pv;
            pv.r = p->r;
            pv.i = p->i;
            m = model_configure(&pv, p->time, msg, sizeof msg);
            if (!m)
                return core_fail(c, MODEL_ERROR, "%s: the state's parameters do not make a model (%s); nothing "
                                 "restored", fn, msg);
            fresh = 1;
        }
        if (model_state_restore(m, p->model, p->n_model) != 0) {
            if (fresh) model_free(m);
            return core_fail(c, MODEL_ERROR, "%s: the state was saved with another configuration or is corrupt; "
                             "nothing restored", fn);
        }
    }
    if (m != c->m) {
        model_free(c->m);
        c->m = m;
    }
    c->phase = p->phase;
    c->time = p->time;
    c->last_good = p->last_good;
    memcpy(c->r, p->r, CORE_N_VARS * sizeof(double));
    memcpy(c->i, p->i, CORE_N_VARS * sizeof(int));
    memcpy(c->message, p->message, CORE_MSG_LEN);
    c->stopped = p->stopped;
    memcpy(c->stop_reason, p->stop_reason, CORE_MSG_LEN);
    c->inputs_changed = 0;
    c->initial_stale = 1;
    return MODEL_OK;
}

model_status core_free_state(fmu_core *c, const char *fn, void **state)
{
    if (!state || !*state) return MODEL_OK;
    if (*state == (void *)state) {
        /* the state itself where the standard passes the address of the host's variable holding it (fmusim
         * 0.0.39 does this): its first field is its own address. Freed, so the host neither crashes nor leaks;
         * the host's variable cannot be cleared, hence the warning. */
        if (!IS_OURS(c, (snapshot_t *)state)) return core_fail(c, MODEL_ERROR, "%s: not a state of this FMU", fn);
        free_snapshot((snapshot_t *)state);
        /* OK, not Warning: fmusim ends its run at any status above OK, and the state is freed as it asked */
        core_warn(c, "%s: was given the FMU state itself instead of a pointer to it (a defect of the host); the state "
                  "is freed, but the host's variable still holds its address: do not use it", fn);
        return MODEL_OK;
    }
    if (!IS_OURS(c, (snapshot_t *)*state)) return core_fail(c, MODEL_ERROR, "%s: not a state of this FMU", fn);
    free_snapshot((snapshot_t *)*state);
    *state = NULL;
    return MODEL_OK;
}

/* serialised: magic, guid (64 bytes), phase, n_vars, n_model, stopped (8 bytes each), time, last_good, r[], i[],
 * message, stop_reason, model[], and the 64-bit FNV-1a checksum of every byte before it (any single changed byte
 * changes it: each step of FNV-1a is a bijection of the running hash) */
#define GUID_BYTES 64
#define HEAD_BYTES (4 + GUID_BYTES + 4 * 8 + 2 * 8)
#define SUM_BYTES 8
static size_t serialized_size_of(size_t n_model)
{
    return HEAD_BYTES + CORE_N_VARS * 8 + CORE_N_VARS * 4 + 2 * CORE_MSG_LEN + n_model * 8 + SUM_BYTES;
}

static unsigned long long fnv1a64(const unsigned char *bytes, size_t n)
{
    unsigned long long h = 0xcbf29ce484222325ull;
    size_t k;
    for (k = 0; k < n; ++k) {
        h ^= bytes[k];
        h *= 0x100000001b3ull;
    }
    return h;
}

model_status core_serialized_size(fmu_core *c, const char *fn, const void *state, size_t *size)
{
    if (!IS_OURS(c, (const snapshot_t *)state) || !size)
        return core_fail(c, MODEL_ERROR, "%s: not a state of this FMU", fn);
    *size = serialized_size_of(((const snapshot_t *)state)->n_model);
    return MODEL_OK;
}

model_status core_serialize(fmu_core *c, const char *fn, const void *state, unsigned char *bytes, size_t size)
{
    const snapshot_t *p = (const snapshot_t *)state;
    size_t at = 0;
    unsigned long long u;
    char guid[GUID_BYTES];
    if (!IS_OURS(c, p)) return core_fail(c, MODEL_ERROR, "%s: not a state of this FMU", fn);
    if (!bytes || size != serialized_size_of(p->n_model))
        return core_fail(c, MODEL_ERROR, "%s: the buffer has %zu bytes, the state needs %zu", fn, size,
                         serialized_size_of(p->n_model));
    memset(guid, 0, sizeof guid);
    strncpy(guid, MODEL_INFO.guid, GUID_BYTES - 1);
#define PUT(src, nbytes) (memcpy(bytes + at, (src), (nbytes)), at += (nbytes))
    PUT(&p->magic, 4);
    PUT(guid, GUID_BYTES);
    u = (unsigned long long)p->phase;
    PUT(&u, 8);
    u = (unsigned long long)CORE_N_VARS;
    PUT(&u, 8);
    u = (unsigned long long)p->n_model;
    PUT(&u, 8);
    u = (unsigned long long)p->stopped;
    PUT(&u, 8);
    PUT(&p->time, 8);
    PUT(&p->last_good, 8);
    PUT(p->r, CORE_N_VARS * 8);
    PUT(p->i, CORE_N_VARS * 4);
    PUT(p->message, CORE_MSG_LEN);
    PUT(p->stop_reason, CORE_MSG_LEN);
    if (p->n_model) PUT(p->model, p->n_model * 8);
    u = fnv1a64(bytes, at);
    PUT(&u, SUM_BYTES);
#undef PUT
    return MODEL_OK;
}

model_status core_deserialize(fmu_core *c, const char *fn, const unsigned char *bytes, size_t size, void **state)
{
    size_t at = 0, k;
    unsigned long long phase, nv, nm, stopped, sum;
    unsigned magic;
    char guid[GUID_BYTES];
    snapshot_t *p;
    if (!bytes || !state) return core_fail(c, MODEL_ERROR, "%s: NULL pointer", fn);
    if (size < HEAD_BYTES + SUM_BYTES)
        return core_fail(c, MODEL_ERROR, "%s: %zu bytes: too short to be a state of this FMU", fn, size);
#define GET(dst, nbytes) (memcpy((dst), bytes + at, (nbytes)), at += (nbytes))
    GET(&magic, 4);
    GET(guid, GUID_BYTES);
    guid[GUID_BYTES - 1] = '\0';
    if (magic != c->d->state_magic || strcmp(guid, MODEL_INFO.guid) != 0)
        return core_fail(c, MODEL_ERROR, "%s: not a state of this FMU (wrong magic or GUID: another FMU's or build's, "
                         "or changed there); nothing restored", fn);
    memcpy(&sum, bytes + size - SUM_BYTES, SUM_BYTES);
    if (size < HEAD_BYTES + SUM_BYTES || fnv1a64(bytes, size - SUM_BYTES) != sum)
        return core_fail(c, MODEL_ERROR, "%s: corrupt state: its checksum does not match its %zu bytes (changed "
                         "after it was serialized, or cut short); nothing restored", fn, size);
    GET(&phase, 8);
    GET(&nv, 8);
    GET(&nm, 8);
    GET(&stopped, 8);
    if (phase > PH_TERMINATED || nv != CORE_N_VARS || nm > 100000 || stopped > 1 ||
        size != serialized_size_of((size_t)nm))
        return core_fail(c, MODEL_ERROR, "%s: corrupt state (sizes do not match this FMU)", fn);
    if (!(p = new_snapshot(c, (size_t)nm))) return core_fail(c, MODEL_ERROR, "%s: out of memory", fn);
    p->phase = (core_phase)phase;
    p->stopped = (int)stopped;
    GET(&p->time, 8);
    GET(&p->last_good, 8);
    GET(p->r, CORE_N_VARS * 8);
    GET(p->i, CORE_N_VARS * 4);
    GET(p->message, CORE_MSG_LEN);
    p->message[CORE_MSG_LEN - 1] = '\0';
    GET(p->stop_reason, CORE_MSG_LEN);
    p->stop_reason[CORE_MSG_LEN - 1] = '\0';
    if (nm) GET(p->model, (size_t)nm * 8);
#undef GET
    if (!isfinite(p->time) || !isfinite(p->last_good)) {
        free_snapshot(p);
        return core_fail(c, MODEL_ERROR, "%s: corrupt state (time)", fn);
    }
    for (k = 0; k < CORE_N_VARS; ++k) {
        const model_var *v = CORE_VAR(k);
        if (!v->name) continue;
        if ((v->type == VT_REAL && v->causality != VC_OUTPUT &&
             (!isfinite(p->r[k]) || (v->has_range && (p->r[k] < v->min || p->r[k] > v->max)))) ||
            (v->type == VT_ENUM && (p->i[k] < v->min || p->i[k] > v->max))) {
            free_snapshot(p);
            return core_fail(c, MODEL_ERROR, "%s: corrupt state (%s out of range)", fn, v->name);
        }
    }
    *state = p;
    return MODEL_OK;
}
