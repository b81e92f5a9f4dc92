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

/* The same in the contact coordinates themselves, without the full Jacobians (their projection assembled blade by
 * blade, from the law's slopes: rr_jacobian's rows and columns projected on P): at each of the m reduced states
 * (y, yd: m x r; yd NULL: q' = 0) q = P^T y, q' = P^T yd, the surface at phi[i]: F (m x r) = P F_nl,
 * J, Jv (m x r x r, either NULL) = P (dF/dq) P^T, P (dF/dq') P^T. work: rr_batch_reduced_work_size doubles.
 * Returns the number of states at which some blade touches. */
RR_API int rr_batch_reduced_work_size(int n, int nb, int np, int r);
RR_API int rr_batch_reduced(const rr_contact *c, int m, const double *y, const double *yd, double omega,
                            const double *phi, int r, const double *P, double *F, double *J, double *Jv, double *work);

/* Gaps (m x nb*np) and per-blade law values (m x nb x RR_LAW_WIDTH) at m full states Q (m x n), the surface at
 * phi[i] (phi NULL: its own angle; restored after the call). */
RR_API void rr_batch_laws(const rr_contact *c, int m, const double *Q, const double *phi, double *gaps, double *law);

/* The AFT of a sampled Jacobian, D[a, u, b, v] = sum_i Pdft[a, i] (J_i[u, v] E[i, b] + w Jv_i[u, v] dE[i, b])
 * on the stacked basis (1, cos tau, sin tau, ..., cos H tau, sin H tau), Pdft the m-sample transform (weights
 * 1/m, 2/m), from the discrete harmonics of the samples Cj[k] = sum_i cos(k tau_i) J_i, Sj[k] = sum_i
 * sin(k tau_i) J_i, k = 0..2H (each r x r; Cv, Sv the same of Jv, or NULL) by the product-to-sum identities: the
 * same sums as the sample-by-sample product, at (2H+1) m r^2 instead of (2H+1)^2 m r^2. D: (2H+1) r x (2H+1) r. */
RR_API void rr_batch_aft_assemble(int H, int r, int m, const double *Cj, const double *Sj, const double *Cv,
                                  const double *Sv, double w, double *D);

/* The monodromy of z' = (A0 + B Cr(t)) z by Strang splitting on `steps` steps of h, in A0's real modal form
 * (nblk blocks of size 1 or 2: a real eigenvalue re, or the pair re +- i im acting on two rows as
 * e^{re t} [[cos im t, sin im t], [-sin im t, cos im t]]). At an active step j (active[j] != 0; the idx-th
 * active one) Cr = Jp_idx Pq + Jv_idx Pv (Jp, Jv: one r x r per active step, Jv may be NULL; Pq, Pv: r x N2) and
 * the contact's exponential is I + B Cr with B = Bh (N2 x r: h B), or Bx_idx (N2 x r per active step: h B
 * phi1(h Cr B), where Jv makes Cr B non-zero). U (N2 x N2, row-major) is propagated in place: pass I for the
 * monodromy. work: 2 r N2 doubles. Returns the number of active steps, or -1 if the blocks do not fill N2. */
RR_API int rr_batch_monodromy(int N2, int nblk, const int *size, const double *re, const double *im, int steps,
                              double h, const int *active, int r, const double *Jp, const double *Jv, const double *Pq,
                              const double *Pv, const double *Bh, const double *Bx, double *U, double *work);

#ifdef __cplusplus
}
#endif
#endif
