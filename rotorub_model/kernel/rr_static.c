/* rotorub kernel: balanced static solutions (Newton) (see rotorub_kernel.h; internal declarations in rr_internal.h). */
#include "rr_internal.h"

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
                /* -dF_nl/dq with every blade in full contact (at the law's largest slope) */
                rr_closed_stiffness(c, omega, Kc);
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
