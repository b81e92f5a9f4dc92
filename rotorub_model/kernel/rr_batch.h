/*
 * rotorub kernel, batch evaluation for the harmonic balance (rr_batch.c): the contact force and its two
 * Jacobians at m states in one call, each state with its own frame angle (the casing surface, fixed in the
 * other frame, is seen at phi_i by the state at time t_i), optionally projected on a reduced basis.
 */
#ifndef RR_BATCH_H
#define RR_BATCH_H

#include "rotorub_kernel.h"

#ifdef __cplusplus
extern "C" {
#endif

/* At each of the m states (Q, Qdot: m x n row-major; Qdot NULL: q' = 0), the surface (if the contact has one)
 * at frame angle phi[i] (phi NULL: the surface's own angle), spin omega:
 *   P == NULL: F (m x n) = F_nl, J and Jv (m x n x n, either NULL: not computed) = dF_nl/dq, dF_nl/dq';
 *   P != NULL (r x n, orthonormal rows): F (m x r) = P F_nl, J, Jv (m x r x r) = P (dF/dq) P^T, P (dF/dq') P^T.
 * work: 2 n n + r n doubles (rr_batch_work_size). The surface's angle is restored after the call. Returns the
 * number of states at which some blade touches, or -1 if P is given for a model of more than 512 dofs. */
RR_API int rr_batch_work_size(int n, int r);
RR_API int rr_batch_eval(const rr_contact *c, int m, const double *Q, const double *Qdot, double omega,
                         const double *phi, int r, const double *P, double *F, double *J, double *Jv, double *work);

#ifdef __cplusplus
}
#endif
#endif
