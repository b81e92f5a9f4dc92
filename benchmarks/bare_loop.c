/* The bare reference of benchmarks/bench_transient.py: the same central-difference step as
 * rr_cd_advance (three dense mat-vecs + the contact law of every blade and its projection),
 * with nothing else: no records, no outputs, no divergence check, no ramp. It includes the
 * kernel's source so the physics (and its arithmetic) is the kernel's own. */
#include "rotorub_kernel.c"

RR_API void bare_cd(const rr_contact *c, const rr_cd_matrices *m, double *q, double *qp, int n_steps, double me)
{
    int i, nb = c->nb, rows = nb * c->np;
    double *gaps = c->work, *law = c->work + rows, *rhs = law + nb * RR_LAW_WIDTH;
    for (i = 0; i < n_steps; ++i) {
        gaps_of(c, q, gaps);
        laws_of(c, gaps, law);
        cd_update(c->n, nb, law, c->A, c->B, c->C, c->D, c->mu, m->Ainv, m->K2, m->Cm1, m->f, me, q, qp, rhs);
    }
}
