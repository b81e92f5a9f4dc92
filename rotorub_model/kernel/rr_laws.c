/* rotorub kernel: the normal contact laws of one blade, one dispatch (see rotorub_kernel.h, "Contact laws").
 *
 * Every law here is a sum of ramps: the penalty law is one ramp F = k (-g)_+, the bilinear law adds a second
 * ramp of slope (ratio - 1) k starting at the knee penetration d, F = k (-g)_+ + (ratio - 1) k (-g - d)_+.
 * A ramp's chord integral (eq. 5-8 of the paper) is exact and closed-form, and the chord's gap is linear in
 * c whatever the law, so the bilinear chord law is the penalty chord law at (g_le, g_te) plus (ratio - 1)
 * times the penalty chord law at (g_le + d, g_te + d): forces, moments, their derivatives in (eta, zeta) and
 * the potential all add. The chord fraction in contact is the first ramp's. */
#include "rr_internal.h"

/* One ramp over the chord: gap(c) = zeta c + eta along c in [-l/2, l/2], pressure -(k/l) gap(c) where
 * gap(c) < 0. The integrand vanishes at the moving front c* = -eta/zeta, so the derivatives with respect to
 * (eta, zeta) come from the fixed limits alone (Leibniz). The potential is (k/l) int 1/2 gap(c)^2 over the
 * contact interval, expanded in the same moments d1, d2, d3 (no cancellation when zeta is small). */
static void chord_ramp(double g_le, double g_te, double k, double l, double *out)
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
    out[7] = 0.5 * s * (zeta * zeta * d3 + 2.0 * zeta * eta * d2 + eta * eta * d1);
}

/* One ramp at a point (2D): F_N = -k g where g < 0. */
static void point_ramp(double g, double k, double *out)
{
    int i;
    for (i = 0; i < RR_LAW_WIDTH; ++i) out[i] = 0.0;
    if (g >= 0.0) return;
    out[0] = -k * g;
    out[2] = -k;
    out[6] = out[0] > 0.0 ? 1.0 : 0.0;
    out[7] = 0.5 * k * g * g;
}

static void ramp(int np, double g_le, double g_te, double k, double l, double *out)
{
    if (np == 2)
        chord_ramp(g_le, g_te, k, l, out);
    else
        point_ramp(g_le, k, out);
}

void rri_blade_law(const rr_law *law, int np, double g_le, double g_te, double k, double l, double *out)
{
    ramp(np, g_le, g_te, k, l, out);
    if (law->id == RR_LAW_BILINEAR) {
        const double d = law->par[RR_BILINEAR_KNEE], a = (law->par[RR_BILINEAR_RATIO] - 1.0) * k;
        if (g_le < -d || (np == 2 && g_te < -d)) {
            double more[RR_LAW_WIDTH];
            int i;
            ramp(np, g_le + d, g_te + d, a, l, more);
            for (i = 0; i < RR_LAW_WIDTH; ++i)
                if (i != 6) out[i] += more[i];
        }
    }
}

double rri_law_max_slope(const rr_law *law)
{
    if (law->id == RR_LAW_BILINEAR && law->par[RR_BILINEAR_RATIO] > 1.0) return law->par[RR_BILINEAR_RATIO];
    return 1.0;
}

double rri_point_force(const rr_law *law, double pen, double k)
{
    double f = pen > 0.0 ? k * pen : 0.0;
    if (law->id == RR_LAW_BILINEAR && pen > law->par[RR_BILINEAR_KNEE])
        f += (law->par[RR_BILINEAR_RATIO] - 1.0) * k * (pen - law->par[RR_BILINEAR_KNEE]);
    return f;
}

int rr_law_check(const rr_law *law)
{
    if (law->id == RR_LAW_PENALTY) return 0;
    if (law->id == RR_LAW_BILINEAR)
        return law->par[RR_BILINEAR_KNEE] > 0.0 && law->par[RR_BILINEAR_RATIO] > 0.0 &&
                       law->par[RR_BILINEAR_KNEE] < HUGE_VAL && law->par[RR_BILINEAR_RATIO] < HUGE_VAL
                   ? 0
                   : -1;
    return -1;
}

void rr_blade_law(const rr_law *law, int np, double g_le, double g_te, double k, double l, double *out)
{
    rri_blade_law(law, np, g_le, g_te, k, l, out);
}

double rr_law_max_slope(const rr_law *law) { return rri_law_max_slope(law); }
