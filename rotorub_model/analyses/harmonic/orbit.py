"""What a periodic response shows a user: blade-tip deflection, fan-disk motion, contact forces, the incursion
into the casing, harmonic content. One function of q(t) serves the HB orbits and the transients alike, so
the two are measured the same way.

*Blade-tip amplitude*: the tip deflection of blade j along its flexible direction, v_j(t) = psi(l_b) . b_j(t)
(the blade functions are tip-normalised), its half peak-to-peak over the period, the largest over the blades.
*Incursion*: the deepest penetration (-gap) of any blade point at each fixed-frame angle of the casing over a
period, in 360 bins: what a liner facing that orbit would be cut to before it yields (the HB has no wear
history; :func:`incursion_profile` is the orbit's footprint, its lobes the ones a liner would take first).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ...structure.blades import blade_functions
from ...structure.model import Model
from .basis import HarmonicBasis
from .problem import HBProblem

FINE_SAMPLES = 1024  # samples per period for the reported extremes (a force peak between AFT samples counts)


def tip_deflection(model: Model, q: np.ndarray) -> np.ndarray:
    """v_j of every blade (..., N) from states q (..., n). An imported blade: its tip nodes' mean elastic
    displacement along the direction the tip moves most (the leading left singular vector of the mean tip
    recovery, 3 x m, in the blade's frame): a signed scalar like the built-in blade's psi(l_b) . b_j."""
    p = model.params
    qb = q[..., model.slices["blades"]].reshape(*q.shape[:-1], p.blades.count, model.blade_dofs)
    if model.fe_blade is not None:
        return qb @ _fe_tip_row(model)
    psi = blade_functions(p, p.blades.length)[0]
    return (qb * psi).sum(axis=-1)


def _fe_tip_row(model: Model) -> np.ndarray:
    """(m,) the imported blade's tip deflection along its principal direction per reduced dof."""
    tip = np.asarray(model.fe_blade.tip_recovery).mean(axis=0)  # (3, m)
    u = np.linalg.svd(tip, full_matrices=False)[0][:, 0]
    u = u if u[np.argmax(np.abs(u))] > 0 else -u  # one sign for every call
    return u @ tip


def blade_normal_forces(problem: HBProblem, law: np.ndarray) -> np.ndarray:
    """Each blade's normal force (m, N) from the kernel's law values (m, N_kernel, LAW_WIDTH): an imported tip's
    segments summed per blade (as the kernel's outputs report them), else the law's own column."""
    c = problem.contact
    t = None if c is None else c.geometry.tips
    if t is None:
        return law[:, :, 0]
    out = np.zeros((law.shape[0], t.n_blades))
    np.add.at(out, (slice(None), np.asarray(t.blade_of)), law[:, :, 0])
    return out


def disk_displacement(model: Model, q: np.ndarray) -> np.ndarray:
    T, _ = model.disk_maps
    return q @ T[:2].T


@dataclass
class OrbitMeasures:
    tip_amplitude: float  # [m] largest half peak-to-peak tip deflection over the blades
    tip_amplitudes: np.ndarray  # (N,) per blade
    disk_amplitude: float  # [m] largest distance of the fan-disk centre from the axis
    max_force: float  # [N] largest blade normal force
    penetration: float  # [m] deepest penetration (>= 0)
    contact_fraction: float  # share of (blade, sample) pairs in contact
    tip_harmonics: np.ndarray  # (H+1,) amplitude of each harmonic of the most deflected blade's tip [m]

    def summary(self) -> dict:
        return {"tip_amplitude_m": self.tip_amplitude, "disk_amplitude_m": self.disk_amplitude,
                "max_force_N": self.max_force, "penetration_m": self.penetration,
                "contact_fraction": self.contact_fraction, "tip_harmonics_m": self.tip_harmonics.tolist()}


def measures_from_states(model: Model, q: np.ndarray, F_N: np.ndarray, gaps: np.ndarray,
                         harmonics: int = 0) -> OrbitMeasures:
    """Measures of one period sampled uniformly: q (m, n), F_N (m, N), gaps (m, N, P)."""
    v = tip_deflection(model, q)
    amp = 0.5 * np.ptp(v, axis=0)
    d = np.hypot(*disk_displacement(model, q).T)
    j = int(np.argmax(amp))
    H = harmonics or min(20, q.shape[0] // 2 - 1)
    c = np.fft.rfft(v[:, j]) / v.shape[0]
    th = np.abs(c[: H + 1]) * 2
    th[0] /= 2
    return OrbitMeasures(float(amp.max()), amp, float(d.max()), float(F_N.max()), float(max(0.0, -gaps.min())),
                         float(np.mean(F_N > 0)), th)


def measures_at_phases(problem: HBProblem, Y: np.ndarray, omega: float, w: float, samples: int) -> OrbitMeasures:
    """The measures of the orbit read on ``samples`` equal phases a period only, as a transient recorded at that
    rate reads its own (its peaks between samples unseen): what to compare a transient's amplitudes with. On
    the oval reference at 3.25 Omega_ref (2D) 64 phases read the tip amplitude 0.37 % low."""
    Q = problem.full(Y, omega, w)
    tau = 2 * math.pi * np.arange(samples) / samples
    q = problem.basis.evaluate(Q, tau)
    phi = tau * (omega / w) if problem.forced else None
    gaps, law = problem.nl.laws(q, phi)
    return measures_from_states(problem.model, q, blade_normal_forces(problem, law), gaps, problem.H)


class OrbitView:
    """An HB orbit of ``problem`` resolved on a fine grid: states, kernel outputs at each sample's frame angle."""

    def __init__(self, problem: HBProblem, Y: np.ndarray, omega: float, w: float, samples: int = FINE_SAMPLES):
        self.problem, self.omega, self.w = problem, omega, w
        b = problem.basis
        self.Q = problem.full(Y, omega, w)  # (2H+1, n)
        fine = HarmonicBasis(b.harmonics, max(samples, b.m))
        self.fine = fine
        self.q = fine.E @ self.Q
        self.qd = w * (fine.dE @ self.Q)
        self.phi = fine.tau * (omega / w) if problem.forced else np.zeros(fine.m)
        self.F_N, self.gaps = self._laws()

    def _laws(self) -> tuple[np.ndarray, np.ndarray]:
        """Blade normal forces (m, N) and gaps (m, N, P) at the fine samples, each at its own frame angle."""
        gaps, law = self.problem.nl.laws(self.q, self.phi if self.problem.forced else None)
        return blade_normal_forces(self.problem, law), gaps

    def measures(self) -> OrbitMeasures:
        m = measures_from_states(self.problem.model, self.q, self.F_N, self.gaps, self.problem.H)
        # the tip's harmonics exactly from the coefficients (not from the fine samples)
        v = tip_deflection(self.problem.model, self.Q)  # (2H+1, N)
        j = int(np.argmax(m.tip_amplitudes))
        m.tip_harmonics = self.problem.basis.amplitudes(v[:, j : j + 1])[:, 0]
        return m

    def incursion_profile(self, bins: int = 360) -> np.ndarray:
        """Deepest penetration [m] (>= 0) at each fixed-frame angle bin over the period."""
        c = self.problem.contact
        pts = c.geometry.points.reshape(-1, 3)
        alpha = np.arctan2(pts[:, 1], pts[:, 0])
        theta = (alpha[None, :] + self.phi[:, None]) % (2 * math.pi)
        pen = np.maximum(-self.gaps.reshape(self.fine.m, -1), 0.0)
        k = np.minimum((theta / (2 * math.pi) * bins).astype(int), bins - 1)
        out = np.zeros(bins)
        np.maximum.at(out, k.ravel(), pen.ravel())
        return out


def profile_lobes(profile: np.ndarray, max_harmonic: int = 8) -> tuple[int, np.ndarray]:
    """(dominant lobe count 1..max_harmonic or 0 for none, amplitudes of harmonics 1..max_harmonic) of a profile
    over the circumference (the kernel's rule for a worn profile: a harmonic must reach 1 % of the mean)."""
    c = np.fft.rfft(profile) / profile.size
    amps = 2 * np.abs(c[1 : max_harmonic + 1])
    mean = abs(c[0].real)
    if mean <= 0 or amps.max() < 0.01 * mean:
        return 0, amps
    return int(np.argmax(amps) + 1), amps
