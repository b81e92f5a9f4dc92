"""What the blades' Ritz discretisation costs: frequencies against the number of functions.

Two views, both on the blade alone (clamped on a fixed disk, the blade block of the model's
matrices, so exactly what the model computes):

* the uniform rotating cantilever of the literature (hub radius 0), in units of
  sqrt(EI / (rho A l^4)): first flapwise mode (bending out of the rotation plane, stagger 90 deg)
  and first lagwise mode (in the plane, stagger 0: spin softening lowers lambda^2 by mu^2),
  for mu = Omega / sqrt(EI / (rho A l^4)) = 0..10;
* the configuration's own blade (its hub radius and stagger) over the model's speed range: the
  first bending frequency with n functions against the converged value;
* the blade basis reduced to ``n_modes`` functions (modes at rest and at the top speed,
  structure/blades.py): the first two frequencies of the configuration's blade over the speed range
  against the converged ones, and the highest frequency the kept functions bring in (what sets the
  explicit time step), for a few (n_ritz, n_modes) and the configuration's own.

``run_blade_convergence`` returns a result that tabulates, plots and saves itself.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..plotting import pyplot
from ..structure.blades import bladed_disk_matrices
from ..structure.params import Parameters
from ..writing import save_result

N_CONVERGED = 8  # functions of the converged reference (flap and lag agree with 10 to 1e-5)


def blade_unit(p: Parameters) -> float:
    """sqrt(E I / (rho A l^4)) of the blade [rad/s]."""
    b = p.blades
    return float(np.sqrt(b.E * b.second_moment / (b.rho * b.area * b.length**4)))


def full(p: Parameters, n_ritz: int) -> Parameters:
    """``p`` with ``n_ritz`` polynomials, all kept (no reduction)."""
    return p.replace(blades={"n_ritz": n_ritz, "n_modes": n_ritz})


def blade_block(p: Parameters) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(K, M, S2 + N2) of blade 1 with the disk held fixed."""
    mats = bladed_disk_matrices(p)
    ns = 2 * p.shaft.n_ritz
    sl = slice(ns, ns + p.blades.dofs)
    return mats.K[sl, sl], mats.M[sl, sl], (mats.S2 + mats.N2)[sl, sl]


def frequencies(p: Parameters, omega: float) -> np.ndarray:
    """Bending frequencies of a blade of ``p`` at spin speed omega [rad/s] (rotating frame), ascending."""
    K, M, KS = blade_block(p)
    lam = np.linalg.eigvals(np.linalg.solve(M, K + omega * omega * KS)).real
    return np.sqrt(np.sort(lam))


def first_frequency(p: Parameters, omega: float) -> float:
    """First bending frequency of a blade of ``p`` at spin speed omega [rad/s] (rotating frame)."""
    return float(frequencies(p, omega)[0])


def rotating_cantilever(p: Parameters, n_ritz: int, stagger_deg: float, mus: np.ndarray) -> np.ndarray:
    """First frequency of the uniform rotating cantilever (hub radius 0) with n_ritz functions,
    nondimensional, at nondimensional speeds mus; stagger 90: flapwise, 0: lagwise."""
    q = full(p, n_ritz).replace(blades={"stagger_deg": stagger_deg, "hub_radius": 1e-9})
    u = blade_unit(q)
    K, M, KS = blade_block(q)
    out = []
    for mu in mus:
        lam = np.linalg.eigvals(np.linalg.solve(M, K + (mu * u) ** 2 * KS)).real
        out.append(np.sqrt(lam.min()) / u)
    return np.array(out)


