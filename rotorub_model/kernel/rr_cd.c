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
    rri_gaps_of(c, q, gaps);
    rri_laws_of(c, gaps, law);
    rri_friction_of(c, law, omega, NULL, q, qp, dt, fr);
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
    return done;
}
