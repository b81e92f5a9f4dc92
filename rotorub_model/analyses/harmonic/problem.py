"""The harmonic-balance residual of the rub response and its exact Jacobian, condensed on the contact coordinates.

Equations (rotating frame, docs/THEORY.md section 3): M q'' + (D + G(Omega)) q' + K(Omega) q = F_nl(q, q'; Omega,
phi) + F(Omega^2), F_nl the kernel's contact force at frame angle phi = Omega t (the casing surface, fixed in the
other frame: :mod:`.surface`). A periodic response of fundamental w (forced: w = Omega; autonomous: unknown),
q(t) = sum_k Re(Q_k e^{i k w t}), balances harmonic by harmonic:

    Z_k Q_k = F_k + F_nl,k,     Z_k = K(Omega) - (k w)^2 M + i k w (D + G(Omega)),    k = 0..H.

**Condensation (exact).** The kernel's force depends on q only through the gaps G q and on q' only through the
sliding rows S q', and it lies in the span of the rows of [G; S; A; B] (docs/THEORY.md section 4: Q = A^T F_N +
B^T M_N - sum_p mu s_p w_p S_p^T). With P (r x n) an orthonormal basis of that span, F_nl = P^T f(y, y') with
y = P q, f = P F_nl, and y' = P q'. So the unknowns are the r (2H + 1) coefficients of y (r = 6 for the
reference's 2D contact, 18 in 3D, against 38 dofs), and

    R(Y) = Y - Y_lin - L(w) f^(Y) = 0,     L_k = P Z_k^-1 P^T (the receptance of the contact coordinates),

f^ the Fourier coefficients of f at the m AFT samples (:mod:`.basis`). The full response follows as
Q_k = Z_k^-1 (F_k + P^T f_k). Nothing is approximated beyond the truncation at H harmonics and the samples.

**Jacobian (exact).** dR/dY = I - L (P_dft [J_i E_i + w Jv_i dE_i]), J_i = P (dF_nl/dq) P^T and
Jv_i = P (dF_nl/dq') P^T at sample i: the AFT of the kernel's analytic Jacobians (tested against finite
differences). The forces and the projected Jacobians at the m samples come from one kernel call
(``rr_batch_reduced``, ``kernel/rr_batch.c``: assembled blade by blade in the contact coordinates from the laws'
slopes, never as a full n x n Jacobian), each sample with its own frame angle; the AFT of the sampled Jacobian
goes through the samples' discrete harmonics k = 0..2H (``rr_batch_aft_assemble``: the product-to-sum identities
give the same sums at (2H+1) m r^2 instead of (2H+1)^2 m r^2 operations).
"""

from __future__ import annotations

import ctypes
import math
from dataclasses import dataclass

import numpy as np

from ... import kernel
from ...contact import ContactModel
from ...errors import ParameterError
from ...structure.model import Model
from .basis import HarmonicBasis
from .surface import CasingForcing

_declared = False


def _lib():
    global _declared
    lib = kernel.load()
    if not _declared:
        dp = ctypes.c_void_p
        lib.rr_batch_eval.argtypes = [ctypes.POINTER(kernel.RRContact), ctypes.c_int, dp, dp, ctypes.c_double, dp,
                                      ctypes.c_int, dp, dp, dp, dp, dp]
        lib.rr_batch_eval.restype = ctypes.c_int
        lib.rr_batch_work_size.argtypes = [ctypes.c_int, ctypes.c_int]
        lib.rr_batch_work_size.restype = ctypes.c_int
        ci = ctypes.c_int
        lib.rr_batch_reduced_work_size.argtypes = [ci, ci, ci, ci]
        lib.rr_batch_reduced_work_size.restype = ci
        lib.rr_batch_reduced.argtypes = [ctypes.POINTER(kernel.RRContact), ci, dp, dp, ctypes.c_double, dp, ci, dp,
                                         dp, dp, dp, dp]
        lib.rr_batch_reduced.restype = ci
        lib.rr_batch_laws.argtypes = [ctypes.POINTER(kernel.RRContact), ci, dp, dp, dp, dp]
        lib.rr_batch_laws.restype = None
        lib.rr_batch_aft_assemble.argtypes = [ci, ci, ci, dp, dp, dp, dp, ctypes.c_double, dp]
        lib.rr_batch_aft_assemble.restype = None
        lib.rr_batch_monodromy.argtypes = [ci, ci, dp, dp, dp, ci, ctypes.c_double, dp, ci, dp, dp, dp, dp, dp, dp,
                                           dp, dp]
        lib.rr_batch_monodromy.restype = ci
        _declared = True
    return lib


