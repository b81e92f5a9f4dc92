/*
 * rotorub kernel, internal declarations shared by its source files (not part of the API: with
 * -fvisibility=hidden nothing here is exported). The public header is rotorub_kernel.h.
 *
 * The kernel's files, one concern each:
 *   rr_core.c      version, source id, scratch sizes, the elementary functions for tests
 *   rr_geometry.c  the contact geometry of the 2D and 3D formulations (gap gradients, sliding rows)
 *   rr_laws.c      the normal contact laws of one blade, one dispatch (penalty, bilinear)
 *   rr_contact.c   gaps, friction, the generalised contact force and its Jacobians, outputs of a state
 *   rr_liner.c     the casing surface: abradable liner, clearance closure, casing offset and distortion
 *   rr_cd.c        explicit central differences (the time loop, its matrices, K(Omega), the stability limit)
 *   rr_linalg.c    dense linear algebra: LU, inverse, eigenvalues
 *   rr_static.c    balanced static solutions (Newton)
 */
#ifndef RR_INTERNAL_H
#define RR_INTERNAL_H

#include <math.h>
#include <stddef.h>

#include "rotorub_kernel.h"
#include "rr_math.h" /* sin, cos, tan, atan2, tanh, sqrt: the same bits on every platform */

/* rr_laws.c: the one dispatch of the normal laws */
void rri_blade_law(const rr_law *law, int np, double g_le, double g_te, double k, double l, double *out);
double rri_law_max_slope(const rr_law *law);
/* the force of a point's share k of the law at penetration pen (>= 0 where it touches) */
double rri_point_force(const rr_law *law, double pen, double k);

/* rr_contact.c */
void rri_raw_gaps(const rr_contact *c, const double *q, double *gaps);
void rri_gaps_of(const rr_contact *c, const double *q, double *gaps);
void rri_laws_of(const rr_contact *c, const double *gaps, double *law);
void rri_friction_of(const rr_contact *c, const double *law, double omega, const double *qdot, const double *q,
                     const double *q_prev, double dt, double *fr);
/* a copy of c with every blade closed (g0 = -1 m) under a linear law at the law's largest slope, no surface */
rr_contact rri_closed_contact(const rr_contact *c);
void rri_outputs_from_law(const rr_contact *c, const double *q, const double *gaps, const double *law,
                          const double *fr, double phi, const int *index, double *dest);

/* rr_cd.c: one central-difference step from the laws and friction factors already evaluated at q */
void rri_cd_update(const rr_contact *c, const double *restrict law, const double *restrict fr,
                   const rr_cd_matrices *mats, double r, double *restrict q, double *restrict qp,
                   double *restrict rhs);

/* rr_liner.c */
void rri_surface_apply(const rr_contact *c, double *gaps);
void rri_surface_cut(const rr_contact *c, const double *gaps, double phi_new);
double rri_liner_law(const rr_law *law, double g, double k, double fy, double h, double thickness, int wears,
                     double *depth, double *work);
/* the surface's inputs differ from those it was last cut at */
int rri_surface_inputs_changed(const rr_surface *s);
/* cut every point's current cell at state q under the surface's inputs (noted as cut at); gaps: scratch */
void rri_surface_recut(const rr_contact *c, const double *q, double *gaps);

/* small and on the hot path: inline in every file */

/* the rows of segment (blade) j: their stride, and the dofs of their columns (NULL: all n, dense) */
static inline int rri_ld(const rr_contact *c) { return c->nloc > 0 ? c->nloc : c->n; }
static inline const int *rri_cols(const rr_contact *c, int j)
{
    return c->nloc > 0 ? c->cols + (size_t)j * c->nloc : NULL;
}
static inline double rri_len(const rr_contact *c, int j) { return c->seg_len ? c->seg_len[j] : c->chord; }
static inline double rri_k(const rr_contact *c, int j) { return c->seg_k ? c->seg_k[j] * c->k_r : c->k_r; }
static inline int rri_nb_out(const rr_contact *c) { return c->nb_out > 0 ? c->nb_out : c->nb; }
static inline int rri_row(const rr_contact *c, int k) { return c->point_row ? c->point_row[k] : k % c->np; }
static inline int rri_n_rows(const rr_contact *c) { return c->point_row && c->n_rows > 0 ? c->n_rows : c->np; }
/* row . x over the row's own columns (dense: the arithmetic of a plain dot product) */
static inline double rri_dot(int len, const double *row, const int *cols, const double *x)
{
    double s = 0.0;
    int k;
    if (cols)
        for (k = 0; k < len; ++k) s += row[k] * x[cols[k]];
    else
        for (k = 0; k < len; ++k) s += row[k] * x[k];
    return s;
}
/* f += a row */
static inline void rri_axpy(int len, double a, const double *row, const int *cols, double *f)
{
    int k;
    if (cols)
        for (k = 0; k < len; ++k) f[cols[k]] += a * row[k];
    else
        for (k = 0; k < len; ++k) f[k] += a * row[k];
}
/* Share of the blade's normal force carried by each contact point: the pressure p(c) >= 0 on
 * [-l/2, l/2] is statically equivalent to w_LE = F/2 - M/l at the LE and w_TE = F/2 + M/l at
 * the TE (both >= 0); dw/dF and dw/dM are (1/2, -1/l) and (1/2, 1/l). 2D: w = F_N. */
static inline void rri_point_weights(int np, double l, double FN, double MN, double *w, double *aF, double *aM)
{
    if (np == 2) {
        w[0] = 0.5 * FN - MN / l;
        w[1] = 0.5 * FN + MN / l;
        aF[0] = 0.5;
        aF[1] = 0.5;
        aM[0] = -1.0 / l;
        aM[1] = 1.0 / l;
    } else {
        w[0] = FN;
        aF[0] = 1.0;
        aM[0] = 0.0;
    }
}

/* (e_z x r).e_t: the sliding speed of the point per unit spin (its radius for e_t = e_theta) */
static inline double rri_spin_arm(const double *P, const double *t) { return P[0] * t[1] - P[1] * t[0]; }

#endif
