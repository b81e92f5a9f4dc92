"""Exact periodic solutions of piecewise-linear rub models: the harmonic balance's independent reference.

A structure with unilateral springs (a gap oscillator; the reference's 2D formulation, whose point law is a
penalty F_N = k_r (-g)_+ on affine gaps and whose friction is saturated Coulomb at the tip speeds) is linear
between contact events:

    M q'' + C q' + K q = f0 + Re(sum_l F_l e^{i nu_l t}) + sum_{j in S} k_j (-g_j(t)) D_j,
    g_j(t) = g0_j + W_j q + Re(sum_l c_jl e^{i nu_l t})                               (j in S: touching),

so within a contact set S the state x = (q, q') follows x(t) = x_p(t) + V e^{Lambda (t - t0)} V^-1 (x(t0) -
x_p(t0)), A_S = V Lambda V^-1 its first-order matrix and x_p the particular response (constant plus one complex
harmonic per frequency nu_l) — in closed form, no time step. An event is where a gap changes sign: located on a
fine grid of the closed form and refined by Brent's method to round-off. The force is continuous across an event
(the spring enters at zero force), so the flow's derivative needs no saltation: the monodromy is the product of
the sets' exponentials over their intervals, exact. Periodic solutions by Newton shooting on it: forced (period
2 pi / nu given) or autonomous (the period unknown, a Poincare section q'_k(0) = 0).

Nothing here shares code with the harmonic balance: no Fourier series, no AFT, no kernel call (the 2D builder
reads the contact's geometry rows and checks its own forces against the kernel's).

Examples
--------
>>> osc = gap_oscillator()
>>> orb = osc.shoot_forced(osc.nu[0], np.zeros(2 * osc.n))
>>> bool(orb.converged), bool(orb.events > 0)
(True, True)
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import brentq

from ...contact import ContactModel
from ...errors import ParameterError
from ...structure.model import Model
from .surface import CasingForcing

GRID_PER_PERIOD = 1024  # event search: a gap's sign on this grid of a period, then Brent to round-off


@dataclass
class _Set:
    """One contact set's closed form."""

    lam: np.ndarray  # (2n,) eigenvalues of A_S
    V: np.ndarray  # (2n, 2n) eigenvectors
    Vinv: np.ndarray
    xc: np.ndarray  # (2n,) constant particular response
    xh: np.ndarray  # (2n, L) complex harmonic particular responses
    A: np.ndarray  # (2n, 2n) first-order matrix
    b: np.ndarray  # (2n,) constant input
    bh: np.ndarray  # (2n, L) harmonic inputs
    WV: np.ndarray  # (s, 2n) the gaps' modal rows W V_q
    gc: np.ndarray  # (s,) the gaps' constant part g0 + W xc_q
    gh: np.ndarray  # (s, L) their harmonic part W xh_q + c


@dataclass
class Segment:
    t0: float
    t1: float
    key: tuple
    u0: np.ndarray  # modal amplitudes of the homogeneous part at t0


@dataclass
class ExactOrbit:
    """A periodic solution of the piecewise-linear system: its state at t = 0, period, the segments between
    events, the monodromy and Newton's record."""

    x0: np.ndarray
    period: float
    converged: bool
    residual: float  # |Phi_T(x0) - x0| / |x0|
    iterations: int
    monodromy: np.ndarray
    segments: list[Segment] = field(repr=False, default_factory=list)
    events: int = 0

    def multipliers(self, autonomous: bool = False) -> np.ndarray:
        rho = np.linalg.eigvals(self.monodromy)
        if autonomous:
            rho = np.delete(rho, int(np.argmin(np.abs(rho - 1.0))))
        return rho[np.argsort(-np.abs(rho))]


