/* rotorub kernel: batch evaluation for the harmonic balance (declarations and contract in rr_batch.h). */
#include "rr_batch.h"
#include "rr_internal.h"

#include <stddef.h>

/* out (r x r) = P A P^T for A (n x n), P (r x n); tmp: r * n doubles */
static void project(int n, int r, const double *P, const double *A, double *tmp, double *out)
{
    int a, b, k, l;
    for (a = 0; a < r; ++a) { /* tmp = P A */
        const double *pa = P + (size_t)a * n;
        double *ta = tmp + (size_t)a * n;
        for (l = 0; l < n; ++l) ta[l] = 0.0;
        for (k = 0; k < n; ++k) {
            const double *Ak = A + (size_t)k * n;
            double p = pa[k];
            if (p == 0.0) continue;
            for (l = 0; l < n; ++l) ta[l] += p * Ak[l];
        }
    }
    for (a = 0; a < r; ++a) {
        const double *ta = tmp + (size_t)a * n;
        for (b = 0; b < r; ++b) {
            const double *pb = P + (size_t)b * n;
            double s = 0.0;
            for (l = 0; l < n; ++l) s += ta[l] * pb[l];
            out[(size_t)a * r + b] = s;
        }
    }
}

static int all_zero(const double *x, int len)
{
    int k;
    for (k = 0; k < len; ++k)
        if (x[k] != 0.0) return 0;
    return 1;
}

int rr_batch_work_size(int n, int r) { return 2 * n * n + r * n; }

int rr_batch_eval(const rr_contact *c, int m, const double *Q, const double *Qdot, double omega,
                  const double *phi, int r, const double *P, double *F, double *J, double *Jv, double *work)
{
    int i, k, a, n = c->n, touching = 0, contact;
    rr_surface *s = c->surface;
    const double phi0 = s ? s->phi : 0.0;
    for (i = 0; i < m; ++i) {
        const double *q = Q + (size_t)i * n, *qd = Qdot ? Qdot + (size_t)i * n : NULL;
        double f[512];
        double *fi = P ? (n <= 512 ? f : NULL) : F + (size_t)i * n;
        if (!fi) {
            if (s) s->phi = phi0;
            return -1; /* a reduced basis is for models of up to 512 dofs (the force's stack copy) */
        }
        if (s && phi) s->phi = phi[i];
        rr_force(c, q, qd, omega, fi);
        contact = !all_zero(fi, n);
        touching += contact;
        if (P)
            for (a = 0; a < r; ++a) {
                const double *pa = P + (size_t)a * n;
                double sum = 0.0;
                for (k = 0; k < n; ++k) sum += pa[k] * fi[k];
                F[(size_t)i * r + a] = sum;
            }
        if (!J && !Jv) continue;
        if (!contact) { /* no blade touches: both Jacobians vanish (the laws are zero on open gaps) */
            size_t len = P ? (size_t)r * r : (size_t)n * n;
            if (J)
                for (k = 0; k < (int)len; ++k) J[(size_t)i * len + k] = 0.0;
            if (Jv)
                for (k = 0; k < (int)len; ++k) Jv[(size_t)i * len + k] = 0.0;
            continue;
        }
        if (!P) {
            double *Ji = J ? J + (size_t)i * n * n : work, *Jvi = Jv ? Jv + (size_t)i * n * n : NULL;
            rr_jacobian(c, q, qd, omega, Ji, Jvi);
        } else {
            /* work: [n*n] the full Jacobian, then r*n of projection scratch, then n*n for Jv */
            double *full = work, *tmp = work + (size_t)n * n, *fullv = tmp + (size_t)r * n;
            rr_jacobian(c, q, qd, omega, full, Jv ? fullv : NULL);
            if (J) project(n, r, P, full, tmp, J + (size_t)i * r * r);
            if (Jv) {
                if (all_zero(fullv, n * n)) /* saturated friction (tip speeds): no damping to project */
                    for (k = 0; k < r * r; ++k) Jv[(size_t)i * r * r + k] = 0.0;
                else
                    project(n, r, P, fullv, tmp, Jv + (size_t)i * r * r);
            }
        }
    }
    if (s) s->phi = phi0;
    return touching;
}

/* ------------------------------------------------------------------ reduced evaluation (contact coordinates) */

int rr_batch_reduced_work_size(int n, int nb, int np, int r)
{
    int rows = nb * np;
    return 2 * n + rows + nb * RR_LAW_WIDTH + rows + (2 * nb + rows) * r;
}

