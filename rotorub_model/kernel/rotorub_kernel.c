/* rotorub kernel: contact laws, outputs of a state, central-difference loop (see rotorub_kernel.h). */
#include "rotorub_kernel.h"

#include <math.h>
#include <stddef.h>

#include "rr_math.h" /* sin, cos, tan, atan2, tanh, sqrt: the same bits on every platform */

#ifndef RR_SOURCE_ID
#define RR_SOURCE_ID "unversioned"
#endif

int rr_abi_version(void) { return RR_ABI_VERSION; }

const char *rr_source_id(void) { return RR_SOURCE_ID; }

/* scratch: gaps (nb*np) + law (nb*7) + friction (nb*np) + right-hand side (n) */
int rr_work_size(int n, int nb, int np) { return nb * np + nb * RR_LAW_WIDTH + nb * np + n; }

void rr_elementary(int fn, int m, const double *x, const double *y, double *out)
{
    int i;
    for (i = 0; i < m; ++i) {
        switch (fn) {
        case RR_FN_SIN: out[i] = rr_sin(x[i]); break;
        case RR_FN_COS: out[i] = rr_cos(x[i]); break;
        case RR_FN_TAN: out[i] = rr_tan(x[i]); break;
        case RR_FN_ATAN2: out[i] = rr_atan2(x[i], y[i]); break;
        case RR_FN_TANH: out[i] = rr_tanh(x[i]); break;
        case RR_FN_EXP: out[i] = rr_exp(x[i]); break;
        case RR_FN_SQRT: out[i] = rr_sqrt(x[i]); break;
        case RR_FN_FLOOR: out[i] = rr_floor(x[i]); break;
        case RR_FN_CEIL: out[i] = rr_ceil(x[i]); break;
        default: out[i] = 0.0; break; /* unreachable from kernel.elementary(), which checks the name */
        }
    }
}

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

/* ------------------------------------------------------------------ laws */

/* Chord law (eq. 5-8): gap(c) = zeta c + eta along c in [-l/2, l/2], pressure -(k/l) gap(c)
 * where gap(c) < 0. The integrand vanishes at the moving front c* = -eta/zeta, so the
 * derivatives with respect to (eta, zeta) come from the fixed limits alone (Leibniz). */
static void chord_law(double g_le, double g_te, double k, double l, double *out)
{
    double eta, zeta, h, c1, c2, s, d1, d2, d3;
    int i;
    if (g_le >= 0.0 && g_te >= 0.0) {
        for (i = 0; i < RR_LAW_WIDTH; ++i) out[i] = 0.0;
        return;
    }
    eta = 0.5 * (g_le + g_te);
    zeta = (g_te - g_le) / l;
    h = 0.5 * l;
    if (g_le < 0.0 && g_te < 0.0) {
        c1 = -h;
        c2 = h;
    } else if (g_le < 0.0) {
        c1 = -h;
        c2 = -eta / zeta;
    } else {
        c1 = -eta / zeta;
        c2 = h;
    }
    s = k / l;
    d1 = c2 - c1;
    d2 = 0.5 * (c2 * c2 - c1 * c1);
    d3 = (c2 * c2 * c2 - c1 * c1 * c1) / 3.0;
    out[0] = -s * (zeta * d2 + eta * d1);
    out[1] = -s * (zeta * d3 + eta * d2);
    out[2] = -s * d1;
    out[3] = -s * d2;
    out[4] = -s * d2;
    out[5] = -s * d3;
    out[6] = d1 / l;
}

/* Point law (2D): F_N = -k g where g < 0. */
static void point_law(double g, double k, double *out)
{
    int i;
    for (i = 0; i < RR_LAW_WIDTH; ++i) out[i] = 0.0;
    if (g >= 0.0) return;
    out[0] = -k * g;
    out[2] = -k;
    out[6] = out[0] > 0.0 ? 1.0 : 0.0;
}

void rr_blade_law(int np, double g_le, double g_te, double k, double l, double *out)
{
    if (np == 2)
        chord_law(g_le, g_te, k, l, out);
    else
        point_law(g_le, k, out);
}

/* gaps to the unworn, centred casing */
static void raw_gaps(const rr_contact *c, const double *q, double *gaps)
{
    int row, k, n = c->n, rows = c->nb * c->np;
    for (row = 0; row < rows; ++row) {
        const double *g = c->G + (size_t)row * n;
        double s = 0.0;
        for (k = 0; k < n; ++k) s += g[k] * q[k];
        gaps[row] = c->g0 + s; /* g0 added last: gap - g0 does not depend on g0 (exact detection maps) */
    }
}

static void surface_apply(const rr_contact *c, double *gaps);

static void gaps_of(const rr_contact *c, const double *q, double *gaps)
{
    raw_gaps(c, q, gaps);
    if (c->surface) surface_apply(c, gaps);
}

static void laws_of(const rr_contact *c, const double *gaps, double *law)
{
    int j;
    for (j = 0; j < c->nb; ++j) {
        if (c->np == 2)
            chord_law(gaps[2 * j], gaps[2 * j + 1], c->k_r, c->chord, law + RR_LAW_WIDTH * j);
        else
            point_law(gaps[j], c->k_r, law + RR_LAW_WIDTH * j);
    }
}

void rr_laws(const rr_contact *c, const double *q, double *gaps, double *law)
{
    gaps_of(c, q, gaps);
    laws_of(c, gaps, law);
}

void rr_gaps_batch(const rr_contact *c, int m, const double *Q, double *gaps)
{
    int i, rows = c->nb * c->np;
    for (i = 0; i < m; ++i) gaps_of(c, Q + (size_t)i * c->n, gaps + (size_t)i * rows);
}

/* ------------------------------------------------------------------ friction */

/* Share of the blade's normal force carried by each contact point: the pressure p(c) >= 0 on
 * [-l/2, l/2] is statically equivalent to w_LE = F/2 - M/l at the LE and w_TE = F/2 + M/l at
 * the TE (both >= 0); dw/dF and dw/dM are (1/2, -1/l) and (1/2, 1/l). 2D: w = F_N. */
static void point_weights(int np, double l, double FN, double MN, double *w, double *aF, double *aM)
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
static double spin_arm(const double *P, const double *t) { return P[0] * t[1] - P[1] * t[0]; }

/* Friction factors mu tanh(v_p / v_slip) of every point of a blade in contact, from the law at q;
 * the velocity is qdot, or (q - q_prev) / dt when qdot is NULL and q_prev is not, or zero. */
