/* rotorub kernel: contact geometry of the 2D and 3D formulations (see rotorub_kernel.h; internal declarations in rr_internal.h). */
#include "rr_internal.h"

/* ------------------------------------------------------------------ geometry */

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/* Displacement of the casing inner-surface point at rest position (x, y, z) (z from the tip
 * plane), columns over the casing dofs: rigid translation, tilt about the centre of gravity,
 * ring radial u and inextensional tangential w at the point's angle. D is (3, nc). */
static void casing_point_map(const rr_geometry_spec *s, const double *P, int tilt, double *D, int nc)
{
    double x = P[0], y = P[1], z = P[2];
    double alpha = rr_atan2(y, x), ca = rr_cos(alpha), sa = rr_sin(alpha);
    double az = z - s->z_cg;
    int i, r;
    for (r = 0; r < 3 * nc; ++r) D[r] = 0.0;
    D[0 * nc + 0] = 1.0;
    D[1 * nc + 1] = 1.0;
    if (tilt) {
        /* rotation vectors (0, 1, 0) and (-1, 0, 0): displacement = theta x arm */
        D[0 * nc + 2] = az;
        D[2 * nc + 2] = -x;
        D[1 * nc + 3] = az;
        D[2 * nc + 3] = -y;
    }
    for (i = 0; i < s->n_modes; ++i) {
        double nn = (double)s->modes[i];
        double uc = rr_cos(nn * alpha), us = rr_sin(nn * alpha);
        double wc = -rr_sin(nn * alpha) / nn, ws = rr_cos(nn * alpha) / nn;
        /* e_r = (ca, sa, 0), e_t = (-sa, ca, 0) */
        D[0 * nc + 4 + 2 * i] = uc * ca + wc * -sa;
        D[1 * nc + 4 + 2 * i] = uc * sa + wc * ca;
        D[0 * nc + 5 + 2 * i] = us * ca + ws * -sa;
        D[1 * nc + 5 + 2 * i] = us * sa + ws * ca;
    }
}

int rr_contact_geometry(const rr_geometry_spec *s, rr_geometry *o)
{
    int n = s->n, nb = s->nb, np = s->np, nc = 4 + 2 * s->n_modes;
    int j, k, i, e, r;
    double D[3 * (4 + 2 * 16)];
    double cb = rr_cos(s->stagger), sb = rr_sin(s->stagger), tth = rr_tan(s->theta), cth = rr_cos(s->theta), sth = rr_sin(s->theta);
    if ((np != 1 && np != 2) || (np == 2 && !(s->chord > 0.0)) || s->n_modes > 16) return -1;
    for (j = 0; j < nb; ++j) {
        double a = 2.0 * M_PI * j / nb;
        double er[3] = {rr_cos(a), rr_sin(a), 0.0}, et[3] = {-rr_sin(a), rr_cos(a), 0.0};
        for (k = 0; k < np; ++k) {
            size_t pk = (size_t)j * np + k;
            double *P = o->points + 3 * pk, *nv = o->normals + 3 * pk, *tv = o->tangents + 3 * pk;
            double *Jb = o->Jb + 3 * n * pk, *Jc = o->Jc + 3 * n * pk;
            int tilt = np == 2 && s->rotations;
            if (np == 1) {
                for (i = 0; i < 3; ++i) {
                    P[i] = s->r_tip * er[i];
                    nv[i] = er[i];
                    tv[i] = et[i];
                }
            } else {
                /* chord from LE (c = -l/2) to TE (+l/2) along cos(beta) e_z - sin(beta) e_t */
                double c = (k == 0 ? -0.5 : 0.5) * s->chord;
                double cdir[3] = {cb * 0.0 - sb * et[0], cb * 0.0 - sb * et[1], cb * 1.0 - sb * et[2]};
                double P0[3] = {s->r_tip * er[0] + c * cdir[0], s->r_tip * er[1] + c * cdir[1],
                                s->r_tip * er[2] + c * cdir[2]};
                double z = P0[2], ap = rr_atan2(P0[1], P0[0]);
                double erho[3] = {rr_cos(ap), rr_sin(ap), 0.0};
                double rad = s->r_tip - z * tth; /* tip cut parallel to the cone */
                for (i = 0; i < 3; ++i) P[i] = rad * erho[i] + z * (i == 2 ? 1.0 : 0.0);
                for (i = 0; i < 3; ++i) nv[i] = cth * erho[i] + sth * (i == 2 ? 1.0 : 0.0);
                tv[0] = -rr_sin(ap);
                tv[1] = rr_cos(ap);
                tv[2] = 0.0;
            }
            /* blade point: disk translation (+ disk rotation x position + tip flexure in 3D) */
            for (r = 0; r < 3 * n; ++r) Jb[r] = s->T[r];
            if (tilt) {
                /* - skew(P) Rot: rows (-P2 Rot1 + P1 Rot2, P2 Rot0 - P0 Rot2, -P1 Rot0 + P0 Rot1) */
                for (e = 0; e < n; ++e) {
                    double r0 = s->Rot[e], r1 = s->Rot[n + e], r2 = s->Rot[2 * n + e];
                    Jb[e] -= 0.0 * r0 + -P[2] * r1 + P[1] * r2;
                    Jb[n + e] -= P[2] * r0 + 0.0 * r1 + -P[0] * r2;
                    Jb[2 * n + e] -= -P[1] * r0 + P[0] * r1 + 0.0 * r2;
                }
                /* tip deflection psi(l_b) along n_j = cos(beta) e_t + sin(beta) e_z */
                {
                    double nj[3] = {cb * et[0] + sb * 0.0, cb * et[1] + sb * 0.0, cb * et[2] + sb * 1.0};
                    for (i = 0; i < 3; ++i)
                        for (e = 0; e < s->n_ritz; ++e) Jb[i * n + s->blade_dof0 + j * s->n_ritz + e] = nj[i] * s->psi_tip[e];
                }
            }
            /* casing point: translation (+ tilt in 3D) + ring */
            casing_point_map(s, P, tilt, D, nc);
            for (r = 0; r < 3 * n; ++r) Jc[r] = 0.0;
            for (i = 0; i < 3; ++i)
                for (e = 0; e < nc; ++e) Jc[i * n + s->casing_dof0 + e] = D[i * nc + e];
            /* gap gradient -n.(Jb - Jc) and sliding t.(Jb - Jc) */
            for (e = 0; e < n; ++e) {
                double r0 = Jb[e] - Jc[e], r1 = Jb[n + e] - Jc[n + e], r2 = Jb[2 * n + e] - Jc[2 * n + e];
                double g = -(nv[0] * r0 + nv[1] * r1 + nv[2] * r2);
                o->G[pk * n + e] = g;
                o->S[pk * n + e] = tv[0] * r0 + tv[1] * r1 + tv[2] * r2;
                if (np == 1) {
                    o->A[(size_t)j * n + e] = g;
                    o->B[(size_t)j * n + e] = 0.0;
                } else if (k == 0) {
                    o->A[(size_t)j * n + e] = g; /* completed with the TE below */
                } else {
                    double gle = o->A[(size_t)j * n + e];
                    o->A[(size_t)j * n + e] = 0.5 * (gle + g);
                    o->B[(size_t)j * n + e] = (g - gle) / s->chord;
                }
            }
        }
    }
    for (r = 0; r < 2 * n; ++r) o->T2[r] = s->T[r];
    return 0;
}
