"""Pseudo-arclength continuation of balanced static solutions in one parameter (g0 at fixed
Omega, or Omega at fixed g0), through contact changes, with the special points located.

Unknowns y = (q / q_s, (p - p_start) / p_s): scaled so that a millimetre of displacement and the
whole parameter range weigh alike. Predictor: the unit tangent of [dR/dq, dR/dp] (its null
vector); corrector: Newton on [R(y); t . (y - y_pred)] = 0 (the bordered system). A step is halved
when the corrector fails or when more than one contact point changes state within it, so each
accepted step holds at most one contact event. Located along a step (on the step's own planes,
normal to its starting tangent, the corrector solving at each trial position: :class:`_Step`):

* **contact**: a contact point's gap crosses zero (regula falsi on the gap, to 1e-9 of the step);
* **fold**: the parameter component of the tangent changes sign (the branch turns back; a static
  solution is lost or gained), to 1e-6 of the parameter;
* **hopf**: the stability changes within one contact set and the critical eigenvalue's real part
  is brought to |Re mu| <= 1e-8 /s (regula falsi on Re mu of one mode, after bisecting the verdict
  until both ends lead with it); its imaginary part is the frequency of the cycle it gives birth to;
* **switch**: the stability changes at a contact event (2D: the point law's stiffness jumps when a
  blade enters contact, so the eigenvalues jump across the axis; a discontinuity-induced
  bifurcation, located with the event);
* **unlocated**: a change of stability that is neither (its event not located, or Re mu not brought
  to 1e-8 /s): reported as such with its reason, never as a Hopf point. A real eigenvalue crossing
  zero where the step holds a fold is the fold's (``stability_change`` on it).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ...errors import ParameterError
from ..stability import RE_TOL
from .equilibria import Equilibria, Point
from .roots import illinois

# a Hopf point is reported only where its critical eigenvalue's real part is brought below this [1/s]
HOPF_TOL = 1e-8


@dataclass
class Special:
    kind: str  # "hopf", "fold", "contact", "switch", "unlocated"
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
        return np.array([p.max_real <= RE_TOL for p in self.points], dtype=bool)  # bool also when empty

    def of_kind(self, kind: str) -> list[Special]:
        return [s for s in self.specials if s.kind == kind]


class _Tracer:
    def __init__(self, eq: Equilibria, parameter: str, fixed: float, start: float, stop: float, q_scale: float):
        self.eq, self.par, self.fixed = eq, parameter, fixed
        self.p0, self.ps = start, abs(stop - start)
        self.qs = q_scale
        self.n = eq.n
        # the residual's scale is the imbalance load; without one (me = 0) a stiffness times the displacement
        # scale, a millionth of it: the load's 1e-10 would ask |R| <= 1e-40 N, and round-off past g0 = 0 failed
        w = fixed if parameter == "g0" else start
        self.f_floor = 1e-6 * float(np.abs(eq.model.K_omega(w)).max()) * q_scale

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
        fnorm = max(float(np.linalg.norm(self.eq.model.force(self.args(self.unpack(y)[1])[0], self.eq.me))),
                    self.f_floor)
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


class _Step:
    """The branch between two accepted points, parametrised as the step's own corrector sees it: the
    point at s in [0, 1] lies on the plane t_a . (y - y_a) = s t_a . (y_b - y_a), found by Newton from
    y_a + s (t_a . (y_b - y_a)) t_a (where the step's corrector starts).

    Not the chord's normal planes: across a 2D contact event the branch has a kink (the point law's
    stiffness jumps), and where the part in contact turns far from the part before it, Newton on a
    plane normal to the chord cycles between the two linear pieces (measured: friction 0.3, the first
    contact at Omega = 3.3 was not located and its switch was reported as a Hopf point). On the
    tangent's planes the piece before the event is crossed at its own predictor and the piece after
    it by one Newton step, whatever the step length."""

    def __init__(self, tr: _Tracer, ya: np.ndarray, yb: np.ndarray, ta: np.ndarray):
        self.tr, self.ya, self.yb, self.ta = tr, ya, yb, ta
        self.d = float(ta @ (yb - ya))
        self._cache: dict[float, np.ndarray | None] = {0.0: ya, 1.0: yb}

    def at(self, s: float) -> np.ndarray | None:
        s = float(s)
        if s in self._cache:
            return self._cache[s]
        tr, ya, yb, ta = self.tr, self.ya, self.yb, self.ta
        y = None
        if self.d > 1e-6 * float(np.linalg.norm(yb - ya)):
            anchor = ya + s * self.d * ta
            y = tr.correct(anchor, ta)
            if y is None:  # the same plane from the chord's point (a strongly curved step)
                y = tr.correct(ya + s * (yb - ya), ta, anchor=anchor)
        else:  # the branch turned by ~90 degrees within the step: the chord's planes
            y = tr.on_chord(ya, yb, s)
        self._cache[s] = y
        return y

    def point(self, s: float, spectrum: bool = True) -> Point | None:
        y = self.at(s)
        return None if y is None else self.tr.point(y, spectrum)


def _unstable(p: Point) -> bool:
    return p.max_real > RE_TOL


def _locate(tr: _Tracer, ya: np.ndarray, yb: np.ndarray, pa: Point, pb: Point, ta: np.ndarray, tb: np.ndarray,
            spectrum: bool) -> list[Special]:
    out: list[Special] = []
    step = _Step(tr, ya, yb, ta)
    # fold: the parameter component of the tangent changes sign
    if ta[-1] * tb[-1] < 0:
        def tp(s):
            y = step.at(s)
            return None if y is None else tr.tangent(y, ta, 1.0)[-1]

        s = illinois(tp, ta[-1], tb[-1], 1e-9, retry_midpoint=True)
        if s is not None:
            y = step.at(s)
            if y is not None:
                out.append(Special("fold", tr.point(y, spectrum)))
    s_event, event = None, None
    changed = [k for k, (a, b) in enumerate(zip(pa.contact_set, pb.contact_set)) if a != b]
    if changed:
        k = changed[0]

        def gap(s):
            y = step.at(s)
            if y is None:
                return None
            q, p = tr.unpack(y)
            return float(tr.eq.gaps(q, tr.args(p)[1]).ravel()[k])

        ga = float(tr.eq.gaps(pa.q, pa.g0).ravel()[k])
        gb = float(tr.eq.gaps(pb.q, pb.g0).ravel()[k])
        if (ga < 0) != (gb < 0) and ga != gb:
            s_event = illinois(gap, ga, gb, 1e-9, f_tol=1e-15, retry_midpoint=True)
        if s_event is not None:
            ev = step.point(s_event, spectrum)
            if ev is not None:
                event = Special("contact", ev, {"point_index": k, "entering": bool(pb.contact_set[k])})
            else:
                s_event = None
    if not spectrum:
        return out + ([event] if event is not None else [])
    if event is None:
        if _unstable(pa) != _unstable(pb):
            # a change of stability with an event we could not place is not taken for a Hopf point
            out.append(_unlocated(pb, "the contact event within the step was not located") if changed
                       else _crossing(step, 0.0, 1.0, pa, pb))
        return _at_fold(out)
    sides = _event_sides(step, s_event, k, pa, pb)
    if sides is None:
        out.append(event)
        if _unstable(pa) != _unstable(pb):
            out.append(_unlocated(event.point, "no solution either side of the contact event"))
        return out
    (sl, pl), (sr, pr) = sides
    if _unstable(pl) != _unstable(pa):
        out.append(_crossing(step, 0.0, sl, pa, pl))
    out.append(event)
    if _unstable(pl) != _unstable(pr):
        direction = "destabilising" if _unstable(pr) else "stabilising"
        out.append(Special("switch", event.point, {
            "left_real_part": pl.max_real, "right_real_part": pr.max_real, "left_frequency_rad_s": abs(pl.mu.imag),
            "right_frequency_rad_s": abs(pr.mu.imag), "direction": direction}))
    if _unstable(pr) != _unstable(pb):
        out.append(_crossing(step, sr, 1.0, pr, pb))
    return _at_fold(out)


def _at_fold(out: list[Special]) -> list[Special]:
    """A real eigenvalue crossing zero in a step holding a fold is the fold's change of stability (the
    static Jacobian is singular there): noted on the fold, not reported as unlocated."""
    folds = [s for s in out if s.kind == "fold"]
    static = [s for s in out if s.kind == "unlocated" and s.detail.get("static")]
    if folds and static:
        folds[0].detail["stability_change"] = True
        out = [s for s in out if all(s is not t for t in static)]
    return out


def _event_sides(step: _Step, s_event: float, k: int, pa: Point,
                 pb: Point) -> tuple[tuple[float, Point], tuple[float, Point]] | None:
    """The solutions just before and just after the event at s_event, each with its end's state of
    contact point k: ((s, point), (s, point)), or None where either is not found."""
    out: list[tuple[float, Point]] = []
    for side, end in ((-1.0, pa), (1.0, pb)):
        found = None
        for eps in (1e-7, 1e-6, 1e-5, 1e-4):
            s = min(max(s_event + side * eps, 0.0), 1.0)
            p = step.point(s)
            if p is not None and p.contact_set[k] == end.contact_set[k]:
                found = (s, p)
                break
        if found is None:
            return None
        out.append(found)
    return out[0], out[1]


def _unlocated(p: Point, reason: str) -> Special:
    return Special("unlocated", p, {"reason": reason})


def _same_mode(tr: _Tracer, stable: Point, unstable: Point) -> tuple[bool, complex]:
    """Is the unstable end's critical eigenvalue, followed to the stable end by Newton, the stable end's
    critical one (then the crossing between them is that mode's alone)? Also: the followed eigenvalue
    at the stable end."""
    mu, _ = tr.eq.refine(stable.q, stable.omega, stable.g0, unstable.mu)
    return bool(abs(mu - stable.mu) <= 1e-6 * abs(stable.mu)), mu


def _crossing(step: _Step, s0: float, s1: float, p0: Point, p1: Point) -> Special:
    """The change of stability between s0 and s1 (one contact set, or a continuous law): a Hopf point
    where the critical eigenvalue's real part is brought to |Re mu| <= 1e-8 /s, otherwise what it is.

    First the verdict (whole spectra) is bisected until the critical eigenvalues at the two ends are the
    same mode: another mode may lead at one end (a step across a contact event, or a long one), and
    regula falsi on a mode followed from one end would then converge on a jump between modes, not a
    root. Then regula falsi on the real part of that mode, followed by Newton from the unstable end."""
    tr = step.tr
    destabilising = _unstable(p1)
    for _ in range(48):
        st, un = (p0, p1) if destabilising else (p1, p0)
        if un.max_real > un.mu.real + 1e-9 and un.mu.real <= RE_TOL:
            out = _unlocated(un, "a real eigenvalue crosses zero (a static bifurcation, not a Hopf point)")
            out.detail["static"] = True
            return out
        same, mu_st = _same_mode(tr, st, un)
        if same:
            break
        if s1 - s0 <= 1e-12:
            return _unlocated(un, "the critical mode changes at the crossing (a discontinuity of the spectrum)")
        sm = 0.5 * (s0 + s1)
        pm = step.point(sm)
        if pm is None:
            return _unlocated(un, "the corrector failed while bracketing the crossing")
        if _unstable(pm) == _unstable(p0):
            s0, p0 = sm, pm
        else:
            s1, p1 = sm, pm
    else:
        return _unlocated(p1, "the crossing could not be bracketed")
    state = {"mu": un.mu, "v": None}

    def re(frac):
        y = step.at(s0 + frac * (s1 - s0))
        if y is None:
            return None
        q, p = tr.unpack(y)
        w, g = tr.args(p)
        mu, v = tr.eq.refine(q, w, g, state["mu"], state["v"])
        state["mu"], state["v"] = mu, v
        return mu.real

    f0 = mu_st.real if p0 is st else un.mu.real
    f1 = un.mu.real if p1 is un else mu_st.real
    frac = illinois(re, f0, f1, 1e-12, f_tol=1e-10, retry_midpoint=True)
    y = None if frac is None else step.at(s0 + frac * (s1 - s0))
    if y is None:
        return _unlocated(un, "the corrector failed while locating the crossing")
    pt = tr.point(y, False)
    q, p = tr.unpack(y)
    w, g = tr.args(p)
    pt.mu, _ = tr.eq.refine(q, w, g, state["mu"], state["v"])
    pt.max_real = pt.mu.real
    detail = {"frequency_rad_s": abs(pt.mu.imag), "direction": "destabilising" if destabilising else "stabilising"}
    if abs(pt.mu.real) > HOPF_TOL:
        return Special("unlocated", pt, {"reason": f"|Re mu| = {abs(pt.mu.real):.3g} /s at the located point, "
                                                   f"above {HOPF_TOL:g}: not a Hopf point", **detail})
    return Special("hopf", pt, detail)