static void friction_of(const rr_contact *c, const double *law, double omega, const double *qdot, const double *q,
                        const double *q_prev, double dt, double *fr)
{
    int j, p, e, n = c->n, np = c->np;
    for (j = 0; j < c->nb; ++j) {
        const double *L = law + RR_LAW_WIDTH * j;
        int touching = !(L[0] == 0.0 && L[1] == 0.0);
        for (p = 0; p < np; ++p) {
            size_t pk = (size_t)j * np + p;
            double v;
            if (!touching) {
                fr[pk] = 0.0;
                continue;
            }
            v = omega * spin_arm(c->points + 3 * pk, c->tangents + 3 * pk);
            if (qdot || q_prev) {
                const double *S = c->S + pk * n;
                double sv = 0.0;
                if (qdot)
                    for (e = 0; e < n; ++e) sv += S[e] * qdot[e];
                else
                    for (e = 0; e < n; ++e) sv += S[e] * (q[e] - q_prev[e]);
                v += qdot ? sv : sv / dt;
            }
            fr[pk] = c->mu * rr_tanh(v / c->v_slip);
        }
    }
}

void rr_friction(const rr_contact *c, const double *q, const double *qdot, double omega, double *fr)
{
    double *gaps = c->work, *law = c->work + c->nb * c->np;
    rr_laws(c, q, gaps, law);
    friction_of(c, law, omega, qdot, NULL, NULL, 1.0, fr);
}

/* Q = A^T F_N + B^T M_N - sum_p f_p w_p S_p^T: the virtual work of the normal pressure on the gap's
 * derivatives and of the friction on the sliding, reactions on the casing included (through the
 * casing part of G and S). */
static void force_from_law(const rr_contact *c, const double *law, const double *fr, double *f)
{
    int j, k, p, n = c->n, np = c->np;
    for (k = 0; k < n; ++k) f[k] = 0.0;
    for (j = 0; j < c->nb; ++j) {
        const double *L = law + RR_LAW_WIDTH * j;
        const double *A = c->A + (size_t)j * n, *B = c->B + (size_t)j * n;
        double w[2], aF[2], aM[2];
        if (L[0] == 0.0 && L[1] == 0.0) continue;
        point_weights(np, c->chord, L[0], L[1], w, aF, aM);
        for (k = 0; k < n; ++k) f[k] += A[k] * L[0] + B[k] * L[1];
        for (p = 0; p < np; ++p) {
            size_t pk = (size_t)j * np + p;
            const double *S = c->S + pk * n;
            double fw = fr[pk] * w[p];
            if (fw != 0.0)
                for (k = 0; k < n; ++k) f[k] -= fw * S[k];
        }
    }
}

void rr_force(const rr_contact *c, const double *q, const double *qdot, double omega, double *f)
{
    int nb = c->nb, rows = nb * c->np;
    double *gaps = c->work, *law = gaps + rows, *fr = law + nb * RR_LAW_WIDTH;
    rr_laws(c, q, gaps, law);
    friction_of(c, law, omega, qdot, NULL, NULL, 1.0, fr);
    force_from_law(c, law, fr, f);
}

void rr_jacobian(const rr_contact *c, const double *q, const double *qdot, double omega, double *J, double *Jv)
{
    int j, r, k, p, e, n = c->n, nb = c->nb, np = c->np, rows = nb * np;
    double *gaps = c->work, *law = gaps + rows, *fr = law + nb * RR_LAW_WIDTH;
    rr_laws(c, q, gaps, law);
    friction_of(c, law, omega, qdot, NULL, NULL, 1.0, fr);
    for (r = 0; r < n * n; ++r) J[r] = 0.0;
    if (Jv)
        for (r = 0; r < n * n; ++r) Jv[r] = 0.0;
    for (j = 0; j < nb; ++j) {
        const double *L = law + RR_LAW_WIDTH * j;
        const double *A = c->A + (size_t)j * n, *B = c->B + (size_t)j * n;
        const double *S0 = c->S + (size_t)j * np * n, *S1 = np == 2 ? S0 + n : S0;
        double w[2], aF[2], aM[2], f0, f1;
        if (L[2] == 0.0 && L[3] == 0.0 && L[4] == 0.0 && L[5] == 0.0) continue;
        point_weights(np, c->chord, L[0], L[1], w, aF, aM);
        f0 = fr[(size_t)j * np];
        f1 = np == 2 ? fr[(size_t)j * np + 1] : 0.0;
        for (r = 0; r < n; ++r) {
            /* row r of A^T dF + B^T dM - sum_p f_p S_p^T dw_p, dw_p = aF_p dF + aM_p dM,
             * dF = L2 A + L3 B, dM = L4 A + L5 B */
            double wF = A[r] - (f0 * aF[0] * S0[r] + (np == 2 ? f1 * aF[1] * S1[r] : 0.0));
            double wM = B[r] - (f0 * aM[0] * S0[r] + (np == 2 ? f1 * aM[1] * S1[r] : 0.0));
            double *Jr = J + (size_t)r * n;
            if (wF == 0.0 && wM == 0.0) continue;
            for (k = 0; k < n; ++k) {
                double dF = L[2] * A[k] + L[3] * B[k];
                double dM = L[4] * A[k] + L[5] * B[k];
                Jr[k] += wF * dF + wM * dM;
            }
        }
        if (!Jv) continue;
        /* d/dq' of -mu tanh(v_p / v_slip) w_p S_p^T, v_p = omega rho_p + S_p q' */
        for (p = 0; p < np; ++p) {
            size_t pk = (size_t)j * np + p;
            const double *S = c->S + pk * n;
            double th, cpl;
            if (c->mu == 0.0 || w[p] == 0.0) continue;
            th = fr[pk] / c->mu;
            cpl = c->mu * w[p] * (1.0 - th * th) / c->v_slip;
            if (cpl == 0.0) continue;
            for (r = 0; r < n; ++r) {
                double a = cpl * S[r];
                if (a == 0.0) continue;
                for (e = 0; e < n; ++e) Jv[(size_t)r * n + e] -= a * S[e];
            }
        }
    }
}

/* ------------------------------------------------------------------ outputs of a state */