@dataclass
class BladeConvergence:
    n_values: list[int]
    mus: np.ndarray  # nondimensional speeds of the cantilever table
    flap: dict[int, np.ndarray]  # n -> first flapwise lambda at each mu
    lag: dict[int, np.ndarray]  # n -> first lagwise lambda at each mu
    speeds: np.ndarray  # [rad/s] the configuration's speed range
    blade_hz: dict[int, np.ndarray]  # n -> first bending frequency of the configuration's blade [Hz]
    n_model: int  # the configuration's n_ritz
    # (n_ritz, n_modes) -> (speeds, 2) first two frequencies [Hz] and the highest one at the top speed [Hz]
    reduced: dict[tuple[int, int], tuple[np.ndarray, float]]
    model_basis: tuple[int, int]  # the configuration's (n_ritz, n_modes)

    def error(self, kind: str, n: int) -> np.ndarray:
        """Relative error of n functions against the converged reference."""
        d = {"flap": self.flap, "lag": self.lag, "blade": self.blade_hz}[kind]
        return d[n] / d[N_CONVERGED] - 1.0

    def reduced_errors(self, key: tuple[int, int]) -> tuple[float, float, float]:
        """(worst relative error of the first, of the second frequency over the speed range, highest
        frequency [Hz]) of the blade with ``key`` = (n_ritz, n_modes) against the converged blade."""
        f, top = self.reduced[key]
        ref = self.reduced[(N_CONVERGED, N_CONVERGED)][0]
        e = np.abs(f / ref - 1.0).max(axis=0)
        return float(e[0]), float(e[1]) if f.shape[1] > 1 and np.isfinite(e[1]) else float("nan"), top

    def summary(self) -> dict:
        f_model, _ = self.reduced[self.model_basis]
        cost = f_model[:, 0] / self.reduced[(N_CONVERGED, N_CONVERGED)][0][:, 0] - 1.0
        k = int(np.argmax(np.abs(cost)))
        red = {f"{nr}/{nm}": dict(zip(("first_max_error", "second_max_error", "highest_hz"),
                                      self.reduced_errors((nr, nm)))) for nr, nm in self.reduced}
        return {
            "n_ritz_of_the_model": self.n_model,
            "blade_basis_of_the_model": {"n_ritz": self.model_basis[0], "n_modes": self.model_basis[1]},
            "reduced_bases": red,
            "cantilever_mu": self.mus,
            "flap_max_error": {n: float(np.abs(self.error("flap", n)).max()) for n in self.n_values},
            "lag_max_error": {n: float(np.abs(self.error("lag", n)).max()) for n in self.n_values},
            "model_blade_max_error": float(cost[k]),
            "model_blade_max_error_at_rad_s": float(self.speeds[k]),
            "model_blade_error_at_rest": float(cost[0]),
            "model_blade_hz_converged_at_rest_and_top": [float(self.blade_hz[N_CONVERGED][0]),
                                                         float(self.blade_hz[N_CONVERGED][-1])],
        }

    def table_markdown(self, mus: tuple[float, ...] = (0.0, 5.0, 10.0)) -> str:
        """Flap and lag errors against n at a few speeds (the theory notes' table)."""
        idx = [int(np.argmin(np.abs(self.mus - m))) for m in mus]
        head = "| n_ritz | " + " | ".join(f"flap mu={self.mus[i]:g}" for i in idx) + " | " + \
               " | ".join(f"lag mu={self.mus[i]:g}" for i in idx) + " | reference blade, worst over 0-speed_max |"
        rows = [head, "|" + "---|" * (2 + 2 * len(idx))]
        for n in self.n_values:
            f, g = self.error("flap", n), self.error("lag", n)
            cells = [f"{100 * f[i]:+.3f} %" for i in idx] + [f"{100 * g[i]:+.3f} %" for i in idx]
            cells.append(f"{100 * np.abs(self.error('blade', n)).max():.3f} %")
            rows.append(f"| {n} | " + " | ".join(cells) + " |")
        return "\n".join(rows)

    def reduction_markdown(self) -> str:
        """The reduced bases' table (docs/THEORY.md): accuracy against what they cost in time step."""
        ref_top = self.reduced[(N_CONVERGED, N_CONVERGED)][1]
        rows = ["| n_ritz | n_modes | dofs per blade | first frequency, worst over 0-speed_max | second | "
                "highest frequency at speed_max |", "|---|---|---|---|---|---|"]
        for (nr, nm) in self.reduced:
            if (nr, nm) == (N_CONVERGED, N_CONVERGED):
                continue
            e1, e2, top = self.reduced_errors((nr, nm))
            mark = " (this configuration)" if (nr, nm) == self.model_basis else ""
            rows.append(f"| {nr} | {nm}{mark} | {min(nr, nm)} | {100 * e1:.3f} % | "
                        f"{'-' if e2 != e2 else f'{100 * e2:.2f} %'} | {top:.0f} Hz |")
        rows.append(f"| {N_CONVERGED} (converged) | {N_CONVERGED} | {N_CONVERGED} | 0 | 0 | {ref_top:.0f} Hz |")
        return "\n".join(rows)

    def figure(self):
        """Error against n: one colour per number of functions in both panels (flap solid, lag dashed; the
        reduced bases in their n_ritz's colour, a line style and marker per n_modes), legends outside."""
        from ..plotting import legend_outside

        plt = pyplot()
        fig, axes = plt.subplots(1, 2, figsize=(12, 4.4))
        ns = sorted({*self.n_values, *(nr for nr, _ in self.reduced)} - {N_CONVERGED})
        colour = dict(zip(ns, plt.get_cmap("viridis")(np.linspace(0.0, 0.9, len(ns)))))
        colour[N_CONVERGED] = "k"
        floor = 1e-6  # [%] where an error below the plot's resolution is drawn (log axis)
        for n in self.n_values:
            if n == N_CONVERGED:
                continue
            axes[0].semilogy(self.mus, np.abs(self.error("flap", n)) * 100 + floor, "-", color=colour[n], lw=1.4,
                             label=f"n_ritz = {n}")
            axes[0].semilogy(self.mus, np.abs(self.error("lag", n)) * 100 + floor, "--", color=colour[n], lw=1.4)
            axes[1].semilogy(self.speeds, np.abs(self.error("blade", n)) * 100 + floor, "-", color=colour[n], lw=1.4,
                             label=f"n_ritz = {n} (all kept)")
        axes[0].set_xlabel("μ = Ω / √(EI / ρA l⁴) [-]")
        axes[0].set_ylabel("|error| of the first frequency [%]")
        axes[0].set_title("uniform rotating cantilever (hub radius 0)")
        axes[0].plot([], [], color="0.3", ls="-", label="flap (solid)")  # the line styles' key
        axes[0].plot([], [], color="0.3", ls="--", label="lag (dashed)")
        ref = self.reduced[(N_CONVERGED, N_CONVERGED)][0][:, 0]
        styles = {2: (":", "o"), 3: ("-.", "s"), 4: ((0, (1, 1, 3, 1)), "^")}
        for (nr, nm), (f, _) in self.reduced.items():
            if nm < nr:
                ls, mk = styles.get(nm, ("--", "x"))
                axes[1].semilogy(self.speeds, np.abs(f[:, 0] / ref - 1) * 100 + floor, ls=ls, marker=mk, ms=3.5,
                                 color=colour.get(nr, "0.4"), lw=1.2, label=f"n_ritz = {nr}, n_modes = {nm}")
        axes[1].set_xlabel("spin speed Ω [rad/s]")
        axes[1].set_ylabel("|error| of the first frequency [%]")
        axes[1].set_title(f"the configuration's blade (model: n_ritz = {self.model_basis[0]}, "
                          f"n_modes = {self.model_basis[1]})")
        for ax in axes:
            ax.grid(alpha=0.3, which="both")
            legend_outside(ax)
        return fig

    def save(self, out: str | Path) -> dict:
        s = save_result(self, out, "blade_convergence")
        (Path(out) / "blade_convergence.md").write_text(self.table_markdown() + "\n\n" + self.reduction_markdown()
                                                        + "\n")
        return s


