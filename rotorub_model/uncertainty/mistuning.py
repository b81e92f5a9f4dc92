"""Blade mistuning: per-blade stiffness or frequency scatter, its correlation, and the mistuned model.

A study file's ``[mistuning]`` table gives the scatter of one blade's deviation (``kind = "stiffness"``: the
relative stiffness deviation delta_j; ``"frequency"``: the relative deviation eps_j of the blade's
frequencies at rest, delta_j = (1 + eps_j)^2 - 1, the blade's mass being unchanged), its standard deviation
``sd``, its ``distribution`` (truncnormal, truncated at ``truncate`` standard deviations, default 3; uniform;
normal is refused: its support leaves delta > -1) and the ``correlation`` of neighbouring blades, decaying as
rho^d with the distance d around the disk (d = 1, 2, ... N/2): blades cut from one forging lot, or
ground in sequence, deviate together. Correlated deviations come from a Gaussian copula: independent
coordinates u_j of the unit cube (what the samplers draw), z = L Phi^-1(u) with L L^T the correlation matrix,
then each blade's marginal quantile at Phi(z_j). The copula keeps the marginals exact; the correlation of
the deviations themselves is that of the normals to within a few per cent for truncnormal marginals.

The mistuned model is the tuned one with blade j's stiffness and stiffness-proportional damping blocks
times (1 + delta_j): :func:`mistuned_model` does this on an assembled model in microseconds and gives the
same matrices, bit for bit, as ``build_model(params, mistuning=delta)`` (tests).

Examples
--------
>>> spec = MistuningSpec.from_table({"kind": "frequency", "sd": 0.02, "distribution": "truncnormal"}, 10)
>>> d = spec.deviations(np.full((1, 10), 0.5))
>>> bool(np.allclose(d, 0.0))
True
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import ParameterError
from ..structure.model import Model
from .distributions import Distribution

KINDS = ("stiffness", "frequency")
DISTRIBUTIONS = ("truncnormal", "uniform", "normal")
KEYS = ("kind", "sd", "distribution", "truncate", "correlation")


@dataclass(frozen=True)
class MistuningSpec:
    kind: str
    sd: float
    distribution: str
    truncate: float
    correlation: float
    n_blades: int

    @classmethod
    def from_table(cls, table: Any, n_blades: int, where: str = "mistuning") -> MistuningSpec:
        if not isinstance(table, dict):
            raise ParameterError(f"{where}: expected a table (kind, sd, distribution, truncate, correlation)")
        unknown = sorted(set(table) - set(KEYS))
        if unknown:
            raise ParameterError(f"{where}.{unknown[0]}: unknown key; accepted: {', '.join(KEYS)}")
        kind = table.get("kind", "stiffness")
        if kind not in KINDS:
            raise ParameterError(f"{where}.kind: {kind!r} unknown; accepted: {', '.join(KINDS)}")
        dist = table.get("distribution", "truncnormal")
        if dist not in DISTRIBUTIONS:
            raise ParameterError(f"{where}.distribution: {dist!r} unknown; accepted: {', '.join(DISTRIBUTIONS)}")
        nums = {}
        for k, default, lo, hi, rng in (("sd", None, 0.0, 0.3, "(0, 0.3]"), ("truncate", 3.0, 0.5, 6.0, "[0.5, 6]"),
                                        ("correlation", 0.0, 0.0, 0.99, "[0, 0.99]")):
            v = table.get(k, default)
            if v is None:
                raise ParameterError(f"{where}.{k}: missing (the standard deviation of one blade's relative "
                                     f"{kind} deviation, e.g. 0.02)")
            if isinstance(v, bool) or not isinstance(v, int | float) or not math.isfinite(v):
                raise ParameterError(f"{where}.{k}: expected a number in {rng}, got {v!r}")
            if not ((lo < v if k == "sd" else lo <= v) and v <= hi):
                raise ParameterError(f"{where}.{k}: {v!r} out of range; accepted range {rng}")
            nums[k] = float(v)
        spec = cls(kind, nums["sd"], dist, nums["truncate"], nums["correlation"], int(n_blades))
        lo, hi = spec.marginal.support()
        if not lo > -1.0:  # delta > -1 (a positive stiffness); for a frequency, eps > -1 likewise
            raise ParameterError(f"{where}.distribution: {dist} has support [{lo:g}, {hi:g}] which leaves the accepted "
                                 f"range of a blade's relative {kind} deviation, (-1, inf); use truncnormal "
                                 "(truncated at 'truncate' standard deviations) or uniform")
        spec.cholesky  # noqa: B018 - refuses a correlation that is not positive definite here
        return spec

    @property
    def marginal(self) -> Distribution:
        """One blade's deviation (eps for a frequency scatter, delta for a stiffness scatter), mean 0."""
        s = self.sd
        if self.distribution == "normal":
            return Distribution("normal", {"mean": 0.0, "sd": s})
        if self.distribution == "uniform":
            h = math.sqrt(3.0) * s  # the uniform with standard deviation sd
            return Distribution("uniform", {"low": -h, "high": h})
        t = self.truncate * s
        return Distribution("truncnormal", {"mean": 0.0, "sd": s, "low": -t, "high": t})

    @property
    def correlation_matrix(self) -> np.ndarray:
        N = self.n_blades
        i = np.arange(N)
        d = np.abs(i[:, None] - i[None, :])
        d = np.minimum(d, N - d)
        return self.correlation ** d if self.correlation > 0 else np.eye(N)

    @property
    def cholesky(self) -> np.ndarray:
        try:
            return np.linalg.cholesky(self.correlation_matrix)
        except np.linalg.LinAlgError:
            raise ParameterError(f"mistuning.correlation: {self.correlation:g} gives a correlation matrix that is not "
                                 f"positive definite for {self.n_blades} blades; accepted: a smaller value") from None

    def deviations(self, u: np.ndarray) -> np.ndarray:
        """Per-blade stiffness deviations delta (n, N) from unit-cube points u (n, N)."""
        from scipy.stats import norm

        u = np.atleast_2d(np.asarray(u, dtype=float))
        if u.shape[1] != self.n_blades:
            raise ParameterError(f"mistuning: {u.shape[1]} coordinates for {self.n_blades} blades")
        if self.correlation > 0:
            z = norm.ppf(np.clip(u, 1e-12, 1 - 1e-12)) @ self.cholesky.T
            u = norm.cdf(z)
        eps = self.marginal.ppf(u)
        return eps if self.kind == "stiffness" else (1.0 + eps) ** 2 - 1.0

    def summary(self) -> dict:
        return {"kind": self.kind, "sd": self.sd, "distribution": self.marginal.describe(),
                "correlation_neighbours": self.correlation, "blades": self.n_blades,
                "stiffness_factor": "1 + delta_j" if self.kind == "stiffness" else "(1 + eps_j)^2"}


