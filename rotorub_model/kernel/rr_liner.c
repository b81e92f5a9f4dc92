/* rotorub kernel: the casing surface: abradable liner, clearance closure, casing offset (see rotorub_kernel.h; internal declarations in rr_internal.h). */
#include "rr_internal.h"

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

double rri_liner_law(double g, double k, double fy, double h, double thickness, int wears, double *depth,
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
    return rri_liner_law(g, k, fy, h, thickness, wears, depth, work);
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
void rri_surface_apply(const rr_contact *c, double *gaps)
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
void rri_surface_cut(const rr_contact *c, const double *gaps, double phi_new)
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
                rri_liner_law(gc, kp, fy, hp, s->thickness, 1, row + cell, &work);
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
