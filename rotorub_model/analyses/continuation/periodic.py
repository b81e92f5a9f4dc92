"""Periodic solutions (limit cycles in the rotating frame) by shooting with the transient kernel,
their Floquet multipliers, and their continuation in a parameter.

In the rotating frame at constant spin speed the equations are autonomous, so an unstable
balanced solution can give way to a periodic orbit x(t + T) = x(t), x = (q, q'). The flow map
Phi_T is the central-difference scheme itself (the kernel, N steps of T / N): the orbit found is
the one the transient settles on, not a neighbour computed with another discretisation.

Shooting unknowns z = (x / x_s, T / T_s, p / p_s) with x_s = (q_s, q_s omega_s), solved with
Newton on

    Phi_T(x) - x = 0,   q'_k(0) = 0 (a Poincare section: k the disk dof the orbit moves most),
    tau . (z - z_pred) = 0 (pseudo-arclength in (x, T, p): the branch may fold),

the Jacobian by finite differences of the flow (2n + 2 runs of one period). Floquet multipliers:
the eigenvalues of dPhi_T/dx at the orbit; one is 1 (the time shift); the orbit is stable when
every other one lies inside the unit circle.

A branch starts at a Hopf point (amplitude 0, T = 2 pi / Im mu, the first step along the
critical eigenvector) or from a state on a settled transient.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ...errors import ParameterError
from ..transient import CentralDifference
from .equilibria import Equilibria

MULTIPLIER_TOL = 1e-6  # a multiplier within this of the unit circle is neutral (finite-difference resolution)
# [m] an "orbit" whose fan disk moves less than this is the static solution (a fixed point of the flow for any
# period, which shooting converges on from a transient that has not settled: measured 1e-15 m, against 1e-7 m
# for the first orbit a step from a Hopf point)
TRIVIAL_PEAK_TO_PEAK = 1e-12


@dataclass
class Orbit:
    omega: float  # [rad/s]
    g0: float  # [m]
    x0: np.ndarray  # (2n) q, q' at the section
    period: float  # [s]
    multipliers: np.ndarray  # Floquet multipliers (the trivial one removed), by decreasing modulus
    disk_peak_to_peak: float  # [m] largest peak-to-peak of the fan-disk displacement components
    disk_mean_radius: float  # [m] mean distance of the fan-disk centre from the axis
    max_force: float  # [N] largest blade normal force over the period
    residual: float  # |Phi_T(x) - x| / |x_s|
    # [m] the fan-disk centre's largest and smallest distance from the axis over the period: the static
    # branch's disk_amplitude is that distance, so an orbit born at a Hopf point starts on the branch
    disk_max_radius: float = math.nan
    disk_min_radius: float = math.nan

    @property
    def stable(self) -> bool:
        # the multipliers come from central differences of the flow: resolved to ~1e-8
        return bool(self.multipliers.size == 0 or np.abs(self.multipliers).max() < 1.0 + MULTIPLIER_TOL)

    @property
    def trivial(self) -> bool:
        return self.disk_peak_to_peak < TRIVIAL_PEAK_TO_PEAK

    @property
    def frequency(self) -> float:
        return 2 * math.pi / self.period

    def summary(self) -> dict:
        return {"omega_rad_s": self.omega, "g0_m": self.g0, "period_s": self.period,
                "frequency_rad_s": self.frequency, "stable": self.stable,
                "largest_multiplier": float(np.abs(self.multipliers).max()) if self.multipliers.size else 0.0,
                "disk_peak_to_peak_m": self.disk_peak_to_peak, "disk_radius_range_m": [self.disk_min_radius,
                                                                                        self.disk_max_radius],
                "max_force_N": self.max_force, "residual": self.residual}


@dataclass
class OrbitBranch:
    formulation: str
    omega: float
    orbits: list[Orbit]
    message: str
    hopf_g0: float | None = None
    hopf_frequency: float | None = None
    notes: dict = field(default_factory=dict)


class Shooting:
    """The flow map of the central-difference scheme at fixed (Omega, g0) and its derivatives."""

    def __init__(self, eq: Equilibria, omega: float, steps_per_period: int = 256):
        if steps_per_period < 16:
            raise ParameterError(f"steps_per_period: {steps_per_period} out of range; accepted range [16, inf)")
        self.eq, self.omega, self.N = eq, float(omega), int(steps_per_period)
        self.n = eq.n
        self._cd = CentralDifference(eq.model, eq.base, dt=None, t_ramp=0.0,
                                     omega_max_for_dt=self.omega)
        T, _ = eq.model.disk_maps
        self._T2 = T[:2]

    def flow(self, x: np.ndarray, T: float, g0: float, record: bool = False):
        """Phi_T(x): N steps of T / N from x = (q, q'); with ``record``, also q at every step."""
        cd, n, N = self._cd, self.n, self.N
        if cd.contact.g0 != g0:
            cd.contact = self.eq.contact(g0)
        dt = T / N
        cd.dt = dt
        cd.t, cd.steps, cd.diverged, cd.phi = 0.0, 0, False, 0.0
        cd.q[:] = x[:n]
        cd.q_prev[:] = x[:n] - dt * x[n:]
        rec = np.empty((N, n)) if record else None
        done, _ = cd.advance(N, self.omega, self.eq.me, rec_every=1 if record else 0, rec_q=rec)
        if done < N:
            return (None, None) if record else None
        out = np.concatenate([cd.q, (cd.q - cd.q_prev) / dt])
        return (out, rec) if record else out

    def orbit(self, x: np.ndarray, T: float, g0: float, residual: float, multipliers: np.ndarray) -> Orbit:
        _, rec = self.flow(x, T, g0, record=True)
        d = rec @ self._T2.T
        c = self.eq.contact(g0)
        fmax = float(c.split_outputs(c.outputs_array(rec, self.omega))["F_N"].max())
        r = np.hypot(d[:, 0], d[:, 1])
        return Orbit(self.omega, float(g0), x.copy(), float(T), multipliers, float(np.ptp(d, axis=0).max()),
                     float(r.mean()), fmax, float(residual), float(r.max()), float(r.min()))


def _multipliers(D: np.ndarray, along: np.ndarray | None = None) -> np.ndarray:
    """The Floquet multipliers of the monodromy D, the trivial one removed (a shift along the orbit: its
    eigenvector is the flow's direction ``along``). Near a Hopf point a second multiplier comes close to 1 (the
    orbit's amplitude), within the differences' error of the trivial one: the trivial one is then the one whose
    eigenvector lies along the orbit, not merely the one nearest 1 (on a newcomer's configuration the first
    orbit past a Hopf point read 1.000006, the trivial one, and was called unstable)."""
    rho, vec = np.linalg.eig(D)
    near = np.flatnonzero(np.abs(rho - 1.0) < 1e-3)
    if along is not None and near.size > 1 and np.linalg.norm(along) > 0:
        cos = np.abs(vec[:, near].conj().T @ along) / (np.linalg.norm(vec[:, near], axis=0) * np.linalg.norm(along))
        k = int(near[np.argmax(cos)])
    else:
        k = int(np.argmin(np.abs(rho - 1.0)))
    rho = np.delete(rho, k)
    return rho[np.argsort(-np.abs(rho))]


class _OrbitSolver:
    def __init__(self, sh: Shooting, q_scale: float, w_scale: float, T_scale: float, g_scale: float, section: int):
        self.sh = sh
        n = sh.n
        self.xs = np.concatenate([np.full(n, q_scale), np.full(n, q_scale * w_scale)])
        self.Ts, self.gs = T_scale, g_scale
        self.k = section

    def unpack(self, z):
        return z[:-2] * self.xs, z[-2] * self.Ts, z[-1] * self.gs

    def pack(self, x, T, g0):
        return np.concatenate([x / self.xs, [T / self.Ts, g0 / self.gs]])

    def equations(self, z):
        x, T, g0 = self.unpack(z)
        xT = self.sh.flow(x, T, g0)
        if xT is None:
            return None
        return np.concatenate([(xT - x) / self.xs, [x[self.sh.n + self.k] / self.xs[self.sh.n + self.k]]])

    def jacobian(self, z, f0):
        m = z.size
        J = np.empty((m - 1, m))
        for i in range(m):
            h = 1e-6 * max(1.0, abs(z[i]))
            zp = z.copy()
            zp[i] += h
            fp = self.equations(zp)
            if fp is None:
                return None
            J[:, i] = (fp - f0) / h
        return J

    def along(self, z) -> np.ndarray | None:
        """The flow's direction at the orbit's point, in the scaled coordinates of :meth:`monodromy`: the
        trivial multiplier's eigenvector (a 1/256 of a period forward, one-sided: a direction is all it gives)."""
        x, T, g0 = self.unpack(z)
        d = T / 256
        xd = self.sh.flow(x, d, g0)
        return None if xd is None else (xd - x) / d / self.xs

    def monodromy(self, z) -> np.ndarray | None:
        """dPhi_T/dx at the orbit by central differences (Floquet multipliers to ~1e-8; the forward
        differences of the Newton iterations resolve them to ~1e-4 only)."""
        n2 = 2 * self.sh.n
        D = np.empty((n2, n2))
        for i in range(n2):
            h = 1e-5 * max(1.0, abs(z[i]))
            zp, zm = z.copy(), z.copy()
            zp[i] += h
            zm[i] -= h
            fp, fm = self.equations(zp), self.equations(zm)
            if fp is None or fm is None:
                return None
            D[:, i] = (fp[:n2] - fm[:n2]) / (2 * h)
        return D + np.eye(n2)

    def correct(self, z_pred, tau, max_iter: int = 12, tol: float = 1e-9):
        z = z_pred.copy()
        for _ in range(max_iter):
            f = self.equations(z)
            if f is None:
                return None, None, math.inf
            g = tau @ (z - z_pred)
            res = float(np.linalg.norm(f))
            J = self.jacobian(z, f)
            if J is None:
                return None, None, math.inf
            if res <= tol and abs(g) <= tol:
                return z, J, res
            B = np.vstack([J, tau])
            try:
                dz = np.linalg.solve(B, -np.concatenate([f, [g]]))
            except np.linalg.LinAlgError:
                return None, None, math.inf
            z = z + dz
            if np.linalg.norm(dz) <= tol * max(1.0, np.linalg.norm(z)):
                f = self.equations(z)
                if f is None:
                    return None, None, math.inf
                J = self.jacobian(z, f)
                return (z, J, float(np.linalg.norm(f))) if J is not None else (None, None, math.inf)
        return None, None, math.inf

    def tangent(self, J, previous):
        t = np.linalg.svd(J)[2][-1]
        return t if t @ previous >= 0 else -t


def continue_orbits_from_hopf(eq: Equilibria, omega: float, g0_hopf: float, mu: complex, g0_stop: float,
                              steps_per_period: int = 256, h: float = 0.05, max_orbits: int = 40) -> OrbitBranch:
    """The branch of periodic orbits born at a Hopf point (Omega, g0_hopf) with critical eigenvalue
    mu, followed by pseudo-arclength in (orbit, T, g0) until g0 passes g0_stop or max_orbits."""
    sh = Shooting(eq, omega, steps_per_period)
    q = eq.solve(omega, g0_hopf)
    if q is None:
        return OrbitBranch(eq.formulation, omega, [], "no balanced solution at the Hopf point", g0_hopf, abs(mu.imag))
    mu, v = eq.refine(q, omega, g0_hopf, mu)
    w = abs(mu.imag)
    T_h = 2 * math.pi / w
    n = eq.n
    k = int(np.argmax(np.abs(eq._T2).max(axis=0) * np.abs(v)))  # the disk dof the mode moves most
    # rotate the eigenvector so that its velocity at the section dof is zero (x = Re(v), v_k real)
    v = v * np.exp(-1j * np.angle(v[k]))
    e_q, e_v = np.real(v), np.real(mu * v)
    q_scale = 1e-4
    solver = _OrbitSolver(sh, q_scale, w, T_h, abs(g0_hopf) if g0_hopf else 1e-3, k)
    x_h = np.concatenate([q, np.zeros(n)])
    z0 = solver.pack(x_h, T_h, g0_hopf)
    tau = np.concatenate([np.concatenate([e_q, e_v]) / solver.xs, [0.0, 0.0]])
    orbits, msg = _follow(solver, z0, tau / np.linalg.norm(tau), g0_hopf, g0_stop, h, max_orbits)
    return OrbitBranch(eq.formulation, omega, orbits, msg, g0_hopf, w)


def _follow(solver: _OrbitSolver, z: np.ndarray, tau: np.ndarray, g0_from: float, g0_stop: float, h: float,
            max_orbits: int) -> tuple[list[Orbit], str]:
    """Pseudo-arclength along the orbits from z in the direction tau until g0 passes g0_stop."""
    sh, n = solver.sh, solver.sh.n
    orbits: list[Orbit] = []
    step = h
    while len(orbits) < max_orbits:
        z_new, J, res = solver.correct(z + step * tau, tau)
        if z_new is None:
            step *= 0.5
            if step < 1e-4:
                return orbits, "the shooting corrector failed (step below 1e-4)"
            continue
        x, T, g0 = solver.unpack(z_new)
        D = solver.monodromy(z_new)
        o = sh.orbit(x, T, g0, res, _multipliers(D if D is not None else J[:2 * n, :2 * n] + np.eye(2 * n),
                                                 solver.along(z_new)))
        if o.trivial:
            return orbits, f"the orbits shrank onto the static solution at g0 = {g0:.6g} m"
        orbits.append(o)
        tau = solver.tangent(J, tau)
        z = z_new
        if (g0 - g0_stop) * (g0_from - g0_stop) <= 0:
            return orbits, f"reached g0 = {g0_stop:.6g} m"
        step = min(step * 1.5, 40 * h)
    return orbits, f"stopped after {max_orbits} orbits"


def continue_orbits(eq: Equilibria, start: Orbit, g0_stop: float, steps_per_period: int = 256, h: float = 0.05,
                    max_orbits: int = 40) -> OrbitBranch:
    """The branch of periodic orbits through ``start`` followed towards g0_stop."""
    sh = Shooting(eq, start.omega, steps_per_period)
    k = _section(eq, start.x0)
    solver = _OrbitSolver(sh, 1e-4, start.frequency, start.period, abs(start.g0) if start.g0 else 1e-3, k)
    z0 = solver.pack(start.x0, start.period, start.g0)
    f0 = solver.equations(z0)
    J = solver.jacobian(z0, f0)
    tau = np.linalg.svd(J)[2][-1]
    if tau[-1] * (g0_stop - start.g0) < 0:
        tau = -tau
    orbits, msg = _follow(solver, z0, tau, start.g0, g0_stop, h, max_orbits)
    return OrbitBranch(eq.formulation, start.omega, [start, *orbits], msg)


def _section(eq: Equilibria, x: np.ndarray) -> int:
    """The Poincare section dof: the disk dof (through the maps) whose velocity is zero at x."""
    n = eq.n
    w = np.abs(eq._T2).max(axis=0)
    cand = np.flatnonzero(w > 0.1 * w.max())
    return int(cand[np.argmin(np.abs(x[n + cand]) / w[cand])])


def orbit_from_state(eq: Equilibria, omega: float, g0: float, q: np.ndarray, qdot: np.ndarray, period: float,
                     steps_per_period: int = 256) -> Orbit | None:
    """Newton-shoot the periodic orbit through (or near) a state (a settled transient's), period guess."""
    sh = Shooting(eq, omega, steps_per_period)
    n = eq.n
    k = int(np.argmax(np.abs(eq._T2).max(axis=0) * (np.abs(qdot) + 1e-30)))
    # move to the section: the first step where q'_k changes sign
    x = np.concatenate([q, qdot])
    xT, rec = sh.flow(x, period, g0, record=True)
    if xT is None:
        return None
    vel = np.diff(np.vstack([q, rec]), axis=0)[:, k]
    idx = np.flatnonzero(np.sign(vel[1:]) != np.sign(vel[:-1]))
    if idx.size:
        i = int(idx[0]) + 1
        dt = period / sh.N
        qi = rec[i]
        qd = (rec[i] - rec[i - 1]) / dt
        x = np.concatenate([qi, qd])
    w = 2 * math.pi / period
    solver = _OrbitSolver(sh, 1e-4, w, period, abs(g0) if g0 else 1e-3, k)
    z0 = solver.pack(x, period, g0)
    tau = np.zeros_like(z0)
    tau[-1] = 1.0  # g0 held
    z, J, res = solver.correct(z0, tau, max_iter=20)
    if z is None:
        return None
    x, T, g = solver.unpack(z)
    D = solver.monodromy(z)
    o = sh.orbit(x, T, g, res, _multipliers(D if D is not None else J[:2 * n, :2 * n] + np.eye(2 * n),
                                            solver.along(z)))
    return None if o.trivial else o
