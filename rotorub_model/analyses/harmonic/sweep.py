"""The forced HB response at given speeds (what a transient sweep gives, plus stability), as cheap as the contact
allows: the speed sweep the benchmark times against the transients, and the map's point-by-point agreement.

At each speed, in order:

1. the response without contact (one evaluation: the imbalance's static deflection in the rotating frame, and
   the surface's gap); where no blade touches at any sample, that *is* the orbit, and its multipliers are the
   contact-free spectrum's e^{lambda T} (no Newton, no monodromy);
2. otherwise Newton from the previous speed's orbit where it touched (a warm start), else from the contact-free
   response, then from the other if the first fails;
3. the monodromy (:func:`.stability.monodromy_multipliers`) on ``steps`` steps (default: one per AFT sample).

Examples
--------
>>> from rotorub_model.structure.model import build_model
>>> from rotorub_model.contact import make_contact
>>> from .surface import CasingForcing
>>> m = build_model()
>>> pb = HBProblem(m, make_contact(m, "2D", g0=0.5e-3), 6, forcing=CasingForcing.lobe(2, 0.15e-3))
>>> pts = run_hb_sweep(pb, [2.5 * 53.4, 3.25 * 53.4])
>>> [p.touching > 0 for p in pts], [p.stable for p in pts]
([False, True], [True, True])
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .orbit import OrbitMeasures, OrbitView
from .problem import HBProblem, newton
from .stability import Floquet, linear_multipliers, monodromy_multipliers


@dataclass
class SweepPoint:
    omega: float
    Y: np.ndarray
    converged: bool
    iterations: int
    touching: int  # AFT samples at which a blade touches
    floquet: Floquet | None
    measures: OrbitMeasures | None

    @property
    def stable(self) -> bool | None:
        return None if self.floquet is None else self.floquet.stable


def hb_point(problem: HBProblem, omega: float, warm: np.ndarray | None = None, stability: bool = True,
             steps: int | None = None, measure_samples: int = 256) -> SweepPoint:
    """The forced orbit at one speed (w = omega), by the rule of the module's docstring."""
    Y_lin = problem.linear_start(omega, omega)
    ev = problem.evaluate(Y_lin, omega, omega, jacobian=False)
    if ev.touching == 0:
        fl = linear_multipliers(problem, omega, omega) if stability else None
        me = OrbitView(problem, Y_lin, omega, omega, samples=measure_samples).measures() if measure_samples else None
        return SweepPoint(omega, Y_lin, True, 0, 0, fl, me)
    starts = [warm, Y_lin] if warm is not None else [Y_lin]
    res = None
    for Y0 in starts:
        res = newton(problem, Y0, omega, omega)
        if res.converged:
            break
    fl = None
    if stability and res.converged:
        fl = monodromy_multipliers(problem, res.Y, omega, omega, steps=steps)
    me = (OrbitView(problem, res.Y, omega, omega, samples=measure_samples).measures()
          if measure_samples and res.converged else None)
    touching = res.evaluation.touching if res.evaluation is not None else 0
    return SweepPoint(omega, res.Y, res.converged, res.iterations, touching, fl, me)


def run_hb_sweep(problem: HBProblem, omegas, stability: bool = True, steps: int | None = None,
                 measure_samples: int = 256) -> list[SweepPoint]:
    """:func:`hb_point` at each speed [rad/s] in turn, warm-started from the previous touching orbit."""
    out: list[SweepPoint] = []
    warm = None
    for om in omegas:
        p = hb_point(problem, float(om), warm, stability, steps, measure_samples)
        warm = p.Y if (p.converged and p.touching) else None
        out.append(p)
    return out
