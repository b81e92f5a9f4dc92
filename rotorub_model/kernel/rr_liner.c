/* rotorub kernel: the casing surface: abradable liner, clearance closure, casing offset and distortion (see
 * rotorub_kernel.h; internal declarations in rr_internal.h). */
#include "rr_internal.h"

/* ------------------------------------------------------------------ abradable liner */

#define RR_TWO_PI 6.283185307179586476925286766559

#if RR_MAX_LOBES > RR_WEAR_HARMONICS
#error "the cut reads the lobes' cos/sin at the cells from the profile's harmonic tables"
#endif
#define RR_N_INPUTS (3 + 2 * (RR_MAX_LOBES + 1))

/* tables: angle, cos, sin of each point's rest angle; radial part of its normal; cos, sin (h th_c) of the cells'
 * centres, h = 1..RR_WEAR_HARMONICS; cos, sin (n a) of each point's rest angle, n = 2..RR_MAX_LOBES */
int rr_surface_table_size(int nb, int np, int n_sectors)
{
    return 4 * nb * np + 2 * RR_WEAR_HARMONICS * n_sectors + 2 * (RR_MAX_LOBES - 1) * nb * np;
}

static void inputs_of(const rr_surface *s, double *v)
{
    int n;
    v[0] = s->closure;
    v[1] = s->offset_x;
    v[2] = s->offset_y;
    for (n = 0; n <= RR_MAX_LOBES; ++n) {
        v[3 + 2 * n] = s->lobe_amp[n];
        v[4 + 2 * n] = s->lobe_phase[n];
    }
}

int rri_surface_inputs_changed(const rr_surface *s)
{
    double v[RR_N_INPUTS];
    int i;
    inputs_of(s, v);
    for (i = 0; i < RR_N_INPUTS; ++i)
        if (!(v[i] == s->cut_inputs[i])) return 1; /* NaN (never cut) counts as changed */
    return 0;
}

/* the largest radial distance the offset and the lobes move the surface by (an upper bound) */
static double reach_of(const rr_surface *s)
{
    double r = rr_sqrt(s->offset_x * s->offset_x + s->offset_y * s->offset_y);
    int n;
    for (n = 2; n <= RR_MAX_LOBES; ++n) r += rr_fabs(s->lobe_amp[n]);
    return r;
}

static int has_lobes(const rr_surface *s)
{
    int n;
    for (n = 2; n <= RR_MAX_LOBES; ++n)
        if (s->lobe_amp[n] != 0.0) return 1;
    return 0;
}

int rr_surface_init(const rr_contact *c, rr_surface *s)
{
    int k, h, m, rows = c->nb * c->np, ns = s->n_sectors;
    double *a0, *ca, *sa, *nr, *bc, *bs;
    if (!(ns >= 8 && ns <= 1000000) || !(s->yield_force > 0.0) || !(s->hardening >= 0.0) || !(s->thickness > 0.0) ||
        !(s->work_weight > 0.0) ||
        !(s->closure == s->closure) || !(s->offset_x == s->offset_x) || !(s->offset_y == s->offset_y) ||
        !s->tables || !s->depth)
        return -1;
    for (h = 0; h <= RR_MAX_LOBES; ++h)
        if (!(rr_fabs(s->lobe_amp[h]) < HUGE_VAL) || !(rr_fabs(s->lobe_phase[h]) < HUGE_VAL) ||
            (h < 2 && s->lobe_amp[h] != 0.0))
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
    {
        double *lc = bs + RR_WEAR_HARMONICS * ns, *ls = lc + (RR_MAX_LOBES - 1) * rows;
        for (h = 2; h <= RR_MAX_LOBES; ++h)
            for (k = 0; k < rows; ++k) {
                double a = h * rr_atan2(c->points[3 * k + 1], c->points[3 * k]);
                lc[(h - 2) * rows + k] = rr_cos(a);
                ls[(h - 2) * rows + k] = rr_sin(a);
            }
    }
    for (k = 0; k < RR_N_INPUTS; ++k) s->cut_inputs[k] = 0.0 / 0.0; /* never cut: the first run cuts first */
    return 0;
}

