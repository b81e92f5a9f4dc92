/* rotorub kernel: gaps, friction, generalised contact force and its Jacobians, outputs of a state (see rotorub_kernel.h; internal declarations in rr_internal.h). */
#include "rr_internal.h"

/* gaps to the unworn, centred casing */
void rri_raw_gaps(const rr_contact *c, const double *q, double *gaps)
{
    int row, k, n = c->n, rows = c->nb * c->np;
    for (row = 0; row < rows; ++row) {
        const double *g = c->G + (size_t)row * n;
        double s = 0.0;
        for (k = 0; k < n; ++k) s += g[k] * q[k];
        gaps[row] = c->g0 + s; /* g0 added last: gap - g0 does not depend on g0 (exact detection maps) */
    }
}

void rri_surface_apply(const rr_contact *c, double *gaps);

void rri_gaps_of(const rr_contact *c, const double *q, double *gaps)
{
    rri_raw_gaps(c, q, gaps);
    if (c->surface) rri_surface_apply(c, gaps);
}

void rri_laws_of(const rr_contact *c, const double *gaps, double *law)
{
    int j;
    for (j = 0; j < c->nb; ++j) {
        const double *g = gaps + (size_t)c->np * j;
        rri_blade_law(&c->law, c->np, g[0], g[c->np - 1], c->k_r, c->chord, law + RR_LAW_WIDTH * j);
    }
}

void rr_laws(const rr_contact *c, const double *q, double *gaps, double *law)
{
    rri_gaps_of(c, q, gaps);
    rri_laws_of(c, gaps, law);
}

void rr_potential_batch(const rr_contact *c, int m, const double *gaps, double *out)
{
    int i, j, np = c->np, rows = c->nb * np;
    double L[RR_LAW_WIDTH];
    for (i = 0; i < m; ++i) {
        const double *g = gaps + (size_t)i * rows;
        double v = 0.0;
        for (j = 0; j < c->nb; ++j) {
            rri_blade_law(&c->law, np, g[np * j], g[np * j + np - 1], c->k_r, c->chord, L);
            v += L[7];
        }
        out[i] = v;
    }
}

rr_contact rri_closed_contact(const rr_contact *c)
{
    rr_contact closed = *c;
    int i;
    closed.g0 = -1.0;
    closed.surface = NULL; /* every blade closed: the surface changes nothing the stiffness sees */
    closed.k_r = c->k_r * rri_law_max_slope(&c->law);
    closed.law.id = RR_LAW_PENALTY;
    for (i = 0; i < RR_LAW_PARAMS; ++i) closed.law.par[i] = 0.0;
    return closed;
}

void rr_closed_stiffness(const rr_contact *c, double omega, double *Kc)
{
    /* the law's Jacobian at g0 = -1, q = 0 (the friction's part needs the slopes only, not the force) */
    rr_contact closed = rri_closed_contact(c);
    int i, n = c->n;
    double *zero = c->work + (c->nb * c->np + c->nb * RR_LAW_WIDTH + c->nb * c->np); /* the rhs scratch: n */
    for (i = 0; i < n; ++i) zero[i] = 0.0;
    rr_jacobian(&closed, zero, NULL, omega, Kc, NULL);
    for (i = 0; i < n * n; ++i) Kc[i] = -Kc[i];
}

void rr_gaps_batch(const rr_contact *c, int m, const double *Q, double *gaps)
{
    int i, rows = c->nb * c->np;
    for (i = 0; i < m; ++i) rri_gaps_of(c, Q + (size_t)i * c->n, gaps + (size_t)i * rows);
}

/* ------------------------------------------------------------------ friction */


/* Friction factors mu tanh(v_p / v_slip) of every point of a blade in contact, from the law at q;
 * the velocity is qdot, or (q - q_prev) / dt when qdot is NULL and q_prev is not, or zero. */
void rri_friction_of(const rr_contact *c, const double *law, double omega, const double *qdot, const double *q,
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
            v = omega * rri_spin_arm(c->points + 3 * pk, c->tangents + 3 * pk);
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
    rri_friction_of(c, law, omega, qdot, NULL, NULL, 1.0, fr);
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
        rri_point_weights(np, c->chord, L[0], L[1], w, aF, aM);
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
    rri_friction_of(c, law, omega, qdot, NULL, NULL, 1.0, fr);
    force_from_law(c, law, fr, f);
}

void rr_jacobian(const rr_contact *c, const double *q, const double *qdot, double omega, double *J, double *Jv)
{
    int j, r, k, p, e, n = c->n, nb = c->nb, np = c->np, rows = nb * np;
    double *gaps = c->work, *law = gaps + rows, *fr = law + nb * RR_LAW_WIDTH;
    rr_laws(c, q, gaps, law);
    rri_friction_of(c, law, omega, qdot, NULL, NULL, 1.0, fr);
    for (r = 0; r < n * n; ++r) J[r] = 0.0;
    if (Jv)
        for (r = 0; r < n * n; ++r) Jv[r] = 0.0;
    for (j = 0; j < nb; ++j) {
        const double *L = law + RR_LAW_WIDTH * j;
        const double *A = c->A + (size_t)j * n, *B = c->B + (size_t)j * n;
        const double *S0 = c->S + (size_t)j * np * n, *S1 = np == 2 ? S0 + n : S0;
        double w[2], aF[2], aM[2], f0, f1;
        if (L[2] == 0.0 && L[3] == 0.0 && L[4] == 0.0 && L[5] == 0.0) continue;
        rri_point_weights(np, c->chord, L[0], L[1], w, aF, aM);
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

void rri_outputs_from_law(const rr_contact *c, const double *q, const double *gaps, const double *law,
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
            rri_point_weights(np, c->chord, FN, MN, w, aF, aM);
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
    rri_friction_of(c, law, omega, qdot, NULL, NULL, 1.0, fr);
    rri_outputs_from_law(c, q, gaps, law, fr, phi, index, dest);
}

void rr_outputs_batch(const rr_contact *c, int m, const double *Q, const double *Qdot, double omega, double *out)
{
    int i;
    for (i = 0; i < m; ++i)
        rr_outputs(c, Q + (size_t)i * c->n, Qdot ? Qdot + (size_t)i * c->n : NULL, omega, 0.0, NULL,
                   out + (size_t)i * RR_N_OUT(c->nb));
}