class PiecewiseLinear:
    """M q'' + C q' + K q = f0 + Re(F e^{i nu t}) + the unilateral springs (see the module's docstring).

    ``W``, ``D`` (s, n): the springs' gap rows and force directions; ``g0`` (s,), ``k`` (s,); ``nu`` (L,)
    the harmonic frequencies [rad/s], ``c`` (s, L) the gaps' and ``F`` (n, L) the force's complex amplitudes.
    """

    def __init__(self, M, C, K, f0, W, D, g0, k, nu=(), c=None, F=None):
        self.M, self.C, self.K = (np.asarray(a, dtype=float) for a in (M, C, K))
        self.n = self.M.shape[0]
        self.f0 = np.asarray(f0, dtype=float)
        self.W, self.D = np.atleast_2d(np.asarray(W, dtype=float)), np.atleast_2d(np.asarray(D, dtype=float))
        self.g0, self.k = np.atleast_1d(np.asarray(g0, dtype=float)), np.atleast_1d(np.asarray(k, dtype=float))
        self.s = self.W.shape[0]
        self.nu = np.atleast_1d(np.asarray(nu, dtype=float))
        L = self.nu.size
        self.c = np.zeros((self.s, L), complex) if c is None else np.asarray(c, dtype=complex).reshape(self.s, L)
        self.F = np.zeros((self.n, L), complex) if F is None else np.asarray(F, dtype=complex).reshape(self.n, L)
        self.Minv = np.linalg.inv(self.M)
        self._sets: dict[tuple, _Set] = {}

    # ------------------------------------------------------------------ one contact set in closed form
    def closed_form(self, key: tuple) -> _Set:
        st = self._sets.get(key)
        if st is not None:
            return st
        n = self.n
        on = np.array(key, dtype=bool)
        KS = self.K + self.D[on].T @ (self.k[on, None] * self.W[on])
        fS = self.f0 - self.D[on].T @ (self.k[on] * self.g0[on])
        FS = self.F - self.D[on].T @ (self.k[on, None] * self.c[on])
        A = np.zeros((2 * n, 2 * n))
        A[:n, n:] = np.eye(n)
        A[n:, :n] = -self.Minv @ KS
        A[n:, n:] = -self.Minv @ self.C
        b = np.concatenate([np.zeros(n), self.Minv @ fS])
        bh = np.vstack([np.zeros((n, self.nu.size), complex), self.Minv @ FS])
        lam, V = np.linalg.eig(A)
        xc = -np.linalg.solve(A, b)
        xh = np.column_stack([np.linalg.solve(1j * nu * np.eye(2 * n) - A, bh[:, l])
                              for l, nu in enumerate(self.nu)]) if self.nu.size else np.zeros((2 * n, 0), complex)
        st = _Set(lam, V, np.linalg.inv(V), xc, xh, A, b, bh, self.W @ V[:n], self.g0 + self.W @ xc[:n],
                  self.W @ xh[:n] + self.c)
        self._sets[key] = st
        return st

    def particular(self, st: _Set, t: np.ndarray) -> np.ndarray:
        """x_p at times t (G,) -> (2n, G)."""
        t = np.atleast_1d(t)
        out = np.repeat(st.xc[:, None], t.size, axis=1)
        if self.nu.size:
            out = out + (st.xh @ np.exp(1j * np.outer(self.nu, t))).real
        return out

    def state(self, st: _Set, seg_t0: float, u0: np.ndarray, t: np.ndarray) -> np.ndarray:
        """x at times t (G,) of the segment that starts at seg_t0 with modal amplitudes u0 -> (2n, G)."""
        t = np.atleast_1d(t)
        hom = (st.V @ (u0[:, None] * np.exp(np.outer(st.lam, t - seg_t0)))).real
        return self.particular(st, t) + hom

    def gaps(self, x: np.ndarray, t: np.ndarray) -> np.ndarray:
        """(s, G) gaps at states x (2n, G) and times t."""
        g = self.g0[:, None] + self.W @ x[: self.n]
        if self.nu.size:
            g = g + (self.c @ np.exp(1j * np.outer(self.nu, np.atleast_1d(t)))).real
        return g

    def segment_gaps(self, st: _Set, seg_t0: float, u0: np.ndarray, t: np.ndarray) -> np.ndarray:
        """(s, G) gaps along a segment in closed form (no state needed)."""
        t = np.atleast_1d(t)
        g = st.gc[:, None] + (st.WV @ (u0[:, None] * np.exp(np.outer(st.lam, t - seg_t0)))).real
        if self.nu.size:
            g = g + (st.gh @ np.exp(1j * np.outer(self.nu, t))).real
        return g

    def key_of(self, x: np.ndarray, t: float) -> tuple:
        g = self.gaps(x[:, None], np.array([t]))[:, 0]
        return tuple(bool(v) for v in (g < 0))

    def rhs(self, x: np.ndarray, t: float) -> np.ndarray:
        """The vector field (what an integrator would evaluate; the flow's derivative in the period)."""
        st = self.closed_form(self.key_of(x, t))
        out = st.A @ x + st.b
        if self.nu.size:
            out = out + (st.bh @ np.exp(1j * self.nu * t)).real
        return out

    # ------------------------------------------------------------------ the flow
    def flow(self, x0: np.ndarray, t_end: float, t0: float = 0.0, grid: int = GRID_PER_PERIOD,
             period: float | None = None) -> tuple[np.ndarray, np.ndarray, list[Segment]]:
        """x(t_end) from x(t0) = x0, the flow's derivative dx(t_end)/dx0, and the segments."""
        x = np.array(x0, dtype=float)
        t = float(t0)
        span = float(t_end) - t
        dt_grid = (period or span) / grid
        Phi = np.eye(2 * self.n)
        segs: list[Segment] = []
        key = self.key_of(x, t)
        switched = -1
        while t < t_end:
            st = self.closed_form(key)
            u0 = st.Vinv @ (x - self.particular(st, np.array([t]))[:, 0])
            nmax = max(2, int(math.ceil((t_end - t) / dt_grid)) + 1)
            tg_all = np.linspace(t, t_end, nmax)
            # the side each spring must stay on: touching springs keep g <= 0, open ones g >= 0
            sgn = np.where(np.array(key), -1.0, 1.0)
            t_ev, j_ev = t_end, -1
            for c0 in range(0, nmax, 128):  # in chunks: most sets last a fraction of the period
                tg = tg_all[max(c0 - 1, 0): c0 + 128]
                side = sgn[:, None] * self.segment_gaps(st, t, u0, tg)  # >= 0 while the set holds
                if switched >= 0 and c0 == 0:  # the spring that just switched sits at zero at tg[0]
                    side[switched, 0] = abs(side[switched, 0])
                bad = side < 0
                if not bad.any():
                    continue
                first = np.argmax(bad, axis=1)
                cand = [(int(first[j]), j) for j in range(self.s) if bad[j].any()]
                i_min = min(i for i, _ in cand)
                for i, j in cand:
                    if i != i_min:
                        continue
                    a, b = tg[max(i - 1, 0)], tg[i]

                    def fj(tt, j=j, st=st, t0_=t, u0=u0, sgn=sgn):
                        return sgn[j] * self.segment_gaps(st, t0_, u0, np.array([tt]))[j, 0]

                    fa = fj(a)
                    if fa <= 0:  # the switched spring at the interval's start: nudge inside
                        a = a + 1e-9 * (b - a)
                        fa = fj(a)
                        if fa <= 0:
                            continue
                    root = brentq(fj, a, b, xtol=1e-15 * max(1.0, abs(b)), rtol=4 * np.finfo(float).eps,
                                  maxiter=200)
                    if root < t_ev:
                        t_ev, j_ev = root, j
                if j_ev >= 0:
                    break
            x_new = self.state(st, t, u0, np.array([t_ev]))[:, 0]
            E = (st.V * np.exp(st.lam * (t_ev - t))) @ st.Vinv
            Phi = E.real @ Phi
            segs.append(Segment(t, t_ev, key, u0))
            x, t = x_new, t_ev
            if j_ev >= 0:
                key = tuple(not v if i == j_ev else v for i, v in enumerate(key))
                switched = j_ev
            else:
                break
        return x, Phi, segs

    def sample(self, segs: list[Segment], t: np.ndarray) -> np.ndarray:
        """q at times t (G,) on the recorded segments -> (G, n)."""
        t = np.atleast_1d(t)
        out = np.empty((t.size, self.n))
        for sg in segs:
            sel = (t >= sg.t0) & (t <= sg.t1)
            if sel.any():
                out[sel] = self.state(self.closed_form(sg.key), sg.t0, sg.u0, t[sel])[: self.n].T
        return out

    # ------------------------------------------------------------------ periodic solutions
    def shoot_forced(self, nu: float, x0: np.ndarray, tol: float = 1e-13, max_iter: int = 30) -> ExactOrbit:
        """The periodic solution of period 2 pi / nu through (near) x0: Newton on Phi_T(x) - x with the exact
        monodromy."""
        T = 2 * math.pi / nu
        x = np.array(x0, dtype=float)
        res, done, Phi, segs = math.inf, 0, None, []
        xT, Phi, segs = self.flow(x, T, period=T)
        for it in range(1, max_iter + 1):
            done = it
            r = xT - x
            scale = max(float(np.abs(x).max()), 1e-30)
            res = float(np.abs(r).max()) / scale
            if res <= tol:
                break
            dx = np.linalg.solve(Phi - np.eye(x.size), -r)
            lam = 1.0
            while True:  # backtracking on |Phi_T(x) - x|: far from the orbit the contact set changes
                xn = x + lam * dx
                xTn, Phin, segn = self.flow(xn, T, period=T)
                if np.abs(xTn - xn).max() < (1 - 1e-4 * lam) * np.abs(r).max() or lam < 1e-3:
                    break
                lam *= 0.5
            x, xT, Phi, segs = xn, xTn, Phin, segn
        events = max(len(segs) - 1, 0)
        return ExactOrbit(x, T, res <= tol, res, done, Phi, segs, events)

    def shoot_autonomous(self, x0: np.ndarray, T0: float, section: int, tol: float = 1e-13,
                         max_iter: int = 40) -> ExactOrbit:
        """The autonomous periodic solution (no harmonic terms) through (near) x0 of period near T0, on the
        Poincare section q'_section(0) = 0: Newton on (Phi_T(x) - x, x[n + section]) in (x, T)."""
        if self.nu.size and np.any(self.c) or np.any(self.F):
            raise ParameterError("shoot_autonomous: the system has harmonic terms (a forced system); accepted: none")
        n2 = 2 * self.n
        x = np.array(x0, dtype=float)
        T = float(T0)
        res, done, Phi, segs = math.inf, 0, None, []
        for it in range(1, max_iter + 1):
            done = it
            xT, Phi, segs = self.flow(x, T, period=T)
            r = np.concatenate([xT - x, [x[self.n + section]]])
            scale = max(float(np.abs(x).max()), 1e-30)
            res = float(np.abs(r).max()) / scale
            if res <= tol:
                break
            Jac = np.zeros((n2 + 1, n2 + 1))
            Jac[:n2, :n2] = Phi - np.eye(n2)
            Jac[:n2, n2] = self.rhs(xT, T)
            Jac[n2, self.n + section] = 1.0
            d = np.linalg.solve(Jac, -r)
            x, T = x + d[:n2], T + d[n2]
        events = max(len(segs) - 1, 0)
        return ExactOrbit(x, T, res <= tol, res, done, Phi, segs, events)