def contact_basis(contact: ContactModel, tol: float = 1e-12) -> np.ndarray:
    """P (r x n): orthonormal rows spanning [G; S; A; B], what the contact force depends on and acts along."""
    W = np.vstack(contact.dense_rows())  # an imported tip's compact rows over all dofs
    _, s, Vt = np.linalg.svd(W, full_matrices=False)
    r = int(np.sum(s > tol * s[0])) if s.size and s[0] > 0 else 0
    return np.ascontiguousarray(Vt[:r])


@dataclass
class Evaluation:
    """What one AFT evaluation gives (reduced coordinates)."""

    R: np.ndarray  # residual (N,)
    J: np.ndarray | None  # dR/dY (N, N)
    f_hat: np.ndarray  # (2H+1, r) force coefficients
    touching: int  # samples at which a blade touches
    Jp: np.ndarray | None = None  # (m, r, r) P dF/dq P^T at the samples
    Jvp: np.ndarray | None = None  # (m, r, r) P dF/dq' P^T


TRUNCATION_WARNING = 1e-2  # the highest harmonic above 1 % of the largest: too few harmonics for this contact


class HarmonicsWarning(UserWarning):
    """Too few harmonics for the contact's kinks: the highest kept harmonic still carries the response."""


def check_truncation(problem: HBProblem, Y: np.ndarray) -> str | None:
    """A stated warning (returned and issued) where the highest harmonic holds more than 1 % of the response."""
    share = problem.truncation_share(Y)
    if share <= TRUNCATION_WARNING:
        return None
    import warnings

    msg = (f"harmonics: H = {problem.H} is too few for this contact: harmonic {problem.H} still holds "
           f"{100 * share:.2g} % of the largest (the truncation error is of that order); raise the harmonic count")
    warnings.warn(msg, HarmonicsWarning, stacklevel=2)
    return msg


class KernelContact:
    """The rotor's contact force through the kernel, in the contact coordinates y = P q: the nonlinearity of the
    balance (any object with ``P``, ``g0``, ``set_clearance`` and ``batch`` serves: :mod:`.oscillator` has one in
    numpy for the independent check)."""

    def __init__(self, contact: ContactModel, forcing: CasingForcing):
        self.contact = contact
        self.P = contact_basis(contact)
        self.liner = forcing.liner(contact)
        self._view = self.liner.attach(contact.kernel) if self.liner is not None else \
            kernel.RRContact.from_buffer_copy(contact.kernel)
        self._vref = ctypes.byref(self._view)
        lib = _lib()
        self._work = np.empty(lib.rr_batch_reduced_work_size(contact.n_dofs, contact.n_segments, contact.n_points,
                                                             self.P.shape[0]))
        self.g0 = float(contact.g0)

    def set_clearance(self, g0: float) -> None:
        self.g0 = float(g0)
        self._view.g0 = self.g0

    def batch(self, y: np.ndarray, yd: np.ndarray | None, omega: float, phi: np.ndarray | None,
              jacobians: bool = True) -> tuple[np.ndarray, np.ndarray | None, np.ndarray | None, int]:
        """f (m, r), P J P^T and P Jv P^T (m, r, r) at reduced states y, y' (m, r): one kernel call."""
        m, r = y.shape
        y = np.ascontiguousarray(y, dtype=float)
        yd = None if yd is None else np.ascontiguousarray(yd, dtype=float)
        F = np.empty((m, r))
        J = np.empty((m, r, r)) if jacobians else None
        Jv = np.empty((m, r, r)) if jacobians else None
        ptr = kernel.ptr
        touching = _lib().rr_batch_reduced(self._vref, m, ptr(y), None if yd is None else ptr(yd), float(omega),
                                           None if phi is None else ptr(phi), r, ptr(self.P), ptr(F),
                                           None if J is None else ptr(J), None if Jv is None else ptr(Jv),
                                           ptr(self._work))
        return F, J, Jv, int(touching)

    def laws(self, q: np.ndarray, phi: np.ndarray | None) -> tuple[np.ndarray, np.ndarray]:
        """Gaps (m, N, P) and law values (m, N, LAW_WIDTH) of the kernel's blades at full states q (m, n), one
        kernel call (an imported tip: N its segments, :func:`.orbit.blade_normal_forces` sums them per blade)."""
        c = self.contact
        m = q.shape[0]
        q = np.ascontiguousarray(q, dtype=float)
        gaps = np.empty((m, c.n_segments, c.n_points))
        law = np.empty((m, c.n_segments, kernel.LAW_WIDTH))
        phi = None if phi is None else np.ascontiguousarray(phi, dtype=float)
        _lib().rr_batch_laws(self._vref, m, kernel.ptr(q), None if phi is None else kernel.ptr(phi),
                             kernel.ptr(gaps), kernel.ptr(law))
        return gaps, law


