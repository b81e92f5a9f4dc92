/*
 * fmu_core.h: what the FMI 2.0 and FMI 3.0 co-simulation wrappers (fmi2_cs.c, fmi3_cs.c) share around a model
 * (fmu_model.h): the values (one slot per FMI 2.0 value reference of MODEL_INFO), the phases of a simulation,
 * the checks of a value (causality, variability, declared range, the model's rules), the communication step
 * with the divergence rule, logging, and the FMU-state snapshots with their serialisation. A wrapper adds its
 * standard's calling conventions: names, callbacks, types, and for FMI 3.0 the arrays and the early return.
 *
 * Status codes are model_status (numbered as fmi2Status and fmi3Status); every message names the call with
 * the wrapper's function names (core_dialect), so an FMI 3.0 user reads fmi3SetFMUState, not fmi2SetFMUstate.
 */
#ifndef ROTORUB_FMU_CORE_H
#define ROTORUB_FMU_CORE_H

#include <stdarg.h>
#include <stddef.h>

#include "fmu_model.h"

#define CORE_MSG_LEN 1024

typedef enum { PH_INSTANTIATED, PH_INITIALIZATION, PH_STEP, PH_TERMINATED } core_phase;
extern const char *const CORE_PHASE_NAME[];

/* the standard's names as the messages use them */
typedef struct {
    unsigned state_magic;       /* of in-memory and serialized states: "RRF2", "RRF3" */
    const char *set_state;      /* fmi2SetFMUstate */
    const char *reset;          /* fmi2Reset */
    const char *terminate;      /* fmi2Terminate */
    const char *free_instance;  /* fmi2FreeInstance */
    const char *enter_init;     /* fmi2EnterInitializationMode */
    const char *exit_init;      /* fmi2ExitInitializationMode */
    const char *terminated;     /* fmi2Terminated: the flag that says the run ended */
    int read_before_init;       /* values may be read in the instantiated phase (FMI 3.0: the start values) */
    /* a step after which the model cannot go on (a divergence) ends the run: FMI 2.0 says so with fmi2Discard and
     * fmi2Terminated; FMI 3.0 with fmi3OK and terminateSimulation (its fmi3Discard means "nothing changed, the
     * output arguments are undefined", which is not the case: the step reached a time and its outputs stand) */
    int end_run_with_ok;
} core_dialect;

typedef struct fmu_core fmu_core;
/* hand one finished message to the host (the wrapper knows its callback) */
typedef void (*core_log_fn)(fmu_core *c, model_status status, const char *category, const char *text);

struct fmu_core {
    const core_dialect *d;
    core_log_fn log;
    char *name;
    int logging;
    core_phase phase;
    double time;
    double last_good;
    double *r;
    int *i;
    char message[CORE_MSG_LEN];
    int stopped; /* the model ended the run (a discarded step) */
    char stop_reason[CORE_MSG_LEN];
    model_values v;
    model_runtime *m;
    int inputs_changed; /* feedthrough: outputs to recompute before a read */
    int initial_stale;  /* initialization mode: a value changed since the outputs were last computed */
};

#define CORE_N_VARS ((size_t)MODEL_INFO.n_vars)
#define CORE_VAR(slot) (&MODEL_INFO.vars[slot])

/* 0, or -1 (out of memory: nothing allocated); the values start at their start values */
int core_init(fmu_core *c, const core_dialect *d, core_log_fn log, const char *name, int logging);
void core_release(fmu_core *c);

/* A refused call: logged (status MODEL_ERROR or MODEL_DISCARD), its cause in 'message', and for an error the
 * 'status' output says bad input or configuration. Returns status. */
model_status core_fail(fmu_core *c, model_status status, const char *fmt, ...);
void core_warn(fmu_core *c, const char *fmt, ...);
void core_debug(fmu_core *c, const char *fmt, ...);

/* refused in the instantiated phase unless the dialect allows it */
model_status core_check_readable(fmu_core *c, const char *fn);
/* may slot be set now? name: how the message calls the variable (NULL: the slot's own name) */
model_status core_check_settable(fmu_core *c, const char *fn, int slot, const char *name);
/* x within slot's declared range, finite, and allowed by the model's rules */
model_status core_check_range(fmu_core *c, const char *fn, int slot, const char *name, double x);
/* store a checked value (marks the outputs of a feedthrough model stale) */
void core_store_real(fmu_core *c, int slot, double x);
void core_store_int(fmu_core *c, int slot, int x);
/* feedthrough build: recompute the outputs at the current inputs before a read */
model_status core_refresh_outputs(fmu_core *c);

/* the phases */
model_status core_enter_init(fmu_core *c, const char *fn);
model_status core_exit_init(fmu_core *c, const char *fn);
model_status core_terminate(fmu_core *c, const char *fn);
void core_reset(fmu_core *c);

/* One communication step [t, t + h] with the divergence rule. to_event NULL: model_step; else the model's step
 * that ends at its first event inside the step (model_step_to_event), *early then 1 and the FMU's time the
 * event's. A step that ends the run: MODEL_DISCARD, or with the dialect's end_run_with_ok MODEL_OK, the FMU's
 * time then the last successful one; c->stopped says it in both. */
typedef model_status (*core_event_step)(model_runtime *m, model_values *v, double t, double h, int *event, char *msg,
                                        size_t len);
model_status core_step(fmu_core *c, const char *fn, double t, double h, core_event_step to_event, int *early);

/* FMU states: opaque pointers to snapshots this binary made */
model_status core_get_state(fmu_core *c, const char *fn, void **state);
model_status core_set_state(fmu_core *c, const char *fn, const void *state);
model_status core_free_state(fmu_core *c, const char *fn, void **state);
model_status core_serialized_size(fmu_core *c, const char *fn, const void *state, size_t *size);
model_status core_serialize(fmu_core *c, const char *fn, const void *state, unsigned char *bytes, size_t size);
model_status core_deserialize(fmu_core *c, const char *fn, const unsigned char *bytes, size_t size, void **state);

#endif
