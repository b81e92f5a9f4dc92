/*
 * contact_model.h: what RotorCasingContact's model (contact_model.c) takes from the data
 * `rotorub build-fmu --native` generates into model_data.c from the parameter file and
 * fmu_src/interface.py: the structure's matrices, the contact geometry's ingredients and where the
 * kernel's outputs go.
 */
#ifndef ROTORUB_CONTACT_MODEL_H
#define ROTORUB_CONTACT_MODEL_H

#include "fmu_model.h"
#include "rotorub_kernel.h"

typedef struct {
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

/* value references the model reads and writes (fixed by fmu_src/interface.py; checked at build). Value
 * reference 4 is the pythonfmu flavour's param_file: the native FMU has no variable there. */
enum {
    VR_OMEGA, VR_IMBALANCE, VR_FORMULATION, VR_MODE, VR_PARAM_FILE_PYTHONFMU, VR_G0, VR_K_R, VR_MU, VR_THETA,
    VR_CHORD, VR_DT_MAX, VR_MAX_PEN, VR_SLIP
};
extern const int VR_N_CONTACT, VR_MAX_REAL, VR_DT_INTERNAL, VR_N_SUBSTEPS;
/* the liner and the engine's inputs on the casing (after every earlier variable) */
extern const int VR_LINER, VR_YIELD, VR_HARDENING, VR_THICKNESS, VR_N_SECTORS, VR_CLOSURE, VR_OFFSET_X, VR_OFFSET_Y,
    VR_CLEARANCE_EFFECTIVE;
/* where rr_surface_summary's RR_WEAR_OUT values go (RR_WEAR_LOBES: the Integer array) */
extern const int WEAR_INDEX[];
extern const double BLADE_THICKNESS; /* [m]: a tip's footprint on the liner is this x the chord */
/* where the kernel's outputs of a state (its order, RR_N_OUT(nb)) go in the Real value array */
extern const int OUTPUT_INDEX[];

enum { STATUS_UNSTABLE = 3 }; /* quasi_static: the balanced solution is unstable */
enum { FORMULATION_2D = 1, FORMULATION_3D = 2 };
enum { MODE_TRANSIENT = 1, MODE_QUASI_STATIC = 2 };
enum { LINER_RIGID = 1, LINER_ABRADABLE = 2 };

#endif
