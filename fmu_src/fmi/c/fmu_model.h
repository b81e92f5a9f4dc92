/*
 * fmu_model.h: the contract between the FMI co-simulation wrappers and a model behind them (contact_model.c:
 * RotorCasingContact; spool_model.c: LPSpool; clearance_model.c: TipClearance), as the Modelica Reference-FMUs
 * keep one small model source behind their FMI 1/2/3 wrappers. fmi2_cs.c (FMI 2.0) and fmi3_cs.c (FMI 3.0) are
 * thin layers over fmu_core.c, which holds what both share: the values, the state machine, the checks, the
 * divergence rule and the FMU-state snapshots.
 *
 * The wrapper owns the variable values (one slot per FMI 2.0 value reference in each of a Real and an Integer
 * array; FMI 3.0 arrays are runs of these slots), the FMI state machine, logging, the checks every variable has
 * (type, causality, variability, declared range) and FMU-state snapshots; the model owns the physics:
 * configuration at the end of initialisation, a communication step, the outputs of its state, rules that tie
 * one variable to another, and what a snapshot of its state holds. `rotorub build-fmu --native` generates each
 * model's variable table (MODEL_INFO) from the Python definition of its interface.
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

/* The most substeps one communication step (fmi2DoStep, fmi3DoStep) may take (fmu_src/interface.py
 * MAX_SUBSTEPS): a longer communication step is refused with MODEL_ERROR and the longest step allowed, instead of minutes to hours inside one call
 * that no master can cancel (and an int that overflows). */
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
 * Before initialisation the same rules are model_configure's. */
model_status model_check_set(const model_runtime *m, const model_values *v, int vr, double x, char *msg, size_t len);

/* One communication step [t, t + h] at the inputs held in v: MODEL_OK; MODEL_DISCARD (the model cannot go
 * on: diverged, stopped, no balanced solution) or MODEL_ERROR (an input the step cannot take) with the
 * reason in msg. Outputs and the status output are written to v. */
model_status model_step(model_runtime *m, model_values *v, double t, double h, char *msg, size_t len);

/* The outputs at time t of the current state, at the current inputs, without advancing time (after
 * initialisation; feedthrough models after a set): MODEL_OK or MODEL_DISCARD with msg. */
model_status model_solve_now(model_runtime *m, model_values *v, double t, char *msg, size_t len);

/* The time advanced by the last step (all of h, or up to the last good substep). */
double model_time_advanced(const model_runtime *m);

/* Snapshot of the state a rollback needs, as doubles: model_state_size of them. restore returns 0,
 * or -1 if the data are not a state of this configuration (nothing is changed). */
size_t model_state_size(const model_runtime *m);
void model_state_save(const model_runtime *m, double *out);
int model_state_restore(model_runtime *m, const double *in, size_t n);

/* ------------------------------------------------------------------ FMI 3.0 events (the contact model only) */
/* A communication step that ends early at the model's first event inside it: as model_step, but the step
 * stops after the first internal substep that brings a gap below 0 from a state without contact (a first
 * contact: the event indicator gap_min crossing 0 downwards); *event is then 1 and model_time_advanced() the
 * time reached (< h). The substeps taken are those model_step takes, bit for bit; a step without an event is
 * model_step's. */
model_status model_step_to_event(model_runtime *m, model_values *v, double t, double h, int *event, char *msg,
                                 size_t len);

/* ------------------------------------------------------------------ what the wrapper offers a model */
/* the shortest decimal that reads back as x (%.17g writes 640.8 as 640.79999999999995): every number a message
 * gives a master to act on (a step, a limit) reads back as the double the FMU used (fmu_core.c) */
const char *core_num(double x, char *buf, size_t len);
#endif