class HBProblem:
    """The condensed harmonic balance of one model, contact and casing surface.

    ``forcing``: the casing surface (:class:`.surface.CasingForcing`); None or round: the response is forced
    by the imbalance only (constant in the rotating frame: the static solution, or an autonomous orbit).
    ``nonlinearity``: instead of ``contact``, any force in contact coordinates (:class:`KernelContact`'s
    interface), with ``model`` any structure holding M, D, G(Omega), K_omega(Omega), force(Omega, me), n_dofs
    and M_inv (:mod:`.oscillator`'s gap oscillator: the independent check).
    """

    def __init__(self, model: Model, contact: ContactModel | None, harmonics: int, samples: int | None = None,
                 forcing: CasingForcing | None = None, me: float | None = None, external: np.ndarray | None = None,
                 nonlinearity=None):
        self.model, self.contact = model, contact
        self.basis = HarmonicBasis(harmonics, samples)
        self.forcing = forcing if forcing is not None else CasingForcing()
        self.me = model.params.imbalance.me if me is None else float(me)
        if not (math.isfinite(self.me) and self.me >= 0):
            raise ParameterError(f"me: {self.me!r} out of range; accepted range [0, inf) kg m")
        top = max(self.forcing.lobe_counts, default=0)
        if top and harmonics < top:
            raise ParameterError(f"harmonics: {harmonics} is fewer than the casing's lobe count {top}: its forcing "
                                 f"(harmonic {top} of the spin) is not represented; accepted: harmonics >= {top} "
                                 f"(>= {4 * top} for a rub: see the convergence study)")
        # an extra rotating-frame force of the response's period, (2H+1, n) real coefficients (tests, users' loads)
        self.external = None if external is None else np.asarray(external, dtype=float)
        if self.external is not None and self.external.shape != (2 * harmonics + 1, model.n_dofs):
            raise ParameterError(f"external: shape {self.external.shape}; accepted (2 H + 1, n) = "
                                 f"({2 * harmonics + 1}, {model.n_dofs})")
        if nonlinearity is None:
            if contact is None:
                raise ParameterError("contact: None; accepted: a ContactModel (or a nonlinearity in its place)")
            nonlinearity = KernelContact(contact, self.forcing)
        self.nl = nonlinearity
        self.P = np.asarray(nonlinearity.P)
        self.r = self.P.shape[0]
        self.n = model.n_dofs
        self.liner = getattr(nonlinearity, "liner", None)
        self._vref = getattr(nonlinearity, "_vref", None)
        b = self.basis
        # the discrete harmonics k = 0..2H at the samples (the AFT of a sampled Jacobian, rr_batch_aft_assemble)
        k2 = np.arange(2 * self.H + 1)
        self._cos2 = np.cos(np.outer(k2, b.tau))
        self._sin2 = np.sin(np.outer(k2, b.tau))
        self._lin_key = None

    # ------------------------------------------------------------------ parameters
    @property
    def H(self) -> int:
        return self.basis.harmonics

    @property
    def N(self) -> int:
        """Unknowns of the condensed balance: r (2H + 1)."""
        return self.r * self.basis.size

    @property
    def forced(self) -> bool:
        return not self.forcing.round

    @property
    def g0(self) -> float:
        return float(self.nl.g0)

    def set_clearance(self, g0: float) -> None:
        self.nl.set_clearance(g0)

    def linear(self, omega: float, w: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(L (H+1, r, r) complex receptances P Z_k^-1 P^T, X (H+1, n, r) = Z_k^-1 P^T, q_lin (n,) = K^-1 F)."""
        key = (float(omega), float(w), self.me)
        if self._lin_key != key:
            m = self.model
            K, C = m.K_omega(omega), m.D + m.G(omega)
            k = np.arange(self.H + 1)
            Z = K[None] - ((k * w) ** 2)[:, None, None] * m.M[None] + 1j * (k * w)[:, None, None] * C[None]
            X = np.linalg.solve(Z, np.broadcast_to(self.P.T.astype(complex), (self.H + 1, self.n, self.r)))
            L = self.P[None] @ X
            q_lin = np.linalg.solve(K, m.force(omega, self.me))
            self._ext = None
            if self.external is not None:  # its response Z_k^-1 F_k on real coefficients
                E = self.external
                Fk = np.concatenate([E[:1].astype(complex), E[1::2] - 1j * E[2::2]])
                Xe = np.linalg.solve(Z, Fk[..., None])[..., 0]
                Qe = np.empty_like(E)
                Qe[0] = Xe[0].real
                Qe[1::2], Qe[2::2] = Xe[1:].real, -Xe[1:].imag
                self._ext = Qe
            self._lin = (L, X, q_lin)
            self._Lri = (np.ascontiguousarray(L[1:].real), np.ascontiguousarray(L[1:].imag))
            self._lin_key = key
        return self._lin

    # ------------------------------------------------------------------ the AFT
    def samples(self, Y: np.ndarray, w: float) -> tuple[np.ndarray, np.ndarray]:
        """(y, y') at the samples (m, r) of coefficients Y (2H+1, r)."""
        b = self.basis
        return b.E @ Y, w * (b.dE @ Y)

    def phases(self, w: float, omega: float, tau: np.ndarray | None = None) -> np.ndarray | None:
        """The surface's frame angle at the samples: phi = Omega t, t_i = tau_i / w (None: a round casing)."""
        if not self.forced:
            return None
        tau = self.basis.tau if tau is None else tau
        return np.ascontiguousarray(tau * (omega / w))

    def kernel_batch(self, y: np.ndarray, yd: np.ndarray | None, omega: float, phi: np.ndarray | None,
                     jacobians: bool = True) -> tuple[np.ndarray, np.ndarray | None, np.ndarray | None, int]:
        """f (m, r), P J P^T, P Jv P^T (m, r, r) at reduced states y, y' (m, r)."""
        return self.nl.batch(y, yd, omega, phi, jacobians)

    def apply_L(self, L: np.ndarray, f: np.ndarray) -> np.ndarray:
        """The receptance on real coefficients f (2H+1, r, ...) -> (2H+1, r, ...)."""
        shape = f.shape
        f3 = f.reshape(shape[0], shape[1], -1)
        out = np.empty(f3.shape, dtype=float)
        out[0] = L[0].real @ f3[0]
        if self._lin_key is not None and L is self._lin[0]:
            Lr, Li = self._Lri
        else:
            Lr, Li = L[1:].real, L[1:].imag
        fc, fs = f3[1::2], f3[2::2]
        out[1::2] = Lr @ fc + Li @ fs
        out[2::2] = Lr @ fs - Li @ fc
        return out.reshape(shape)

    def aft_jacobian(self, Jp: np.ndarray, Jvp: np.ndarray | None, w: float) -> np.ndarray:
        """D ((2H+1) r, (2H+1) r): the AFT of sampled Jacobians, P_dft [J_i E_i + w Jv_i dE_i], through the
        discrete harmonics of the samples (only the samples where some blade touches contribute)."""
        b, r, H = self.basis, self.r, self.H
        Jr = Jp.reshape(b.m, r * r)
        act = np.flatnonzero(Jr.any(axis=1))
        Cj = np.ascontiguousarray(self._cos2[:, act] @ Jr[act])
        Sj = np.ascontiguousarray(self._sin2[:, act] @ Jr[act])
        Cv = Sv = None
        if Jvp is not None:
            Jv = Jvp.reshape(b.m, r * r)
            actv = np.flatnonzero(Jv.any(axis=1))
            if actv.size:
                Cv = np.ascontiguousarray(self._cos2[:, actv] @ Jv[actv])
                Sv = np.ascontiguousarray(self._sin2[:, actv] @ Jv[actv])
        D = np.empty((b.size * r, b.size * r))
        ptr = kernel.ptr
        _lib().rr_batch_aft_assemble(H, r, b.m, ptr(Cj), ptr(Sj), None if Cv is None else ptr(Cv),
                                     None if Sv is None else ptr(Sv), float(w), ptr(D))
        return D

    def evaluate(self, Y: np.ndarray, omega: float, w: float, jacobian: bool = True) -> Evaluation:
        """Residual (and Jacobian) at coefficients Y (N,) for spin omega and fundamental w."""
        b, r = self.basis, self.r
        nh = b.size
        Yc = Y.reshape(nh, r)
        y, yd = self.samples(Yc, w)
        F, Jp, Jvp, touching = self.kernel_batch(y, yd, omega, self.phases(w, omega), jacobian)
        L, _, q_lin = self.linear(omega, w)
        f_hat = b.P @ F
        R = Yc - self.apply_L(L, f_hat)
        R[0] -= self.P @ q_lin
        if self._ext is not None:
            R -= self._ext @ self.P.T
        Jac = None
        if jacobian:
            if touching:
                D = self.aft_jacobian(Jp, Jvp, w).reshape(nh, r, nh * r)
                Jac = np.eye(self.N) - self.apply_L(L, D).reshape(self.N, self.N)
            else:
                Jac = np.eye(self.N)
        return Evaluation(R.ravel(), Jac, f_hat, touching, Jp, Jvp)

    # ------------------------------------------------------------------ the linear start and the full response
    def linear_start(self, omega: float, w: float) -> np.ndarray:
        """Y of the response without contact (the imbalance's static deflection)."""
        _, _, q_lin = self.linear(omega, w)
        Y = np.zeros((self.basis.size, self.r))
        Y[0] = self.P @ q_lin
        if self._ext is not None:
            Y += self._ext @ self.P.T
        return Y.ravel()

    def full(self, Y: np.ndarray, omega: float, w: float, f_hat: np.ndarray | None = None) -> np.ndarray:
        """Q (2H+1, n): the coefficients of every dof, Q_k = Z_k^-1 (F_k + P^T f_k)."""
        if f_hat is None:
            f_hat = self.evaluate(Y, omega, w, jacobian=False).f_hat
        _, X, q_lin = self.linear(omega, w)
        nh = self.basis.size
        Q = np.empty((nh, self.n))
        Q[0] = q_lin + X[0].real @ f_hat[0]
        fc, fs = f_hat[1::2], f_hat[2::2]
        Xr, Xi = X[1:].real, X[1:].imag
        ein = "knv,kv->kn"
        Q[1::2] = np.einsum(ein, Xr, fc) + np.einsum(ein, Xi, fs)
        Q[2::2] = np.einsum(ein, Xr, fs) - np.einsum(ein, Xi, fc)
        if self._ext is not None:
            Q += self._ext
        return Q

    def truncation_share(self, Y: np.ndarray) -> float:
        """The highest kept harmonic's amplitude over the largest oscillating one (contact coordinates): what
        the truncation leaves out is of this order or below."""
        a = self.basis.amplitudes(Y.reshape(self.basis.size, self.r))[1:]
        top = float(np.linalg.norm(a, axis=1).max())
        return float(np.linalg.norm(a[-1])) / top if top > 0 else 0.0


def frequency_derivative(problem: HBProblem, Y: np.ndarray, omega: float, w: float) -> np.ndarray:
    """dR/dw at fixed Y and Omega (an autonomous orbit's frequency is an unknown): central differences, step
    1e-6 w (R is smooth in w: the receptances and the samples' velocities; error ~1e-12 relative)."""
    h = 1e-6 * abs(w)
    Rp = problem.evaluate(Y, omega, w + h, jacobian=False).R
    Rm = problem.evaluate(Y, omega, w - h, jacobian=False).R
    return (Rp - Rm) / (2 * h)


@dataclass
class NewtonResult:
    Y: np.ndarray
    converged: bool
    iterations: int
    residual: float  # |R| / scale
    evaluation: Evaluation | None


def newton(problem: HBProblem, Y0: np.ndarray, omega: float, w: float, tol: float = 1e-10,
           max_iter: int = 40) -> NewtonResult:
    """Newton with a backtracking line search on |R| at fixed (Omega, w, g0)."""
    Y = np.array(Y0, dtype=float)
    scale = max(float(np.linalg.norm(problem.linear_start(omega, w))), abs(problem.g0), 1e-9)
    ev = problem.evaluate(Y, omega, w)
    res = float(np.linalg.norm(ev.R)) / scale
    for it in range(1, max_iter + 1):
        if res <= tol:
            return NewtonResult(Y, True, it - 1, res, ev)
        try:
            dY = np.linalg.solve(ev.J, -ev.R)
        except np.linalg.LinAlgError:
            return NewtonResult(Y, False, it, res, ev)
        lam = 1.0
        while lam > 1e-4:
            Yn = Y + lam * dY
            evn = problem.evaluate(Yn, omega, w)
            resn = float(np.linalg.norm(evn.R)) / scale
            if np.isfinite(resn) and resn < (1 - 1e-4 * lam) * res:
                break
            lam *= 0.5
        else:
            return NewtonResult(Y, False, it, res, ev)
        Y, ev, res = Yn, evn, resn
    return NewtonResult(Y, res <= tol, max_iter, res, ev)
