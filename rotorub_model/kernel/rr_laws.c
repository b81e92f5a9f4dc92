/* rotorub kernel: normal contact laws of one blade (see rotorub_kernel.h; internal declarations in rr_internal.h). */
#include "rr_internal.h"

/* ------------------------------------------------------------------ laws */

/* Chord law (eq. 5-8): gap(c) = zeta c + eta along c in [-l/2, l/2], pressure -(k/l) gap(c)
 * where gap(c) < 0. The integrand vanishes at the moving front c* = -eta/zeta, so the
 * derivatives with respect to (eta, zeta) come from the fixed limits alone (Leibniz). */
void rri_chord_law(double g_le, double g_te, double k, double l, double *out)
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
void rri_point_law(double g, double k, double *out)
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
        rri_chord_law(g_le, g_te, k, l, out);
    else
        rri_point_law(g_le, k, out);
}