REDUCED = ((2, 2), (5, 5), (5, 2), (5, 3), (5, 4), (8, 2), (8, 3), (8, 4))  # (n_ritz, n_modes) of the table


def run_blade_convergence(p: Parameters, n_values: tuple[int, ...] = (2, 3, 4, 5, 6, N_CONVERGED),
                          n_speeds: int = 25) -> BladeConvergence:
    """Flap and lag frequencies of the rotating cantilever (mu = 0..10) and of the configuration's
    blade over 0..speed_max omega_ref, for each number of Ritz functions; and the reduced bases."""
    ns = sorted(set(n_values) | {N_CONVERGED, p.blades.n_ritz})
    mus = np.arange(11.0)
    flap = {n: rotating_cantilever(p, n, 90.0, mus) for n in ns}
    lag = {n: rotating_cantilever(p, n, 0.0, mus) for n in ns}
    speeds = np.linspace(0.0, p.normalisation.speed_max * p.normalisation.omega_ref, n_speeds)
    blade = {}
    for n in ns:
        blade[n] = np.array([first_frequency(full(p, n), w) for w in speeds]) / (2 * np.pi)
    model_basis = (p.blades.n_ritz, p.blades.dofs)
    reduced = {}
    for nr, nm in dict.fromkeys((*REDUCED, model_basis, (N_CONVERGED, N_CONVERGED))):
        q = p.replace(blades={"n_ritz": nr, "n_modes": nm})
        f = [frequencies(q, w) for w in speeds]
        two = np.array([np.pad(x[:2], (0, 2 - min(2, x.size)), constant_values=np.nan) for x in f])
        reduced[(nr, nm)] = (two / (2 * np.pi), float(f[-1][-1] / (2 * np.pi)))
    return BladeConvergence(ns, mus, flap, lag, speeds, blade, p.blades.n_ritz, reduced, model_basis)
