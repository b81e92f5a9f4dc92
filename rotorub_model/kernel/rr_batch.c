/* rotorub kernel: batch evaluation for the harmonic balance (declarations and contract in rr_batch.h). */
#include "rr_batch.h"

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
