"""Small probabilities with OpenTURNS (optional extra ``uq``): FORM and subset sampling.

Monte Carlo needs about 100 / p evaluations for a 20 % interval on a probability p: a million for 1e-4. FORM
(first-order reliability) finds the most probable point of the limit state in the standard normal space
and returns p = Phi(-beta) from a few dozen evaluations (exact for a limit state linear in normal inputs,
approximate otherwise, with no error estimate); subset sampling (Au & Beck 2001) writes the probability as a
product of conditional probabilities of about 0.1 each, sampled by Markov chains, and gives its coefficient
of variation (the interval below is p (1 +- z cv), the normal approximation OpenTURNS documents).

Both work in the coordinates the samplers use: independent standard normals z, u = Phi(z), the inputs'
quantiles at u (distributions.py, mistuning.py), so that a finite-difference step is of the same size for
every input and the design point maps back to physical values with the study's own mapping. Evaluations go
through the project's executor in batches (each FORM gradient: one batch of 2d points; each subset step:
batches of n / 10 points), and are kept as the other methods' are: an interrupted run replays its requests
from the rows already written.
"""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np

from .study import Study

OUTER = 10  # batches per subset step: the chains advance once per batch (one batch per step does not mix)


def run_small_probability(study: Study, evaluate: Callable[[np.ndarray], np.ndarray]) -> dict:
    """FORM or subset sampling on the study's first event; ``evaluate(U)`` returns the limit state's value
    quantity at unit-cube points U (n, dims)."""
    import openturns as ot
    from scipy.stats import norm

    ev = study.events[0]
    quantity, op, thr = ev.limit_state
    # the limit state in display units (mm, N): the solvers' absolute tolerances (1e-5) then mean the same
    # thing whatever the quantity (a margin of 1e-3 m met to 1e-5 m is 1 % off)
    from .results import _scale

    k = _scale(quantity)[0]
    d = study.dims
    n_calls = [0]

    def fsample(Z):
        Z = np.asarray(Z, dtype=float)
        n_calls[0] += len(Z)
        y = k * evaluate(norm.cdf(Z))
        if not np.all(np.isfinite(y)):
            from ..errors import ConvergenceError

            raise ConvergenceError(f"{quantity}: undefined at {int((~np.isfinite(y)).sum())} of the points "
                                   f"{study.method} asked for; the limit state must exist everywhere")
        return y.reshape(-1, 1).tolist()

    f = ot.PythonFunction(d, 1, func_sample=fsample)
    f.setGradient(ot.CenteredFiniteDifferenceGradient(1e-4, f.getEvaluation()))
    Y = ot.CompositeRandomVector(f, ot.RandomVector(ot.Normal(d)))
    event = ot.ThresholdEvent(Y, ot.Less() if op == "<" else ot.Greater(), k * thr)
    ot.RandomGenerator.SetSeed(int(study.seed))
    out: dict = {"event": ev.text, "limit_state": f"{quantity} {op} {thr:g}", "dims": d}
    if study.method == "form":
        solver = ot.AbdoRackwitz()
        solver.setStartingPoint(ot.Point(d, 0.0))
        algo = ot.FORM(solver, event)
        algo.run()
        r = algo.getResult()
        z = np.array(r.getStandardSpaceDesignPoint())
        beta = float(r.getHasoferReliabilityIndex())
        # OpenTURNS' beta is |z*|: negative here where the origin (the median point) is in the event
        p = float(r.getEventProbability())
        inside = r.getIsStandardPointOriginInFailureSpace()
        out.update(probability=p, beta=-beta if inside else beta, design_point_standard=z.tolist(),
                   design_point_unit=norm.cdf(z).tolist(),
                   importance_factors=[float(v) for v in r.getImportanceFactors()],
                   interval=None, interval_note="FORM has no error estimate: exact for a limit state linear in "
                                                "normal inputs; check with subset sampling otherwise")
    else:
        per = max(1, study.n // OUTER)
        algo = ot.SubsetSampling(event)
        algo.setMaximumOuterSampling(OUTER)
        algo.setBlockSize(per)
        algo.run()
        r = algo.getResult()
        p = float(r.getProbabilityEstimate())
        cv = float(r.getCoefficientOfVariation())
        z = float(norm.ppf(0.5 + study.confidence / 2))
        out.update(probability=p, coefficient_of_variation=cv, low=max(p * (1 - z * cv), 0.0), high=p * (1 + z * cv),
                   steps=int(algo.getStepsNumber()), points_per_step=per * OUTER,
                   probability_per_step=[float(v) for v in algo.getProbabilityEstimatePerStep()],
                   interval=f"p (1 +- z cv), cv from OpenTURNS' subset estimate ({algo.getStepsNumber()} steps)")
    out["evaluations"] = n_calls[0]
    if not math.isfinite(out["probability"]):
        out["probability"] = None
    return out
