"""Reduction of a clamped FE blade from its sparse matrices, and what each reduction allows an explicit scheme.

The root is clamped to the disk (its rigid motion is in the kinematics), so the natural basis is the
blade's fixed-interface modes: the cantilever's lowest modes, found by shift-invert Lanczos
(``scipy.sparse.linalg.eigsh`` with sigma = 0 on one sparse LU factorization of K), as many as lie below a
frequency cut-off. The tip nodes, where the casing touches, are interior dofs of that basis. What the modes
miss at the tip is the static flexibility of the modes left out, the residual flexibility

    G = E^T (K^-1 - V (V^T K V)^-1 V^T) E        (E: unit loads at the tip dofs, V: the kept basis),

which the massless-boundary idea (MacNeal's residual flexibility kept without its mass; Monjaraz-Tec, Gross
& Krack, Computers & Structures 260 (2022) 106698) puts in series with the contact, so that the tip carries
no fictitious mass and the step stays that of the kept modes and of the contact.

Variants measured by :func:`compare_reductions` (step, accuracy, cost):

* ``modal``: fixed-interface modes at rest below the cut-off;
* ``two-speed``: the modes at rest and at the top speed below the cut-off, orthonormalised (the built-in
  blades' choice, structure/blades.py);
* ``craig-bampton``: Craig-Bampton with the tip nodes' three translations as boundary dofs: modes with the
  tip fixed, plus one static constraint mode a tip dof (mass-carrying: stiff);
* ``residual-attachment``: modes plus the residual attachment modes of the tip dofs, with their mass;
* ``massless-boundary``: modes plus the tip's residual flexibility in series with the contact, massless;
* ``condensed``: the modes at rest carry the mass, and what the modes at the top speed add to their span is
  condensed statically into K(Omega) (massless): the prestressed blade's modes hold small, stiff components
  (15-40 kHz Rayleigh quotients on the example blade) that the rest modes lack, however many (35 modes to
  4 kHz still 15 % off at the top speed on one mode); with their mass they set the step (``two-speed``: 27 kHz),
  without it they only relax K(Omega); ``condensed+massless-boundary`` adds the tip's residual flexibility.

The explicit (central difference) step each allows is 2 / omega_max of the reduced blade with the contact
stiffness k_r spread over the tip nodes along their radial direction (the casing's normal).
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as sla
from scipy.linalg import eigh

from ..errors import FEImportError

TWO_PI = 2.0 * np.pi


@dataclass
class Factor:
    """One sparse LU factorization of a symmetric matrix, with its inertia (count of negative pivots)."""

    lu: object
    n: int
    negative: int

    def solve(self, b: np.ndarray) -> np.ndarray:
        return self.lu.solve(np.asarray(b, dtype=float))

    def operator(self) -> sla.LinearOperator:
        return sla.LinearOperator((self.n, self.n), matvec=self.solve, dtype=float)


def factorize(K: sp.spmatrix, where: str, check_inertia: bool = True) -> Factor:
    """LU of K with diagonal pivots in symmetric mode: the signs of U's diagonal are K's inertia (Sylvester),
    so an indefinite stiffness is told without any eigen-solve."""
    K = sp.csc_matrix(K)
    try:
        lu = sla.splu(K, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                      options={"SymmetricMode": True})
    except RuntimeError as exc:
        raise FEImportError(f"{where}: the stiffness is singular ({exc}): the blade has rigid-body modes or "
                            "mechanisms (is the root clamped? are all elements connected?)") from None
    d = lu.U.diagonal()
    neg = int(np.sum(d < 0))
    if check_inertia and neg:
        raise FEImportError(f"{where}: the stiffness is indefinite ({neg} negative pivots of {K.shape[0]}): not a "
                            "stable structure's stiffness (a buckled prestress, a sign error, or a matrix that is "
                            "not a stiffness)")
    return Factor(lu=lu, n=K.shape[0], negative=neg)


def lowest_modes(K: sp.spmatrix, M: sp.spmatrix, factor: Factor, cutoff_hz: float, at_least: int = 1,
                 at_most: int = 400) -> tuple[np.ndarray, np.ndarray]:
    """(omega [rad/s], Phi M-orthonormal) of every mode below ``cutoff_hz`` (at least ``at_least``), by
    shift-invert Lanczos about 0 with the given factorization."""
    n = K.shape[0]
    # massless dofs (a beam's rotations with lumped masses) carry no mode: the Lanczos space stays below their count
    n_eff = min(n, int(np.count_nonzero(M.diagonal())))
    top = max(1, min(at_most, n_eff - 2, n - 2))
    k = min(max(at_least, 24), top)  # one Lanczos run for the usual cut-offs (each restart costs one)
    op = factor.operator()
    while True:
        try:
            lam, V = sla.eigsh(K, k=k, M=M, sigma=0.0, OPinv=op, which="LM", tol=1e-10,
                               ncv=min(n_eff, max(2 * k + 1, 20)))
        except (sla.ArpackError, sla.ArpackNoConvergence) as exc:
            raise FEImportError(f"eigenvalues: the Lanczos iteration failed ({str(exc).splitlines()[0][:120]}): "
                                "is the mass matrix positive semi-definite, with mass on the blade's "
                                "translations?") from None
        order = np.argsort(lam)
        lam, V = lam[order], V[:, order]
        if lam[0] <= 0:
            raise FEImportError(f"eigenvalues: {lam[0]:.3g} (rad/s)^2 <= 0: mass or stiffness is not positive "
                                "definite (a negative or zero mass, or rigid-body modes)")
        w = np.sqrt(lam)
        if w[-1] > TWO_PI * cutoff_hz or k >= top:
            break
        k = min(2 * k, top)
    keep = max(at_least, int(np.sum(w <= TWO_PI * cutoff_hz)))
    return w[:keep], V[:, :keep]


def orthonormal_basis(cols: list[np.ndarray], M: sp.spmatrix, tol: float = 1e-8) -> np.ndarray:
    """An M-orthonormal basis of the span of the columns, dropping directions below ``tol`` (relative)."""
    V = np.hstack(cols)
    G = V.T @ (M @ V)
    lam, U = np.linalg.eigh(0.5 * (G + G.T))
    keep = lam > tol * lam.max()
    return V @ (U[:, keep] / np.sqrt(lam[keep]))


def modes_in_basis(V: np.ndarray, K: sp.spmatrix, M: sp.spmatrix) -> tuple[np.ndarray, np.ndarray]:
    """The reduced eigenproblem on V: (omega, basis combinations z, M-normalised)."""
    Kr, Mr = V.T @ (K @ V), V.T @ (M @ V)
    lam, z = eigh(0.5 * (Kr + Kr.T), 0.5 * (Mr + Mr.T))
    return np.sqrt(np.clip(lam, 0.0, None)), z


def mac(A: np.ndarray, B: np.ndarray, M: sp.spmatrix) -> np.ndarray:
    """Mass-weighted modal assurance criterion between the columns of A and B."""
    AB = A.T @ (M @ B)
    aa = np.einsum("ij,ij->j", A, M @ A)
    bb = np.einsum("ij,ij->j", B, M @ B)
    return AB**2 / np.outer(aa, bb)


def residual_flexibility(factor: Factor, K: sp.spmatrix, V: np.ndarray, rows: np.ndarray) -> np.ndarray:
    """G (len(rows) x len(rows)) [m/N]: the static flexibility at ``rows`` that the basis V does not hold."""
    n = K.shape[0]
    E = np.zeros((n, rows.size))
    E[rows, np.arange(rows.size)] = 1.0
    F = np.column_stack([factor.solve(E[:, i]) for i in range(rows.size)])
    Kr = V.T @ (K @ V)
    Vt = V[rows]
    G = F[rows] - Vt @ np.linalg.solve(Kr, Vt.T)
    return 0.5 * (G + G.T)


def contact_stiffness(T: np.ndarray, normals: np.ndarray, k_r: float, G: np.ndarray | None = None) -> np.ndarray:
    """Reduced stiffness of the contact, k_r spread over the tip nodes along their normals.

    ``T`` (n_t, 3, m): tip displacement per reduced dof; ``normals`` (n_t, 3). With ``G`` (3 n_t x 3 n_t, the
    tip's massless residual flexibility) the contact springs act through it: k_eff = (G_nn + 1/k)^-1."""
    nt = T.shape[0]
    Tn = np.einsum("ia,iam->im", normals, T)
    k = k_r / nt
    if G is None:
        return k * Tn.T @ Tn
    Nmat = np.zeros((nt, 3 * nt))
    for i in range(nt):
        Nmat[i, 3 * i:3 * i + 3] = normals[i]
    Gnn = Nmat @ G @ Nmat.T
    return Tn.T @ np.linalg.solve(Gnn + np.eye(nt) / k, Tn)


def explicit_step(Kr: np.ndarray, Mr: np.ndarray) -> tuple[float, float]:
    """(2 / omega_max [s], f_max [Hz]) of the reduced matrices (central differences, undamped)."""
    lam = eigh(0.5 * (Kr + Kr.T), 0.5 * (Mr + Mr.T), eigvals_only=True)
    wmax = float(np.sqrt(lam.max()))
    return 2.0 / wmax, wmax / TWO_PI


@dataclass
class Variant:
    name: str
    dofs: int
    step: float  # [s] 2 / omega_max with contact, at the top speed (the stiffest)
    f_max: float  # [Hz] the highest frequency then
    step_free: float  # [s] without contact, at the top speed
    freq_error_rest: float  # worst relative error of the compared modes at rest
    freq_error_top: float  # same at the top speed
    mac_min: float  # smallest diagonal MAC of the compared modes (rest and top)
    tip_compliance_error: float  # relative error of the mean radial tip compliance at rest
    seconds: float  # cost of building the basis and its matrices (after the shared factorizations and modes)

    def as_dict(self) -> dict:
        return dict(self.__dict__)


def compare_reductions(K0, Ktop, M, cutoff_hz: float, tip_rows: np.ndarray, normals: np.ndarray, k_r: float,
                       n_compare: int, factor0: Factor | None = None, factor_top: Factor | None = None,
                       rest=None, top=None) -> tuple[list[Variant], dict]:
    """Measure the variants on one blade (free dofs; ``tip_rows`` (n_t, 3) the tip nodes' x, y, z rows, all
    free; ``normals`` (n_t, 3) their contact normals in the file's axes). Returns the variants and the full
    model's reference frequencies."""
    f0 = factor0 or factorize(K0, "stiffness at rest")
    ft = factor_top or factorize(Ktop, "stiffness at the top speed")
    w0, P0 = rest or lowest_modes(K0, M, f0, cutoff_hz, at_least=n_compare)
    wt, Pt = top or lowest_modes(Ktop, M, ft, cutoff_hz, at_least=n_compare)
    nc = min(n_compare, w0.size, wt.size)
    ref = {"rest_hz": w0[:nc] / TWO_PI, "top_hz": wt[:nc] / TWO_PI}
    nt = tip_rows.shape[0]
    flat = tip_rows.reshape(-1)
    # the full model's mean radial tip compliance: unit total load spread over the tip nodes, radially
    load = np.zeros(K0.shape[0])
    for i in range(nt):
        load[tip_rows[i]] += normals[i] / nt
    u = f0.solve(load)
    c_full = float(sum(normals[i] @ u[tip_rows[i]] for i in range(nt)) / nt)

    def measure(name, V, t0, massless=False, Kt_red=None):
        Mr = V.T @ (M @ V)
        Kr0 = V.T @ (K0 @ V)
        Krt = V.T @ (Ktop @ V) if Kt_red is None else Kt_red
        T = V[flat].reshape(nt, 3, -1)
        G = residual_flexibility(f0, K0, V, flat) if massless else None
        seconds = time.perf_counter() - t0
        step, fmax = explicit_step(Krt + contact_stiffness(T, normals, k_r, G), Mr)
        step_free, _ = explicit_step(Krt, Mr)
        wr0, z0 = eigh(0.5 * (Kr0 + Kr0.T), 0.5 * (Mr + Mr.T))
        wrt, zt = eigh(0.5 * (Krt + Krt.T), 0.5 * (Mr + Mr.T))
        wr0, wrt = np.sqrt(np.clip(wr0, 0, None)), np.sqrt(np.clip(wrt, 0, None))
        m = min(nc, wr0.size)
        e0 = np.max(np.abs(wr0[:m] / w0[:m] - 1.0))
        et = np.max(np.abs(wrt[:m] / wt[:m] - 1.0))
        macs = np.concatenate([np.diag(mac(P0[:, :m], V @ z0[:, :m], M)), np.diag(mac(Pt[:, :m], V @ zt[:, :m], M))])
        ur = V @ np.linalg.solve(Kr0, V.T @ load)
        if G is not None:
            ur = ur.copy()
            ur[flat] += G @ load[flat]
        c_red = float(sum(normals[i] @ ur[tip_rows[i]] for i in range(nt)) / nt)
        return Variant(name, V.shape[1], step, fmax, step_free, float(e0), float(et), float(macs.min()),
                       float(c_red / c_full - 1.0), seconds)

    out = [measure("modal", P0, time.perf_counter())]
    out.append(measure("massless-boundary", P0, time.perf_counter(), massless=True))
    t = time.perf_counter()
    Cm = complement(Pt, P0, M)
    out.append(measure("condensed", P0, t, Kt_red=condensed(P0, Cm, Ktop)))
    t = time.perf_counter()
    Cm = complement(Pt, P0, M)
    out.append(measure("condensed+massless-boundary", P0, t, massless=True, Kt_red=condensed(P0, Cm, Ktop)))
    t = time.perf_counter()
    out.append(measure("two-speed", orthonormal_basis([P0, Pt], M), t))
    t = time.perf_counter()
    n = K0.shape[0]
    E = np.zeros((n, flat.size))
    E[flat, np.arange(flat.size)] = 1.0
    F = np.column_stack([f0.solve(E[:, i]) for i in range(flat.size)])
    F -= P0 @ (P0.T @ (M @ F))  # residual attachment modes: M-orthogonal to the kept modes, with their mass
    F /= np.sqrt(np.einsum("ij,ij->j", F, M @ F))
    out.append(measure("residual-attachment", orthonormal_basis([P0, F], M, tol=1e-12), t))
    t = time.perf_counter()
    inner = np.setdiff1d(np.arange(n), flat)
    K0c = sp.csr_matrix(K0)
    Kii = K0c[inner][:, inner]
    Mii = sp.csr_matrix(M)[inner][:, inner]
    fi = factorize(Kii, "stiffness with the tip fixed")
    wi, Pi = lowest_modes(Kii, Mii, fi, cutoff_hz, at_least=max(1, w0.size))
    Kib = K0c[inner][:, flat].toarray()
    Psi = -np.column_stack([fi.solve(Kib[:, i]) for i in range(flat.size)])
    Vcb = np.zeros((n, wi.size + flat.size))
    Vcb[inner, :wi.size] = Pi
    Vcb[inner, wi.size:] = Psi
    Vcb[flat, wi.size + np.arange(flat.size)] = 1.0
    out.append(measure("craig-bampton", Vcb, t))
    return out, ref


def complement(P: np.ndarray, V: np.ndarray, M) -> np.ndarray:
    """An M-orthonormal basis of what the columns of P add to span(V) (V M-orthogonal columns)."""
    MV = M @ V
    C = P - V @ np.linalg.solve(V.T @ MV, MV.T @ P)
    C = C / np.sqrt(np.einsum("ij,ij->j", C, M @ C))  # scale first: the added parts are small in mass
    return orthonormal_basis([C], M, tol=1e-10)


def condensed(V: np.ndarray, C: np.ndarray, K) -> np.ndarray:
    """K on span(V) with the directions C condensed statically (massless): K_VV - K_VC K_CC^-1 K_CV."""
    KV, KC = K @ V, K @ C
    Kvc = V.T @ KC
    return V.T @ KV - Kvc @ np.linalg.solve(C.T @ KC, Kvc.T)
