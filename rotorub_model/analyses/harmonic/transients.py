"""Transients of the forced rub response, the independent check of the harmonic balance: one task per speed
(through the project's executor, :mod:`..sweeps`), and the classifier that says whether a run settled on a
periodic orbit.

A run starts from the imbalance's static deflection without contact (no ramp: the casing surface acts from
t = 0) and steps with dt = T / (64 s), T = 2 pi / Omega, s the smallest whole number that keeps dt within half
the central-difference limit; q is recorded 64 times a revolution, at the frame angles 2 pi i / 64, the
phases at which the HB orbit is compared sample by sample.

**Settling classifier** (Poincare samples once per revolution, the tip deflections of all blades and the
fan-disk centre, over the last ``window`` revolutions; distances relative to the orbit's amplitude):

* ``divergent``: the run stopped (penetration beyond contact.max_penetration, or not finite);
* ``periodic``: what is left to go to the orbit, estimated as the geometric tail of the steps between
  consecutive Poincare points (their contraction rho per revolution measured over the second half of the run:
  the tail is s rho / (1 - rho), s the last steps), is within ``tol``. *Why the tail, not the last step*: an
  orbit whose leading multiplier is 0.995 is still 200 steps away from where its last step says (the first
  round of this map called such runs periodic, or period 2 when the multiplier was -0.995);
* ``period-k`` (k = 2..6): the points k revolutions apart settle so, the consecutive ones do not contract
  (a subharmonic);
* ``settling``: the consecutive steps (or those k revolutions apart, towards a subharmonic) contract by half or
  more over the window but are not there yet (too short a run: not marked periodic, no amplitude);
* ``non-periodic``: none of these (quasi-periodic past a Neimark-Sacker point, or chaotic): the map marks it
  and reports no amplitude.
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

from ...contact import make_contact
from ...structure.model import Model, build_model
from ...structure.params import from_dict
from ..transient import critical_time_step, run_transient
from .orbit import measures_from_states, profile_lobes, tip_deflection
from .surface import CasingForcing

SAMPLES_PER_REV = 64
KINDS = ("periodic", "period-2", "period-3", "period-4", "period-5", "period-6", "settling", "non-periodic",
         "divergent")
SETTLE_TOL = 2e-3
ROUND_OFF = 1e-7  # relative steps below this are the time loop's round-off (measured 2e-8 on a settled run)
SCALE_FLOOR = 1e-3  # the classifier's distances are relative to max(orbit range, SCALE_FLOOR g0)


def contraction(steps: np.ndarray) -> float:
    """The steps' contraction per revolution, from their envelope: the largest step of the last third of the
    sequence over that of the first third, to the power one over the thirds' distance (1 for a steady or noisy
    sequence; |rho| for a ring-down on a multiplier rho, complex pairs included)."""
    n = steps.size
    if n < 6:
        return 1.0
    third = n // 3
    first, last = float(steps[:third].max()), float(steps[-third:].max())
    if first <= 0:
        return 1.0
    return float(min((last / first) ** (1.0 / (n - third)), 1.5))


def classify(poincare: np.ndarray, scale: float, diverged: bool = False, tol: float = SETTLE_TOL,
             window: int = 24) -> tuple[str, float]:
    """(kind, remaining): the kind of the sequence of Poincare points (K, d) and the estimated distance, relative
    to ``scale``, between its last point and the orbit it settles on.

    The settling rule: the steps between consecutive points over the second half of the run (at least
    ``window`` of them) contract by rho per revolution (:func:`contraction`); what is left to go is the
    geometric tail s rho / (1 - rho) of the last steps s, not s itself (with a multiplier of 0.995, 200 times
    s). A run is periodic when that tail is within ``tol``; a subharmonic (period k) when the points k
    revolutions apart settle so (with the same tail rule) while the consecutive steps do not contract; still
    settling when the steps contract (by half or more over the window) but have not arrived; non-periodic
    otherwise (quasi-periodic past a Neimark-Sacker point, or chaotic).

    >>> p = np.array([[1.0, 0.0]] * 30)
    >>> classify(p, 1.0)[0]
    'periodic'
    >>> classify(np.array([[(-1.0) ** k, 0.0] for k in range(30)]), 1.0)[0]
    'period-2'
    >>> k = np.arange(60) * 2 * np.pi * 0.3819660112501051     # a quasi-periodic circle
    >>> classify(np.c_[np.cos(k), np.sin(k)], 1.0)[0]
    'non-periodic'
    >>> ring = np.array([[(-0.995) ** k, 0.0] for k in range(800)])  # a slow ring-down, alternating: not period 2
    >>> classify(ring, 1.0)[0]
    'settling'
    """
    if diverged or poincare.shape[0] < 8 or not np.all(np.isfinite(poincare)):
        return "divergent" if diverged or not np.all(np.isfinite(poincare)) else "settling", math.inf
    K = poincare.shape[0]
    W = max(window, K // 2)
    P = poincare[-(W + 1):]
    scale = max(scale, 1e-12)

    def tail(st: np.ndarray) -> tuple[float, float]:
        rate = contraction(st)
        last = float(st[-8:].max())
        if last <= ROUND_OFF:  # steps at the integration's round-off: there is nothing left to contract
            return last, rate
        return (last * rate / (1.0 - rate) if rate < 1.0 else last), rate

    steps = np.linalg.norm(np.diff(P, axis=0), axis=1) / scale
    remaining, rate = tail(steps)
    if remaining <= tol:
        return "periodic", remaining
    decaying = rate ** steps.size < 0.5
    if not decaying:
        for k in range(2, 7):
            if P.shape[0] > 2 * k + 8:
                kst = np.linalg.norm(P[k:] - P[:-k], axis=1) / scale
                rem_k, rate_k = tail(kst)
                if rem_k <= tol:
                    return f"period-{k}", rem_k
                if rate_k ** kst.size < 0.5 and float(kst[-8:].max()) < 0.1:  # a subharmonic still approached
                    return "settling", rem_k
    if decaying:
        return "settling", remaining
    return "non-periodic", remaining


@lru_cache(maxsize=4)
def _model(key: str) -> Model:
    import json

    return build_model(from_dict(json.loads(key)))


def forced_transient(params: dict, formulation: str, omega: float, g0: float, offset: tuple[float, float],
                     lobes: dict, t_end: float, wears: bool = False, me: float | None = None,
                     refine: int = 1) -> dict[str, np.ndarray]:
    """One speed of the transient sweep (a top-level function of plain data: it pickles to any worker).
    ``refine``: the step divided by this (the time step's own error, O(dt^2), measured against the HB)."""
    import json

    model = _model(json.dumps(params, sort_keys=True))
    contact = make_contact(model, formulation, g0=g0)
    forcing = CasingForcing(offset=tuple(offset), lobes={int(k): tuple(v) for k, v in lobes.items()})
    liner = forcing.liner(contact, wears=wears, model=model)
    T = 2 * math.pi / omega
    cap = 0.5 * critical_time_step(model, contact, omega)
    s = max(1, math.ceil(T / SAMPLES_PER_REV / cap)) * max(1, int(refine))
    dt = T / (SAMPLES_PER_REV * s)
    n_rev = max(8, int(t_end / T))
    me_ = model.params.imbalance.me if me is None else me
    q0 = np.linalg.solve(model.K_omega(omega), model.force(omega, me_))
    r = run_transient(model, contact, omega, t_end=n_rev * T, t_ramp=0.0, me=me_, dt=dt, record_dt=T / SAMPLES_PER_REV,
                      q0=q0, liner=liner, wear_record_dt=T * n_rev / 4)
    K = r.q.shape[0] // SAMPLES_PER_REV
    out: dict[str, np.ndarray] = {"omega": np.array(omega), "dt": np.array(dt), "t_end": np.array(r.t_end)}
    if K < 2:
        out.update(kind=np.array(KINDS.index("divergent")), remaining=np.array(math.inf))
        return out
    q = r.q[: K * SAMPLES_PER_REV].reshape(K, SAMPLES_PER_REV, -1)
    v = tip_deflection(model, q[:, -1])
    d = q[:, -1] @ model.disk_maps[0][:2].T
    last = slice((K - 1) * SAMPLES_PER_REV, K * SAMPLES_PER_REV)
    meas = measures_from_states(model, r.q[last], r.outputs["F_N"][last], r.outputs["gap"][last])
    # distances relative to the orbit's own size in the same coordinates (the last revolution's range), and at
    # least 1e-3 g0: an orbit that touches nowhere is a fixed point in the rotating frame (no range), and the
    # round-off drift of a long run (1e-12 m) must not pass for a subharmonic
    ring = np.hstack([tip_deflection(model, q[-1]), q[-1] @ model.disk_maps[0][:2].T])
    scale = max(float(np.linalg.norm(np.ptp(ring, axis=0))), SCALE_FLOOR * abs(g0), 1e-12)
    kind, remaining = classify(np.hstack([v, d]), scale, r.diverged)
    out.update(kind=np.array(KINDS.index(kind)), remaining=np.array(remaining),
               tip_amplitude=np.array(meas.tip_amplitude), max_force=np.array(meas.max_force),
               disk_amplitude=np.array(meas.disk_amplitude),
               penetration=np.array(meas.penetration), last_rev_q=r.q[last], tip_harmonics=meas.tip_harmonics)
    if wears and r.wear is not None:
        prof = liner.profile
        lobes_, amps = profile_lobes(prof)
        out.update(wear_depth=np.array(float(prof.max())), wear_lobes=np.array(lobes_), wear_harmonics=amps,
                   wear_profile=prof)
    return out