static void outputs_from_law(const rr_contact *c, const double *q, const double *gaps, const double *law,
                             const double *fr, double phi, const int *index, double *dest)
{
    int j, k, p, nb = c->nb, np = c->np, n = c->n;
    double Fc[3] = {0.0, 0.0, 0.0}, torque = 0.0;
    double dx = 0.0, dy = 0.0, gmin = HUGE_VAL, cs, sn, vals[RR_OUT_GLOBALS];
    int n_contact = 0;
#define RR_PUT(pos, value) (index ? (dest[index[(pos)]] = (value)) : (dest[(pos)] = (value)))
    for (j = 0; j < nb; ++j) {
        const double *L = law + RR_LAW_WIDTH * j;
        double FN = L[0], MN = L[1], FT = 0.0, w[2], aF[2], aM[2];
        double gle = gaps[np * j], gte = gaps[np * j + np - 1];
        double gtip = (gle <= gte || gle != gle) ? gle : gte; /* a NaN propagates, as numpy's min */
        if (!(FN == 0.0 && MN == 0.0)) {
            point_weights(np, c->chord, FN, MN, w, aF, aM);
            for (p = 0; p < np; ++p) {
                /* on the casing: w_p (n_p + f_p t_p); its torque on the rotor about e_z is the opposite */
                size_t pk = (size_t)j * np + p;
                const double *P = c->points + 3 * pk, *nv = c->normals + 3 * pk, *tv = c->tangents + 3 * pk;
                double f[3];
                for (k = 0; k < 3; ++k) {
                    f[k] = w[p] * (nv[k] + fr[pk] * tv[k]);
                    Fc[k] += f[k];
                }
                torque -= P[0] * f[1] - P[1] * f[0];
                FT += fr[pk] * w[p];
            }
        }
        RR_PUT(RR_OUT_FN * nb + j, FN);
        RR_PUT(RR_OUT_FT * nb + j, FT);
        RR_PUT(RR_OUT_GAP_LE * nb + j, gle);
        RR_PUT(RR_OUT_GAP_TE * nb + j, gte);
        RR_PUT(RR_OUT_GAP_TIP * nb + j, gtip);
        RR_PUT(RR_OUT_FRACTION * nb + j, L[6]);
        if (FN > 0.0) ++n_contact;
        if (gtip < gmin || gtip != gtip) gmin = gtip;
    }
    for (k = 0; k < n; ++k) {
        dx += c->T2[k] * q[k];
        dy += c->T2[n + k] * q[k];
    }
    cs = rr_cos(phi);
    sn = rr_sin(phi);
    vals[RR_OUT_CASING_X] = cs * Fc[0] - sn * Fc[1];
    vals[RR_OUT_CASING_Y] = sn * Fc[0] + cs * Fc[1];
    vals[RR_OUT_CASING_Z] = Fc[2];
    vals[RR_OUT_TORQUE] = torque;
    vals[RR_OUT_DISK_X] = cs * dx - sn * dy;
    vals[RR_OUT_DISK_Y] = sn * dx + cs * dy;
    vals[RR_OUT_GAP_MIN] = gmin;
    vals[RR_OUT_N_CONTACT] = (double)n_contact;
    for (k = 0; k < RR_OUT_GLOBALS; ++k) RR_PUT(RR_OUT_BLADE_BLOCKS * nb + k, vals[k]);
#undef RR_PUT
}

void rr_outputs(const rr_contact *c, const double *q, const double *qdot, double omega, double phi,
                const int *index, double *dest)
{
    int rows = c->nb * c->np;
    double *gaps = c->work, *law = gaps + rows, *fr = law + c->nb * RR_LAW_WIDTH;
    rr_laws(c, q, gaps, law);
    friction_of(c, law, omega, qdot, NULL, NULL, 1.0, fr);
    outputs_from_law(c, q, gaps, law, fr, phi, index, dest);
}

void rr_outputs_batch(const rr_contact *c, int m, const double *Q, const double *Qdot, double omega, double *out)
{
    int i;
    for (i = 0; i < m; ++i)
        rr_outputs(c, Q + (size_t)i * c->n, Qdot ? Qdot + (size_t)i * c->n : NULL, omega, 0.0, NULL,
                   out + (size_t)i * RR_N_OUT(c->nb));
}

/* ------------------------------------------------------------------ abradable liner */

#define RR_TWO_PI 6.283185307179586476925286766559

/* tables: angle, cos, sin of each point's rest angle; radial part of its normal; cos, sin (h th_c) */
int rr_surface_table_size(int nb, int np, int n_sectors) { return 4 * nb * np + 2 * RR_WEAR_HARMONICS * n_sectors; }

int rr_surface_init(const rr_contact *c, rr_surface *s)
{
    int k, h, m, rows = c->nb * c->np, ns = s->n_sectors;
    double *a0, *ca, *sa, *nr, *bc, *bs;
    if (!(ns >= 8 && ns <= 1000000) || !(s->yield_force > 0.0) || !(s->hardening >= 0.0) || !(s->thickness > 0.0) ||
        !(s->work_weight > 0.0) ||
        !(s->closure == s->closure) || !(s->offset_x == s->offset_x) || !(s->offset_y == s->offset_y) ||
        !s->tables || !s->depth)
        return -1;
    a0 = s->tables;
    ca = a0 + rows;
    sa = ca + rows;
    nr = sa + rows;
    bc = nr + rows;
    bs = bc + RR_WEAR_HARMONICS * ns;
    for (k = 0; k < rows; ++k) {
        const double *P = c->points + 3 * k, *nv = c->normals + 3 * k;
        double a = rr_atan2(P[1], P[0]);
        a0[k] = a * (ns / RR_TWO_PI); /* in cells: a point's cell is floor(a0 + phi ns / 2 pi) mod ns */
        ca[k] = rr_cos(a);
        sa[k] = rr_sin(a);
        nr[k] = rr_sqrt(nv[0] * nv[0] + nv[1] * nv[1]);
    }
    for (h = 1; h <= RR_WEAR_HARMONICS; ++h)
        for (m = 0; m < ns; ++m) {
            double th = h * ((m + 0.5) * (RR_TWO_PI / ns));
            bc[(h - 1) * ns + m] = rr_cos(th);
            bs[(h - 1) * ns + m] = rr_sin(th);
        }
    return 0;
}

static double liner_law(double g, double k, double fy, double h, double thickness, int wears, double *depth,
                        double *work)
{
    double w = *depth, p = -(g + w), f, dw;
    if (!(p > 0.0)) return 0.0;
    f = k * p;
    if (wears && f > fy + h * w && w < thickness) {
        dw = (f - fy - h * w) / (k + h);
        if (w + dw > thickness) dw = thickness - w;
        *work += (fy + h * (w + 0.5 * dw)) * dw; /* the integral of F_y + H w over the removed depth */
        *depth = w + dw;
        f = k * (p - dw);
    }
    return f;
}

double rr_liner_law(double g, double k, double fy, double h, double thickness, int wears, double *depth, double *work)
{
    return liner_law(g, k, fy, h, thickness, wears, depth, work);
}

/* A frame angle in cells (phi ns / 2 pi) split once per evaluation into a whole cell in [0, ns) and a
 * fraction in [0, 1): a point's cell is then floor(a0 + fraction) + whole, within one turn of [0, ns). */
typedef struct {
    int whole;
    double frac;
} rr_turn;

static rr_turn turn_of(double phi, int ns)
{
    rr_turn t = {0, 0.0};
    double u = phi * (ns / RR_TWO_PI), x = rr_floor(u);
    if (rr_fabs(x) < 9.0e15) { /* else not a number of cells: the state is diverging anyway */
        long long m = (long long)x % ns;
        t.whole = (int)(m < 0 ? m + ns : m);
        t.frac = u - x;
    }
    return t;
}