# ---------------------------------------------------------------------- the systems
def gap_oscillator(m1: float = 1.0, m2: float = 0.2, k1: float = 1.0e4, k2: float = 4.0e3, c1: float = 2.0,
                   c2: float = 0.8, k_c: float = 5.0e4, gap: float = 1.0e-3, force: float = 10.0,
                   nu: float = 120.0) -> PiecewiseLinear:
    """A 2-dof oscillator forced harmonically on its first mass, whose second mass meets a unilateral spring
    (stiffness k_c) across a gap: the small gap oscillator of the independent check (SI units; the defaults
    put the forcing between the two linear resonances, 87 and 163 rad/s: one contact a period, a stable orbit
    with multipliers 0.93)."""
    M = np.diag([m1, m2])
    K = np.array([[k1 + k2, -k2], [-k2, k2]])
    C = np.array([[c1 + c2, -c2], [-c2, c2]])
    # the gap closes as mass 2 moves up: g = gap - x2; the spring pushes it back: Q = F_N dg/dq
    return PiecewiseLinear(M, C, K, np.zeros(2), W=[[0.0, -1.0]], D=[[0.0, -1.0]], g0=[gap], k=[k_c], nu=[nu],
                           F=[[force], [0.0]])


def reference_2d(model: Model, contact: ContactModel, omega: float, forcing: CasingForcing | None = None,
                 me: float | None = None) -> PiecewiseLinear:
    """The reference's 2D formulation at spin omega as a piecewise-linear system: the point penalty law on the
    affine gaps g = g0 + G q + n_r dR(alpha + Omega t) and saturated friction (tanh(v / v_slip) = 1 at the
    tip speeds: the force on blade j is k_r (-g_j)_+ (A_j - mu S_j)). Refused where the friction is not
    saturated or the law is not the penalty."""
    if contact.formulation != "2D" or contact.law != "penalty":
        raise ParameterError(f"reference_2d: formulation {contact.formulation}, law {contact.law}; accepted: 2D, "
                             "penalty (the piecewise-linear case)")
    forcing = forcing or CasingForcing()
    pts = contact.geometry.points.reshape(-1, 3)
    rho = np.hypot(pts[:, 0], pts[:, 1])
    if contact.mu and np.tanh(omega * rho.min() / contact.v_slip) != 1.0:
        raise ParameterError(f"reference_2d: omega = {omega:g} rad/s leaves the friction unsaturated; accepted: tip "
                             "speeds where tanh(v / v_slip) = 1 (the law is then piecewise linear)")
    alpha = np.arctan2(pts[:, 1], pts[:, 0])
    nrm = contact.geometry.normals.reshape(-1, 3)
    n_r = nrm[:, 0] * np.cos(alpha) + nrm[:, 1] * np.sin(alpha)
    nus, cs = [], []
    ex, ey = forcing.offset
    if ex or ey:
        nus.append(omega)
        cs.append(n_r * (ex - 1j * ey) * np.exp(1j * alpha))
    for nl, (a, psi) in sorted(forcing.lobes.items()):
        nus.append(nl * omega)
        cs.append(n_r * a * np.exp(1j * nl * (alpha - psi)))
    me = model.params.imbalance.me if me is None else me
    D = contact.A - contact.mu * contact.S
    return PiecewiseLinear(model.M, model.D + model.G(omega), model.K_omega(omega), model.force(omega, me),
                           W=contact.G, D=D, g0=np.full(contact.G.shape[0], contact.g0),
                           k=np.full(contact.G.shape[0], contact.k_r), nu=nus,
                           c=np.column_stack(cs) if cs else None)
