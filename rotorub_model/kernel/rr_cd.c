/* rotorub kernel: explicit central differences (see rotorub_kernel.h; internal declarations in rr_internal.h). */
#include <string.h>

#include "rr_internal.h"

/* ------------------------------------------------------------------ central differences */

/* y += K2 x - Cm1 xp for one block of rows (r x c): the order of the dense step's sums */
static void block_mv(int r, int cc, const double *restrict K2, const double *restrict Cm1, const double *restrict x,
                     const double *restrict xp, double *restrict y)
{
    int k, e;
    for (k = 0; k < r; ++k) {
        const double *K2k = K2 + (size_t)k * cc, *Cm1k = Cm1 + (size_t)k * cc;
        double acc = y[k];
        for (e = 0; e < cc; ++e) acc += K2k[e] * x[e] - Cm1k[e] * xp[e];
        y[k] = acc;
    }
}

/* y = A x (r x c) */
static void mv(int r, int cc, const double *restrict A, const double *restrict x, double *restrict y)
{
    int k, e;
    for (k = 0; k < r; ++k) {
        const double *Ak = A + (size_t)k * cc;
        double acc = 0.0;
        for (e = 0; e < cc; ++e) acc += Ak[e] * x[e];
        y[k] = acc;
    }
}

/* The step's linear part by blocks (rr_cd_blocks): every product touches a hub block, one blade's blocks or the
 * casing's, so its cost grows linearly with the blades; the solve is the Schur complement on the hub. rhs holds
 * the loads on entry; q, qp the scheme's two states (qp <- q, q <- the new state); work: m + ns doubles. */
static void block_step(const rr_cd_blocks *b, double *restrict q, double *restrict qp, double *restrict rhs,
                       double *restrict work)
{
    int j, k, ns = b->ns, nb = b->nb, m = b->m, nc = b->nc, n = ns + nb * m + nc;
    size_t hb = (size_t)ns * m, bb = (size_t)m * m;
    const double *qh = q, *qph = qp;
    double *z = work, *t = work + m;
    /* rhs += K2 q - Cm1 qp */
    block_mv(ns, ns, b->K2_hh, b->C_hh, qh, qph, rhs);
    for (j = 0; j < nb; ++j) {
        const double *qj = q + ns + (size_t)j * m, *qpj = qp + ns + (size_t)j * m;
        double *rj = rhs + ns + (size_t)j * m;
        block_mv(ns, m, b->K2_hb + j * hb, b->C_hb + j * hb, qj, qpj, rhs);
        block_mv(m, ns, b->K2_bh + j * hb, b->C_bh + j * hb, qh, qph, rj);
        block_mv(m, m, b->K2_bb + j * bb, b->C_bb + j * bb, qj, qpj, rj);
    }
    if (nc) block_mv(nc, nc, b->K2_cc, b->C_cc, q + ns + nb * m, qp + ns + nb * m, rhs + ns + nb * m);
    for (k = 0; k < n; ++k) qp[k] = q[k];
    /* A q = rhs: z_j = A_bb_j^-1 r_j; the hub from its Schur complement; the blades from z_j - W_j q_h */
    for (k = 0; k < ns; ++k) t[k] = rhs[k];
    for (j = 0; j < nb; ++j) {
        const double *Ahb = b->A_hb + j * hb;
        mv(m, m, b->Binv + j * bb, rhs + ns + (size_t)j * m, z);
        for (k = 0; k < ns; ++k) {
            const double *row = Ahb + (size_t)k * m;
            double acc = 0.0;
            int e;
            for (e = 0; e < m; ++e) acc += row[e] * z[e];
            t[k] -= acc;
        }
        for (k = 0; k < m; ++k) q[ns + (size_t)j * m + k] = z[k]; /* z_j, completed once the hub is known */
    }
    mv(ns, ns, b->Sinv, t, q);
    for (j = 0; j < nb; ++j) {
        const double *Wj = b->W + j * (size_t)m * ns;
        double *qj = q + ns + (size_t)j * m;
        for (k = 0; k < m; ++k) {
            const double *row = Wj + (size_t)k * ns;
            double acc = 0.0;
            int e;
            for (e = 0; e < ns; ++e) acc += row[e] * q[e];
            qj[k] -= acc;
        }
    }
    if (nc) mv(nc, nc, b->Cinv, rhs + ns + nb * m, q + ns + nb * m);
}