/* the cell of a point at a0 cells (its rest angle, within half a turn of 0) at frame turn t */
static int cell_at(double a0, rr_turn t, int ns)
{
    int cell = (int)rr_floor(a0 + t.frac) + t.whole;
    if (cell >= ns) cell -= ns;
    if (cell < 0) cell += ns;
    return cell;
}

/* raw gaps -> gaps to the surface at frame angle s->phi */
static void surface_apply(const rr_contact *c, double *gaps)
{
    const rr_surface *s = c->surface;
    int k, np = c->np, rows = c->nb * np, ns = s->n_sectors;
    const double *a0 = s->tables, *ca = a0 + rows, *sa = ca + rows, *nr = sa + rows;
    const int offset = s->offset_x != 0.0 || s->offset_y != 0.0;
    const double cp = offset ? rr_cos(s->phi) : 1.0, sp = offset ? rr_sin(s->phi) : 0.0;
    const rr_turn turn = turn_of(s->phi, ns);
    for (k = 0; k < rows; ++k) {
        double extra = s->depth[(size_t)(k % np) * ns + cell_at(a0[k], turn, ns)] - s->closure;
        if (offset) {
            double ct = ca[k] * cp - sa[k] * sp, st = sa[k] * cp + ca[k] * sp;
            extra += nr[k] * (s->offset_x * ct + s->offset_y * st);
        }
        gaps[k] += extra;
    }
}

/* The time loop's cut: every cell a contact point swept from the surface's angle to phi_new, at the
 * point's raw gap (the state at phi_new); then the surface is at phi_new. */
static void surface_cut(const rr_contact *c, const double *gaps, double phi_new)
{
    rr_surface *s = c->surface;
    int k, j, np = c->np, rows = c->nb * np, ns = s->n_sectors;
    const double *a0 = s->tables, *nr = a0 + 3 * rows, *bc = a0 + 4 * rows, *bs = bc + RR_WEAR_HARMONICS * ns;
    const double share = np == 2 ? 0.5 : 1.0; /* 3D: each end carries half the chord */
    const double kp = share * c->k_r, fy = share * s->yield_force, hp = share * s->hardening;
    const double reach = rr_sqrt(s->offset_x * s->offset_x + s->offset_y * s->offset_y);
    const int offset = reach > 0.0;
    const rr_turn turn0 = turn_of(s->phi, ns), turn1 = turn_of(phi_new, ns);
    const double turns = (phi_new - s->phi) * (ns / RR_TWO_PI);
    for (k = 0; k < rows; ++k) {
        double g = gaps[k] - s->closure;
        int c0, c1, count, step;
        double *row = s->depth + (size_t)(k % np) * ns;
        if (g - nr[k] * reach >= 0.0) continue; /* open everywhere this point can be: nothing to cut */
        c0 = cell_at(a0[k], turn0, ns);
        c1 = cell_at(a0[k], turn1, ns);
        {
            count = turns >= ns || -turns >= ns ? ns : (c1 - c0 + ns) % ns;
            step = phi_new >= s->phi ? 1 : -1;
            if (step < 0 && count != ns) count = (c0 - c1 + ns) % ns;
        }
        if (count == 0) count = 1, c0 = c1 - step; /* still in the cell: cut it */
        for (j = 1; j <= count; ++j) {
            int cell = ((c0 + step * j) % ns + ns) % ns;
            double gc = offset ? g + nr[k] * (s->offset_x * bc[cell] + s->offset_y * bs[cell]) : g;
            if (gc + row[cell] < 0.0 && kp * -(gc + row[cell]) > fy + hp * row[cell]) {
                double work = 0.0;
                liner_law(gc, kp, fy, hp, s->thickness, 1, row + cell, &work);
                s->plastic_work += s->work_weight * work;
                s->changed = 1;
            }
        }
    }
    s->phi = phi_new;
}

void rr_surface_summary(const rr_contact *c, const rr_surface *s, double area_per_sector, double *out)
{
    int m, h, p, np = c->np, ns = s->n_sectors, rows = c->nb * np;
    const double *bc = s->tables + 4 * rows, *bs = bc + RR_WEAR_HARMONICS * ns;
    double big = 0.0, sum = 0.0, best = 0.0, cs[RR_WEAR_HARMONICS], sn[RR_WEAR_HARMONICS];
    int lobes = 0;
    for (h = 0; h < RR_WEAR_HARMONICS; ++h) cs[h] = sn[h] = 0.0;
    for (m = 0; m < ns; ++m) {
        double w = 0.0;
        for (p = 0; p < np; ++p) {
            double d = s->depth[(size_t)p * ns + m];
            if (d > big) big = d;
            w += d;
        }
        w /= np; /* the profile: the rows' mean (the axial mean over the chord in 3D) */
        sum += w;
        for (h = 0; h < RR_WEAR_HARMONICS; ++h) {
            cs[h] += w * bc[h * ns + m];
            sn[h] += w * bs[h * ns + m];
        }
    }
    for (h = 0; h < RR_WEAR_HARMONICS; ++h) {
        double a = (2.0 / ns) * rr_sqrt(cs[h] * cs[h] + sn[h] * sn[h]);
        out[RR_WEAR_AMP + h] = a;
        if (a > best) {
            best = a;
            lobes = h + 1;
        }
    }
    out[RR_WEAR_MAX] = big;
    out[RR_WEAR_MEAN] = sum / ns;
    out[RR_WEAR_VOLUME] = sum * area_per_sector;
    out[RR_WEAR_WORK] = s->plastic_work;
    /* a 360-degree rub (a synchronous whirl's) wears the liner evenly: no lobes, not the harmonic that round-off
     * and the rub's start leave largest */
    out[RR_WEAR_LOBES] = best > 1e-15 && best >= 0.01 * out[RR_WEAR_MEAN] ? (double)lobes : 0.0;
}

/* ------------------------------------------------------------------ central differences */

/* One step: (M/dt^2 + C/2dt) q+ = r F + F0 + F_nl(q, q') + (2M/dt^2 - K) q - (M/dt^2 - C/2dt) q-,
 * with the contact force at the current state only (explicit; q' = (q - q-)/dt for the friction),
 * from the laws and friction factors already evaluated there. The order of the sums is fixed (see
 * the header); locals and restrict let the compiler keep the matrices streaming instead of
 * reloading the structs after every store. */
