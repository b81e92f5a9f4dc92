/* rotorub kernel: contact laws, outputs of a state, central-difference loop (see rotorub_kernel.h). */
#include "rotorub_kernel.h"

#include <math.h>
#include <stddef.h>

#ifndef RR_SOURCE_ID
#define RR_SOURCE_ID "unversioned"
#endif

int rr_abi_version(void) { return RR_ABI_VERSION; }

const char *rr_source_id(void) { return RR_SOURCE_ID; }

/* scratch: gaps (nb*np) + law (nb*7) + right-hand side (n) */
int rr_work_size(int n, int nb, int np) { return nb * np + nb * RR_LAW_WIDTH + n; }

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

static void gaps_of(const rr_contact *c, const double *q, double *gaps)
{
    int row, k, n = c->n, rows = c->nb * c->np;
    for (row = 0; row < rows; ++row) {
        const double *g = c->G + (size_t)row * n;
        double s = 0.0;
        for (k = 0; k < n; ++k) s += g[k] * q[k];
        gaps[row] = c->g0 + s; /* g0 added last: gap - g0 does not depend on g0 (exact detection maps) */
    }
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

/* Q = A^T F_N + B^T M_N - mu (C^T F_N + D^T M_N): the virtual work of the pressure on the
 * gap's derivatives, reactions on the casing included (through the casing part of G). */
void rr_force(const rr_contact *c, const double *q, double *f)
{
    int j, k, n = c->n, nb = c->nb;
    double *gaps = c->work, *law = c->work + nb * c->np;
    rr_laws(c, q, gaps, law);
    for (k = 0; k < n; ++k) {
        double a = 0.0, b = 0.0, cc = 0.0, d = 0.0;
        for (j = 0; j < nb; ++j) {
            double FN = law[RR_LAW_WIDTH * j], MN = law[RR_LAW_WIDTH * j + 1];
            size_t o = (size_t)j * n + k;
            a += c->A[o] * FN;
            b += c->B[o] * MN;
            cc += c->C[o] * FN;
            d += c->D[o] * MN;
        }
        f[k] = a + b - c->mu * (cc + d);
    }
}

void rr_jacobian(const rr_contact *c, const double *q, double *J)
{
    int j, r, k, n = c->n, nb = c->nb;
    double *gaps = c->work, *law = c->work + nb * c->np;
    rr_laws(c, q, gaps, law);
    for (r = 0; r < n * n; ++r) J[r] = 0.0;
    for (j = 0; j < nb; ++j) {
        const double *L = law + RR_LAW_WIDTH * j;
        const double *A = c->A + (size_t)j * n, *B = c->B + (size_t)j * n;
        const double *C = c->C + (size_t)j * n, *D = c->D + (size_t)j * n;
        if (L[2] == 0.0 && L[3] == 0.0 && L[4] == 0.0 && L[5] == 0.0) continue;
        for (r = 0; r < n; ++r) {
            /* row r of A^T dF + B^T dM - mu (C^T dF + D^T dM), dF = L2 A + L3 B, dM = L4 A + L5 B */
            double wF = A[r] - c->mu * C[r], wM = B[r] - c->mu * D[r];
            double *Jr = J + (size_t)r * n;
            if (wF == 0.0 && wM == 0.0) continue;
            for (k = 0; k < n; ++k) {
                double dF = L[2] * A[k] + L[3] * B[k];
                double dM = L[4] * A[k] + L[5] * B[k];
                Jr[k] += wF * dF + wM * dM;
            }
        }
    }
}

/* ------------------------------------------------------------------ outputs of a state */

static void outputs_from_law(const rr_contact *c, const double *q, const double *gaps, const double *law,
                             double phi, const int *index, double *dest)
{
    int j, k, nb = c->nb, np = c->np, n = c->n;
    double Fc[3] = {0.0, 0.0, 0.0}, Mc[3] = {0.0, 0.0, 0.0}, tF = 0.0, tM = 0.0;
    double dx = 0.0, dy = 0.0, gmin = HUGE_VAL, cs, sn, vals[RR_OUT_GLOBALS];
    int n_contact = 0;
#define RR_PUT(pos, value) (index ? (dest[index[(pos)]] = (value)) : (dest[(pos)] = (value)))
    for (j = 0; j < nb; ++j) {
        const double *L = law + RR_LAW_WIDTH * j;
        double FN = L[0], MN = L[1];
        double gle = gaps[np * j], gte = gaps[np * j + np - 1];
        double gtip = (gle <= gte || gle != gle) ? gle : gte; /* a NaN propagates, as numpy's min */
        RR_PUT(RR_OUT_FN * nb + j, FN);
        RR_PUT(RR_OUT_FT * nb + j, c->mu * FN);
        RR_PUT(RR_OUT_GAP_LE * nb + j, gle);
        RR_PUT(RR_OUT_GAP_TE * nb + j, gte);
        RR_PUT(RR_OUT_GAP_TIP * nb + j, gtip);
        RR_PUT(RR_OUT_FRACTION * nb + j, L[6]);
        for (k = 0; k < 3; ++k) {
            Fc[k] += FN * c->res_F[3 * j + k];
            Mc[k] += MN * c->res_M[3 * j + k];
        }
        tF += FN * c->tq_F[j];
        tM += MN * c->tq_M[j];
        if (FN > 0.0) ++n_contact;
        if (gtip < gmin || gtip != gtip) gmin = gtip;
    }
    for (k = 0; k < n; ++k) {
        dx += c->T2[k] * q[k];
        dy += c->T2[n + k] * q[k];
    }
    cs = cos(phi);
    sn = sin(phi);
    Fc[0] += Mc[0];
    Fc[1] += Mc[1];
    Fc[2] += Mc[2];
    vals[RR_OUT_CASING_X] = cs * Fc[0] - sn * Fc[1];
    vals[RR_OUT_CASING_Y] = sn * Fc[0] + cs * Fc[1];
    vals[RR_OUT_CASING_Z] = Fc[2];
    vals[RR_OUT_TORQUE] = tF + tM;
    vals[RR_OUT_DISK_X] = cs * dx - sn * dy;
    vals[RR_OUT_DISK_Y] = sn * dx + cs * dy;
    vals[RR_OUT_GAP_MIN] = gmin;
    vals[RR_OUT_N_CONTACT] = (double)n_contact;
    for (k = 0; k < RR_OUT_GLOBALS; ++k) RR_PUT(RR_OUT_BLADE_BLOCKS * nb + k, vals[k]);
#undef RR_PUT
}

void rr_outputs(const rr_contact *c, const double *q, double phi, const int *index, double *dest)
{
    double *gaps = c->work, *law = c->work + c->nb * c->np;
    rr_laws(c, q, gaps, law);
    outputs_from_law(c, q, gaps, law, phi, index, dest);
}

void rr_outputs_batch(const rr_contact *c, int m, const double *Q, double *out)
{
    int i;
    for (i = 0; i < m; ++i) rr_outputs(c, Q + (size_t)i * c->n, 0.0, NULL, out + (size_t)i * RR_N_OUT(c->nb));
}

/* ------------------------------------------------------------------ central differences */

/* One step: (M/dt^2 + C/2dt) q+ = r F + F_nl(q) + (2M/dt^2 - K) q - (M/dt^2 - C/2dt) q-, with the
 * contact force at the current q only (explicit), from the laws already evaluated at q. The order
 * of the sums is fixed (see the header); locals and restrict let the compiler keep the matrices
 * streaming instead of reloading the structs after every store. */
static void cd_update(int n, int nb, const double *restrict law, const double *restrict A,
                      const double *restrict B, const double *restrict C, const double *restrict D, double mu,
                      const double *restrict Ainv, const double *restrict K2, const double *restrict Cm1,
                      const double *restrict f, double r, double *restrict q, double *restrict qp,
                      double *restrict rhs)
{
    int j, k, e;
    for (k = 0; k < n; ++k) {
        double acc = r * f[k];
        const double *K2k = K2 + (size_t)k * n, *Cm1k = Cm1 + (size_t)k * n;
        for (j = 0; j < nb; ++j) {
            double FN = law[RR_LAW_WIDTH * j], MN = law[RR_LAW_WIDTH * j + 1];
            size_t o = (size_t)j * n + k;
            if (FN == 0.0 && MN == 0.0) continue; /* adds an exact zero */
            acc += A[o] * FN + B[o] * MN - mu * (C[o] * FN + D[o] * MN);
        }
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

/* The law is evaluated once per state: at the end of a step it serves both the record of the
 * new state and the next step's contact force. */
int rr_cd_run(rr_cd_job *job)
{
    rr_cd_state *s = job->state;
    const rr_contact *c = job->contact;
    const rr_cd_matrices *m = job->mats;
    int i, k, n = c->n, nb = c->nb, rows = nb * c->np;
    int done = 0, written = job->n_rec, rec_every = job->rec_every < 1 ? 1 : job->rec_every;
    double *gaps = c->work, *law = c->work + rows;
    double *rhs = law + nb * RR_LAW_WIDTH;
    double *q = s->q, *qp = s->q_prev;
    const double t0 = s->t, dt = s->dt, floor_gap = -s->max_pen, t_ramp = job->t_ramp, me = job->me;
    const long long step0 = s->steps;
    job->done = 0;
    if (s->diverged) return 0;
    gaps_of(c, q, gaps);
    laws_of(c, gaps, law);
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
        cd_update(n, nb, law, c->A, c->B, c->C, c->D, c->mu, m->Ainv, m->K2, m->Cm1, m->f, r * me, q, qp, rhs);
        ++done;
        gaps_of(c, q, gaps);
        laws_of(c, gaps, law);
        if ((step0 + i + 1) % rec_every == 0 && written < job->rec_cap) {
            for (k = 0; k < n; ++k) job->rec_q[(size_t)written * n + k] = q[k];
            if (job->rec_out)
                outputs_from_law(c, q, gaps, law, 0.0, NULL, job->rec_out + (size_t)written * RR_N_OUT(nb));
            ++written;
        }
    }
    s->steps += done;
    s->t += done * dt;
    s->phi += done * dt * job->omega;
    job->n_rec = written;
    job->done = done;
    if (job->out_dest) outputs_from_law(c, q, gaps, law, s->phi, job->out_index, job->out_dest);
    return done;
}
