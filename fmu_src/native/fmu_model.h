/*
 * fmu_model.h: the contract between the FMI 2.0 co-simulation wrapper (fmi2_cs.c) and a model
 * (contact_model.c, RotorCasingContact), and the data `rotorub build-fmu --native` generates into
 * model_data.c from the parameter file and fmu_src/interface.py.
 *
 * The wrapper owns the variable values (one slot per value reference in each of a Real, an
 * Integer and a String array), the FMI state machine, logging and FMU-state snapshots; the
 * model owns the physics: configuration at the end of initialisation, a communication step,
 * the outputs of its state, and what a snapshot of its state holds.
 */
#ifndef ROTORUB_FMU_MODEL_H
#define ROTORUB_FMU_MODEL_H

#include <stddef.h>

#include "fmi2Functions.h"
#include "rotorub_kernel.h"

/* ------------------------------------------------------------------ variables (generated table) */
typedef enum { VT_REAL, VT_INTEGER, VT_ENUM, VT_STRING } var_type;
typedef enum { VC_INPUT, VC_PARAMETER, VC_OUTPUT } var_causality;
typedef enum { VV_CONTINUOUS, VV_DISCRETE, VV_FIXED, VV_TUNABLE } var_variability;

typedef struct {
    const char *name;
    var_type type;
    var_causality causality;
    var_variability variability;
    int has_range;
    double min, max;       /* declared, inclusive */
    double start;          /* Real, Integer, Enumeration */
    const char *start_str; /* String */
} model_var;

/* ------------------------------------------------------------------ the model's data (generated) */
typedef struct {
    const char *guid;
    int n_vars;
    const model_var *vars;
    int feedthrough;       /* built for quasi_static: outputs follow the inputs without a step */
    int n;                 /* generalised coordinates */
    int nb;                /* blades */
    /* structure, rotating frame: M q'' + (D + W G1) q' + (K + W^2 (S2 + N2) + W C1) q = F_nl + me W^2 f_unit */
    const double *M, *D, *K, *G1, *C1, *N2, *S2, *f_unit;
    /* contact geometry ingredients (rr_geometry_spec but theta, chord, np, rotations) */
    double r_tip, stagger, z_cg;
    int blade_dof0, n_ritz, casing_dof0, n_modes;
    const double *psi_tip;
    const int *modes;
    const double *T, *Rot; /* (3, n) fan-disk translation and rotation */
} model_data;

extern const model_data MODEL_DATA;

/* value references the model reads and writes (fixed by fmu_src/interface.py; checked at build) */
enum {
    VR_OMEGA, VR_IMBALANCE, VR_FORMULATION, VR_MODE, VR_PARAM_FILE, VR_G0, VR_K_R, VR_MU, VR_THETA, VR_CHORD,
    VR_DT_MAX, VR_MAX_PEN, VR_SLIP
};
extern const int VR_N_CONTACT, VR_MAX_REAL, VR_STATUS, VR_MESSAGE, VR_DT_INTERNAL, VR_N_SUBSTEPS;
/* where the kernel's outputs of a state (its order, RR_N_OUT(nb)) go in the Real value array */
extern const int OUTPUT_INDEX[];

enum { STATUS_OK = 0, STATUS_DIVERGED = 1, STATUS_BAD_INPUT = 2, STATUS_UNSTABLE = 3 };
enum { FORMULATION_2D = 1, FORMULATION_3D = 2 };
enum { MODE_TRANSIENT = 1, MODE_QUASI_STATIC = 2 };

/* The values the wrapper holds (one slot per value reference in each array). */
typedef struct {
    double *r; /* Real */
    int *i;    /* Integer, Enumeration */
} model_values;

/* ------------------------------------------------------------------ the model (contact_model.c) */
typedef struct model_runtime model_runtime;

/* Build the runtime from the parameters in v; NULL with the reason in msg on error. */
model_runtime *model_configure(const model_values *v, char *msg, size_t len);
void model_free(model_runtime *m);

/* One communication step [t, t + h] at the inputs held in v: fmi2OK; fmi2Discard (diverged, no
 * balanced solution) or fmi2Error (an input the step cannot take) with the reason in msg.
 * Outputs, status, dt_internal and n_substeps are written to v. */
fmi2Status model_step(model_runtime *m, model_values *v, double h, char *msg, size_t len);

/* Quasi-static feedthrough: the balanced solution at the current inputs, without advancing time
 * (outputs written to v); fmi2OK or fmi2Discard with msg. */
fmi2Status model_solve_now(model_runtime *m, model_values *v, char *msg, size_t len);

/* The time advanced by the last step (all of h, or up to the last good substep). */
double model_time_advanced(const model_runtime *m);

/* Snapshot of the state a rollback needs, as doubles: model_state_size of them. restore
 * returns 0, or -1 if the data are not a state of this configuration (nothing is changed). */
size_t model_state_size(const model_runtime *m);
void model_state_save(const model_runtime *m, double *out);
int model_state_restore(model_runtime *m, const double *in, size_t n);

#endif