static void cd_update(int n, int nb, int np, double l, const double *restrict law, const double *restrict fr,
                      const double *restrict A, const double *restrict B, const double *restrict S,
                      const double *restrict Ainv, const double *restrict K2, const double *restrict Cm1,
                      const double *restrict f, const double *restrict f0, double r, double *restrict q,
                      double *restrict qp, double *restrict rhs)
{
    int j, k, e;
    for (k = 0; k < n; ++k) rhs[k] = f0 ? r * f[k] + f0[k] : r * f[k];
    for (j = 0; j < nb; ++j) {
        const double *L = law + RR_LAW_WIDTH * j;
        const double *Aj = A + (size_t)j * n, *Bj = B + (size_t)j * n;
        const double *S0 = S + (size_t)j * np * n, *S1 = S0 + (np == 2 ? n : 0);
        double FN = L[0], MN = L[1], w[2], aF[2], aM[2], c0, c1;
        if (FN == 0.0 && MN == 0.0) continue; /* adds an exact zero */
        point_weights(np, l, FN, MN, w, aF, aM);
        c0 = fr[(size_t)j * np] * w[0];
        c1 = np == 2 ? fr[(size_t)j * np + 1] * w[1] : 0.0;
        for (k = 0; k < n; ++k) rhs[k] += Aj[k] * FN + Bj[k] * MN - (c0 * S0[k] + c1 * S1[k]);
    }
    for (k = 0; k < n; ++k) {
        const double *K2k = K2 + (size_t)k * n, *Cm1k = Cm1 + (size_t)k * n;
        double acc = rhs[k];
        for (e = 0; e < n; ++e) acc += K2k[e] * q[e] - Cm1k[e] * qp[e];
        rhs[k] = acc;
    }
    for (k = 0; k < n; ++k) qp[k] = q[k];
    for (k = 0; k < n; ++k) {
        const double *Ak = Ainv + (size_t)k * n;
        double acc = 0.0;
        for (e = 0; e < n; ++e) acc += Ak[e] * rhs[e];
        q[k] = acc;
    }
}

/* The law and the friction are evaluated once per state: at the end of a step they serve both the
 * record of the new state and the next step's contact force. */
int rr_cd_run(rr_cd_job *job)
{
    rr_cd_state *s = job->state;
    const rr_contact *c = job->contact;
    const rr_cd_matrices *m = job->mats;
    int i, k, n = c->n, nb = c->nb, rows = nb * c->np;
    int done = 0, written = job->n_rec, rec_every = job->rec_every < 1 ? 1 : job->rec_every;
    double *gaps = c->work, *law = gaps + rows, *fr = law + nb * RR_LAW_WIDTH, *rhs = fr + rows;
    double *q = s->q, *qp = s->q_prev;
    const double t0 = s->t, dt = s->dt, floor_gap = -s->max_pen, t_ramp = job->t_ramp, me = job->me;
    const double omega = job->omega;
    const long long step0 = s->steps;
    rr_surface *sf = c->surface;
    /* the job's options in locals: read once, not after every store into the records (they may alias) */
    const int stop_on_contact = job->stop_on_contact, rec_cap = job->rec_cap;
    const int rec_wear_every = job->rec_wear_every < 1 ? 1 : job->rec_wear_every;
    double *const rec_wear = sf ? job->rec_wear : NULL, *const rec_q = job->rec_q, *const rec_out = job->rec_out;
    int open = 1;
    job->done = 0;
    if (s->diverged) return 0;
    if (sf) sf->phi = s->phi; /* the surface is read, and cut, at the state's angle */
    gaps_of(c, q, gaps);
    laws_of(c, gaps, law);
    friction_of(c, law, omega, NULL, q, qp, dt, fr);
    for (k = 0; k < rows; ++k)
        if (gaps[k] < 0.0) open = 0;
    for (i = 0; i < job->n_steps; ++i) {
        double t = t0 + i * dt;
        double r = (t_ramp <= 0.0 || t >= t_ramp) ? 1.0 : t / t_ramp;
        int bad = 0;
        for (k = 0; k < rows; ++k)
            if (!(gaps[k] > floor_gap)) bad = 1;
        if (bad) {
            s->diverged = 1;
            break;
        }
        cd_update(n, nb, c->np, c->chord, law, fr, c->A, c->B, c->S, m->Ainv, m->K2, m->Cm1, m->f, m->f0, r * me,
                  q, qp, rhs);
        ++done;
        if (sf) {
            double phi_new = s->phi + (i + 1) * dt * omega; /* as s->phi at the end of the job */
            raw_gaps(c, q, gaps);
            if (sf->wears)
                surface_cut(c, gaps, phi_new);
            else
                sf->phi = phi_new;
            surface_apply(c, gaps);
        } else {
            gaps_of(c, q, gaps);
        }
        laws_of(c, gaps, law);
        friction_of(c, law, omega, NULL, q, qp, dt, fr);
        if (rec_wear && (step0 + i + 1) % rec_wear_every == 0 && job->n_rec_wear < job->rec_wear_cap) {
            int m, p, ns = sf->n_sectors, np = c->np;
            double *dst = rec_wear + (size_t)job->n_rec_wear * ns;
            for (m = 0; m < ns; ++m) {
                double w = 0.0;
                for (p = 0; p < np; ++p) w += sf->depth[(size_t)p * ns + m];
                dst[m] = w / np;
            }
            ++job->n_rec_wear;
        }
        if ((step0 + i + 1) % rec_every == 0 && written < rec_cap) {
            for (k = 0; k < n; ++k) rec_q[(size_t)written * n + k] = q[k];
            if (rec_out) outputs_from_law(c, q, gaps, law, fr, 0.0, NULL, rec_out + (size_t)written * RR_N_OUT(nb));
            ++written;
        }
        if (stop_on_contact) {
            int was_open = open;
            open = 1;
            for (k = 0; k < rows; ++k)
                if (gaps[k] < 0.0) open = 0;
            if (was_open && !open) break;
        }
    }
    if (!s->diverged) { /* the state the last substep reached counts too: a step ends inside the limit or diverged */
        for (k = 0; k < rows; ++k)
            if (!(gaps[k] > floor_gap)) s->diverged = 1;
    }
    s->steps += done;
    s->t += done * dt;
    s->phi += done * dt * omega;
    job->n_rec = written;
    job->done = done;
    if (job->out_dest) outputs_from_law(c, q, gaps, law, fr, s->phi, job->out_index, job->out_dest);
    return done;
}

/* ------------------------------------------------------------------ dense linear algebra */

