"""Balanced static solutions with contact (eq. 10): K(Omega) q0 = F_nl(q0) + F(Omega^2).

Newton's method on R(q) = K(Omega) q - F_nl(q) - F with the analytic contact
Jacobian and a backtracking line search on |R|. The contact forces are piecewise
smooth (2D: piecewise linear), so a full Newton step can jump between contact
states and cycle. Near the critical speed the contact stiffening bends the
resonance (as a hardening Duffing oscillator): the solution branch followed by a
continuation in g0 or in the imbalance can end at a fold, beyond which the
equilibrium lies on another branch. So when Newton fails from the warm start, it
is restarted from a set of candidates: the linear response, the responses with
all contacts closed (full and half stiffness), scaled linear responses, and a
continuation in the imbalance. The first converged one is returned; the result
always says whether it converged and with what residual.

Examples
--------
>>> from rotorub_model.structure.model import build_model
>>> from rotorub_model.contact import make_contact
>>> m = build_model()
>>> r = solve_static(m, make_contact(m, "3D", g0=0.2e-3), 3.3 * 53.4)
>>> r.converged, r.n_contact
(True, 4)
"""

from __future__ import annotations

import ctypes
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from .. import kernel
from ..contact import ContactModel
from ..errors import ConvergenceError, ParameterError
from ..structure.model import Model

if TYPE_CHECKING:
    from .stability import StabilityResult


@dataclass
class StaticResult:
    q: np.ndarray
    omega: float  # rad/s
    g0: float
    converged: bool
    residual: float  # |R| / |F|
    iterations: int
    n_contact: int
    fractions: np.ndarray  # chord fraction in contact per blade (2D: 0/1)
    forces_N: np.ndarray  # F_N per blade
    gaps: np.ndarray | None = None  # (N, points) [m] at q: 2D the tip, 3D the leading and trailing edges
    formulation: str = ""
    omega_ref: float | None = None  # [rad/s] to state the speed normalised
    stability: StabilityResult | None = None  # run_static fills it: the eigen-analysis about q

    def summary(self) -> dict:
        s = {
            "formulation": self.formulation,
            "omega_rad_s": self.omega,
            "speed": None if not self.omega_ref else self.omega / self.omega_ref,
            "g0_m": self.g0,
            "converged": self.converged,
            "relative_residual": self.residual,
            "iterations": self.iterations,
            "blades_in_contact": self.n_contact,
            "chord_fractions": self.fractions,
            "normal_forces_N": self.forces_N,
        }
        if self.stability is not None:
            s["stability"] = self.stability.summary()
        s["verdict"] = self.verdict()
        return s

    def verdict(self) -> str:
        """The outcome in words: converged or not, blades touching, stable or not (with the leading eigenvalue)."""
        if not self.converged:
            return (f"no balanced solution found (relative residual {self.residual:.2g} after {self.iterations} "
                    "iterations)")
        touch = f"{self.n_contact} blade{'s' if self.n_contact != 1 else ''} in contact"
        if self.stability is None:
            return f"balanced solution, {touch} (stability not computed)"
        st = self.stability
        return (f"balanced solution, {touch}, max F_N {float(np.max(self.forces_N, initial=0.0)):.4g} N; "
                + ("stable" if st.stable else f"UNSTABLE ({len(st.unstable_modes)} mode"
                   f"{'s' if len(st.unstable_modes) != 1 else ''})") + f": max Re λ = {st.max_real:+.3g} 1/s")

    def figure(self):
        """Forces per blade and gaps per blade (and edge), the verdict in the title; with the stability, a third
        panel of its eigenvalues (:meth:`StabilityResult.draw`)."""
        from ..plotting import pyplot

        plt = pyplot()
        n = 3 if self.stability is not None else 2
        fig, axes = plt.subplots(1, n, figsize=(4.4 * n, 3.9), layout="constrained")
        x = np.arange(1, len(self.forces_N) + 1)
        axes[0].bar(x, self.forces_N, color="C0")
        axes[0].set_xlabel("blade")
        axes[0].set_ylabel("normal contact force F_N [N]")
        axes[0].set_xticks(x)
        if self.gaps is not None:
            g = np.atleast_2d(self.gaps) * 1e3
            names = ("tip",) if g.shape[1] == 1 else ("leading edge", "trailing edge")
            for k in range(g.shape[1]):
                axes[1].plot(x, g[:, k], "o-", label=names[k] if k < len(names) else f"point {k}")
            axes[1].axhline(0, color="k", lw=0.8, label="casing (gap 0)")
            axes[1].legend(fontsize=7.5)
        axes[1].set_xlabel("blade")
        axes[1].set_ylabel("gap [mm] (< 0: in contact)")
        axes[1].set_xticks(x)
        for ax in axes[:2]:
            ax.grid(alpha=0.3)
        if self.stability is not None:
            self.stability.draw(axes[2])
        speed = f"Ω = {self.omega / self.omega_ref:.4g} Ω_ref" if self.omega_ref else f"Ω = {self.omega:.4g} rad/s"
        fig.suptitle(f"{self.formulation} static solution at {speed}, g0 = {self.g0 * 1e3:.4g} mm: {self.verdict()}",
                     fontsize=9.5)
        return fig

    def save(self, out: str | Path, stem: str = "static") -> dict:
        """``<stem>.png`` and ``<stem>.json`` (the summary, with the stability) in ``out``; returns the summary."""
        from ..writing import save_result

        return save_result(self, out, stem)


