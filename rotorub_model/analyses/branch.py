"""Pseudo-arclength continuation of balanced static solutions in one parameter (g0 at fixed
Omega, or Omega at fixed g0), through contact changes, with the special points located.

Unknowns y = (q / q_s, (p - p_start) / p_s): scaled so that a millimetre of displacement and the
whole parameter range weigh alike. Predictor: the unit tangent of [dR/dq, dR/dp] (its null
vector); corrector: Newton on [R(y); t . (y - y_pred)] = 0 (the bordered system). A step is halved
when the corrector fails or when more than one contact point changes state within it, so each
accepted step holds at most one contact event. Located along a step (the chord between its ends,
the corrector solving at each trial position):

* **contact**: a contact point's gap crosses zero (regula falsi on the gap, to 1e-9 of the step);
* **fold**: the parameter component of the tangent changes sign (the branch turns back; a static
  solution is lost or gained), to 1e-6 of the parameter;
* **hopf**: the critical eigenvalue's real part changes sign within one contact set (regula falsi
  on Re mu, to |Re mu| <= 1e-8 /s); its imaginary part is the frequency of the cycle it gives
  birth to;
* **switch**: the stability changes at a contact event (2D: the point law's stiffness jumps when a
  blade enters contact, so the eigenvalues jump across the axis; a discontinuity-induced
  bifurcation, located with the event).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..errors import ParameterError
from .equilibria import Equilibria, Point
from .roots import illinois
from .stability import RE_TOL


@dataclass
class Special:
    kind: str  # "hopf", "fold", "contact", "switch"
    point: Point
    detail: dict = field(default_factory=dict)

    def summary(self) -> dict:
        p = self.point
        out = {"kind": self.kind, "omega_rad_s": p.omega, "g0_m": p.g0, "n_contact": p.n_contact,
               "max_force_N": p.max_force, "disk_amplitude_m": p.disk_amplitude}
        if p.mu is not None:
            out["critical_eigenvalue"] = [p.mu.real, p.mu.imag]
        out.update(self.detail)
        return out


@dataclass
class Branch:
    formulation: str
    parameter: str  # "g0" or "omega"
    fixed: float  # the other parameter's value
    points: list[Point]
    specials: list[Special]
    complete: bool  # reached the end of the range
    message: str

    def values(self) -> np.ndarray:
        return np.array([getattr(p, self.parameter) for p in self.points])

    def stable(self) -> np.ndarray:
        return np.array([p.max_real <= RE_TOL for p in self.points])

    def of_kind(self, kind: str) -> list[Special]:
        return [s for s in self.specials if s.kind == kind]


class _Tracer:
    def __init__(self, eq: Equilibria, parameter: str, fixed: float, start: float, stop: float, q_scale: float):
        self.eq, self.par, self.fixed = eq, parameter, fixed
        self.p0, self.ps = start, abs(stop - start)
        self.qs = q_scale
        self.n = eq.n

    def args(self, p: float) -> tuple[float, float]:
        return (self.fixed, p) if self.par == "g0" else (p, self.fixed)

    def unpack(self, y: np.ndarray) -> tuple[np.ndarray, float]:
        return y[:-1] * self.qs, self.p0 + y[-1] * self.ps

    def pack(self, q: np.ndarray, p: float) -> np.ndarray:
        return np.concatenate([q / self.qs, [(p - self.p0) / self.ps]])

    def blocks(self, y: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        q, p = self.unpack(y)
        w, g = self.args(p)
        R = self.eq.residual(q, w, g)
        Jq = self.eq.jacobian(q, w, g) * self.qs
        Jp = self.eq.d_param(q, w, g, self.par) * self.ps
        return R, Jq, Jp

    def tangent(self, y: np.ndarray, previous: np.ndarray | None, direction: float) -> np.ndarray:
        _, Jq, Jp = self.blocks(y)
        A = np.hstack([Jq, Jp[:, None]])
        t = np.linalg.svd(A)[2][-1]
        if previous is not None:
            return t if t @ previous >= 0 else -t
        return t if t[-1] * direction >= 0 else -t

    def correct(self, y_pred: np.ndarray, t: np.ndarray, anchor: np.ndarray | None = None,
                max_iter: int = 12) -> np.ndarray | None:
        """Newton on [R(y); t.(y - anchor)] with anchor = y_pred (the arclength step)."""
        anchor = y_pred if anchor is None else anchor
        y = y_pred.copy()
        fnorm = np.linalg.norm(self.eq.model.force(self.args(self.unpack(y)[1])[0], self.eq.me)) + 1e-30
        for _ in range(max_iter):
            R, Jq, Jp = self.blocks(y)
            g = t @ (y - anchor)
            if np.linalg.norm(R) <= 1e-10 * fnorm and abs(g) <= 1e-13:
                return y
            B = np.zeros((self.n + 1, self.n + 1))
            B[:-1, :-1] = Jq
            B[:-1, -1] = Jp
            B[-1] = t
            try:
                y = y - np.linalg.solve(B, np.concatenate([R, [g]]))
            except np.linalg.LinAlgError:
                return None
            if not np.all(np.isfinite(y)):
                return None
        R = self.blocks(y)[0]
        return y if np.linalg.norm(R) <= 1e-9 * fnorm else None

    def on_chord(self, a: np.ndarray, b: np.ndarray, sigma: float) -> np.ndarray | None:
        """The branch point whose projection on the chord a -> b is at the fraction sigma of it."""
        c = b - a
        L = np.linalg.norm(c)
        c = c / L
        return self.correct(a + sigma * (b - a), c, anchor=a + sigma * L * c)

    def point(self, y: np.ndarray, spectrum: bool = True) -> Point:
        q, p = self.unpack(y)
        w, g = self.args(p)
        return self.eq.point(q, w, g, spectrum)


def continue_static(eq: Equilibria, parameter: str, fixed: float, start: float, stop: float,
                    q0: np.ndarray | None = None, h_max: float = 0.01, max_points: int = 5000,
                    spectrum: bool = True) -> Branch:
    """Follow the balanced solutions from ``parameter = start`` to ``stop`` at the other parameter
    held at ``fixed`` (g0 [m] or Omega [rad/s]). ``h_max``: largest step, as a fraction of the
    range. Returns the branch with its located special points."""
    if parameter not in ("g0", "omega"):
        raise ParameterError(f"parameter: '{parameter}' unknown; accepted: g0, omega")
    if not (np.isfinite(start) and np.isfinite(stop)) or start == stop:
        raise ParameterError(f"start, stop: {start}, {stop}: a range of finite, distinct values is needed")
    w0, g00 = (fixed, start) if parameter == "g0" else (start, fixed)
    q = eq.solve(w0, g00, q0)
    if q is None:
        return Branch(eq.formulation, parameter, fixed, [], [], False, "no balanced solution at the start")
    qs = max(float(np.abs(q).max()), 1e-6)
    tr = _Tracer(eq, parameter, fixed, start, stop, qs)
    direction = float(np.sign(stop - start))
    y = tr.pack(q, start)
    t = tr.tangent(y, None, direction)
    pts = [tr.point(y, spectrum)]
    specials: list[Special] = []
    h = 0.2 * h_max
    message, complete = "", False
    while len(pts) < max_points:
        y_pred = y + h * t
        y_new = tr.correct(y_pred, t)
        if y_new is not None:
            cs_old, cs_new = pts[-1].contact_set, tr.point(y_new, False).contact_set
            changed = sum(a != b for a, b in zip(cs_old, cs_new))
            if changed > 1 and h > 1e-7:
                y_new = None
        if y_new is None:
            h *= 0.5
            if h < 1e-9:
                message = f"the corrector failed at {parameter} = {tr.unpack(y)[1]:.6g} (step below 1e-9)"
                break
            continue
        # the end of the range: land on it exactly
        p_new = tr.unpack(y_new)[1]
        if (p_new - stop) * (start - stop) < 0:
            frac = (stop - tr.unpack(y)[1]) / (p_new - tr.unpack(y)[1])
            e = np.zeros_like(y)
            e[-1] = 1.0
            y_end = tr.correct(y + frac * (y_new - y), e, anchor=tr.pack(q, stop))
            if y_end is not None:
                y_new = y_end
            complete = True
        t_new = tr.tangent(y_new, t, direction)
        new = tr.point(y_new, spectrum)
        specials += _locate(tr, y, y_new, pts[-1], new, t, t_new, spectrum)
        pts.append(new)
        y, t = y_new, t_new
        if complete:
            break
        h = min(h * 1.5, h_max)
    else:
        message = f"stopped after {max_points} points"
    if complete:
        message = f"reached {parameter} = {stop:.6g}"
    return Branch(eq.formulation, parameter, fixed, pts, specials, complete, message)


def _locate(tr: _Tracer, ya: np.ndarray, yb: np.ndarray, pa: Point, pb: Point, ta: np.ndarray, tb: np.ndarray,
            spectrum: bool) -> list[Special]:
    out: list[Special] = []
    # fold: the parameter component of the tangent changes sign
    if ta[-1] * tb[-1] < 0:
        def tp(s):
            y = tr.on_chord(ya, yb, s)
            return None if y is None else tr.tangent(y, ta, 1.0)[-1]

        s = illinois(tp, ta[-1], tb[-1], 1e-9, retry_midpoint=True)
        if s is not None:
            y = tr.on_chord(ya, yb, s)
            if y is not None:
                out.append(Special("fold", tr.point(y, spectrum)))
    s_event = None
    changed = [k for k, (a, b) in enumerate(zip(pa.contact_set, pb.contact_set)) if a != b]
    if changed:
        k = changed[0]

        def gap(s):
            y = tr.on_chord(ya, yb, s)
            if y is None:
                return None
            q, p = tr.unpack(y)
            return float(tr.eq.gaps(q, tr.args(p)[1]).ravel()[k])

        ga = float(tr.eq.gaps(pa.q, pa.g0).ravel()[k])
        gb = float(tr.eq.gaps(pb.q, pb.g0).ravel()[k])
        if ga * gb < 0:
            s_event = illinois(gap, ga, gb, 1e-9, f_tol=1e-15, retry_midpoint=True)
        if s_event is not None:
            y = tr.on_chord(ya, yb, s_event)
            if y is not None:
                ev = tr.point(y, spectrum)
                out.append(Special("contact", ev, {"point_index": k, "entering": bool(pb.contact_set[k])}))
    if not spectrum:
        return out
    unstable_a, unstable_b = pa.mu.real > 0, pb.mu.real > 0
    if s_event is None:
        if unstable_a != unstable_b:
            out.append(_hopf(tr, ya, yb, 0.0, 1.0, pa, pb))
        return out
    # an event inside the step: the spectrum on either side of it
    eps = 1e-7
    left = tr.on_chord(ya, yb, max(s_event - eps, 0.0))
    right = tr.on_chord(ya, yb, min(s_event + eps, 1.0))
    if left is None or right is None:
        return out
    pl, pr = tr.point(left), tr.point(right)
    if (pl.mu.real > 0) != unstable_a:
        out.append(_hopf(tr, ya, yb, 0.0, s_event - eps, pa, pl))
    if (pl.mu.real > 0) != (pr.mu.real > 0):
        ev = out[-1].point if out and out[-1].kind == "contact" else pl
        out.append(Special("switch", ev, {"left_real_part": pl.mu.real, "right_real_part": pr.mu.real,
                                          "left_frequency_rad_s": abs(pl.mu.imag),
                                          "right_frequency_rad_s": abs(pr.mu.imag)}))
    if (pr.mu.real > 0) != unstable_b:
        out.append(_hopf(tr, ya, yb, s_event + eps, 1.0, pr, pb))
    return out


def _hopf(tr: _Tracer, ya: np.ndarray, yb: np.ndarray, s0: float, s1: float, pa: Point, pb: Point) -> Special:
    """Locate Re mu = 0 between chord fractions s0 and s1 (one contact set), refining mu by Newton
    from the nearer end's eigenvalue (the pair is followed, not re-picked)."""
    state = {"mu": pa.mu, "v": None}

    def re(frac):
        y = tr.on_chord(ya, yb, s0 + frac * (s1 - s0))
        if y is None:
            return None
        q, p = tr.unpack(y)
        w, g = tr.args(p)
        mu, v = tr.eq.refine(q, w, g, state["mu"], state["v"])
        state["mu"], state["v"], state["y"] = mu, v, y
        return mu.real

    frac = illinois(re, pa.mu.real, pb.mu.real, 1e-12, f_tol=1e-10, retry_midpoint=True)
    y = tr.on_chord(ya, yb, s0 + frac * (s1 - s0))
    pt = tr.point(y, False)
    q, p = tr.unpack(y)
    w, g = tr.args(p)
    pt.mu, _ = tr.eq.refine(q, w, g, state["mu"], state["v"])
    pt.max_real = pt.mu.real
    return Special("hopf", pt, {"frequency_rad_s": abs(pt.mu.imag), "direction": "destabilising"
                                if pb.mu.real > pa.mu.real else "stabilising"})
