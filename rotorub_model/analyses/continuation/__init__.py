"""The continuation family: balanced solutions followed in a parameter, their special points, the periodic orbits
past Hopf points and the stability boundary as curves over the maps (docs/THEORY.md 5.1).

* :mod:`.equilibria` — one model's balanced solutions and their spectra at a (speed, clearance), cached;
* :mod:`.branch` — pseudo-arclength branches in g0 or Omega, contact events, folds, Hopf points, switches;
* :mod:`.periodic` — periodic orbits by shooting with the central-difference flow, Floquet multipliers;
* :mod:`.boundary` — the stability boundary traced as curves over the (Omega, g0) maps;
* :mod:`.roots` — the scalar root finder they share;
* :mod:`.study` — ``run_continuation``: all of it at one speed, the result that saves and plots itself.
"""

from .study import PAPER_SPEED, ContinuationResult, agreement, boundary_curves_only, off_branch, run_continuation

__all__ = ["PAPER_SPEED", "ContinuationResult", "agreement", "boundary_curves_only", "off_branch", "run_continuation"]