def mistuned_model(model: Model, delta: np.ndarray | None) -> Model:
    """``model`` (tuned) with blade j's stiffness and stiffness-proportional damping times (1 + delta_j): the
    matrices of ``build_model(model.params, mistuning=delta)`` without assembling anything again. The blade
    blocks of the assembled K and D hold the blade's own matrices and nothing else (structure/blades.py), so
    scaling them in place is that assembly, to the last bit."""
    if delta is None or len(delta) == 0:
        return model
    if model.mistuning is not None:
        raise ParameterError("mistuning: the model is mistuned already; start from the tuned model")
    from ..structure.blades import check_mistuning

    d = check_mistuning(model.params, delta)
    K, D = model.K.copy(), model.D.copy()
    s0, nb = model.slices["blades"].start, model.blade_dofs
    for j, v in enumerate(d):
        sl = slice(s0 + j * nb, s0 + (j + 1) * nb)
        K[sl, sl] = (1.0 + v) * model.K[sl, sl]
        D[sl, sl] = (1.0 + v) * model.D[sl, sl]
    return dataclasses.replace(model, K=K, D=D, mistuning=d)


def blade_tip_deflections(model: Model, Q: np.ndarray) -> np.ndarray:
    """Each blade's elastic tip deflection |psi(l_b) . b_j| [m] (its own bending, relative to the disk; an
    imported blade: the length of its tip nodes' mean displacement) for states Q (..., n): shape (..., N). What
    the amplification factors compare (docs/THEORY.md section 10)."""
    from ..structure.blades import blade_functions

    p = model.params
    N, nb = p.blades.count, model.blade_dofs
    b = np.asarray(Q)[..., model.slices["blades"]].reshape(*np.shape(Q)[:-1], N, nb)
    if model.fe_blade is not None:  # an imported blade: its tip nodes' mean elastic displacement (blade frame)
        tip = model.fe_blade.tip_recovery.mean(axis=0)  # (3, m)
        return np.linalg.norm(b @ tip.T, axis=-1)
    psi_tip = blade_functions(p, p.blades.length)[0]  # (dofs,)
    return np.abs(b @ psi_tip)
