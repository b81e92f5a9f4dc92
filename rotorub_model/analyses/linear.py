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
from ..plotting import pyplot
from ..structure.model import Model
from ..writing import save_result


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
    warning: str = ""  # a response beyond what the model is written for

    def summary(self) -> dict:
        return {
            "critical_speeds": self.critical_speeds,
            "critical_speeds_rad_s": [c * self.omega_ref for c in self.critical_speeds],
            "peak_amplitudes_m": self.peak_amplitudes,
            "peak_tilts_rad": self.peak_tilts,
            "peak_ratio_first_to_second": (
                self.peak_amplitudes[0] / self.peak_amplitudes[1]
                if len(self.peak_amplitudes) > 1 and self.peak_amplitudes[1] > 0 else None
            ),
            "omega_ref_rad_s": self.omega_ref,
            "n_dofs": self.n_dofs,
            "speed_range": [float(self.speeds[0]), float(self.speeds[-1])],
            "note": "" if self.critical_speeds else
            f"no critical speed in [{self.speeds[0]:g}, {self.speeds[-1]:g}]: the response grows monotonically "
            "(the first critical lies beyond the range; the rub studies need one within the model's validity)",
            "warning": self.warning,
        }

    def figure(self):
        """The fan disk's response over the speed range, the critical speeds marked."""
        plt = pyplot()
        fig, ax = plt.subplots(figsize=(7, 4))
        if self.amplitude.any():
            ax.semilogy(self.speeds, self.amplitude * 1e3, lw=1.2)
            for c, a in zip(self.critical_speeds, self.peak_amplitudes):
                ax.plot(c, a * 1e3, "o", color="C3")
                ax.annotate(f"Ω={c:.2f}", (c, a * 1e3), textcoords="offset points", xytext=(5, 5))
            ax.set_ylim(top=4.0 * float(self.amplitude.max()) * 1e3)  # room for the peaks' labels
        else:  # no imbalance (imbalance.me = 0): no response, the critical speeds still are where they are
            ax.plot(self.speeds, self.amplitude * 1e3, lw=1.2)
            for c in self.critical_speeds:
                ax.axvline(c, color="C3", ls="--", lw=0.8)
                ax.annotate(f"critical Ω={c:.2f}", (c, 0.0), textcoords="offset points", xytext=(5, 5))
        ax.set_xlabel("normalised spin speed Ω / Ω_ref")
        ax.set_ylabel("fan-disk displacement [mm]")
        crit = ", ".join(f"{c:.3g}" for c in self.critical_speeds) or "none in the range"
        ax.set_title("Imbalance response at the fan disk" + ("" if self.amplitude.any() else
                                                               " (no imbalance: imbalance.me = 0)")
                     + f"\ncritical speeds Ω / Ω_ref: {crit}", fontsize=10)
        ax.set_xlim(float(self.speeds[0]), float(self.speeds[-1]))
        ax.grid(True, which="both", alpha=0.3)
        return fig

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
    me = model.params.imbalance.me if me is None else me
    scale = 1.0
    if me == 0.0:  # the response is linear in me: its peaks (the critical speeds) are found on a unit imbalance
        me, scale = 1.0, 0.0
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
    warning = ""
    r_tip = model.params.blades.tip_radius
    if scale and pamp and max(pamp) > 0.05 * r_tip:  # small rotations and a linear casing gap: a few mm, not dm
        warning = (f"the fan disk's peak displacement {max(pamp) * 1e3:.3g} mm is {100 * max(pamp) / r_tip:.2g} % of "
                   "the tip radius: beyond the small displacements the model is written for (too little damping "
                   "at the critical speed? the bearings' dampers act only where the bearings move)")
    return ResponseResult(speeds, wref, scale * amp, scale * tilt, crit, [scale * a for a in pamp],
                          [scale * a for a in ptilt], model.n_dofs, warning)


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
    N, nb = model.params.blades.count, model.blade_dofs
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

    def figure(self):
        """The modes in the fixed frame: frequency an observer sees against the damping ratio (log scale: the modes
        near Re λ = 0, which overlap on a real-part axis, spread out by frequency), coloured by nodal diameter,
        each labelled with it; a mode with a negative damping ratio (unstable) drawn red at the bottom."""
        from matplotlib.colors import BoundaryNorm, ListedColormap

        plt = pyplot()
        fig, ax = plt.subplots(figsize=(8, 4.6))
        h = np.abs(self.harmonic)
        top = max(int(h.max()), 1)
        cmap = ListedColormap(plt.get_cmap("tab10" if top < 10 else "tab20")(np.arange(top + 1)))
        norm = BoundaryNorm(np.arange(-0.5, top + 1.0), top + 1)
        z = np.asarray(self.damping_ratio, dtype=float)
        stable = z > 0
        floor = max(float(z[stable].min()) * 0.5, 1e-6) if stable.any() else 1e-4
        y = np.where(stable, z, floor)
        sc = ax.scatter(self.fixed_frame_hz, y, c=h, cmap=cmap, norm=norm, s=30, zorder=3,
                        edgecolors=np.where(stable, "none", "red"), linewidths=1.2)
        for f, yy, nd in zip(self.fixed_frame_hz, y, self.harmonic):
            ax.annotate(f"{int(nd):+d}" if nd else "0", (f, yy), textcoords="offset points", xytext=(3, 3),
                        fontsize=6.5, color="0.3")
        ax.set_yscale("log")
        cb = fig.colorbar(sc, ax=ax, ticks=range(top + 1))
        cb.set_label("|nodal diameter index| (the sign: + forward, − backward)")
        ax.set_xlabel("fixed-frame frequency [Hz] (what an observer on the casing sees)")
        ax.set_ylabel("damping ratio ζ (fixed frame) [-]")
        n_unstable = int((~stable).sum())
        ax.set_title(f"Modes at Ω = {self.speed:.3g} Ω_ref, fixed frame: {len(z)} modes, "
                     + (f"{n_unstable} unstable (red, drawn at the bottom)" if n_unstable else "all damped"),
                     fontsize=10)
        ax.grid(alpha=0.3, which="both")
        return fig

    def save(self, out: str | Path) -> dict:
        return save_result(self, out, "modes")


