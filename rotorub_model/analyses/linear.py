"""Linear analyses: imbalance response, modes at a speed, Campbell diagram.

In the rotating frame the imbalance force is constant, so the forced response at
spin speed Omega is the static solution of K(Omega) q = F(Omega^2) (eq. 9).
Critical speeds are the peaks of the fan-disk response, located on a grid and
then refined by a bounded scalar search (the peaks are sharp: mode 1 has a damping
ratio of about 1e-3).

Modes at a speed are the eigenvalues of the first-order form of
M q'' + (D + G) q' + K(Omega) q = 0, in the rotating frame. For the Campbell
diagram each rotating-frame eigenvector is split into circumferential harmonics
(the x/y pairs of shaft and casing, the blade pattern over the blades): a
component with nodal-diameter index m and rotating-frame frequency w is seen in
the fixed frame at |w + m Omega|; the dominant component labels the mode.

Examples
--------
>>> from rotorub_model.structure.model import build_model
>>> r = run_response(build_model(), n_speeds=400)
>>> len(r.critical_speeds)
2
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import ParameterError
from ..results import pyplot, save_figure, save_result
from ..structure.model import Model


def linear_response(model: Model, omega: float, me: float | None = None) -> np.ndarray:
    """Static rotating-frame response q to the imbalance at spin speed omega [rad/s]."""
    return np.linalg.solve(model.K_omega(omega), model.force(omega, me))


def fan_amplitude(model: Model, q: np.ndarray) -> float:
    T, _ = model.disk_maps
    return float(np.hypot(*(T[:2] @ q)))


def _check_speed_range(speed_min: float, speed_max: float, n: int) -> None:
    if not (np.isfinite(speed_min) and np.isfinite(speed_max)) or speed_min <= 0 or speed_max <= speed_min:
        raise ParameterError(
            f"speed range: need 0 < speed_min < speed_max (normalised), got [{speed_min}, {speed_max}]"
        )
    if n < 10 or n > 1_000_000:
        raise ParameterError(f"n_speeds: {n} out of range; accepted range [10, 1e6]")


@dataclass
class ResponseResult:
    """Imbalance response at the fan disk over a speed range."""

    speeds: np.ndarray  # normalised
    omega_ref: float
    amplitude: np.ndarray  # fan-disk radial displacement [m]
    tilt: np.ndarray  # fan-disk tilt magnitude [rad]
    critical_speeds: list[float]  # normalised
    peak_amplitudes: list[float]  # [m]
    peak_tilts: list[float]  # [rad]
    n_dofs: int

    def summary(self) -> dict:
        return {
            "critical_speeds": self.critical_speeds,
            "critical_speeds_rad_s": [c * self.omega_ref for c in self.critical_speeds],
            "peak_amplitudes_m": self.peak_amplitudes,
            "peak_tilts_rad": self.peak_tilts,
            "peak_ratio_first_to_second": (
                self.peak_amplitudes[0] / self.peak_amplitudes[1] if len(self.peak_amplitudes) > 1 else None
            ),
            "omega_ref_rad_s": self.omega_ref,
            "n_dofs": self.n_dofs,
            "speed_range": [float(self.speeds[0]), float(self.speeds[-1])],
        }

    def plot(self, path: str | Path) -> Path:
        plt = pyplot()
        fig, ax = plt.subplots(figsize=(7, 4))
        ax.semilogy(self.speeds, self.amplitude * 1e3, lw=1.2)
        for c, a in zip(self.critical_speeds, self.peak_amplitudes):
            ax.plot(c, a * 1e3, "o", color="C3")
            ax.annotate(f"Ω={c:.2f}", (c, a * 1e3), textcoords="offset points", xytext=(5, 5))
        ax.set_xlabel("normalised spin speed Ω / Ω_ref")
        ax.set_ylabel("fan-disk displacement [mm]")
        ax.set_title("Imbalance response at the fan disk")
        ax.grid(True, which="both", alpha=0.3)
        return save_figure(fig, path)

    def save(self, out: str | Path) -> dict:
        s = save_result(self, out, "response", "summary")
        np.savez(Path(out) / "response.npz", speeds=self.speeds, amplitude=self.amplitude, tilt=self.tilt)
        return s


def run_response(
    model: Model, speed_min: float = 0.05, speed_max: float = 10.0, n_speeds: int = 2000, me: float | None = None
) -> ResponseResult:
    """Imbalance response over normalised speeds [speed_min, speed_max], with refined peaks."""
    from scipy.optimize import minimize_scalar  # here: the FMU's copy of this module must import without scipy
    from scipy.signal import find_peaks

    _check_speed_range(speed_min, speed_max, n_speeds)
    wref = model.params.normalisation.omega_ref
    speeds = np.linspace(speed_min, speed_max, n_speeds)
    T, R = model.disk_maps
    amp = np.empty(n_speeds)
    tilt = np.empty(n_speeds)
    for i, s in enumerate(speeds):
        q = linear_response(model, s * wref, me)
        amp[i] = np.hypot(*(T[:2] @ q))
        tilt[i] = np.hypot(*(R[:2] @ q))
    peaks, _ = find_peaks(amp)
    crit, pamp, ptilt = [], [], []
    h = speeds[1] - speeds[0]
    for i in peaks:
        res = minimize_scalar(
            lambda s: -fan_amplitude(model, linear_response(model, s * wref, me)),
            bounds=(speeds[i] - h, speeds[i] + h),
            method="bounded",
            options={"xatol": 1e-10},
        )
        q = linear_response(model, res.x * wref, me)
        crit.append(float(res.x))
        pamp.append(fan_amplitude(model, q))
        ptilt.append(float(np.hypot(*(R[:2] @ q))))
    return ResponseResult(speeds, wref, amp, tilt, crit, pamp, ptilt, model.n_dofs)


def first_order(model: Model, omega: float, K_extra: np.ndarray | None = None,
                C_extra: np.ndarray | None = None) -> np.ndarray:
    """State matrix A of x' = A x, x = (q, q'), for
    M q'' + (D + G - C_extra) q' + (K(W) - K_extra) q = 0 (K_extra, C_extra: the contact
    force's Jacobians in q and q')."""
    n = model.n_dofs
    K = model.K_omega(omega)
    if K_extra is not None:
        K = K - K_extra
    C = model.D + model.G(omega)
    if C_extra is not None:
        C = C - C_extra
    Minv = model.M_inv
    A = np.zeros((2 * n, 2 * n))
    A[:n, n:] = np.eye(n)
    A[n:, :n] = -Minv @ K
    A[n:, n:] = -Minv @ C
    return A


def harmonic_weights(model: Model, phi: np.ndarray) -> dict[int, float]:
    """Share of the mode shape phi (rotating frame, complex) in each nodal-diameter index m.

    The pair (x, y) of harmonic n holds u(a) = x cos(n a) + y sin(n a). With time
    dependence exp(+i w t), a forward wave (turning with +a, e.g. x = cos, y = sin:
    phi = (1, -i)) has |x + i y| and no |x - i y|: index +n gets |x + i y|^2 / 4,
    -n gets |x - i y|^2 / 4 (weighted by the pair's mass). Blade dofs go through a
    DFT over the blades: the coefficient of exp(+i k a_j) times exp(+i w t) is a
    wave turning with -a, index -k.
    """
    w: dict[int, float] = {}
    Md = np.diag(model.M)
    for i, name in enumerate(model.dofs):
        if not name.endswith(".x"):
            continue
        n = int(name.split(".")[1][1:]) if name.startswith("casing.n") else 1
        x, y = phi[i], phi[i + 1]
        m = Md[i]
        w[n] = w.get(n, 0.0) + m * abs(x + 1j * y) ** 2 / 4
        w[-n] = w.get(-n, 0.0) + m * abs(x - 1j * y) ** 2 / 4
    p = model.params
    N, nb = p.blades.count, p.blades.dofs
    bl = phi[model.slices["blades"]].reshape(N, nb)
    mb = Md[model.slices["blades"]].reshape(N, nb)[0]
    coef = np.fft.fft(bl, axis=0) / N  # coef[k] multiplies exp(+i k a_j)
    for k in range(N):
        m_idx = -(k if k <= N // 2 else k - N)
        w[m_idx] = w.get(m_idx, 0.0) + float(np.sum(mb * np.abs(coef[k]) ** 2)) * N
    return w


@dataclass
class ModesResult:
    speed: float  # normalised
    eigenvalues: np.ndarray  # rotating frame, rad/s, one per conjugate pair (Im >= 0)
    fixed_frame_hz: np.ndarray
    harmonic: np.ndarray
    damping_ratio: np.ndarray

    def summary(self) -> dict:
        return {
            "speed": self.speed,
            "modes": [
                {
                    "rotating_frame_hz": float(ev.imag / (2 * np.pi)),
                    "fixed_frame_hz": float(f),
                    "nodal_diameter_index": int(h),
                    "damping_ratio": float(z),
                    "real_part": float(ev.real),
                }
                for ev, f, h, z in zip(self.eigenvalues, self.fixed_frame_hz, self.harmonic, self.damping_ratio)
            ],
        }

    def plot(self, path: str | Path) -> Path:
        plt = pyplot()
        fig, ax = plt.subplots(figsize=(7, 4))
        h = np.abs(self.harmonic)
        sc = ax.scatter(self.eigenvalues.real, self.eigenvalues.imag / (2 * np.pi), c=h, cmap="viridis",
                        vmin=0, vmax=max(int(h.max()), 1))
        cb = fig.colorbar(sc, ax=ax)
        cb.set_label("|nodal diameter index|")
        ax.axvline(0, color="k", lw=0.8)
        ax.set_xlabel("real part [1/s]")
        ax.set_ylabel("rotating-frame frequency [Hz]")
        ax.set_title(f"Eigenvalues at Ω = {self.speed:.3g} Ω_ref")
        ax.grid(alpha=0.3)
        return save_figure(fig, path)

    def save(self, out: str | Path) -> dict:
        return save_result(self, out, "modes")


def run_modes(model: Model, speed: float, K_extra: np.ndarray | None = None) -> ModesResult:
    """Eigenvalues at normalised speed ``speed`` with fixed-frame labelling."""
    if not np.isfinite(speed) or speed < 0:
        raise ParameterError(f"speed: {speed} out of range; accepted range [0, inf) (normalised)")
    omega = speed * model.params.normalisation.omega_ref
    lam, vec = np.linalg.eig(first_order(model, omega, K_extra))
    n = model.n_dofs
    keep = lam.imag >= -1e-9
    lam, vec = lam[keep], vec[:n, keep]
    order = np.argsort(np.abs(lam.imag))
    lam, vec = lam[order], vec[:, order]
    fixed = np.empty(lam.size)
    harm = np.empty(lam.size, dtype=int)
    for i in range(lam.size):
        w = harmonic_weights(model, vec[:, i])
        m = max(w, key=w.get)
        harm[i] = m
        fixed[i] = abs(lam[i].imag + m * omega) / (2 * np.pi)
    # The damping ratio belongs to the motion an observer sees: a mode whose rotating-frame
    # frequency is near zero (the critical mode near its critical speed) would otherwise read
    # zeta ~ 1 from |lambda| ~ |Re lambda|, while in the fixed frame it whirls at ~Omega.
    zeta = -lam.real / np.maximum(np.hypot(lam.real, 2 * np.pi * fixed), 1e-300)
    return ModesResult(speed, lam, fixed, harm, zeta)


@dataclass
class CampbellResult:
    speeds: np.ndarray
    omega_ref: float
    fixed_frame_hz: np.ndarray  # (n_speeds, n_modes)
    rotating_frame_hz: np.ndarray
    harmonic: np.ndarray

    def summary(self) -> dict:
        return {
            "speeds": self.speeds,
            "omega_ref_rad_s": self.omega_ref,
            "fixed_frame_hz": self.fixed_frame_hz,
            "rotating_frame_hz": self.rotating_frame_hz,
            "nodal_diameter_index": self.harmonic,
        }

    def plot(self, path: str | Path, fmax_hz: float | None = None) -> Path:
        plt = pyplot()
        fig, ax = plt.subplots(figsize=(7, 5))
        sc = None
        for j in range(self.fixed_frame_hz.shape[1]):
            sc = ax.scatter(self.speeds, self.fixed_frame_hz[:, j], s=3, c=np.abs(self.harmonic[:, j]),
                            cmap="tab10", vmin=0, vmax=9)
        ax.plot(self.speeds, self.speeds * self.omega_ref / (2 * np.pi), "k--", lw=1, label="1X (synchronous)")
        fmax = fmax_hz or 1.3 * self.speeds[-1] * self.omega_ref / (2 * np.pi)
        ax.set_ylim(0, fmax)
        ax.set_xlabel("normalised spin speed Ω / Ω_ref")
        ax.set_ylabel("fixed-frame frequency [Hz]")
        ax.set_title("Campbell diagram (colour: |nodal diameter|)")
        if sc is not None:
            fig.colorbar(sc, ax=ax, label="|nodal diameter|")
        ax.legend(loc="upper left")
        ax.grid(alpha=0.3)
        return save_figure(fig, path)

    def save(self, out: str | Path) -> dict:
        return save_result(self, out, "campbell")


def run_campbell(model: Model, speed_max: float = 10.0, n_speeds: int = 60) -> CampbellResult:
    """Fixed-frame frequencies of all modes over 0..speed_max (normalised)."""
    _check_speed_range(1e-9, speed_max, max(n_speeds, 10))
    speeds = np.linspace(0.0, speed_max, n_speeds)
    rows_f, rows_r, rows_h = [], [], []
    for s in speeds:
        r = run_modes(model, float(s))
        rows_f.append(r.fixed_frame_hz)
        rows_r.append(r.eigenvalues.imag / (2 * np.pi))
        rows_h.append(r.harmonic)
    k = min(len(r) for r in rows_f)
    return CampbellResult(
        speeds,
        model.params.normalisation.omega_ref,
        np.array([r[:k] for r in rows_f]),
        np.array([r[:k] for r in rows_r]),
        np.array([r[:k] for r in rows_h]),
    )
