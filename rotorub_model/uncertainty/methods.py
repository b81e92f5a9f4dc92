"""Sampling designs and their analyses, from the field's libraries: scipy.stats.qmc and SALib.

The samplers draw points of the unit cube (one coordinate per input, one per blade when mistuned); the
inputs' quantiles map them to physical values (distributions.py, mistuning.py); our evaluations run on
the project's executor; the libraries analyse what comes back. Nothing statistical is written by hand but
the bookkeeping of the randomised-QMC replicates and the order-statistic intervals of quantiles.

Intervals (confidence c, default 0.95; docs/THEORY.md section 10):

* randomised QMC (``sampler = "qmc"``): R independent scramblings of n Sobol' points (scipy.stats.qmc.Sobol,
  Owen scrambling); each replicate's estimate is unbiased and the R of them are independent, so the
  interval is mean +- t_{R-1} s / sqrt(R), but for a probability never narrower than +- 1/n: a replicate
  resolves no finer (its estimate is a count over n), and a stratified set can give every replicate the same
  count (measured: one normal input, n = 1024, all 8 replicates 107 events, s = 0, the exact probability
  1.2e-5 away). Where an event was seen at fewer than 10 points (or missed at
  fewer than 10) over all replicates, the replicate means are far from normal and the pooled
  Clopper-Pearson interval of the nR points (conservative: QMC does not do worse than MC) is given instead.
* plain Monte Carlo (``sampler = "mc"``): Wilson's score interval for a probability, Clopper-Pearson where
  no point (or every point) is in the event; mean +- z s / sqrt(n).
* quantiles: distribution-free, from the order statistics (binomial), pooled over the replicates.
* Sobol' indices: SALib's (Saltelli's design, Jansen / Saltelli 2010 estimators, bootstrap intervals).
* Morris: SALib's (mu*, sigma, bootstrap interval of mu*).
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import ParameterError
from .study import Study

# an event seen at fewer points than this over all replicates: the pooled Clopper-Pearson interval
FEW_EVENTS = 10


# ----------------------------------------------------------------------------- designs


def salib_problem(study: Study) -> dict:
    """SALib's problem on the unit cube: bounds [0, 1] for every coordinate, the blades' coordinates in one
    group 'mistuning' (an index of the whole pattern: the blades are exchangeable)."""
    names = [i.name for i in study.inputs]
    groups = list(names)
    if study.mistuning is not None:
        names += [f"blade{j + 1}" for j in range(study.mistuning.n_blades)]
        groups += ["mistuning"] * study.mistuning.n_blades
    prob = {"num_vars": len(names), "names": names, "bounds": [[0.0, 1.0]] * len(names)}
    if study.mistuning is not None:
        prob["groups"] = groups
    return prob


def design(study: Study) -> dict:
    """The study's points of the unit cube: ``U`` (n_points, dims) and, for montecarlo, ``replicate`` (the
    replicate of each point); for morris, ``U_design`` (the grid SALib's analysis reads)."""
    d = study.dims
    if study.method == "montecarlo":
        if study.sampler == "mc":
            return {"U": np.random.default_rng(study.seed).random((study.n, d)), "replicate": np.zeros(study.n, int)}
        from scipy.stats import qmc

        seeds = np.random.SeedSequence(study.seed).spawn(study.replicates)
        m = int(round(math.log2(study.n)))
        U = np.vstack([qmc.Sobol(d, scramble=True, seed=np.random.default_rng(s)).random_base2(m) for s in seeds])
        return {"U": U, "replicate": np.repeat(np.arange(study.replicates), study.n)}
    if study.method == "sobol":
        from SALib.sample import sobol

        U = sobol.sample(salib_problem(study), study.n, calc_second_order=False, scramble=True, seed=study.seed)
        return {"U": U}
    if study.method == "morris":
        from SALib.sample import morris

        G = morris.sample(salib_problem(study), study.n, num_levels=study.levels, seed=study.seed)
        # the grid's levels k / (p - 1) to the centres of p equal-probability cells, (k + 1/2) / p: an
        # unbounded distribution's quantile at 0 or 1 is infinite (Campolongo et al. 2007 do the same)
        p = study.levels
        return {"U": (G * (p - 1) + 0.5) / p, "U_design": G}
    raise ParameterError(f"study.method: {study.method} draws its own points (OpenTURNS)")


def to_physical(study: Study, U: np.ndarray) -> tuple[np.ndarray, np.ndarray | None]:
    """(X, delta): the inputs' values (n, n_inputs) and the blades' stiffness deviations (n, N) or None."""
    k = len(study.inputs)
    X = np.column_stack([i.distribution.ppf(U[:, j]) for j, i in enumerate(study.inputs)]) if k else \
        np.zeros((len(U), 0))
    D = study.mistuning.deviations(U[:, k:]) if study.mistuning is not None else None
    return X, D


# ----------------------------------------------------------------------------- montecarlo


def proportion_interval(k: int, n: int, conf: float, method: str = "wilson") -> tuple[float, float]:
    """Binomial interval of k events in n (scipy.stats.binomtest): Wilson's score, Clopper-Pearson where
    k = 0 or k = n (Wilson's is too short there)."""
    from scipy.stats import binomtest

    if n == 0:
        return math.nan, math.nan
    m = "exact" if (k == 0 or k == n) else method
    ci = binomtest(int(k), int(n)).proportion_ci(confidence_level=conf, method=m)
    return float(ci.low), float(ci.high)


def quantile_interval(y: np.ndarray, q: float, conf: float) -> tuple[float, float, float]:
    """(estimate, low, high) of the q-quantile, distribution-free: the order statistics y_(l), y_(u) with
    P(y_(l) <= x_q <= y_(u)) >= conf from the binomial law of the count below x_q."""
    from scipy.stats import binom

    y = np.sort(y[np.isfinite(y)])
    n = y.size
    if n == 0:
        return math.nan, math.nan, math.nan
    a = 1.0 - conf
    lo = int(binom.ppf(a / 2, n, q))  # count of points below x_q: within [lo, hi] with probability >= conf
    hi = int(binom.ppf(1 - a / 2, n, q)) + 1
    est = float(np.quantile(y, q))
    return est, float(y[lo - 1]) if lo >= 1 else -math.inf, float(y[hi - 1]) if hi <= n else math.inf


def replicate_interval(values: np.ndarray, conf: float) -> tuple[float, float, float]:
    """(mean, low, high) over independent replicate estimates: Student's t."""
    from scipy.stats import t

    v = np.asarray(values, dtype=float)
    R = v.size
    m = float(v.mean())
    if R < 2:
        return m, math.nan, math.nan
    h = float(t.ppf(0.5 + conf / 2, R - 1) * v.std(ddof=1) / math.sqrt(R))
    return m, m - h, m + h


def estimate_probability(ind: np.ndarray, rep: np.ndarray, study: Study) -> dict:
    """An event's probability with its interval (the module's rules)."""
    ok = np.isfinite(ind)
    k, n = int(np.nansum(ind[ok])), int(ok.sum())
    out = {"probability": k / n if n else math.nan, "events": k, "points": n, "undefined": int((~ok).sum())}
    if study.sampler == "qmc":
        per = np.array([np.mean(ind[ok & (rep == r)]) for r in range(study.replicates) if (ok & (rep == r)).any()])
        m, lo, hi = replicate_interval(per, study.confidence)
        res = 1.0 / study.n  # one replicate's resolution: the interval is never narrower
        lo, hi = min(lo, m - res), max(hi, m + res)
        if min(k, n - k) < FEW_EVENTS:
            lo, hi = proportion_interval(k, n, study.confidence, "exact")
            how = (f"pooled Clopper-Pearson over the {n} points (the event {'seen' if k <= n - k else 'missed'} at "
                   f"{min(k, n - k)} < {FEW_EVENTS} points: the replicate means are not normal)")
        else:
            how = f"randomised QMC: Student t over {per.size} replicates"
        out.update(probability=m if min(k, n - k) >= FEW_EVENTS else k / n, low=max(lo, 0.0), high=min(hi, 1.0),
                   interval=how, replicates=per.tolist())
    else:
        lo, hi = proportion_interval(k, n, study.confidence)
        out.update(low=lo, high=hi, interval="Wilson score" if 0 < k < n else "Clopper-Pearson (exact)")
    return out


def estimate_value(y: np.ndarray, rep: np.ndarray, study: Study) -> dict:
    """Mean (with its interval), standard deviation, quantiles (with theirs) of a value quantity."""
    ok = np.isfinite(y)
    out: dict = {"points": int(ok.sum()), "undefined": int((~ok).sum())}
    if not ok.any():
        return out
    yy = y[ok]
    if study.sampler == "qmc":
        per = np.array([y[ok & (rep == r)].mean() for r in range(study.replicates) if (ok & (rep == r)).any()])
        m, lo, hi = replicate_interval(per, study.confidence)
        how = f"randomised QMC: Student t over {per.size} replicates"
    else:
        from scipy.stats import norm

        m = float(yy.mean())
        h = float(norm.ppf(0.5 + study.confidence / 2) * yy.std(ddof=1) / math.sqrt(yy.size)) if yy.size > 1 else \
            math.nan
        lo, hi, how = m - h, m + h, "normal approximation, s / sqrt(n)"
    qs = {}
    for q in study.quantiles:
        e, a, b = quantile_interval(yy, q, study.confidence)
        qs[f"{q:g}"] = {"value": e, "low": a, "high": b}
    out.update(mean=m, mean_low=lo, mean_high=hi, mean_interval=how, sd=float(yy.std(ddof=1)) if yy.size > 1 else 0.0,
               min=float(yy.min()), max=float(yy.max()), quantiles=qs,
               quantile_interval="distribution-free (order statistics), pooled points")
    return out


def clearance_curve(margin: np.ndarray, rep: np.ndarray, study: Study, g0_mean: float) -> dict:
    """P(rub) against the build clearance: the whole clearance distribution shifted by dg has margins
    margin + dg (the gaps are affine in g0), so every point of the curve comes from the same evaluations.
    The build clearance is the clearance's mean (or the parameter file's g0 where it is not an input)."""
    ok = np.isfinite(margin)
    mg, rp = margin[ok], rep[ok]
    if study.curve is not None:
        g = np.linspace(study.curve["low"], study.curve["high"], study.curve["n"])
    else:
        lo, hi = np.quantile(-mg, [0.001, 0.999]) + g0_mean
        pad = 0.1 * max(hi - lo, 1e-6)
        g = np.linspace(lo - pad, hi + pad, 61)
    p, lo_, hi_ = [], [], []
    for gb in g:
        ind = (mg + (gb - g0_mean) < 0).astype(float)
        e = estimate_probability(ind, rp, study)
        p.append(e["probability"])
        lo_.append(e["low"])
        hi_.append(e["high"])
    return {"build_clearance_m": g, "probability": np.array(p), "low": np.array(lo_), "high": np.array(hi_),
            "nominal_build_clearance_m": g0_mean}


# ----------------------------------------------------------------------------- correlation


def correlation(a: np.ndarray, b: np.ndarray, conf: float) -> dict:
    """Pearson's r (Fisher-z interval, scipy) and Spearman's rank rho (Fisher z with the Bonett-Wright
    standard error sqrt((1 + rho^2 / 2) / (n - 3))) of two quantities over the points where both exist."""
    from scipy.stats import norm, pearsonr, spearmanr

    ok = np.isfinite(a) & np.isfinite(b)
    x, y = a[ok], b[ok]
    n = int(ok.sum())
    if n < 5 or np.ptp(x) == 0 or np.ptp(y) == 0:
        return {"points": n, "pearson": None, "spearman": None,
                "note": "too few points, or a quantity that does not vary: no correlation"}
    pr = pearsonr(x, y)
    ci = pr.confidence_interval(confidence_level=conf)
    rho = float(spearmanr(x, y).statistic)
    z = math.atanh(max(min(rho, 0.999999), -0.999999))
    h = norm.ppf(0.5 + conf / 2) * math.sqrt((1 + rho * rho / 2) / (n - 3))
    return {"points": n, "pearson": {"r": float(pr.statistic), "low": float(ci.low), "high": float(ci.high),
                                     "p_value": float(pr.pvalue)},
            "spearman": {"rho": rho, "low": math.tanh(z - h), "high": math.tanh(z + h)}}


# ----------------------------------------------------------------------------- SALib analyses


def sobol_indices(study: Study, Y: np.ndarray) -> dict:
    """SALib's first- and total-order indices with their bootstrap intervals (half-widths, at the study's
    confidence), or the reason there are none."""
    from SALib.analyze import sobol

    y = np.asarray(Y, dtype=float)
    bad = int((~np.isfinite(y)).sum())
    if bad:
        return {"undefined": f"{bad} of {y.size} evaluations gave no value (e.g. no static solution): Sobol' "
                             "indices need every point of the design"}
    if np.ptp(y) == 0:
        return {"undefined": "the quantity does not vary over the design: its Sobol' indices are undefined"}
    prob = salib_problem(study)
    r = sobol.analyze(prob, y, calc_second_order=False, num_resamples=study.bootstrap, conf_level=study.confidence,
                      seed=study.seed, print_to_console=False)
    names = list(dict.fromkeys(prob.get("groups", prob["names"])))
    return {"names": names, "S1": r["S1"].tolist(), "S1_conf": r["S1_conf"].tolist(), "ST": r["ST"].tolist(),
            "ST_conf": r["ST_conf"].tolist(),
            "interval": f"SALib bootstrap ({study.bootstrap} resamples), half-width at {study.confidence:g}"}


def morris_indices(study: Study, G: np.ndarray, Y: np.ndarray) -> dict:
    from SALib.analyze import morris

    y = np.asarray(Y, dtype=float)
    bad = int((~np.isfinite(y)).sum())
    if bad:
        return {"undefined": f"{bad} of {y.size} evaluations gave no value: Morris needs every point of the design"}
    prob = salib_problem(study)
    r = morris.analyze(prob, G, y, num_resamples=study.bootstrap, conf_level=study.confidence,
                       num_levels=study.levels, seed=study.seed, print_to_console=False)
    arr = {k: np.asarray(r[k], dtype=float).tolist() for k in ("mu", "mu_star", "mu_star_conf", "sigma")}
    return {"names": [str(n) for n in r["names"]], **arr,  # sigma: NaN for a group (SALib)
            "interval": f"SALib bootstrap of mu* ({study.bootstrap} resamples), half-width at {study.confidence:g}",
            "scale": "elementary effects on the inputs' probability scale (unit cube), in the quantity's unit"}
