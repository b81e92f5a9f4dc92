/*
 * model.h: what RotorCasingContact's model (model.c) takes from the data the build generates into model_data.c
 * from the parameter file (fmu_src/models/contact/builder.py): the structure's matrices, the contact geometry's
 * ingredients and where the kernel's outputs go. Its value references are variables.h's (VR_<NAME>, generated
 * from fmu_src/models/contact/variables.py), as are its enumerations' values (FORMULATION_3D, MODE_TRANSIENT,
 * LINER_ABRADABLE, ...).
 */
#ifndef ROTORUB_CONTACT_MODEL_H
#define ROTORUB_CONTACT_MODEL_H

#include "fmu_model.h"
#include "rotorub_kernel.h"
#include "variables.h"

/* what this model writes beyond fmu_model.h's defaults */
#define MODEL_HAS_CHECK_SET     /* g0 >= -max_penetration, also when g0 is tuned during the run */
#define MODEL_HAS_STEP_TO_EVENT /* FMI 3.0 early return at a first contact */
#define MODEL_HAS_TIME_ADVANCED /* a divergence reports the substep it reached */

/* A contact geometry built into the FMU, the library's arrays as built at the parameter file's cone angle and
 * chord: an imported blade's 3D tip (contact/fe_tip.py: nb segments between chord stations, each a 'blade' of the
 * kernel with compact rows over nloc dofs, the outputs reporting nb_out blades, the liner's n_rows rows the
 * stations), or the built-in blades facing an FE casing's modes (contact/geometry.py with_fe_casing: dense rows,
 * nloc = 0, the other fields 0 or NULL). NULL in model_data: the kernel's rr_contact_geometry, built at
 * initialisation from the ingredients above. */
typedef struct {
    int nb, nloc, nb_out, n_rows;
    double chord;    /* the chord of the law [m] */
    double band;     /* an imported tip: its axial extent, the band of the liner it sweeps [m] (0: chord cos stagger) */
    double tip_area; /* an imported tip: its footprint on the liner [m^2] (0: BLADE_THICKNESS x chord) */
    const double *seg_len, *seg_k, *g_off, *point_share;
    const int *cols, *blade_of, *point_row;
    const double *G, *A, *B, *S, *points, *normals, *tangents;
} model_geometry;

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
    const double *S4;      /* (n, n) an imported blade's Omega^4 prestress term, or NULL */
    int blk_ns, blk_nb, blk_m, blk_nc; /* the time step by blocks (hub, blades, casing) when blk_nb > 0: where the
                                        * library's CentralDifference takes it (BLOCK_MIN_DOFS), the same bits */
    const model_geometry *geo2d, *geo3d; /* built-in geometries (an imported tip, an FE casing), or NULL */
} model_data;

extern const model_data MODEL_DATA;

/* where rr_surface_summary's RR_WEAR_OUT values go (RR_WEAR_LOBES: the Integer array) */
extern const int WEAR_INDEX[];
extern const double BLADE_THICKNESS; /* [m]: a tip's footprint on the liner is this x the chord */
/* where the kernel's outputs of a state (its order, RR_N_OUT(nb)) go in the Real value array */
extern const int OUTPUT_INDEX[];

enum { STATUS_UNSTABLE = 3 }; /* quasi_static: the balanced solution is unstable */

#endif