int rr_batch_reduced(const rr_contact *c, int m, const double *y, const double *yd, double omega, const double *phi,
                     int r, const double *P, double *F, double *J, double *Jv, double *work)
{
    int i, j, k, a, b, p, n = c->n, nb = c->nb, np = c->np, rows = nb * np, touching = 0, ld = rri_ld(c);
    rr_surface *s = c->surface;
    const double phi0 = s ? s->phi : 0.0;
    double *q = work, *qd = q + n, *gaps = qd + n, *law = gaps + rows, *fr = law + (size_t)nb * RR_LAW_WIDTH;
    double *PA = fr + rows, *PB = PA + (size_t)nb * r, *PS = PB + (size_t)nb * r;
    /* the contact's rows in the reduced coordinates: P A_j^T, P B_j^T, P S_p^T (A, B, S lie in P's span); a
     * segment's rows over its own columns when they are compact (an imported tip) */
    for (j = 0; j < nb; ++j)
        for (a = 0; a < r; ++a) {
            const double *pa = P + (size_t)a * n;
            const int *cols = rri_cols(c, j);
            PA[(size_t)j * r + a] = rri_dot(ld, c->A + (size_t)j * ld, cols, pa);
            PB[(size_t)j * r + a] = rri_dot(ld, c->B + (size_t)j * ld, cols, pa);
        }
    for (j = 0; j < rows; ++j)
        for (a = 0; a < r; ++a)
            PS[(size_t)j * r + a] = rri_dot(ld, c->S + (size_t)j * ld, rri_cols(c, j / np), P + (size_t)a * n);
    for (i = 0; i < m; ++i) {
        const double *yi = y + (size_t)i * r, *ydi = yd ? yd + (size_t)i * r : NULL;
        double *Fi = F + (size_t)i * r, *Ji = J ? J + (size_t)i * r * r : NULL, *Jvi = Jv ? Jv + (size_t)i * r * r : NULL;
        int contact = 0;
        for (k = 0; k < n; ++k) { /* q = P^T y, q' = P^T y' */
            double sq = 0.0, sv = 0.0;
            for (a = 0; a < r; ++a) {
                sq += P[(size_t)a * n + k] * yi[a];
                if (ydi) sv += P[(size_t)a * n + k] * ydi[a];
            }
            q[k] = sq;
            qd[k] = sv;
        }
        if (s && phi) s->phi = phi[i];
        rri_gaps_of(c, q, gaps);
        rri_laws_of(c, gaps, law);
        rri_friction_of(c, law, omega, ydi ? qd : NULL, NULL, NULL, 1.0, fr);
        for (a = 0; a < r; ++a) Fi[a] = 0.0;
        if (Ji)
            for (k = 0; k < r * r; ++k) Ji[k] = 0.0;
        if (Jvi)
            for (k = 0; k < r * r; ++k) Jvi[k] = 0.0;
        for (j = 0; j < nb; ++j) {
            const double *L = law + RR_LAW_WIDTH * j;
            const double *pa = PA + (size_t)j * r, *pb = PB + (size_t)j * r;
            const double *ps0 = PS + (size_t)j * np * r, *ps1 = np == 2 ? ps0 + r : ps0;
            double w[2], aF[2], aM[2], f0, f1, fw0, fw1;
            if (L[0] == 0.0 && L[1] == 0.0 && L[2] == 0.0 && L[3] == 0.0 && L[4] == 0.0 && L[5] == 0.0) continue;
            contact = 1;
            rri_point_weights(np, rri_len(c, j), L[0], L[1], w, aF, aM);
            f0 = fr[(size_t)j * np];
            f1 = np == 2 ? fr[(size_t)j * np + 1] : 0.0;
            fw0 = f0 * w[0];
            fw1 = np == 2 ? f1 * w[1] : 0.0;
            /* P Q: A^T F_N + B^T M_N - sum_p f_p w_p S_p^T, projected */
            for (a = 0; a < r; ++a) Fi[a] += pa[a] * L[0] + pb[a] * L[1] - (fw0 * ps0[a] + (np == 2 ? fw1 * ps1[a] : 0.0));
            if (Ji) { /* P (dQ/dq) P^T: rr_jacobian's rows (wF, wM) and columns (dF, dM), projected on both sides */
                for (a = 0; a < r; ++a) {
                    double wF = pa[a] - (f0 * aF[0] * ps0[a] + (np == 2 ? f1 * aF[1] * ps1[a] : 0.0));
                    double wM = pb[a] - (f0 * aM[0] * ps0[a] + (np == 2 ? f1 * aM[1] * ps1[a] : 0.0));
                    double *Ja = Ji + (size_t)a * r;
                    if (wF == 0.0 && wM == 0.0) continue;
                    for (b = 0; b < r; ++b) {
                        double dF = L[2] * pa[b] + L[3] * pb[b];
                        double dM = L[4] * pa[b] + L[5] * pb[b];
                        Ja[b] += wF * dF + wM * dM;
                    }
                }
            }
            /* d/dq' of -mu tanh(v_p / v_slip) w_p S_p^T, projected (rr_jacobian skips a blade whose law has no
             * slope: so does this) */
            if (Jvi && c->mu != 0.0 && !(L[2] == 0.0 && L[3] == 0.0 && L[4] == 0.0 && L[5] == 0.0))
                for (p = 0; p < np; ++p) {
                    const double *ps = p == 0 ? ps0 : ps1;
                    double th = fr[(size_t)j * np + p] / c->mu;
                    double cpl = c->mu * w[p] * (1.0 - th * th) / c->v_slip;
                    if (w[p] == 0.0 || cpl == 0.0) continue;
                    for (a = 0; a < r; ++a)
                        for (b = 0; b < r; ++b) Jvi[(size_t)a * r + b] -= cpl * ps[a] * ps[b];
                }
        }
        touching += contact;
    }
    if (s) s->phi = phi0;
    return touching;
}