def _check_omega(omega: float) -> None:
    if not np.isfinite(omega) or omega < 0:
        raise ParameterError(f"omega: {omega} out of range; accepted range [0, inf) rad/s")


def solve_static(
    model: Model,
    contact: ContactModel,
    omega: float,
    me: float | None = None,
    q0: np.ndarray | None = None,
    tol: float = 1e-10,
    max_iter: int = 60,
    raise_on_failure: bool = False,
) -> StaticResult:
    """Balanced static solution at spin speed omega [rad/s], warm-started from q0.

    Starts from q0 (default: the linear response, which is exact when nothing
    touches); if Newton fails, continues in the imbalance from 0 to m e.
    """
    _check_omega(omega)
    K = np.ascontiguousarray(model.K_omega(omega), dtype=float)
    F = np.ascontiguousarray(model.force(omega, me), dtype=float)
    n = model.n_dofs
    q = np.empty(n)
    start = None if q0 is None else np.ascontiguousarray(q0, dtype=float)
    rel, its = ctypes.c_double(), ctypes.c_int()
    work = np.empty(contact.lib.rr_static_work_size(n))
    iwork = np.empty(n, dtype=np.intc)
    # Newton, its starts and the imbalance continuation run in the kernel (one call): the FMUs'
    # quasi-static steps are the same code
    ok = bool(contact.lib.rr_static_solve(
        contact.kernel, float(omega), kernel.ptr(K), kernel.ptr(F), None if start is None else kernel.ptr(start),
        float(tol), int(max_iter), kernel.ptr(q), ctypes.byref(rel), ctypes.byref(its), kernel.ptr(work),
        kernel.iptr(iwork)))
    rel, its = rel.value, its.value
    if not ok and raise_on_failure:
        raise ConvergenceError(
            f"static solution at omega={omega:g} rad/s, g0={contact.g0:g} m did not converge "
            f"(relative residual {rel:.2e} after {its} iterations)"
        )
    bf = contact.blade_forces(q, omega)
    return StaticResult(
        q=q,
        omega=float(omega),
        g0=contact.g0,
        converged=bool(ok),
        residual=float(rel),
        iterations=int(its),
        n_contact=int(np.sum(bf["F_N"] > 0)),
        fractions=bf["fraction"],
        forces_N=bf["F_N"],
        formulation=contact.formulation,
        omega_ref=model.params.normalisation.omega_ref,
    )


def run_static(model: Model, contact: ContactModel, omega: float, me: float | None = None) -> StaticResult:
    """The balanced static solution at spin ``omega`` [rad/s] and, where it converged, its stability (eq. 11), with
    the gaps for its figure: what ``rotorub static`` computes, saves and draws (``run_static(...).save(dir)``)."""
    from .stability import stability_of

    st = solve_static(model, contact, omega, me)
    st.gaps = contact.gaps(st.q)
    if st.converged:
        st.stability = stability_of(model, contact, omega, st.q)
    return st
