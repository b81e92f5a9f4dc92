/* rotorub kernel: gaps, friction, the generalised contact force and its Jacobians, outputs of a state (see
 * rotorub_kernel.h; internal declarations in rr_internal.h).
 *
 * A 'blade' here is what the law is evaluated on: a built-in blade (one chord, dense rows over every dof) or a
 * segment of an imported blade's tip (its own length and share of k_r, rows over the dofs it touches only: the
 * shaft, its blade, the casing). The arithmetic of the built-in case is the one it always had (bit for bit). */
#include "rr_internal.h"

/* gaps to the unworn, centred casing */
void rri_raw_gaps(const rr_contact *c, const double *q, double *gaps)
{
    int j, p, np = c->np, ld = rri_ld(c);
    for (j = 0; j < c->nb; ++j) {
        const int *cols = rri_cols(c, j);
        for (p = 0; p < np; ++p) {
            size_t row = (size_t)j * np + p;
            double s = rri_dot(ld, c->G + row * ld, cols, q);
            if (c->g_off) s = c->g_off[row] + s;
            gaps[row] = c->g0 + s; /* g0 added last: gap - g0 does not depend on g0 (exact detection maps) */
        }
    }
}

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
        rri_blade_law(&c->law, c->np, g[0], g[c->np - 1], rri_k(c, j), rri_len(c, j), law + RR_LAW_WIDTH * j);
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
            rri_blade_law(&c->law, np, g[np * j], g[np * j + np - 1], rri_k(c, j), rri_len(c, j), L);
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
    closed.g_off = NULL;   /* closed everywhere, whatever each point's rest gap */
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
    int j, p, e, np = c->np, ld = rri_ld(c);
    for (j = 0; j < c->nb; ++j) {
        const double *L = law + RR_LAW_WIDTH * j;
        const int *cols = rri_cols(c, j);
        int touching = !(L[0] == 0.0 && L[1] == 0.0);
        for (p = 0; p < np; ++p) {
            size_t pk = (size_t)j * np + p;
            double v;
            if (!touching) {
                fr[pk] = 0.0;
                continue;
            }
            v = omega * rri_spin_arm(c->points + 3 * pk, c->tangents + 3 * pk);
            if (qdot) {
                v += rri_dot(ld, c->S + pk * ld, cols, qdot);
            } else if (q_prev) {
                const double *S = c->S + pk * ld;
                double sv = 0.0;
                if (cols)
                    for (e = 0; e < ld; ++e) sv += S[e] * (q[cols[e]] - q_prev[cols[e]]);
                else
                    for (e = 0; e < ld; ++e) sv += S[e] * (q[e] - q_prev[e]);
                v += sv / dt;
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
    int j, k, p, n = c->n, np = c->np, ld = rri_ld(c);
    for (k = 0; k < n; ++k) f[k] = 0.0;
    for (j = 0; j < c->nb; ++j) {
        const double *L = law + RR_LAW_WIDTH * j;
        const double *A = c->A + (size_t)j * ld, *B = c->B + (size_t)j * ld;
        const int *cols = rri_cols(c, j);
        double w[2], aF[2], aM[2];
        if (L[0] == 0.0 && L[1] == 0.0) continue;
        rri_point_weights(np, rri_len(c, j), L[0], L[1], w, aF, aM);
        if (cols)
            for (k = 0; k < ld; ++k) f[cols[k]] += A[k] * L[0] + B[k] * L[1];
        else
            for (k = 0; k < n; ++k) f[k] += A[k] * L[0] + B[k] * L[1];
        for (p = 0; p < np; ++p) {
            size_t pk = (size_t)j * np + p;
            double fw = fr[pk] * w[p];
            if (fw != 0.0) rri_axpy(ld, -fw, c->S + pk * ld, cols, f);
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
    int j, r, k, p, e, n = c->n, nb = c->nb, np = c->np, rows = nb * np, ld = rri_ld(c);
    double *gaps = c->work, *law = gaps + rows, *fr = law + nb * RR_LAW_WIDTH;
    rr_laws(c, q, gaps, law);
    rri_friction_of(c, law, omega, qdot, NULL, NULL, 1.0, fr);
    for (r = 0; r < n * n; ++r) J[r] = 0.0;
    if (Jv)
        for (r = 0; r < n * n; ++r) Jv[r] = 0.0;
    for (j = 0; j < nb; ++j) {
        const double *L = law + RR_LAW_WIDTH * j;
        const double *A = c->A + (size_t)j * ld, *B = c->B + (size_t)j * ld;
        const double *S0 = c->S + (size_t)j * np * ld, *S1 = np == 2 ? S0 + ld : S0;
        const int *cols = rri_cols(c, j);
        double w[2], aF[2], aM[2], f0, f1;
        if (L[2] == 0.0 && L[3] == 0.0 && L[4] == 0.0 && L[5] == 0.0) continue;
        rri_point_weights(np, rri_len(c, j), L[0], L[1], w, aF, aM);
        f0 = fr[(size_t)j * np];
        f1 = np == 2 ? fr[(size_t)j * np + 1] : 0.0;
        for (r = 0; r < ld; ++r) {
            /* row r of A^T dF + B^T dM - sum_p f_p S_p^T dw_p, dw_p = aF_p dF + aM_p dM,
             * dF = L2 A + L3 B, dM = L4 A + L5 B */
            double wF = A[r] - (f0 * aF[0] * S0[r] + (np == 2 ? f1 * aF[1] * S1[r] : 0.0));
            double wM = B[r] - (f0 * aM[0] * S0[r] + (np == 2 ? f1 * aM[1] * S1[r] : 0.0));
            double *Jr = J + (size_t)(cols ? cols[r] : r) * n;
            if (wF == 0.0 && wM == 0.0) continue;
            for (k = 0; k < ld; ++k) {
                double dF = L[2] * A[k] + L[3] * B[k];
                double dM = L[4] * A[k] + L[5] * B[k];
                Jr[cols ? cols[k] : k] += wF * dF + wM * dM;
            }
        }
        if (!Jv) continue;
        /* d/dq' of -mu tanh(v_p / v_slip) w_p S_p^T, v_p = omega rho_p + S_p q' */
        for (p = 0; p < np; ++p) {
            size_t pk = (size_t)j * np + p;
            const double *S = c->S + pk * ld;
            double th, cpl;
            if (c->mu == 0.0 || w[p] == 0.0) continue;
            th = fr[pk] / c->mu;
            cpl = c->mu * w[p] * (1.0 - th * th) / c->v_slip;
            if (cpl == 0.0) continue;
            for (r = 0; r < ld; ++r) {
                double a = cpl * S[r];
                double *Jr = Jv + (size_t)(cols ? cols[r] : r) * n;
                if (a == 0.0) continue;
                for (e = 0; e < ld; ++e) Jr[cols ? cols[e] : e] -= a * S[e];
            }
        }
    }
}

/* ------------------------------------------------------------------ outputs of a state */

/* one kernel blade's (or tip segment's) force on the casing, added to Fc and its torque about e_z; returns its
 * friction force along the tangents */
static double segment_on_casing(const rr_contact *c, int j, const double *L, const double *fr, double *Fc,
                                double *torque)
{
    int k, p, np = c->np;
    double w[2], aF[2], aM[2], ft = 0.0;
    if (L[0] == 0.0 && L[1] == 0.0) return 0.0;
    rri_point_weights(np, rri_len(c, j), L[0], L[1], w, aF, aM);
    for (p = 0; p < np; ++p) {
        /* on the casing: w_p (n_p + f_p t_p); its torque on the rotor about e_z is the opposite */
        size_t pk = (size_t)j * np + p;
        const double *P = c->points + 3 * pk, *nv = c->normals + 3 * pk, *tv = c->tangents + 3 * pk;
        double f[3];
        for (k = 0; k < 3; ++k) {
            f[k] = w[p] * (nv[k] + fr[pk] * tv[k]);
            Fc[k] += f[k];
        }
        *torque -= P[0] * f[1] - P[1] * f[0];
        ft += fr[pk] * w[p];
    }
    return ft;
}

/* the lesser tip gap, a NaN propagating as numpy's min does */
static double gap_min(double a, double b) { return (a <= b || a != a) ? a : b; }

#define RR_PUT(pos, value) (index ? (dest[index[(pos)]] = (value)) : (dest[(pos)] = (value)))

/* reported blade b's outputs (into dest, through index when given), and what the globals gather from it */
static void put_blade(double *dest, const int *index, int nbo, int b, double FN, double FT, double gle, double gte,
                      double gtip, double frac, int *n_contact, double *gmin)
{
    RR_PUT(RR_OUT_FN * nbo + b, FN);
    RR_PUT(RR_OUT_FT * nbo + b, FT);
    RR_PUT(RR_OUT_GAP_LE * nbo + b, gle);
    RR_PUT(RR_OUT_GAP_TE * nbo + b, gte);
    RR_PUT(RR_OUT_GAP_TIP * nbo + b, gtip);
    RR_PUT(RR_OUT_FRACTION * nbo + b, frac);
    if (FN > 0.0) ++*n_contact;
    if (gtip < *gmin || gtip != gtip) *gmin = gtip;
}

void rri_outputs_from_law(const rr_contact *c, const double *q, const double *gaps, const double *law,
                          const double *fr, double phi, const int *index, double *dest)
{
    int j, k, nb = c->nb, np = c->np, n = c->n, nbo = rri_nb_out(c);
    double Fc[3] = {0.0, 0.0, 0.0}, torque = 0.0;
    double dx = 0.0, dy = 0.0, gmin = HUGE_VAL, cs, sn, vals[RR_OUT_GLOBALS];
    int n_contact = 0;
    if (!c->blade_of) { /* built-in blades: each kernel blade is a reported blade (the outputs' every step) */
        for (j = 0; j < nb; ++j) {
            const double *L = law + RR_LAW_WIDTH * j;
            double gle = gaps[np * j], gte = gaps[np * j + np - 1], gtip = gap_min(gle, gte);
            double FT = segment_on_casing(c, j, L, fr, Fc, &torque);
            put_blade(dest, index, nbo, j, L[0], FT, gle, gte, gtip, L[6], &n_contact, &gmin);
        }
    } else { /* an imported tip: a reported blade gathers its segments, leading edge first */
        double FN = 0.0, FT = 0.0, gle = 0.0, gte = 0.0, gtip = HUGE_VAL, frac = 0.0, len = 0.0;
        int first = 1;
        for (j = 0; j < nb; ++j) {
            const double *L = law + RR_LAW_WIDTH * j;
            int b = c->blade_of[j], last = j + 1 == nb || c->blade_of[j + 1] != b;
            double lj = rri_len(c, j), sle = gaps[np * j], ste = gaps[np * j + np - 1], sg = gap_min(sle, ste);
            double ft = segment_on_casing(c, j, L, fr, Fc, &torque);
            if (first) {
                FN = L[0];
                FT = ft;
                gle = sle;
                gtip = sg;
                frac = L[6] * lj;
                len = lj;
            } else {
                FN += L[0];
                FT += ft;
                if (sg < gtip || sg != sg) gtip = sg;
                frac += L[6] * lj;
                len += lj;
            }
            gte = ste;
            first = last;
            if (!last) continue;
            put_blade(dest, index, nbo, b, FN, FT, gle, gte, gtip, frac / len, &n_contact, &gmin);
        }
    }
    for (k = 0; k < n; ++k) {
        dx += c->T2[k] * q[k];
        dy += c->T2[n + k] * q[k];
    }
    rr_sincos(phi, &sn, &cs); /* one reduction of the angle for both (the same bits as rr_sin, rr_cos) */
    vals[RR_OUT_CASING_X] = cs * Fc[0] - sn * Fc[1];
    vals[RR_OUT_CASING_Y] = sn * Fc[0] + cs * Fc[1];
    vals[RR_OUT_CASING_Z] = Fc[2];
    vals[RR_OUT_TORQUE] = torque;
    vals[RR_OUT_DISK_X] = cs * dx - sn * dy;
    vals[RR_OUT_DISK_Y] = sn * dx + cs * dy;
    vals[RR_OUT_GAP_MIN] = gmin;
    vals[RR_OUT_N_CONTACT] = (double)n_contact;
    for (k = 0; k < RR_OUT_GLOBALS; ++k) RR_PUT(RR_OUT_BLADE_BLOCKS * nbo + k, vals[k]);
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
                   out + (size_t)i * RR_N_OUT(rri_nb_out(c)));
}