void rr_batch_laws(const rr_contact *c, int m, const double *Q, const double *phi, double *gaps, double *law)
{
    int i, rows = c->nb * c->np;
    rr_surface *s = c->surface;
    const double phi0 = s ? s->phi : 0.0;
    for (i = 0; i < m; ++i) {
        if (s && phi) s->phi = phi[i];
        rr_laws(c, Q + (size_t)i * c->n, gaps + (size_t)i * rows, law + (size_t)i * c->nb * RR_LAW_WIDTH);
    }
    if (s) s->phi = phi0;
}

/* ------------------------------------------------------------------ the AFT of a sampled Jacobian */

/* basis function b of the stacked series: 0 -> 1, 2k-1 -> cos k tau, 2k -> sin k tau */
static void basis_of(int b, int *k, int *is_sin)
{
    *k = (b + 1) / 2;
    *is_sin = b > 0 && b % 2 == 0;
}

/* sum_i phi_a(tau_i) phi_b(tau_i) X_i from the discrete harmonics C[k] = sum_i cos(k tau_i) X_i and
 * S[k] = sum_i sin(k tau_i) X_i (k = 0..2H), by the product-to-sum identities (exact on the samples) */
static void product_terms(int ka, int sa, int kb, int sb, int *i1, double *c1, int *i2, double *c2, int *s1,
                          int *s2)
{
    int d = ka - kb, e = ka + kb, sd = d < 0 ? -1 : 1;
    *i1 = d < 0 ? -d : d;
    *i2 = e;
    if (!sa && !sb) { /* cos cos = (cos d + cos e) / 2 */
        *s1 = 0; *c1 = 0.5; *s2 = 0; *c2 = 0.5;
    } else if (sa && sb) { /* sin sin = (cos d - cos e) / 2 */
        *s1 = 0; *c1 = 0.5; *s2 = 0; *c2 = -0.5;
    } else if (!sa && sb) { /* cos a sin b = (sin e - sin d) / 2 */
        *s1 = 1; *c1 = -0.5 * sd; *s2 = 1; *c2 = 0.5;
    } else { /* sin a cos b = (sin e + sin d) / 2 */
        *s1 = 1; *c1 = 0.5 * sd; *s2 = 1; *c2 = 0.5;
    }
}

void rr_batch_aft_assemble(int H, int r, int m, const double *Cj, const double *Sj, const double *Cv, const double *Sv,
                           double w, double *D)
{
    int nh = 2 * H + 1, a, b, u, v, rr = r * r;
    for (a = 0; a < nh; ++a) {
        int ka, sa;
        double wa = (a == 0 ? 1.0 : 2.0) / m;
        basis_of(a, &ka, &sa);
        for (b = 0; b < nh; ++b) {
            int kb, sb, i1, i2, s1, s2;
            double c1, c2;
            const double *X1, *X2;
            basis_of(b, &kb, &sb);
            product_terms(ka, sa, kb, sb, &i1, &c1, &i2, &c2, &s1, &s2);
            X1 = (s1 ? Sj : Cj) + (size_t)i1 * rr;
            X2 = (s2 ? Sj : Cj) + (size_t)i2 * rr;
            for (u = 0; u < r; ++u) {
                double *Dub = D + (((size_t)a * r + u) * nh + b) * r;
                for (v = 0; v < r; ++v) Dub[v] = wa * (c1 * X1[u * r + v] + c2 * X2[u * r + v]);
            }
            if (Cv && kb > 0) { /* w sum_i phi_a phi_b' Jv_i: d/dtau cos = -k sin, d/dtau sin = k cos */
                int j1, j2, t1, t2;
                double d1, d2, f = w * wa * (sb ? (double)kb : -(double)kb);
                product_terms(ka, sa, kb, !sb, &j1, &d1, &j2, &d2, &t1, &t2);
                X1 = (t1 ? Sv : Cv) + (size_t)j1 * rr;
                X2 = (t2 ? Sv : Cv) + (size_t)j2 * rr;
                for (u = 0; u < r; ++u) {
                    double *Dub = D + (((size_t)a * r + u) * nh + b) * r;
                    for (v = 0; v < r; ++v) Dub[v] += f * (d1 * X1[u * r + v] + d2 * X2[u * r + v]);
                }
            }
        }
    }
}

