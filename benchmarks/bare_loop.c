/* The bare reference of benchmarks/bench_transient.py: the same central-difference step as
 * rr_cd_run (three dense mat-vecs + the contact law of every blade, its friction from the
 * sliding velocity, and its projection), with nothing else: no records, no outputs, no
 * divergence check, no ramp. It is compiled with the kernel's sources (its internal functions are
 * the kernel's own: the physics and its arithmetic are the kernel's). */
#include "rr_internal.h"

RR_API void bare_cd(const rr_contact *c, const rr_cd_matrices *m, double *q, double *qp, double dt, double omega,
                    int n_steps, double me)
{
    int i, nb = c->nb, rows = nb * c->np;
    double *gaps = c->work, *law = gaps + rows, *fr = law + nb * RR_LAW_WIDTH, *rhs = fr + rows;
    for (i = 0; i < n_steps; ++i) {
        rri_gaps_of(c, q, gaps);
        rri_laws_of(c, gaps, law);
        rri_friction_of(c, law, omega, NULL, q, qp, dt, fr);
        rri_cd_update(c, law, fr, m, me, q, qp, rhs);
    }
}