int rr_lu(int n, double *A, int *piv)
{
    int i, j, k;
    for (k = 0; k < n; ++k) {
        int p = k;
        double big = fabs(A[(size_t)k * n + k]);
        for (i = k + 1; i < n; ++i)
            if (fabs(A[(size_t)i * n + k]) > big) {
                big = fabs(A[(size_t)i * n + k]);
                p = i;
            }
        piv[k] = p;
        if (big == 0.0 || big != big) return -1;
        if (p != k)
            for (j = 0; j < n; ++j) {
                double tmp = A[(size_t)k * n + j];
                A[(size_t)k * n + j] = A[(size_t)p * n + j];
                A[(size_t)p * n + j] = tmp;
            }
        for (i = k + 1; i < n; ++i) {
            double l = A[(size_t)i * n + k] / A[(size_t)k * n + k];
            A[(size_t)i * n + k] = l;
            if (l != 0.0)
                for (j = k + 1; j < n; ++j) A[(size_t)i * n + j] -= l * A[(size_t)k * n + j];
        }
    }
    return 0;
}

void rr_lu_solve(int n, const double *LU, const int *piv, double *b)
{
    int i, j;
    for (i = 0; i < n; ++i)
        if (piv[i] != i) {
            double tmp = b[i];
            b[i] = b[piv[i]];
            b[piv[i]] = tmp;
        }
    for (i = 1; i < n; ++i) {
        double s = b[i];
        for (j = 0; j < i; ++j) s -= LU[(size_t)i * n + j] * b[j];
        b[i] = s;
    }
    for (i = n - 1; i >= 0; --i) {
        double s = b[i];
        for (j = i + 1; j < n; ++j) s -= LU[(size_t)i * n + j] * b[j];
        b[i] = s / LU[(size_t)i * n + i];
    }
}

int rr_inverse(int n, const double *A, double *Ainv, double *work, int *piv)
{
    int i, j;
    for (i = 0; i < n * n; ++i) work[i] = A[i];
    if (rr_lu(n, work, piv) != 0) return -1;
    /* column j of the inverse solves LU x = e_j; written as row j, then transposed in place */
    for (j = 0; j < n; ++j) {
        double *x = Ainv + (size_t)j * n;
        for (i = 0; i < n; ++i) x[i] = i == j ? 1.0 : 0.0;
        rr_lu_solve(n, work, piv, x);
    }
    for (i = 0; i < n; ++i)
        for (j = i + 1; j < n; ++j) {
            double tmp = Ainv[(size_t)i * n + j];
            Ainv[(size_t)i * n + j] = Ainv[(size_t)j * n + i];
            Ainv[(size_t)j * n + i] = tmp;
        }
    return 0;
}

/* Scale rows and columns by powers of 2 so that their norms are comparable (similarity: the
 * eigenvalues do not change, their accuracy improves for graded matrices such as M^-1 K). */
static void balance(int n, double *a)
{
    const double radix = 2.0, sqrdx = radix * radix;
    int done = 0, i, j;
    while (!done) {
        done = 1;
        for (i = 0; i < n; ++i) {
            double r = 0.0, c = 0.0;
            for (j = 0; j < n; ++j)
                if (j != i) {
                    c += fabs(a[(size_t)j * n + i]);
                    r += fabs(a[(size_t)i * n + j]);
                }
            if (c != 0.0 && r != 0.0) {
                double g = r / radix, f = 1.0, s = c + r;
                while (c < g) {
                    f *= radix;
                    c *= sqrdx;
                }
                g = r * radix;
                while (c > g) {
                    f /= radix;
                    c /= sqrdx;
                }
                if ((c + r) / f < 0.95 * s) {
                    done = 0;
                    g = 1.0 / f;
                    for (j = 0; j < n; ++j) a[(size_t)i * n + j] *= g;
                    for (j = 0; j < n; ++j) a[(size_t)j * n + i] *= f;
                }
            }
        }
    }
}

/* Householder reduction to upper Hessenberg form (similarity). */
static void hessenberg(int n, double *a, double *v)
{
    int i, j, k;
    for (k = 0; k < n - 2; ++k) {
        double scale = 0.0, h = 0.0, g;
        for (i = k + 1; i < n; ++i) scale += fabs(a[(size_t)i * n + k]);
        if (scale == 0.0) continue;
        for (i = k + 1; i < n; ++i) {
            v[i] = a[(size_t)i * n + k] / scale;
            h += v[i] * v[i];
        }
        g = rr_sqrt(h);
        if (v[k + 1] > 0.0) g = -g;
        h -= v[k + 1] * g;
        v[k + 1] -= g;
        /* H = I - v v^T / h, applied on the left (rows k+1..) and on the right (columns k+1..) */
        for (j = k + 1; j < n; ++j) {
            double f = 0.0;
            for (i = k + 1; i < n; ++i) f += v[i] * a[(size_t)i * n + j];
            f /= h;
            for (i = k + 1; i < n; ++i) a[(size_t)i * n + j] -= f * v[i];
        }
        for (i = 0; i < n; ++i) {
            double f = 0.0;
            for (j = k + 1; j < n; ++j) f += a[(size_t)i * n + j] * v[j];
            f /= h;
            for (j = k + 1; j < n; ++j) a[(size_t)i * n + j] -= f * v[j];
        }
        a[(size_t)(k + 1) * n + k] = scale * g;
        for (i = k + 2; i < n; ++i) a[(size_t)i * n + k] = 0.0;
    }
}

#define AH(i, j) a[(size_t)(i) * n + (j)]

/* Eigenvalues of an upper Hessenberg matrix by the Francis double-shift QR algorithm
 * (Wilkinson & Reinsch's hqr); a is destroyed. Returns 0, or -1 after 30 iterations on one root. */
