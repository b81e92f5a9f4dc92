/*
 * fmu_model.h: the contract between the FMI 2.0 co-simulation wrapper (fmi2_cs.c) and a model behind it
 * (contact_model.c: RotorCasingContact; spool_model.c: LPSpool), as the Modelica Reference-FMUs keep one
 * small model source behind a shared wrapper.
 *
 * The wrapper owns the variable values (one slot per value reference in each of a Real and an Integer
 * array), the FMI state machine, logging, the checks every variable has (type, causality, variability,
 * declared range) and FMU-state snapshots; the model owns the physics: configuration at the end of
 * initialisation, a communication step, the outputs of its state, rules that tie one variable to another,
 * and what a snapshot of its state holds. `rotorub build-fmu --native` generates each model's variable table
 * (MODEL_INFO) from the Python definition of its interface.
 */
#ifndef ROTORUB_FMU_MODEL_H
#define ROTORUB_FMU_MODEL_H

#include <stddef.h>

#include "fmi2Functions.h"

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

/* The most substeps one fmi2DoStep may take (fmu_src/interface.py MAX_SUBSTEPS): a longer communication
 * step is refused with fmi2Error and the longest step allowed, instead of minutes to hours inside one call
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
 * the simulation (m configured): fmi2OK, or fmi2Error with the reason in msg (nothing is stored).
 * Before initialisation the same rules are model_configure's. */
fmi2Status model_check_set(const model_runtime *m, const model_values *v, int vr, double x, char *msg, size_t len);

/* One communication step [t, t + h] at the inputs held in v: fmi2OK; fmi2Discard (the model cannot go
 * on: diverged, stopped, no balanced solution) or fmi2Error (an input the step cannot take) with the
 * reason in msg. Outputs and the status output are written to v. */
fmi2Status model_step(model_runtime *m, model_values *v, double t, double h, char *msg, size_t len);

/* The outputs at time t of the current state, at the current inputs, without advancing time (after
 * initialisation; feedthrough models after a set): fmi2OK or fmi2Discard with msg. */
fmi2Status model_solve_now(model_runtime *m, model_values *v, double t, char *msg, size_t len);

/* The time advanced by the last step (all of h, or up to the last good substep). */
double model_time_advanced(const model_runtime *m);

/* Snapshot of the state a rollback needs, as doubles: model_state_size of them. restore returns 0,
 * or -1 if the data are not a state of this configuration (nothing is changed). */
size_t model_state_size(const model_runtime *m);
void model_state_save(const model_runtime *m, double *out);
int model_state_restore(model_runtime *m, const double *in, size_t n);

#endif