/* One step: (M/dt^2 + C/2dt) q+ = r F + F0 + F_nl(q, q') + (2M/dt^2 - K) q - (M/dt^2 - C/2dt) q-,
 * with the contact force at the current state only (explicit; q' = (q - q-)/dt for the friction),
 * from the laws and friction factors already evaluated there. The order of the sums is fixed (see
 * the header); locals and restrict let the compiler keep the matrices streaming instead of
 * reloading the structs after every store. rhs: n doubles (+ m + ns for a block step). */
void rri_cd_update(const rr_contact *c, const double *restrict law, const double *restrict fr,
                   const rr_cd_matrices *mats, double r, double *restrict q, double *restrict qp,
                   double *restrict rhs)
{
    int j, k, e, n = c->n, nb = c->nb, np = c->np, ld = rri_ld(c);
    const double *restrict f = mats->f, *restrict f0 = mats->f0;
    const double *restrict A = c->A, *restrict B = c->B, *restrict S = c->S;
    for (k = 0; k < n; ++k) rhs[k] = f0 ? r * f[k] + f0[k] : r * f[k];
    for (j = 0; j < nb; ++j) {
        const double *L = law + RR_LAW_WIDTH * j;
        const double *Aj = A + (size_t)j * ld, *Bj = B + (size_t)j * ld;
        const double *S0 = S + (size_t)j * np * ld, *S1 = S0 + (np == 2 ? ld : 0);
        const int *cols = rri_cols(c, j);
        double FN = L[0], MN = L[1], w[2], aF[2], aM[2], c0, c1;
        if (FN == 0.0 && MN == 0.0) continue; /* adds an exact zero */
        rri_point_weights(np, rri_len(c, j), FN, MN, w, aF, aM);
        c0 = fr[(size_t)j * np] * w[0];
        c1 = np == 2 ? fr[(size_t)j * np + 1] * w[1] : 0.0;
        if (cols)
            for (k = 0; k < ld; ++k) rhs[cols[k]] += Aj[k] * FN + Bj[k] * MN - (c0 * S0[k] + c1 * S1[k]);
        else
            for (k = 0; k < n; ++k) rhs[k] += Aj[k] * FN + Bj[k] * MN - (c0 * S0[k] + c1 * S1[k]);
    }
    if (mats->blocks) {
        block_step(mats->blocks, q, qp, rhs, rhs + n);
        return;
    }
    {
        const double *restrict K2 = mats->K2, *restrict Cm1 = mats->Cm1, *restrict Ainv = mats->Ainv;
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

/* The evaluation (gaps, laws, friction factors) lives in the job's cache when it has one, so nothing is copied
 * between calls: the cache holds the key and the state it was made at, checked here, and the evaluation itself,
 * which rr_cd_run writes in place. Without a cache (or on a surface that wears) it lives in the contact's scratch. */
static double *cache_evaluation(const rr_cd_job *job, const rr_contact *c)
{
    return job->cache + RR_CACHE_KEY + 2 * c->n;
}

/* whether the evaluation in the cache was made by the last call at this state with these inputs. Compared bit for
 * bit: equal bits are equal values, and a value equal in another representation (-0 for 0) only costs an evaluation */
static int cache_holds(const rr_cd_job *job, const rr_contact *c, double omega, double dt)
{
    const rr_cd_state *s = job->state;
    size_t n = (size_t)c->n;
    double key[RR_CACHE_KEY];
    const double *kc = job->cache, *qc = kc + RR_CACHE_KEY, *qpc = qc + n;
    if (!job->cache_valid) return 0;
    cache_key(s, c, omega, dt, key);
    return memcmp(key, kc, sizeof key) == 0 && memcmp(s->q, qc, n * sizeof *qc) == 0 &&
           memcmp(s->q_prev, qpc, n * sizeof *qpc) == 0;
}

/* the key and the state of the evaluation rr_cd_run left in the cache (none after a divergence) */
static void cache_keep(rr_cd_job *job, const rr_contact *c, double omega, double dt)
{
    const rr_cd_state *s = job->state;
    size_t n = (size_t)c->n;
    double *kc = job->cache, *qc = kc + RR_CACHE_KEY, *qpc = qc + n;
    job->cache_valid = 0;
    if (s->diverged) return;
    cache_key(s, c, omega, dt, kc);
    memcpy(qc, s->q, n * sizeof *qc);
    memcpy(qpc, s->q_prev, n * sizeof *qpc);
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
    const int rec_last = job->rec_every < 0; /* the call's last step only */
    double *gaps, *law, *fr, *rhs = c->work + 2 * rows + nb * RR_LAW_WIDTH;
    double *q = s->q, *qp = s->q_prev;
    const double t0 = s->t, dt = s->dt, floor_gap = -s->max_pen, t_ramp = job->t_ramp, me = job->me;
    const double omega = job->omega;
    const long long step0 = s->steps;
    rr_surface *sf = c->surface;
    /* the job's options in locals: read once, not after every store into the records (they may alias) */
    const int stop_on_contact = job->stop_on_contact, rec_cap = job->rec_cap;
    const int rec_wear_every = job->rec_wear_every < 1 ? 1 : job->rec_wear_every;
    double *const rec_wear = sf ? job->rec_wear : NULL, *const rec_q = job->rec_q, *const rec_out = job->rec_out;
    /* a surface that wears changes between calls without a key to say so: its evaluation is never kept */
    const int cached = job->cache != NULL && !(sf && sf->wears);
    int open = 1;
    job->done = 0;
    if (s->diverged) return 0;
    gaps = cached ? cache_evaluation(job, c) : c->work;
    law = gaps + rows;
    fr = law + nb * RR_LAW_WIDTH;
    if (sf) sf->phi = s->phi; /* the surface is read, and cut, at the state's angle */
    if (sf && sf->wears && rri_surface_inputs_changed(sf)) {
        /* the engine's inputs changed since the last cut (or none yet): the return map sees the new surface
         * before the first force, so a jump while cutting keeps the force at the yield bound (the liner's law
         * is then exact whatever the inputs do between calls, not only for slow changes) */
        rri_surface_recut(c, q, gaps); /* (a surface that wears: no evaluation kept, see `cached`) */
    }
    if (!(cached && cache_holds(job, c, omega, dt))) {
        rri_gaps_of(c, q, gaps);
        rri_laws_of(c, gaps, law);
        rri_friction_of(c, law, omega, NULL, q, qp, dt, fr);
    }
    if (stop_on_contact)
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
        rri_cd_update(c, law, fr, m, r * me, q, qp, rhs);
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
            int m, p, ns = sf->n_sectors, nr = rri_n_rows(c);
            double *dst = rec_wear + (size_t)job->n_rec_wear * ns;
            for (m = 0; m < ns; ++m) {
                double w = 0.0;
                for (p = 0; p < nr; ++p) w += sf->depth[(size_t)p * ns + m];
                dst[m] = w / nr;
            }
            ++job->n_rec_wear;
        }
        if (written < rec_cap && (rec_last ? i + 1 == job->n_steps : (step0 + i + 1) % rec_every == 0)) {
            for (k = 0; k < n; ++k) rec_q[(size_t)written * n + k] = q[k];
            if (rec_out)
                rri_outputs_from_law(c, q, gaps, law, fr, 0.0, NULL,
                                     rec_out + (size_t)written * RR_N_OUT(rri_nb_out(c)));
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
    if (cached)
        cache_keep(job, c, omega, dt);
    else
        job->cache_valid = 0;
    return done;
}

/* ------------------------------------------------------------------ the scheme's matrices and step limit */

void rr_k_omega(int n, const double *K0, const double *S2, const double *N2, const double *C1, const double *S4,
                double omega, double *out)
{
    size_t i, nn = (size_t)n * n;
    double ww = omega * omega, w4 = ww * ww;
    for (i = 0; i < nn; ++i) out[i] = K0[i] + ww * (S2[i] + N2[i]) + omega * C1[i];
    if (S4) /* an imported blade's prestress beyond the quadratic (FE stiffness at several speeds) */
        for (i = 0; i < nn; ++i) out[i] += w4 * S4[i];
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
                const double *N2, const double *S2, const double *E1, const double *S4, double omega,
                double omega_dot, double dt, double *Ainv, double *K2, double *Cm1, double *work, int *piv)
{
    size_t i, nn = (size_t)n * n;
    double dt2 = dt * dt, ww = omega * omega, two_dt = 2.0 * dt;
    double *Aeff = work + nn;
    for (i = 0; i < nn; ++i) {
        double C = D[i] + omega * G1[i];
        double K = K0[i] + ww * (S2[i] + N2[i]) + omega * C1[i];
        if (E1) K = K + omega_dot * E1[i];
        if (S4) K = K + omega * omega * (omega * omega) * S4[i];
        Aeff[i] = M[i] / dt2 + C / two_dt;
        K2[i] = 2.0 * M[i] / dt2 - K;
        Cm1[i] = M[i] / dt2 - C / two_dt;
    }
    return rr_inverse(n, Aeff, Ainv, work, piv);
}

/* ------------------------------------------------------------------ the step's matrices by blocks */

int rr_cd_blocks_size(int ns, int nb, int m, int nc)
{
    size_t hb = (size_t)ns * m, bb = (size_t)m * m;
    /* K2 and Cm1 blocks, A_hb, Binv, W, Sinv, Cinv */
    return (int)(2 * ((size_t)ns * ns + 2 * nb * hb + nb * bb + (size_t)nc * nc) + nb * hb + nb * bb + nb * hb +
                 (size_t)ns * ns + (size_t)nc * nc);
}

int rr_cd_blocks_work_size(int ns, int m, int nc)
{
    int big = ns > m ? ns : m;
    if (nc > big) big = nc;
    return 3 * big * big + ns * m;
}

/* one entry of the three step matrices at (i, j) of the dense model matrices, in rr_cd_build's arithmetic */
static void step_entry(size_t i, const double *M, const double *D, const double *K0, const double *G1, const double *C1,
                       const double *N2, const double *S2, const double *E1, const double *S4, double omega,
                       double omega_dot, double dt2, double two_dt, double *a, double *k2, double *cm1)
{
    double C = D[i] + omega * G1[i];
    double K = K0[i] + omega * omega * (S2[i] + N2[i]) + omega * C1[i];
    if (E1) K = K + omega_dot * E1[i];
    if (S4) K = K + omega * omega * (omega * omega) * S4[i];
    *a = M[i] / dt2 + C / two_dt;
    *k2 = 2.0 * M[i] / dt2 - K;
    *cm1 = M[i] / dt2 - C / two_dt;
}

int rr_cd_build_blocks(int n, int ns, int nb, int m, int nc, const double *M, const double *D, const double *K0,
                       const double *G1, const double *C1, const double *N2, const double *S2, const double *E1,
                       const double *S4, double omega, double omega_dot, double dt, double *store, rr_cd_blocks *b,
                       double *work, int *piv)
{
    size_t hb = (size_t)ns * m, bb = (size_t)m * m, off = 0;
    double dt2 = dt * dt, two_dt = 2.0 * dt;
    double *Ahh, *Abb, *Abh, *tmp;
    int i, j, k, e, big = ns > m ? ns : m;
    if (nc > big) big = nc;
    if (ns + nb * m + nc != n || ns < 1 || nb < 1 || m < 1 || nc < 0) return -1;
    b->ns = ns;
    b->nb = nb;
    b->m = m;
    b->nc = nc;
#define RR_TAKE(field, count) (b->field = store + off, off += (count))
    RR_TAKE(K2_hh, (size_t)ns * ns);
    RR_TAKE(K2_hb, nb * hb);
    RR_TAKE(K2_bh, nb * hb);
    RR_TAKE(K2_bb, nb * bb);
    RR_TAKE(K2_cc, (size_t)nc * nc);
    RR_TAKE(C_hh, (size_t)ns * ns);
    RR_TAKE(C_hb, nb * hb);
    RR_TAKE(C_bh, nb * hb);
    RR_TAKE(C_bb, nb * bb);
    RR_TAKE(C_cc, (size_t)nc * nc);
    RR_TAKE(A_hb, nb * hb);
    RR_TAKE(Binv, nb * bb);
    RR_TAKE(W, nb * hb);
    RR_TAKE(Sinv, (size_t)ns * ns);
    RR_TAKE(Cinv, (size_t)nc * nc);
#undef RR_TAKE
    /* work: A_hh (big^2), a blade's A_bb, A_bh (big^2 each) and the inverse's scratch (big^2) */
    Ahh = work;
    Abb = Ahh + (size_t)big * big;
    Abh = Abb + (size_t)big * big;
    tmp = Abh + (size_t)ns * m;
    for (i = 0; i < ns; ++i)
        for (k = 0; k < ns; ++k) {
            size_t at = (size_t)i * n + k;
            step_entry(at, M, D, K0, G1, C1, N2, S2, E1, S4, omega, omega_dot, dt2, two_dt, Ahh + (size_t)i * ns + k,
                       (double *)b->K2_hh + (size_t)i * ns + k, (double *)b->C_hh + (size_t)i * ns + k);
        }
    for (j = 0; j < nb; ++j) {
        int j0 = ns + j * m;
        double *k2hb = (double *)b->K2_hb + j * hb, *chb = (double *)b->C_hb + j * hb, *ahb = (double *)b->A_hb + j * hb;
        double *k2bh = (double *)b->K2_bh + j * hb, *cbh = (double *)b->C_bh + j * hb;
        double *k2bb = (double *)b->K2_bb + j * bb, *cbb = (double *)b->C_bb + j * bb;
        double *Bj = (double *)b->Binv + j * bb, *Wj = (double *)b->W + j * hb;
        for (i = 0; i < ns; ++i)
            for (k = 0; k < m; ++k) {
                step_entry((size_t)i * n + j0 + k, M, D, K0, G1, C1, N2, S2, E1, S4, omega, omega_dot, dt2, two_dt,
                           ahb + (size_t)i * m + k, k2hb + (size_t)i * m + k, chb + (size_t)i * m + k);
                step_entry((size_t)(j0 + k) * n + i, M, D, K0, G1, C1, N2, S2, E1, S4, omega, omega_dot, dt2, two_dt,
                           Abh + (size_t)k * ns + i, k2bh + (size_t)k * ns + i, cbh + (size_t)k * ns + i);
            }
        for (i = 0; i < m; ++i)
            for (k = 0; k < m; ++k)
                step_entry((size_t)(j0 + i) * n + j0 + k, M, D, K0, G1, C1, N2, S2, E1, S4, omega, omega_dot, dt2,
                           two_dt, Abb + (size_t)i * m + k, k2bb + (size_t)i * m + k, cbb + (size_t)i * m + k);
        if (rr_inverse(m, Abb, Bj, tmp, piv) != 0) return -1;
        /* W_j = A_bb^-1 A_bh (m x ns); A_hh -= A_hb W_j */
        for (i = 0; i < m; ++i)
            for (k = 0; k < ns; ++k) {
                double s = 0.0;
                for (e = 0; e < m; ++e) s += Bj[(size_t)i * m + e] * Abh[(size_t)e * ns + k];
                Wj[(size_t)i * ns + k] = s;
            }
        for (i = 0; i < ns; ++i)
            for (k = 0; k < ns; ++k) {
                double s = 0.0;
                for (e = 0; e < m; ++e) s += ahb[(size_t)i * m + e] * Wj[(size_t)e * ns + k];
                Ahh[(size_t)i * ns + k] -= s;
            }
    }
    if (rr_inverse(ns, Ahh, (double *)b->Sinv, tmp, piv) != 0) return -1;
    if (nc > 0) {
        int c0 = ns + nb * m;
        for (i = 0; i < nc; ++i)
            for (k = 0; k < nc; ++k)
                step_entry((size_t)(c0 + i) * n + c0 + k, M, D, K0, G1, C1, N2, S2, E1, S4, omega, omega_dot, dt2,
                           two_dt, Abb + (size_t)i * nc + k, (double *)b->K2_cc + (size_t)i * nc + k,
                           (double *)b->C_cc + (size_t)i * nc + k);
        if (rr_inverse(nc, Abb, (double *)b->Cinv, tmp, piv) != 0) return -1;
    }
    return 0;
}
