"""Probability distributions of the uncertain inputs, as a study file writes them.

Each is a scipy.stats distribution behind a small, checked front: the study file names it and gives its
parameters in the input's own unit (SI), and the samplers only ever call :meth:`Distribution.ppf` on points
of the unit cube (quasi-Monte Carlo, SALib's Sobol' and Morris designs), so that one mapping serves every
method. The support is what the checks against a parameter's accepted range read.

Examples
--------
>>> d = make_distribution("g0", {"distribution": "normal", "mean": 1e-3, "sd": 1e-4})
>>> round(float(d.ppf(0.5)), 6), d.support()
(0.001, (-inf, inf))
>>> make_distribution("mu", {"distribution": "uniform", "low": 0.1, "high": 0.2}).variance > 0
True
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..errors import ParameterError

# the parameters each distribution takes (all required), in the order they are written
KINDS: dict[str, tuple[str, ...]] = {
    "normal": ("mean", "sd"),
    "truncnormal": ("mean", "sd", "low", "high"),
    "uniform": ("low", "high"),
    "lognormal": ("mean", "sd"),
    "triangular": ("low", "mode", "high"),
    "fixed": ("value",),
}
# a point of the unit cube is kept this far from 0 and 1: a scrambled Sobol' point may fall on 0 exactly
# (probability 2^-32 per coordinate), where an unbounded distribution's quantile is infinite
U_EPS = 1e-12


@dataclass(frozen=True)
class Distribution:
    """One input's distribution: ``kind`` (a key of :data:`KINDS`) and its parameters."""

    kind: str
    params: dict[str, float] = field(hash=False)

    @property
    def frozen(self):
        """The scipy.stats frozen distribution (None for ``fixed``)."""
        from scipy import stats

        p = self.params
        if self.kind == "normal":
            return stats.norm(p["mean"], p["sd"])
        if self.kind == "truncnormal":
            a, b = (p["low"] - p["mean"]) / p["sd"], (p["high"] - p["mean"]) / p["sd"]
            return stats.truncnorm(a, b, loc=p["mean"], scale=p["sd"])
        if self.kind == "uniform":
            return stats.uniform(p["low"], p["high"] - p["low"])
        if self.kind == "lognormal":
            # mean and sd of the variable itself (what a drawing's tolerance gives), not of its log
            s2 = math.log1p((p["sd"] / p["mean"]) ** 2)
            return stats.lognorm(math.sqrt(s2), scale=p["mean"] * math.exp(-0.5 * s2))
        if self.kind == "triangular":
            w = p["high"] - p["low"]
            return stats.triang((p["mode"] - p["low"]) / w, loc=p["low"], scale=w)
        return None

    def ppf(self, u: np.ndarray | float) -> np.ndarray:
        """Quantiles at the unit-cube coordinates ``u`` (kept within [U_EPS, 1 - U_EPS])."""
        u = np.clip(np.asarray(u, dtype=float), U_EPS, 1.0 - U_EPS)
        if self.kind == "fixed":
            return np.full(u.shape, self.params["value"])
        return self.frozen.ppf(u)

    def cdf(self, x: np.ndarray | float) -> np.ndarray:
        if self.kind == "fixed":
            return (np.asarray(x, dtype=float) >= self.params["value"]).astype(float)
        return self.frozen.cdf(x)

    def support(self) -> tuple[float, float]:
        """(lowest, highest) value the distribution can take."""
        p = self.params
        if self.kind == "fixed":
            return p["value"], p["value"]
        if self.kind in ("truncnormal", "uniform", "triangular"):
            return p["low"], p["high"]
        if self.kind == "lognormal":
            return 0.0, math.inf
        return -math.inf, math.inf

    @property
    def mean(self) -> float:
        return float(self.params["value"]) if self.kind == "fixed" else float(self.frozen.mean())

    @property
    def variance(self) -> float:
        return 0.0 if self.kind == "fixed" else float(self.frozen.var())

    def describe(self) -> str:
        return f"{self.kind}(" + ", ".join(f"{k}={self.params[k]:g}" for k in KINDS[self.kind]) + ")"

    def to_openturns(self):
        """The same distribution in OpenTURNS (FORM and subset sampling work in its standard space)."""
        import openturns as ot

        p = self.params
        if self.kind == "normal":
            return ot.Normal(p["mean"], p["sd"])
        if self.kind == "truncnormal":
            return ot.TruncatedNormal(p["mean"], p["sd"], p["low"], p["high"])
        if self.kind == "uniform":
            return ot.Uniform(p["low"], p["high"])
        if self.kind == "lognormal":
            return ot.LogNormalMuSigma(p["mean"], p["sd"]).getDistribution()
        if self.kind == "triangular":
            return ot.Triangular(p["low"], p["mode"], p["high"])
        return ot.Dirac(p["value"])


def make_distribution(where: str, table: dict[str, Any]) -> Distribution:
    """A :class:`Distribution` from a study file's table (``distribution`` plus its parameters), checked:
    unknown kind or key, missing or non-finite parameter, inconsistent bounds get one line naming ``where``."""
    if not isinstance(table, dict):
        raise ParameterError(f"{where}: expected a table with 'distribution' and its parameters")
    kind = table.get("distribution")
    if kind not in KINDS:
        raise ParameterError(f"{where}.distribution: {kind!r} unknown; accepted: {', '.join(KINDS)}")
    need = KINDS[kind]
    params: dict[str, float] = {}
    for k in need:
        if k not in table:
            raise ParameterError(f"{where}.{k}: missing (a {kind} distribution takes {', '.join(need)})")
        v = table[k]
        if isinstance(v, bool) or not isinstance(v, int | float) or not math.isfinite(v):
            raise ParameterError(f"{where}.{k}: expected a finite number, got {v!r}")
        params[k] = float(v)
    p = params
    if "sd" in p and not p["sd"] > 0:
        raise ParameterError(f"{where}.sd: {p['sd']:g} out of range; accepted range (0, inf) (a zero spread is "
                             "distribution = \"fixed\")")
    if "low" in p and not p["low"] < p["high"]:
        raise ParameterError(f"{where}.low: {p['low']:g} must be below high = {p['high']:g}")
    if kind == "truncnormal" and not p["low"] <= p["mean"] <= p["high"]:
        raise ParameterError(f"{where}.mean: {p['mean']:g} outside [low, high] = [{p['low']:g}, {p['high']:g}]")
    if kind == "triangular" and not p["low"] <= p["mode"] <= p["high"]:
        raise ParameterError(f"{where}.mode: {p['mode']:g} outside [low, high] = [{p['low']:g}, {p['high']:g}]")
    if kind == "lognormal" and not p["mean"] > 0:
        raise ParameterError(f"{where}.mean: {p['mean']:g} out of range; accepted range (0, inf) (lognormal)")
    return Distribution(kind, params)
