/*
 * fmu_model.h: the contract between the FMI co-simulation wrappers and a model behind them (fmu_src/models/<model>/
 * model.c), as the Modelica Reference-FMUs keep one small model source behind their FMI 1/2/3 wrappers. fmi2_cs.c (FMI 2.0) and fmi3_cs.c (FMI 3.0) are thin layers over fmu_core.c,
 * which holds what both share: the values, the state machine, the checks, the divergence rule and the FMU-state
 * snapshots. None of these files knows a model.
 *
 * The wrapper owns the variable values (one slot per FMI 2.0 value reference in each of a Real and an Integer
 * array; FMI 3.0 arrays are runs of these slots), the FMI state machine, logging, the checks every variable has
 * (type, causality, variability, declared range) and FMU-state snapshots; the model owns the physics:
 * configuration at the end of initialisation, a communication step, the outputs of its state, and what a snapshot
 * of its state holds. The build generates each model's variable table (MODEL_INFO, model_data.c) and its value
 * references (variables.h: VR_<NAME>) from the model's variables.py.
 *
 * A model writes only what differs from the defaults (fmu_core.c), and says so in its model.h:
 *   MODEL_HAS_CHECK_SET      model_check_set: rules between variables beyond the declared ranges (default: none)
 *   MODEL_HAS_STEP_TO_EVENT  model_step_to_event: a step that ends at the model's first event (default: no
 *                            events, model_step)
 *   MODEL_HAS_TIME_ADVANCED  model_time_advanced: how far a step that ends early or fails got (default: 0, a
 *                            refused step leaves the state as it was)
 */
#ifndef ROTORUB_FMU_MODEL_H
#define ROTORUB_FMU_MODEL_H

#include <stddef.h>

/* The model's answers, numbered as fmi2Status and fmi3Status are (OK, Warning, Discard, Error, Fatal): each
 * wrapper hands them on as its standard's status. */
typedef enum { MODEL_OK = 0, MODEL_WARNING = 1, MODEL_DISCARD = 2, MODEL_ERROR = 3, MODEL_FATAL = 4 } model_status;

/* ------------------------------------------------------------------ variables (generated table) */
typedef enum { VT_REAL, VT_INTEGER, VT_ENUM, VT_STRING } var_type;
typedef enum { VC_INPUT, VC_PARAMETER, VC_OUTPUT } var_causality;
typedef enum { VV_CONTINUOUS, VV_DISCRETE, VV_FIXED, VV_TUNABLE } var_variability;

typedef struct {
    const char *name;      /* NULL: no variable has this value reference (a gap in the numbering) */
    var_type type;
    var_causality causality;
    var_variability variability;
    int has_range;
    double min, max;       /* declared, inclusive */
    double start;          /* Real, Integer, Enumeration */
    const char *start_str; /* String */
    const char *unit;      /* "" when it has none: messages give a value with its unit */
} model_var;

typedef struct {
    const char *guid;
    const char *model_identifier;
    int n_vars;            /* value references 0 .. n_vars - 1 */
    const model_var *vars;
    int feedthrough;       /* outputs follow the inputs without a step (model_solve_now after a set) */
    int vr_status;         /* the Integer 'status' output */
    int vr_message;        /* the String 'message' output */
} model_info;

extern const model_info MODEL_INFO;

/* The most substeps one communication step (fmi2DoStep, fmi3DoStep) may take (a model's variables.py
 * MAX_SUBSTEPS): a longer communication step is refused with MODEL_ERROR and the longest step allowed, instead of
 * minutes to hours inside one call that no master can cancel (and an int that overflows). */
#define MODEL_MAX_SUBSTEPS 10000000

/* the status output's codes every model shares (a model may add its own above these) */
enum { STATUS_OK = 0, STATUS_DIVERGED = 1, STATUS_BAD_INPUT = 2 };

/* The values the wrapper holds (one slot per value reference in each array). */
typedef struct {
    double *r; /* Real */
    int *i;    /* Integer, Enumeration */
} model_values;

/* ------------------------------------------------------------------ the model */
typedef struct model_runtime model_runtime;

/* Build the runtime from the parameters in v (start time t0); NULL with the reason in msg if the
 * parameters do not make a model (a rule between variables, a singular matrix, ...). */
model_runtime *model_configure(const model_values *v, double t0, char *msg, size_t len);
void model_free(model_runtime *m);

/* A rule of the model between variables, checked when a tunable parameter or an input is set during
 * the simulation (m configured): MODEL_OK, or MODEL_ERROR with the reason in msg (nothing is stored).
 * Before initialisation the same rules are model_configure's. Default: the declared ranges are the only rules. */
model_status model_check_set(const model_runtime *m, const model_values *v, int vr, double x, char *msg, size_t len);

/* One communication step [t, t + h] at the inputs held in v: MODEL_OK; MODEL_DISCARD (the model cannot go
 * on: diverged, stopped, no balanced solution) or MODEL_ERROR (an input the step cannot take) with the
 * reason in msg. Outputs and the status output are written to v. */
model_status model_step(model_runtime *m, model_values *v, double t, double h, char *msg, size_t len);

/* The outputs at time t of the current state, at the current inputs, without advancing time (after
 * initialisation; feedthrough models after a set): MODEL_OK or MODEL_DISCARD with msg. */
model_status model_solve_now(model_runtime *m, model_values *v, double t, char *msg, size_t len);

/* The time advanced by the last step that ended early or failed (up to its last good substep). Default: 0. */
double model_time_advanced(const model_runtime *m);

/* Snapshot of the state a rollback needs, as doubles: model_state_size of them. restore returns 0,
 * or -1 if the data are not a state of this configuration (nothing is changed). */
size_t model_state_size(const model_runtime *m);
void model_state_save(const model_runtime *m, double *out);
int model_state_restore(model_runtime *m, const double *in, size_t n);

/* ------------------------------------------------------------------ FMI 3.0 events */
/* A communication step that ends early at the model's first event inside it (default: a model without events,
 * model_step with *event = 0): as model_step, but the step stops after the first internal substep at which an
 * event indicator of the model crosses 0; *event is then 1 and model_time_advanced() the
 * time reached (< h). The substeps taken are those model_step takes, bit for bit; a step without an event is
 * model_step's. */
model_status model_step_to_event(model_runtime *m, model_values *v, double t, double h, int *event, char *msg,
                                 size_t len);

/* ------------------------------------------------------------------ what the wrapper offers a model */
/* x as a person reads it and as it reads back: the shortest decimal that gives the same double (%.17g writes 640.8
 * as 640.79999999999995), without an exponent between 1e-4 and 1e16 (20, not 2e+01): every number a message
 * gives a master to act on (a step, a limit) reads back as the double the FMU used (fmu_core.c) */
const char *core_num(double x, char *buf, size_t len);
#endif