def _weight_columns(model: Model) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, list[int]]:
    """What harmonic_weights reads, as arrays: (x dof of each (x, y) pair, its harmonic n, its mass, the
    blade mass per function, the harmonic indices in harmonic_weights' order of first appearance, which
    is the order max() breaks ties in)."""
    Md = np.diag(model.M)
    ix, hn = [], []
    for i, name in enumerate(model.dofs):
        if name.endswith(".x"):
            ix.append(i)
            hn.append(int(name.split(".")[1][1:]) if name.startswith("casing.n") else 1)
    N, nb = model.params.blades.count, model.blade_dofs
    keys: dict[int, None] = {}
    for n in hn:
        keys.setdefault(n)
        keys.setdefault(-n)
    for k in range(N):
        keys.setdefault(-(k if k <= N // 2 else k - N))
    mb = Md[model.slices["blades"]].reshape(N, nb)[0]
    return np.array(ix, dtype=int), np.array(hn, dtype=int), Md[ix], mb, list(keys)


def _labels(model: Model, lam: np.ndarray, phi: np.ndarray, omega: float, cols=None) -> tuple[np.ndarray, np.ndarray]:
    """(fixed-frame frequency [Hz], nodal-diameter index) of every mode: harmonic_weights for all the
    columns of phi (n, k) at once, the index its largest weight's."""
    ix, hn, m, mb, keys = cols or _weight_columns(model)
    col = {h: c for c, h in enumerate(keys)}
    W = np.zeros((phi.shape[1], len(keys)))
    x, y = phi[ix], phi[ix + 1]
    fw, bw = m[:, None] * np.abs(x + 1j * y) ** 2 / 4, m[:, None] * np.abs(x - 1j * y) ** 2 / 4
    for r, n in enumerate(hn):
        W[:, col[n]] += fw[r]
        W[:, col[-n]] += bw[r]
    N = model.params.blades.count
    bl = phi[model.slices["blades"]].reshape(N, mb.size, -1)
    coef = np.fft.fft(bl, axis=0) / N
    wk = np.einsum("f,kfm->km", mb, np.abs(coef) ** 2) * N
    for k in range(N):
        W[:, col[-(k if k <= N // 2 else k - N)]] += wk[k]
    harm = np.array(keys)[np.argmax(W, axis=1)]
    return np.abs(lam.imag + harm * omega) / (2 * np.pi), harm


def _free_modes(model: Model, omegas: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
    """(eigenvalues, mode shapes (n, k)) of the contact-open model at each speed, the half with Im >= 0 as
    the dense problem's filter keeps it, solved per cyclic block (structure/cyclic.py): one block of each
    conjugate pair (the other holds the conjugates), the blocks of one size at all the speeds in one
    batched eigen-solve. The reference's real 76 x 76 problem becomes one complex 14 x 14 and a few 2 x 2
    and 4 x 4."""
    cb = model.cyclic
    omegas = np.asarray(omegas, dtype=float)
    S = len(omegas)
    w = omegas[:, None, None]
    solve = [i for i, j in enumerate(cb.conjugate) if i <= j]
    lams: list[list[np.ndarray]] = [[] for _ in omegas]
    phis: list[list[np.ndarray]] = [[] for _ in omegas]
    for k in sorted({len(cb.blocks[i]) for i in solve}, reverse=True):
        which = [i for i in solve if len(cb.blocks[i]) == k]
        A = np.zeros((len(which), S, 2 * k, 2 * k), dtype=complex)
        A[:, :, :k, k:] = np.eye(k)
        for r, i in enumerate(which):
            K0, Ks, K1, C0, C1 = cb.parts[i]
            A[r, :, k:, :k] = -(K0 + w * w * Ks + w * K1)
            if cb.quartic is not None:  # an imported blade's Omega^4 prestress term
                A[r, :, k:, :k] -= (w * w) ** 2 * cb.quartic[i]
            A[r, :, k:, k:] = -(C0 + w * C1)
        lam, vec = np.linalg.eig(A)
        phi = np.einsum("nk,rskm->rsnm", cb.T[:, cb.blocks[which[0]]], vec[:, :, :k, :]) if len(which) == 1 else \
            np.stack([np.einsum("nk,skm->snm", cb.T[:, cb.blocks[i]], vec[r, :, :k, :]) for r, i in enumerate(which)])
        for r, i in enumerate(which):
            paired = cb.conjugate[i] != i
            for s in range(S):
                la, ph = lam[r, s], phi[r, s]
                up = la.imag >= -1e-9
                lams[s].append(la[up])
                phis[s].append(ph[:, up])
                if paired:  # the conjugate block's modes: (conj lambda, conj phi)
                    dn = la.imag <= 1e-9
                    lams[s].append(la[dn].conj())
                    phis[s].append(ph[:, dn].conj())
    return [(np.concatenate(lams[s]), np.hstack(phis[s])) for s in range(S)]


def _modes_at(model: Model, speed: float, lam: np.ndarray, phi: np.ndarray, cols=None) -> ModesResult:
    omega = speed * model.params.normalisation.omega_ref
    keep = lam.imag >= -1e-9  # a conjugate pair once (the free modes come filtered already)
    lam, phi = lam[keep], phi[:, keep]
    order = np.argsort(np.abs(lam.imag), kind="stable")
    lam, phi = lam[order], phi[:, order]
    fixed, harm = _labels(model, lam, phi, omega, cols)
    # The damping ratio belongs to the motion an observer sees: a mode whose rotating-frame
    # frequency is near zero (the critical mode near its critical speed) would otherwise read
    # zeta ~ 1 from |lambda| ~ |Re lambda|, while in the fixed frame it whirls at ~Omega.
    zeta = -lam.real / np.maximum(np.hypot(lam.real, 2 * np.pi * fixed), 1e-300)
    return ModesResult(speed, lam, fixed, harm, zeta)


def run_modes(model: Model, speed: float, K_extra: np.ndarray | None = None) -> ModesResult:
    """Eigenvalues at normalised speed ``speed`` with fixed-frame labelling. The free model (no
    ``K_extra``) is solved block by block (cyclic symmetry); with a contact stiffness, whole."""
    if not np.isfinite(speed) or speed < 0:
        raise ParameterError(f"speed: {speed} out of range; accepted range [0, inf) (normalised)")
    omega = speed * model.params.normalisation.omega_ref
    if K_extra is None:
        lam, phi = _free_modes(model, np.array([omega]))[0]
    else:
        lam, vec = np.linalg.eig(first_order(model, omega, K_extra))
        phi = vec[: model.n_dofs]
    return _modes_at(model, float(speed), lam, phi)


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

    def figure(self, fmax_hz: float | None = None):
        """Every mode's fixed-frame frequency at every speed as a dot coloured by its nodal diameter (a branch of
        nodal diameter m climbs or falls m Ω per unit of rotating-frame frequency: the steep ones are high nodal
        diameters, their dots a speed step apart), the 1X line; up to 1.3 x the top speed's 1X."""
        from matplotlib.lines import Line2D

        plt = pyplot()
        fig, ax = plt.subplots(figsize=(7, 5.6), layout="constrained")
        nd = np.abs(self.harmonic)
        top = max(int(nd.max()), 1)
        # one colour per nodal diameter (a discrete scale: colour means the index, not a shade of it)
        cmap = pyplot().get_cmap("tab10" if top < 10 else "tab20", top + 1)
        dots = 3 if len(self.speeds) > 100 else 8
        S = np.repeat(self.speeds[:, None], nd.shape[1], axis=1)
        sc = ax.scatter(S.ravel(), self.fixed_frame_hz.ravel(), s=dots, c=nd.ravel(), cmap=cmap, vmin=-0.5,
                        vmax=top + 0.5, linewidths=0)
        ax.plot(self.speeds, self.speeds * self.omega_ref / (2 * np.pi), "k--", lw=1, label="1X (synchronous)")
        fmax = fmax_hz or 1.3 * self.speeds[-1] * self.omega_ref / (2 * np.pi)
        ax.set_ylim(0, fmax)
        ax.set_xlabel("normalised spin speed Ω / Ω_ref")
        ax.set_ylabel("fixed-frame frequency [Hz]")
        ax.set_title(f"Campbell diagram ({len(self.speeds)} speeds)")
        fig.colorbar(sc, ax=ax, label="|nodal diameter index|", ticks=range(top + 1))
        dot = Line2D([], [], ls="none", marker="o", ms=3, color="0.4",
                     label="one mode at one speed, coloured by its nodal diameter (the steep branches, high nodal "
                           "diameters,\nclimb m Ω per speed step and so read as dotted lines)")
        h, _ = ax.get_legend_handles_labels()
        fig.legend(handles=[*h, dot], loc="outside lower center", fontsize=7.5, frameon=False)
        ax.grid(alpha=0.3)
        return fig

    def save(self, out: str | Path) -> dict:
        return save_result(self, out, "campbell")


def run_campbell(model: Model, speed_max: float = 10.0, n_speeds: int = 60) -> CampbellResult:
    """Fixed-frame frequencies of all modes over 0..speed_max (normalised)."""
    _check_speed_range(1e-9, speed_max, max(n_speeds, 10))
    speeds = np.linspace(0.0, speed_max, n_speeds)
    rows_f, rows_r, rows_h = [], [], []
    cols = _weight_columns(model)
    for s, (lam, phi) in zip(speeds, _free_modes(model, speeds * model.params.normalisation.omega_ref)):
        r = _modes_at(model, float(s), lam, phi, cols)
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