static int hqr(int n, double *a, double *wr, double *wi)
{
    int nn, m, l, k, j, its, i, mmin;
    double z = 0.0, y, x, w, v, u, t, s, r = 0.0, q = 0.0, p = 0.0, anorm = 0.0;
    for (i = 0; i < n; ++i)
        for (j = (i > 0 ? i - 1 : 0); j < n; ++j) anorm += fabs(AH(i, j));
    nn = n - 1;
    t = 0.0;
    while (nn >= 0) {
        its = 0;
        do {
            for (l = nn; l >= 1; --l) {
                s = fabs(AH(l - 1, l - 1)) + fabs(AH(l, l));
                if (s == 0.0) s = anorm;
                if (fabs(AH(l, l - 1)) + s == s) {
                    AH(l, l - 1) = 0.0;
                    break;
                }
            }
            x = AH(nn, nn);
            if (l == nn) { /* one root */
                wr[nn] = x + t;
                wi[nn] = 0.0;
                --nn;
            } else {
                y = AH(nn - 1, nn - 1);
                w = AH(nn, nn - 1) * AH(nn - 1, nn);
                if (l == nn - 1) { /* two roots */
                    p = 0.5 * (y - x);
                    q = p * p + w;
                    z = rr_sqrt(fabs(q));
                    x += t;
                    if (q >= 0.0) {
                        z = p + (p >= 0.0 ? fabs(z) : -fabs(z));
                        wr[nn - 1] = wr[nn] = x + z;
                        if (z != 0.0) wr[nn] = x - w / z;
                        wi[nn - 1] = wi[nn] = 0.0;
                    } else {
                        wr[nn - 1] = wr[nn] = x + p;
                        wi[nn - 1] = -(wi[nn] = z);
                    }
                    nn -= 2;
                } else { /* no root yet: a double-shift QR sweep on rows/columns l..nn */
                    /* LAPACK's dlahqr allows 30 max(10, n) sweeps per eigenvalue with an exceptional shift every
                     * 10; the first 30 are those of the classic hqr (which stops there and failed on rare matrices) */
                    if (its == 30 * (n > 10 ? n : 10)) return -1;
                    if (its > 0 && its % 10 == 0) { /* exceptional shift */
                        t += x;
                        for (i = 0; i <= nn; ++i) AH(i, i) -= x;
                        s = fabs(AH(nn, nn - 1)) + fabs(AH(nn - 1, nn - 2));
                        y = x = 0.75 * s;
                        w = -0.4375 * s * s;
                    }
                    ++its;
                    for (m = nn - 2; m >= l; --m) {
                        z = AH(m, m);
                        r = x - z;
                        s = y - z;
                        p = (r * s - w) / AH(m + 1, m) + AH(m, m + 1);
                        q = AH(m + 1, m + 1) - z - r - s;
                        r = AH(m + 2, m + 1);
                        s = fabs(p) + fabs(q) + fabs(r);
                        p /= s;
                        q /= s;
                        r /= s;
                        if (m == l) break;
                        u = fabs(AH(m, m - 1)) * (fabs(q) + fabs(r));
                        v = fabs(p) * (fabs(AH(m - 1, m - 1)) + fabs(z) + fabs(AH(m + 1, m + 1)));
                        if (u + v == v) break;
                    }
                    for (i = m + 2; i <= nn; ++i) {
                        AH(i, i - 2) = 0.0;
                        if (i != m + 2) AH(i, i - 3) = 0.0;
                    }
                    for (k = m; k <= nn - 1; ++k) {
                        if (k != m) {
                            p = AH(k, k - 1);
                            q = AH(k + 1, k - 1);
                            r = 0.0;
                            if (k != nn - 1) r = AH(k + 2, k - 1);
                            if ((x = fabs(p) + fabs(q) + fabs(r)) != 0.0) {
                                p /= x;
                                q /= x;
                                r /= x;
                            }
                        }
                        s = rr_sqrt(p * p + q * q + r * r);
                        if (p < 0.0) s = -s;
                        if (s != 0.0) {
                            if (k == m) {
                                if (l != m) AH(k, k - 1) = -AH(k, k - 1);
                            } else {
                                AH(k, k - 1) = -s * x;
                            }
                            p += s;
                            x = p / s;
                            y = q / s;
                            z = r / s;
                            q /= p;
                            r /= p;
                            for (j = k; j <= nn; ++j) {
                                p = AH(k, j) + q * AH(k + 1, j);
                                if (k != nn - 1) {
                                    p += r * AH(k + 2, j);
                                    AH(k + 2, j) -= p * z;
                                }
                                AH(k + 1, j) -= p * y;
                                AH(k, j) -= p * x;
                            }
                            mmin = nn < k + 3 ? nn : k + 3;
                            for (i = l; i <= mmin; ++i) {
                                p = x * AH(i, k) + y * AH(i, k + 1);
                                if (k != nn - 1) {
                                    p += z * AH(i, k + 2);
                                    AH(i, k + 2) -= p * r;
                                }
                                AH(i, k + 1) -= p * q;
                                AH(i, k) -= p;
                            }
                        }
                    }
                }
            }
        } while (l < nn - 1);
    }
    return 0;
}

#undef AH

int rr_eigenvalues(int n, double *A, double *wr, double *wi, double *work)
{
    balance(n, A);
    hessenberg(n, A, work);
    return hqr(n, A, wr, wi);
}

int rr_cd_build(int n, const double *M, const double *D, const double *K0, const double *G1, const double *C1,
                   const double *N2, const double *S2, const double *E1, double omega, double omega_dot, double dt,
                   double *Ainv, double *K2, double *Cm1, double *work, int *piv)
{
    size_t i, nn = (size_t)n * n;
    double dt2 = dt * dt, ww = omega * omega, two_dt = 2.0 * dt;
    double *Aeff = work + nn;
    for (i = 0; i < nn; ++i) {
        double C = D[i] + omega * G1[i];
        double K = K0[i] + ww * (S2[i] + N2[i]) + omega * C1[i];
        if (E1) K = K + omega_dot * E1[i];
        Aeff[i] = M[i] / dt2 + C / two_dt;
        K2[i] = 2.0 * M[i] / dt2 - K;
        Cm1[i] = M[i] / dt2 - C / two_dt;
    }
    return rr_inverse(n, Aeff, Ainv, work, piv);
}

/* ------------------------------------------------------------------ balanced static solutions */

int rr_static_work_size(int n) { return 2 * n * n + 8 * n; }

static double norm2(int n, const double *x)
{
    /* scaled, as LAPACK's dnrm2: no overflow for large forces */
    double scale = 0.0, ssq = 1.0;
    int i;
    for (i = 0; i < n; ++i)
        if (x[i] != 0.0) {
            double a = fabs(x[i]);
            if (scale < a) {
                ssq = 1.0 + ssq * (scale / a) * (scale / a);
                scale = a;
            } else {
                ssq += (a / scale) * (a / scale);
            }
        }
    return scale * rr_sqrt(ssq);
}

/* R = K x - F_nl(x) - lam F; returns |R| */
static double residual(const rr_contact *c, double omega, int n, const double *K, const double *F, double lam,
                       const double *x, double *R, double *fnl)
{
    int i, j;
    rr_force(c, x, NULL, omega, fnl);
    for (i = 0; i < n; ++i) {
        double s = 0.0;
        for (j = 0; j < n; ++j) s += K[(size_t)i * n + j] * x[j];
        R[i] = s - fnl[i] - lam * F[i];
    }
    return norm2(n, R);
}