double rri_liner_law(const rr_law *law, double g, double k, double fy, double h, double thickness, int wears,
                     double *depth, double *work)
{
    double w = *depth, p = -(g + w), f, dw;
    if (!(p > 0.0)) return 0.0;
    f = rri_point_force(law, p, k);
    if (wears && f > fy + h * w && w < thickness) {
        /* the penetration x = p - dw left after the cut has law(x) = fy + h (w + p - x): the law rises, the bound
         * falls, one root; the laws are piecewise linear, so on the piece the root lies on it is exact */
        dw = (k * p - fy - h * w) / (k + h); /* the root on the first piece (the penalty law's only one) */
        if (law->id == RR_LAW_BILINEAR) {
            const double d = law->par[RR_BILINEAR_KNEE], rho = law->par[RR_BILINEAR_RATIO];
            if (p > d && k * d < fy + h * (w + p - d)) /* the root lies beyond the knee */
                dw = (k * d + rho * k * (p - d) - fy - h * w) / (rho * k + h);
        }
        if (w + dw > thickness) dw = thickness - w;
        *work += (fy + h * (w + 0.5 * dw)) * dw; /* the integral of F_y + H w over the removed depth */
        *depth = w + dw;
        f = rri_point_force(law, p - dw, k);
    }
    return f;
}

double rr_liner_law(const rr_law *law, double g, double k, double fy, double h, double thickness, int wears,
                    double *depth, double *work)
{
    return rri_liner_law(law, g, k, fy, h, thickness, wears, depth, work);
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

/* raw gaps -> gaps to the surface at frame angle s->phi; with_depth 0: to the unworn surface under the inputs
 * (closure, offset, lobes at each point's own angle) */
static void surface_shift(const rr_contact *c, double *gaps, int with_depth)
{
    const rr_surface *s = c->surface;
    int k, np = c->np, rows = c->nb * np, ns = s->n_sectors;
    const double *a0 = s->tables, *ca = a0 + rows, *sa = ca + rows, *nr = sa + rows;
    const double *lc = a0 + 4 * rows + 2 * RR_WEAR_HARMONICS * ns, *ls = lc + (RR_MAX_LOBES - 1) * rows;
    const int offset = s->offset_x != 0.0 || s->offset_y != 0.0, lobes = has_lobes(s);
    const double cp = offset ? rr_cos(s->phi) : 1.0, sp = offset ? rr_sin(s->phi) : 0.0;
    const rr_turn turn = turn_of(s->phi, ns);
    double lA[RR_MAX_LOBES + 1], lB[RR_MAX_LOBES + 1];
    int n;
    /* a_n cos(n (a + phi - psi_n)) = cos(n a) A_n - sin(n a) B_n, A_n + i B_n = a_n e^{i n (phi - psi_n)} */
    if (lobes)
        for (n = 2; n <= RR_MAX_LOBES; ++n) {
            double x = n * (s->phi - s->lobe_phase[n]);
            lA[n] = s->lobe_amp[n] == 0.0 ? 0.0 : s->lobe_amp[n] * rr_cos(x);
            lB[n] = s->lobe_amp[n] == 0.0 ? 0.0 : s->lobe_amp[n] * rr_sin(x);
        }
    for (k = 0; k < rows; ++k) {
        double extra = (with_depth ? s->depth[(size_t)rri_row(c, k) * ns + cell_at(a0[k], turn, ns)] : 0.0) -
                       s->closure;
        if (offset) {
            double ct = ca[k] * cp - sa[k] * sp, st = sa[k] * cp + ca[k] * sp;
            extra += nr[k] * (s->offset_x * ct + s->offset_y * st);
        }
        if (lobes) {
            double r = 0.0;
            for (n = 2; n <= RR_MAX_LOBES; ++n)
                r += lc[(n - 2) * rows + k] * lA[n] - ls[(n - 2) * rows + k] * lB[n];
            extra += nr[k] * r;
        }
        gaps[k] += extra;
    }
}

void rri_surface_apply(const rr_contact *c, double *gaps) { surface_shift(c, gaps, 1); }

/* The time loop's cut: every cell a contact point swept from the surface's angle to phi_new, at the
 * point's raw gap (the state at phi_new); then the surface is at phi_new. */
void rri_surface_cut(const rr_contact *c, const double *gaps, double phi_new)
{
    rr_surface *s = c->surface;
    int k, j, np = c->np, rows = c->nb * np, ns = s->n_sectors;
    const double *a0 = s->tables, *nr = a0 + 3 * rows, *bc = a0 + 4 * rows, *bs = bc + RR_WEAR_HARMONICS * ns;
    const double half = np == 2 ? 0.5 : 1.0; /* 3D: each end carries half the chord */
    const double reach = reach_of(s);
    const int offset = s->offset_x != 0.0 || s->offset_y != 0.0, lobes = has_lobes(s);
    double lC[RR_MAX_LOBES + 1], lS[RR_MAX_LOBES + 1];
    int n;
    /* a_n cos(n (th_c - psi_n)) at a cell's centre th_c = cos(n th_c) C_n + sin(n th_c) S_n */
    if (lobes)
        for (n = 2; n <= RR_MAX_LOBES; ++n) {
            lC[n] = s->lobe_amp[n] == 0.0 ? 0.0 : s->lobe_amp[n] * rr_cos(n * s->lobe_phase[n]);
            lS[n] = s->lobe_amp[n] == 0.0 ? 0.0 : s->lobe_amp[n] * rr_sin(n * s->lobe_phase[n]);
        }
    const rr_turn turn0 = turn_of(s->phi, ns), turn1 = turn_of(phi_new, ns);
    const double turns = (phi_new - s->phi) * (ns / RR_TWO_PI);
    for (k = 0; k < rows; ++k) {
        double g = gaps[k] - s->closure, share = c->point_share ? c->point_share[k] : half;
        double kp = share * c->k_r, fy = share * s->yield_force, hp = share * s->hardening;
        int c0, c1, count, step;
        double *row = s->depth + (size_t)rri_row(c, k) * ns;
        if (share == 0.0) continue;                /* a station's second point: cut as its twin */
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
            if (lobes) {
                double r = 0.0;
                for (n = 2; n <= RR_MAX_LOBES; ++n)
                    r += bc[(n - 1) * ns + cell] * lC[n] + bs[(n - 1) * ns + cell] * lS[n];
                gc += nr[k] * r;
            }
            if (gc + row[cell] < 0.0 && rri_point_force(&c->law, -(gc + row[cell]), kp) > fy + hp * row[cell]) {
                double work = 0.0;
                rri_liner_law(&c->law, gc, kp, fy, hp, s->thickness, 1, row + cell, &work);
                s->plastic_work += s->work_weight * work;
                s->changed = 1;
            }
        }
    }
    s->phi = phi_new;
}

