/* rotorub kernel: explicit central differences (see rotorub_kernel.h; internal declarations in rr_internal.h). */
#include "rr_internal.h"

/* ------------------------------------------------------------------ central differences */

/* One step: (M/dt^2 + C/2dt) q+ = r F + F0 + F_nl(q, q') + (2M/dt^2 - K) q - (M/dt^2 - C/2dt) q-,
 * with the contact force at the current state only (explicit; q' = (q - q-)/dt for the friction),
 * from the laws and friction factors already evaluated there. The order of the sums is fixed (see
 * the header); locals and restrict let the compiler keep the matrices streaming instead of
 * reloading the structs after every store. */
void rri_cd_update(int n, int nb, int np, double l, const double *restrict law, const double *restrict fr,
                      const double *restrict A, const double *restrict B, const double *restrict S,
                      const double *restrict Ainv, const double *restrict K2, const double *restrict Cm1,
                      const double *restrict f, const double *restrict f0, double r, double *restrict q,
                      double *restrict qp, double *restrict rhs)
{
    int j, k, e;
    for (k = 0; k < n; ++k) rhs[k] = f0 ? r * f[k] + f0[k] : r * f[k];
    for (j = 0; j < nb; ++j) {
        const double *L = law + RR_LAW_WIDTH * j;
        const double *Aj = A + (size_t)j * n, *Bj = B + (size_t)j * n;
        const double *S0 = S + (size_t)j * np * n, *S1 = S0 + (np == 2 ? n : 0);
        double FN = L[0], MN = L[1], w[2], aF[2], aM[2], c0, c1;
        if (FN == 0.0 && MN == 0.0) continue; /* adds an exact zero */
        rri_point_weights(np, l, FN, MN, w, aF, aM);
        c0 = fr[(size_t)j * np] * w[0];
        c1 = np == 2 ? fr[(size_t)j * np + 1] * w[1] : 0.0;
        for (k = 0; k < n; ++k) rhs[k] += Aj[k] * FN + Bj[k] * MN - (c0 * S0[k] + c1 * S1[k]);
    }
    for (k = 0; k < n; ++k) {
        const double *K2k = K2 + (size_t)k * n, *Cm1k = Cm1 + (size_t)k * n;
        double acc = rhs[k];
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

/* ------------------------------------------------------------------ the contact evaluation kept between calls */
/* key: omega, dt, the contact's scalars and law, whether a surface is seen and, for a fixed one, its angle and
 * inputs; then q, q_prev and the evaluation (gaps, laws, friction factors) */
#define RR_CACHE_KEY (8 + RR_LAW_PARAMS + 2 + 3 + 2 * (RR_MAX_LOBES + 1))

int rr_cd_cache_size(int n, int nb, int np) { return RR_CACHE_KEY + 2 * n + 2 * nb * np + nb * RR_LAW_WIDTH; }

static void cache_key(const rr_cd_state *s, const rr_contact *c, double omega, double dt, double *key)
{
    const rr_surface *sf = c->surface;
    int i, k = 0;
    key[k++] = omega;
    key[k++] = dt;
    key[k++] = c->g0;
    key[k++] = c->k_r;
    key[k++] = c->mu;
    key[k++] = c->v_slip;
    key[k++] = c->chord;
    key[k++] = (double)c->law.id;
    for (i = 0; i < RR_LAW_PARAMS; ++i) key[k++] = c->law.par[i];
    key[k++] = sf ? 1.0 : 0.0;
    key[k++] = sf ? s->phi : 0.0;
    key[k++] = sf ? sf->closure : 0.0;
    key[k++] = sf ? sf->offset_x : 0.0;
    key[k++] = sf ? sf->offset_y : 0.0;
    for (i = 0; i <= RR_MAX_LOBES; ++i) {
        key[k++] = sf ? sf->lobe_amp[i] : 0.0;
        key[k++] = sf ? sf->lobe_phase[i] : 0.0;
    }
}

/* the evaluation kept by the last call, if it was made at this state with these inputs: into gaps, law, fr */
static int cache_take(rr_cd_job *job, const rr_contact *c, double omega, double dt, double *gaps, double *law,
                      double *fr)
{
    const rr_cd_state *s = job->state;
    int i, n = c->n, rows = c->nb * c->np, nl = c->nb * RR_LAW_WIDTH;
    double key[RR_CACHE_KEY];
    const double *kc = job->cache, *qc, *qpc, *g, *L, *f;
    if (!kc || !job->cache_valid || (c->surface && c->surface->wears)) return 0;
    qc = kc + RR_CACHE_KEY;
    qpc = qc + n;
    g = qpc + n;
    L = g + rows;
    f = L + nl;
    cache_key(s, c, omega, dt, key);
    for (i = 0; i < RR_CACHE_KEY; ++i)
        if (!(key[i] == kc[i])) return 0;
    for (i = 0; i < n; ++i)
        if (!(s->q[i] == qc[i]) || !(s->q_prev[i] == qpc[i])) return 0;
    for (i = 0; i < rows; ++i) gaps[i] = g[i];
    for (i = 0; i < nl; ++i) law[i] = L[i];
    for (i = 0; i < rows; ++i) fr[i] = f[i];
    return 1;
}

static void cache_keep(rr_cd_job *job, const rr_contact *c, double omega, double dt, const double *gaps,
                       const double *law, const double *fr)
{
    const rr_cd_state *s = job->state;
    int i, n = c->n, rows = c->nb * c->np, nl = c->nb * RR_LAW_WIDTH;
    double *kc = job->cache, *qc, *qpc, *g, *L, *f;
    job->cache_valid = 0;
    if (!kc || (c->surface && c->surface->wears) || s->diverged) return;
    qc = kc + RR_CACHE_KEY;
    qpc = qc + n;
    g = qpc + n;
    L = g + rows;
    f = L + nl;
    cache_key(s, c, omega, dt, kc);
    for (i = 0; i < n; ++i) {
        qc[i] = s->q[i];
        qpc[i] = s->q_prev[i];
    }
    for (i = 0; i < rows; ++i) g[i] = gaps[i];
    for (i = 0; i < nl; ++i) L[i] = law[i];
    for (i = 0; i < rows; ++i) f[i] = fr[i];
    job->cache_valid = 1;
}

/* The law and the friction are evaluated once per state: at the end of a step they serve both the
 * record of the new state and the next step's contact force. */
int rr_cd_run(rr_cd_job *job)
{
    rr_cd_state *s = job->state;
    const rr_contact *c = job->contact;
    const rr_cd_matrices *m = job->mats;
    int i, k, n = c->n, nb = c->nb, rows = nb * c->np;
    int done = 0, written = job->n_rec, rec_every = job->rec_every < 1 ? 1 : job->rec_every;
    double *gaps = c->work, *law = gaps + rows, *fr = law + nb * RR_LAW_WIDTH, *rhs = fr + rows;
    double *q = s->q, *qp = s->q_prev;
    const double t0 = s->t, dt = s->dt, floor_gap = -s->max_pen, t_ramp = job->t_ramp, me = job->me;
    const double omega = job->omega;
    const long long step0 = s->steps;
    rr_surface *sf = c->surface;
    /* the job's options in locals: read once, not after every store into the records (they may alias) */
    const int stop_on_contact = job->stop_on_contact, rec_cap = job->rec_cap;
    const int rec_wear_every = job->rec_wear_every < 1 ? 1 : job->rec_wear_every;
    double *const rec_wear = sf ? job->rec_wear : NULL, *const rec_q = job->rec_q, *const rec_out = job->rec_out;
    int open = 1;
    job->done = 0;
    if (s->diverged) return 0;
    if (sf) sf->phi = s->phi; /* the surface is read, and cut, at the state's angle */
    if (sf && sf->wears && rri_surface_inputs_changed(sf)) {
        /* the engine's inputs changed since the last cut (or none yet): the return map sees the new surface
         * before the first force, so a jump while cutting keeps the force at the yield bound (the liner's law
         * is then exact whatever the inputs do between calls, not only for slow changes) */
        rri_surface_recut(c, q, gaps);
        job->cache_valid = 0;
    }
    if (!cache_take(job, c, omega, dt, gaps, law, fr)) {
        rri_gaps_of(c, q, gaps);
        rri_laws_of(c, gaps, law);
        rri_friction_of(c, law, omega, NULL, q, qp, dt, fr);
    }
    for (k = 0; k < rows; ++k)
        if (gaps[k] < 0.0) open = 0;
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
        rri_cd_update(n, nb, c->np, c->chord, law, fr, c->A, c->B, c->S, m->Ainv, m->K2, m->Cm1, m->f, m->f0, r * me,
                  q, qp, rhs);
        ++done;
        if (sf) {
            double phi_new = s->phi + (i + 1) * dt * omega; /* as s->phi at the end of the job */
            rri_raw_gaps(c, q, gaps);
            if (sf->wears)
                rri_surface_cut(c, gaps, phi_new);
            else
                sf->phi = phi_new;
            rri_surface_apply(c, gaps);
        } else {
            rri_gaps_of(c, q, gaps);
        }
        rri_laws_of(c, gaps, law);
        rri_friction_of(c, law, omega, NULL, q, qp, dt, fr);
        if (rec_wear && (step0 + i + 1) % rec_wear_every == 0 && job->n_rec_wear < job->rec_wear_cap) {
            int m, p, ns = sf->n_sectors, np = c->np;
            double *dst = rec_wear + (size_t)job->n_rec_wear * ns;
            for (m = 0; m < ns; ++m) {
                double w = 0.0;
                for (p = 0; p < np; ++p) w += sf->depth[(size_t)p * ns + m];
                dst[m] = w / np;
            }
            ++job->n_rec_wear;
        }
        if ((step0 + i + 1) % rec_every == 0 && written < rec_cap) {
            for (k = 0; k < n; ++k) rec_q[(size_t)written * n + k] = q[k];
            if (rec_out) rri_outputs_from_law(c, q, gaps, law, fr, 0.0, NULL, rec_out + (size_t)written * RR_N_OUT(nb));
            ++written;
        }
        if (stop_on_contact) {
            int was_open = open;
            open = 1;
            for (k = 0; k < rows; ++k)
                if (gaps[k] < 0.0) open = 0;
            if (was_open && !open) break;
        }
    }
    if (!s->diverged) { /* the state the last substep reached counts too: a step ends inside the limit or diverged */
        for (k = 0; k < rows; ++k)
            if (!(gaps[k] > floor_gap)) s->diverged = 1;
    }
    s->steps += done;
    s->t += done * dt;
    s->phi += done * dt * omega;
    job->n_rec = written;
    job->done = done;
    if (job->out_dest) rri_outputs_from_law(c, q, gaps, law, fr, s->phi, job->out_index, job->out_dest);
    cache_keep(job, c, omega, dt, gaps, law, fr);
    return done;
}

/* ------------------------------------------------------------------ the scheme's matrices and step limit */

void rr_k_omega(int n, const double *K0, const double *S2, const double *N2, const double *C1, double omega,
                double *out)
{
    size_t i, nn = (size_t)n * n;
    double ww = omega * omega;
    for (i = 0; i < nn; ++i) out[i] = K0[i] + ww * (S2[i] + N2[i]) + omega * C1[i];
}

int rr_critical_step_work_size(int n) { return 2 * n * n + 3 * n; }

double rr_critical_step(const rr_contact *c, double omega, const double *Minv, const double *Kw, double *work)
{
    int n = c->n, i, j, k;
    size_t nn = (size_t)n * n;
    double *Kc = work, *P = work + nn, *wr = P + nn, *wi = wr + n, *ework = wi + n, big = 0.0;
    rr_closed_stiffness(c, omega, Kc);
    for (i = 0; i < (int)nn; ++i) Kc[i] = Kw[i] + Kc[i];
    for (i = 0; i < n; ++i)
        for (j = 0; j < n; ++j) {
            double s = 0.0;
            for (k = 0; k < n; ++k) s += Minv[(size_t)i * n + k] * Kc[(size_t)k * n + j];
            P[(size_t)i * n + j] = s;
        }
    if (rr_eigenvalues(n, P, wr, wi, ework) != 0) return -1.0;
    for (i = 0; i < n; ++i) {
        double a = rr_sqrt(wr[i] * wr[i] + wi[i] * wi[i]);
        if (a > big) big = a;
    }
    return 2.0 / rr_sqrt(big);
}

int rr_cd_build(int n, const double *M, const double *D, const double *K0, const double *G1, const double *C1,
                   const double *N2, const double *S2, const double *E1, double omega, double omega_dot, double dt,
                   double *Ainv, double *K2, double *Cm1, double *work, int *piv)
{
    size_t i, nn = (size_t)n * n;
    double dt2 = dt * dt, ww = omega * omega, two_dt = 2.0 * dt;
    double *Aeff = work + nn;
    for (i = 0; i < nn; ++i) {
        double C = D[i] + omega * G1[i];
        double K = K0[i] + ww * (S2[i] + N2[i]) + omega * C1[i];
        if (E1) K = K + omega_dot * E1[i];
        Aeff[i] = M[i] / dt2 + C / two_dt;
        K2[i] = 2.0 * M[i] / dt2 - K;
        Cm1[i] = M[i] / dt2 - C / two_dt;
    }
    return rr_inverse(n, Aeff, Ainv, work, piv);
}