/* ------------------------------------------------------------------ the monodromy by split exponentials */

/* rows of U (N2 x cols) <- e^{Lambda tau} rows, Lambda in real modal form (blocks of 1 or 2) */
static void free_flow(int N2, int cols, int nblk, const int *size, const double *re, const double *im, double tau,
                      double *U)
{
    int k, row = 0, c;
    for (k = 0; k < nblk; ++k) {
        double e = rr_exp(re[k] * tau);
        double *u0 = U + (size_t)row * cols;
        if (size[k] == 1) {
            for (c = 0; c < cols; ++c) u0[c] *= e;
            row += 1;
        } else {
            double *u1 = u0 + cols, cs = e * rr_cos(im[k] * tau), sn = e * rr_sin(im[k] * tau);
            for (c = 0; c < cols; ++c) {
                double x = u0[c], y = u1[c];
                u0[c] = cs * x + sn * y;
                u1[c] = -sn * x + cs * y;
            }
            row += 2;
        }
    }
    (void)N2;
}

int rr_batch_monodromy(int N2, int nblk, const int *size, const double *re, const double *im, int steps, double h,
                       const int *active, int r, const double *Jp, const double *Jv, const double *Pq,
                       const double *Pv, const double *Bh, const double *Bx, double *U, double *work)
{
    int j, a, k, c, done = 0, idx = 0;
    double pending = 0.0;
    double *Cr = work, *t = Cr + (size_t)r * N2;
    for (k = 0, c = 0; k < nblk; ++k) c += size[k];
    if (c != N2) return -1;
    for (j = 0; j < steps; ++j) {
        const double *Jpj, *Jvj, *B;
        if (!active[j]) {
            pending += h;
            continue;
        }
        /* the free flow up to the middle of this step, the contact's exact exponential, then half a step */
        free_flow(N2, N2, nblk, size, re, im, pending + 0.5 * h, U);
        pending = 0.5 * h;
        Jpj = Jp + (size_t)idx * r * r;
        Jvj = Jv ? Jv + (size_t)idx * r * r : NULL;
        B = Bx ? Bx + (size_t)idx * N2 * r : Bh;
        ++idx;
        for (a = 0; a < r; ++a) { /* Cr = Jp Pq + Jv Pv (r x N2) */
            double *Ca = Cr + (size_t)a * N2;
            for (c = 0; c < N2; ++c) Ca[c] = 0.0;
            for (k = 0; k < r; ++k) {
                double x = Jpj[a * r + k], yv = Jvj ? Jvj[a * r + k] : 0.0;
                const double *pq = Pq + (size_t)k * N2, *pv = Pv + (size_t)k * N2;
                if (x != 0.0)
                    for (c = 0; c < N2; ++c) Ca[c] += x * pq[c];
                if (yv != 0.0)
                    for (c = 0; c < N2; ++c) Ca[c] += yv * pv[c];
            }
        }
        for (a = 0; a < r; ++a) { /* t = Cr U (r x N2) */
            double *ta = t + (size_t)a * N2;
            const double *Ca = Cr + (size_t)a * N2;
            for (c = 0; c < N2; ++c) ta[c] = 0.0;
            for (k = 0; k < N2; ++k) {
                double x = Ca[k];
                const double *Uk = U + (size_t)k * N2;
                if (x == 0.0) continue;
                for (c = 0; c < N2; ++c) ta[c] += x * Uk[c];
            }
        }
        for (k = 0; k < N2; ++k) { /* U += B t */
            double *Uk = U + (size_t)k * N2;
            const double *Bk = B + (size_t)k * r;
            for (a = 0; a < r; ++a) {
                double x = Bk[a];
                const double *ta = t + (size_t)a * N2;
                if (x == 0.0) continue;
                for (c = 0; c < N2; ++c) Uk[c] += x * ta[c];
            }
        }
        ++done;
    }
    free_flow(N2, N2, nblk, size, re, im, pending, U);
    return done;
}