void rri_surface_recut(const rr_contact *c, const double *q, double *gaps)
{
    /* the surface does not turn: every point cuts the cell it is in, at its gap to the unworn surface under the
     * new inputs taken at the point's own angle (the gap its next force sees, so that force is the bound exactly;
     * the time loop's sweep takes the inputs at the cells' centres, where it does not know the points' angles) */
    rr_surface *s = c->surface;
    int k, np = c->np, rows = c->nb * np, ns = s->n_sectors;
    const double half = np == 2 ? 0.5 : 1.0; /* 3D: each end carries half the chord */
    const rr_turn turn = turn_of(s->phi, ns);
    rri_raw_gaps(c, q, gaps);
    surface_shift(c, gaps, 0);
    for (k = 0; k < rows; ++k) {
        double share = c->point_share ? c->point_share[k] : half;
        double kp = share * c->k_r, fy = share * s->yield_force, hp = share * s->hardening;
        double *w = s->depth + (size_t)rri_row(c, k) * ns + cell_at(s->tables[k], turn, ns);
        if (share == 0.0) continue; /* a station's second point: cut as its twin */
        if (gaps[k] + *w < 0.0 && rri_point_force(&c->law, -(gaps[k] + *w), kp) > fy + hp * *w) {
            double work = 0.0;
            rri_liner_law(&c->law, gaps[k], kp, fy, hp, s->thickness, 1, w, &work);
            s->plastic_work += s->work_weight * work;
            s->changed = 1;
        }
    }
    inputs_of(s, s->cut_inputs);
}

void rr_surface_summary(const rr_contact *c, const rr_surface *s, double area_per_sector, double *out)
{
    int m, h, p, np = rri_n_rows(c), ns = s->n_sectors, rows = c->nb * c->np;
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
    /* the lobe rule (rotorub_kernel.h): worn evenly (every harmonic below RR_LOBE_UNIFORM of the mean depth: a
     * 360-degree rub, a synchronous whirl's) has no lobes, not the harmonic that round-off and the rub's start
     * leave largest; else the largest harmonic h dominates when it is RR_LOBE_DOMINANCE times every harmonic
     * that is not one of its multiples (an h-lobed profile that is not a sinusoid has harmonics 2h, 3h too) */
    {
        double other = 0.0;
        for (h = 0; h < RR_WEAR_HARMONICS && lobes > 0; ++h)
            if ((h + 1) % lobes != 0 && out[RR_WEAR_AMP + h] > other) other = out[RR_WEAR_AMP + h];
        out[RR_WEAR_LOBES] = best > 1e-15 && best >= RR_LOBE_UNIFORM * out[RR_WEAR_MEAN] &&
                                     best >= RR_LOBE_DOMINANCE * other
                                 ? (double)lobes
                                 : 0.0;
    }
}
