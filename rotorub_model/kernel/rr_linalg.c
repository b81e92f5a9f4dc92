/* rotorub kernel: dense linear algebra: LU, inverse, eigenvalues (see rotorub_kernel.h; internal declarations in rr_internal.h). */
#include "rr_internal.h"

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