/* Newton from q (overwritten); returns 1 if converged; *rel = |R|/scale, *its += iterations. */
static int newton(const rr_contact *c, double omega, int n, const double *K, const double *F, double lam, double knorm,
                  double tol, int max_iter, double *q, double *rel, int *its, double *work, int *piv)
{
    double *J = work, *R = work + (size_t)n * n, *fnl = R + n, *dq = fnl + n, *qn = dq + n, *Rn = qn + n;
    double nr, scale;
    int it, i, j, no_force;
    /* |R| is measured against |lam F|; with no such force (at rest, no imbalance) against the blades' contact
     * forces, which a symmetric interference balances among themselves (1500 N a blade, a generalised force of
     * 1e-12 N: balanced to 1e-13 N is converged), or else the stiffness */
    for (i = 0; i < n; ++i) R[i] = lam * F[i];
    scale = norm2(n, R);
    no_force = 1e-12 * knorm > scale;
    if (no_force) scale = 1e-12 * knorm;
    if (1e-30 > scale) scale = 1e-30;
    nr = residual(c, omega, n, K, F, lam, q, R, fnl);
    for (it = 1; it <= max_iter; ++it) {
        double step = 1.0, nn = 0.0;
        if (no_force) { /* the per-blade laws residual() left in the contact's work: F_N first */
            const double *law = c->work + (size_t)c->nb * c->np;
            double total = 0.0;
            for (j = 0; j < c->nb; ++j) total += fabs(law[(size_t)RR_LAW_WIDTH * j]);
            if (total > scale) scale = total;
        }
        if (nr <= tol * scale) {
            *rel = nr / scale;
            *its += it - 1;
            return 1;
        }
        rr_jacobian(c, q, NULL, omega, J, NULL);
        for (i = 0; i < n; ++i)
            for (j = 0; j < n; ++j) J[(size_t)i * n + j] = K[(size_t)i * n + j] - J[(size_t)i * n + j];
        if (rr_lu(n, J, piv) != 0) break;
        for (i = 0; i < n; ++i) dq[i] = -R[i];
        rr_lu_solve(n, J, piv, dq);
        while (step > 1e-6) {
            for (i = 0; i < n; ++i) qn[i] = q[i] + step * dq[i];
            nn = residual(c, omega, n, K, F, lam, qn, Rn, fnl);
            if (nn < (1.0 - 1e-4 * step) * nr) break;
            step *= 0.5;
        }
        if (!(step > 1e-6)) {
            *rel = nr / scale;
            *its += it;
            return 0;
        }
        for (i = 0; i < n; ++i) {
            q[i] = qn[i];
            R[i] = Rn[i];
        }
        nr = nn;
    }
    *rel = nr / scale;
    *its += max_iter;
    return nr <= tol * scale;
}

/* the 1-norm (largest column sum) of an n x n matrix: the scale of |R| when there is no force */
static double norm1(int n, const double *K)
{
    double big = 0.0;
    int i, j;
    for (j = 0; j < n; ++j) {
        double s = 0.0;
        for (i = 0; i < n; ++i) s += fabs(K[(size_t)i * n + j]);
        if (s > big) big = s;
    }
    return big;
}

int rr_static_newton(const rr_contact *c, double omega, const double *K, const double *F, double tol, int max_iter,
                     double *q, double *residual_out, int *iterations, double *work, int *iwork)
{
    int n = c->n, its = 0, ok;
    double rel = HUGE_VAL;
    ok = newton(c, omega, n, K, F, 1.0, norm1(n, K), tol, max_iter, q, &rel, &its, work, iwork);
    *residual_out = rel;
    *iterations = its;
    return ok;
}

int rr_static_solve(const rr_contact *c, double omega, const double *K, const double *F, const double *q0,
                    double tol, int max_iter, double *q, double *residual_out, int *iterations, double *work,
                    int *iwork)
{
    int n = c->n, i, k, ok = 0, its = 0, n_start;
    double *nw = work;                               /* newton: n*n + 5n */
    double *qlin = work + (size_t)n * n + 5 * (size_t)n;
    double *best = qlin + n, *start = best + n;      /* + 3n */
    double *Kc = start + n;                          /* n*n: closed-contact stiffness, built when needed */
    double knorm = 0.0, rel = HUGE_VAL, best_rel = HUGE_VAL;
    static const double fracs[3] = {1.0, 0.5, 0.1}, scales[4] = {0.5, 0.25, 1.5, 2.0};
    int have_kc = 0;
    knorm = norm1(n, K);
    /* the linear response */
    for (i = 0; i < n * n; ++i) nw[i] = K[i];
    if (rr_lu(n, nw, iwork) != 0) {
        for (i = 0; i < n; ++i) q[i] = 0.0;
        *residual_out = HUGE_VAL;
        *iterations = 0;
        return 0;
    }
    for (i = 0; i < n; ++i) qlin[i] = F[i];
    rr_lu_solve(n, nw, iwork, qlin);
    n_start = (q0 ? 1 : 0) + 1 + 3 + 4;
    for (k = 0; k < n_start && !ok; ++k) {
        int kk = q0 ? k : k + 1; /* 0: q0, 1: linear, 2..4: closed contacts, 5..8: scaled linear */
        if (kk == 0) {
            for (i = 0; i < n; ++i) start[i] = q0[i];
        } else if (kk == 1) {
            for (i = 0; i < n; ++i) start[i] = qlin[i];
        } else if (kk <= 4) {
            double frac = fracs[kk - 2];
            if (!have_kc) {
                /* -dF_nl/dq with every blade in full contact: the law's Jacobian at g0 = -1, q = 0 */
                rr_contact closed = *c;
                closed.g0 = -1.0;
                for (i = 0; i < n; ++i) start[i] = 0.0;
                rr_jacobian(&closed, start, NULL, omega, Kc, NULL);
                for (i = 0; i < n * n; ++i) Kc[i] = -Kc[i];
                have_kc = 1;
            }
            for (i = 0; i < n * n; ++i) nw[i] = K[i] + frac * Kc[i];
            if (rr_lu(n, nw, iwork) != 0) continue;
            for (i = 0; i < n; ++i) start[i] = F[i];
            rr_lu_solve(n, nw, iwork, start);
        } else {
            for (i = 0; i < n; ++i) start[i] = scales[kk - 5] * qlin[i];
        }
        for (i = 0; i < n; ++i) q[i] = start[i];
        ok = newton(c, omega, n, K, F, 1.0, knorm, tol, max_iter, q, &rel, &its, nw, iwork);
        if (rel < best_rel) {
            best_rel = rel;
            for (i = 0; i < n; ++i) best[i] = q[i];
        }
    }
    if (!ok) {
        /* continuation in the imbalance: lam = 0.1, 0.2, ..., 1 from rest (numpy's linspace values) */
        const double dlam = (1.0 - 0.1) / 9.0;
        for (i = 0; i < n; ++i) q[i] = 0.0;
        for (k = 0; k < 10; ++k) {
            double lam = k == 9 ? 1.0 : k * dlam + 0.1;
            ok = newton(c, omega, n, K, F, lam, knorm, tol, max_iter, q, &rel, &its, nw, iwork);
            if (!ok) break;
        }
        if (!ok) {
            for (i = 0; i < n; ++i) q[i] = best[i];
            rel = best_rel;
        }
    }
    *residual_out = rel;
    *iterations = its;
    return ok;
}
