"""Pseudo-arclength continuation of harmonic-balance orbits in the spin speed (or the clearance), with the
folds, branch points and changes of stability located.

Unknowns z = (Y / y_s, (p - p_0) / p_s): the condensed coefficients (:mod:`.problem`) over a length scale
y_s (the no-contact response, or g0) and the parameter over its range, so a step of the arclength moves
both alike. Forced orbits: w = Omega (p = Omega moves the fundamental too). Predictor z + h t, t the unit
null vector of [dR/dY, dR/dp]; corrector Newton on [R(z); t . (z - z_pred)] = 0 (the bordered system,
dR/dY the exact Jacobian, dR/dp by central differences). The step grows by 1.5 after a fast correction
and is halved after a failed one.

Located between two points (on the step's own planes t_a . (z - z_a) = s t_a . (z_b - z_a), found by the
corrector; regula falsi in s):

* **fold**: the parameter component of the tangent changes sign (the branch turns back: the jump of a
  hardening resonance);
* **branch point**: the sign of det [dR/dY, dR/dp; t^T] changes (two branches cross; at a fold it does not);
* **stability**: the largest Floquet multiplier's modulus crosses 1 (:mod:`.stability`); how it leaves the
  circle says what follows (a fold at +1, period doubling at -1, a quasi-periodic response past a
  Neimark-Sacker pair).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ...errors import ParameterError
from .problem import HBProblem, frequency_derivative
from .roots import regula_falsi
from .stability import DEFAULT_SUBSTEPS, Floquet, monodromy_multipliers


@dataclass
class HBPoint:
    omega: float  # spin speed [rad/s]
    g0: float  # [m]
    w: float  # fundamental [rad/s]
    Y: np.ndarray  # condensed coefficients (2H+1) r
    floquet: Floquet | None = None
    iterations: int = 0

    @property
    def stable(self) -> bool | None:
        return None if self.floquet is None else self.floquet.stable


@dataclass
class Special:
    kind: str  # "fold", "branch", "stability"
    point: HBPoint
    detail: dict = field(default_factory=dict)

    def summary(self) -> dict:
        return {"kind": self.kind, "omega_rad_s": self.point.omega, "g0_m": self.point.g0, **self.detail}


@dataclass
class HBBranch:
    parameter: str  # "omega" or "g0"
    points: list[HBPoint]
    specials: list[Special]
    complete: bool
    message: str

    def values(self) -> np.ndarray:
        return np.array([getattr(p, self.parameter) for p in self.points])

    def stable(self) -> np.ndarray:
        return np.array([bool(p.stable) for p in self.points], dtype=bool)


class _Tracer:
    """The bordered system of one branch. Forced orbits: unknowns (Y, p), w = Omega. Autonomous orbits
    (``autonomous``): unknowns (Y, w, p), w the orbit's own frequency, with the phase condition (:func:`phase_row`)
    as the extra equation."""

    def __init__(self, problem: HBProblem, parameter: str, start: float, stop: float, fixed: float,
                 y_scale: float, autonomous: bool = False, w_scale: float = 1.0, phase: int | None = None):
        self.pb, self.par = problem, parameter
        self.p0, self.ps = start, abs(stop - start)
        self.fixed = fixed
        self.ys = y_scale
        self.N = problem.N
        self.autonomous = autonomous
        self.ws = w_scale
        self.phase = phase

    def args(self, p: float, w: float | None = None) -> tuple[float, float, float]:
        """(omega, w, g0) at parameter value p (and frequency w of an autonomous orbit)."""
        if self.par == "omega":
            return p, (p if w is None else w), self.fixed
        return self.fixed, (self.fixed if w is None else w), p

    def unpack(self, z: np.ndarray) -> tuple[np.ndarray, float]:
        return z[: self.N] * self.ys, self.p0 + z[-1] * self.ps

    def frequency(self, z: np.ndarray) -> float | None:
        return float(z[self.N] * self.ws) if self.autonomous else None

    def pack(self, Y: np.ndarray, p: float, w: float | None = None) -> np.ndarray:
        mid = [w / self.ws] if self.autonomous else []
        return np.concatenate([Y / self.ys, mid, [(p - self.p0) / self.ps]])

    def blocks(self, z: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """R / y_s (with the phase condition), dR/dz."""
        Y, p = self.unpack(z)
        w = self.frequency(z)
        om, w, g0 = self.args(p, w)
        self.pb.set_clearance(g0)
        ev = self.pb.evaluate(Y, om, w)
        # dR/dp by a forward difference: R is smooth in Omega (the receptances, the imbalance) and affine in g0
        # where the contact set does not change; 1e-7 of p keeps its error near 1e-7 relative, below what the
        # predictor needs (the corrector uses the exact dR/dY)
        hp = 1e-7 * max(abs(p), 1e-3 if self.par == "g0" else 1.0)
        o2, w2, g2 = self.args(p + hp, None if not self.autonomous else w)
        self.pb.set_clearance(g2)
        Rp = self.pb.evaluate(Y, o2, w2, jacobian=False).R
        self.pb.set_clearance(g0)
        dRdp = (Rp - ev.R) / hp * self.ps / self.ys
        if not self.autonomous:
            A = np.hstack([ev.J, dRdp[:, None]])  # dR/dY y_s / y_s = J
            return ev.R / self.ys, A, ev.f_hat
        dRdw = frequency_derivative(self.pb, Y, om, w) * self.ws / self.ys
        A = np.zeros((self.N + 1, self.N + 2))
        A[: self.N, : self.N] = ev.J
        A[: self.N, self.N] = dRdw
        A[: self.N, -1] = dRdp
        A[self.N, self.phase] = 1.0
        R = np.concatenate([ev.R / self.ys, [z[self.phase]]])
        return R, A, ev.f_hat

    def tangent(self, A: np.ndarray, previous: np.ndarray | None, direction: float) -> np.ndarray:
        """The null vector of A (N x N+1): one bordered solve with the previous tangent (an SVD at the start)."""
        t = None
        if previous is not None:
            try:
                t = np.linalg.solve(np.vstack([A, previous]), np.concatenate([np.zeros(A.shape[0]), [1.0]]))
                t = t / np.linalg.norm(t)
            except np.linalg.LinAlgError:
                t = None
        if t is None or not np.all(np.isfinite(t)):
            t = np.linalg.svd(A)[2][-1]
        if previous is not None:
            return t if t @ previous >= 0 else -t
        return t if t[-1] * direction >= 0 else -t

    def correct(self, z_pred: np.ndarray, t: np.ndarray, anchor: np.ndarray | None = None, tol: float = 1e-10,
                max_iter: int = 10) -> tuple[np.ndarray | None, np.ndarray | None, int]:
        anchor = z_pred if anchor is None else anchor
        z = z_pred.copy()
        for it in range(1, max_iter + 1):
            R, A, _ = self.blocks(z)
            g = float(t @ (z - anchor))
            if np.linalg.norm(R) <= tol and abs(g) <= tol:
                return z, A, it - 1
            B = np.vstack([A, t])
            try:
                dz = np.linalg.solve(B, -np.concatenate([R, [g]]))
            except np.linalg.LinAlgError:
                return None, None, it
            z = z + dz
            if not np.all(np.isfinite(z)):
                return None, None, it
            if np.linalg.norm(dz) <= 1e-13 * max(1.0, np.linalg.norm(z)):
                R, A, _ = self.blocks(z)
                return (z, A, it) if np.linalg.norm(R) <= 1e3 * tol else (None, None, it)
        return None, None, max_iter

    def point(self, z: np.ndarray, stability: bool, substeps: int | None, its: int = 0) -> HBPoint:
        Y, p = self.unpack(z)
        om, w, g0 = self.args(p, self.frequency(z))
        self.pb.set_clearance(g0)
        fl = monodromy_multipliers(self.pb, Y, om, w, substeps, autonomous=self.autonomous) if stability else None
        return HBPoint(om, g0, w, Y, fl, its)


def continue_hb(problem: HBProblem, parameter: str, start: float, stop: float, fixed: float,
                Y0: np.ndarray | None = None, h_max: float = 0.05, max_points: int = 2000, stability: bool = True,
                substeps: float | None = DEFAULT_SUBSTEPS, progress=None, autonomous: bool = False,
                w0: float | None = None, start_tangent: tuple[np.ndarray, float, float] | None = None,
                y_scale: float | None = None, halt=None, unit: str = "") -> HBBranch:
    """Follow the HB orbit from ``parameter = start`` to ``stop`` (``omega`` [rad/s] at g0 = ``fixed``, or
    ``g0`` [m] at Omega = ``fixed``). ``h_max``: the largest step as a fraction of the range (and of y_s).

    Forced orbits (default): w = Omega. ``autonomous``: the orbit's frequency is an unknown (start ``w0``) and a
    phase condition fixes its time origin (:func:`.autonomous.phase_index`: the sine of harmonic 1 of the
    coordinate that moves most vanishes); ``start_tangent`` (dY, dw, dp) starts the branch at (Y0, w0) as it is
    (a Hopf point: the static solution, any w) along that direction, instead of a Newton solve there.
    ``halt(point) -> str | None``: a reason to end the branch at this point (the map's bound on the amplitude).
    ``unit``: the parameter's unit in the branch's message ("rad/s" for a model's speed; "" for the
    non-dimensional oscillators)."""
    if parameter not in ("omega", "g0"):
        raise ParameterError(f"parameter: '{parameter}' unknown; accepted: omega, g0")
    if not (math.isfinite(start) and math.isfinite(stop)) or start == stop:
        raise ParameterError(f"start, stop: {start}, {stop}: a range of finite, distinct values is needed")
    if autonomous and (Y0 is None or w0 is None):
        raise ParameterError("autonomous: needs a start Y0 and its frequency w0 (an orbit, or a Hopf point's "
                             "static solution with start_tangent)")
    # the branch's message is read in verdicts ("reached omega = 240.3" left a structures engineer guessing rpm)
    unit = f" {unit}" if unit else ""
    pb = problem
    om, w, g0 = (start, start, fixed) if parameter == "omega" else (fixed, fixed, start)
    if autonomous:
        w = float(w0)
    pb.set_clearance(g0)
    from .autonomous import newton_autonomous, phase_index
    from .problem import newton

    phase = None
    if autonomous:
        if start_tangent is not None:
            phase = phase_index(pb, start_tangent[0])
            first_Y, first_it = np.asarray(Y0, dtype=float), 0
        else:
            phase = phase_index(pb, Y0)
            res = newton_autonomous(pb, Y0, w, om, phase=phase)
            if not res.converged:
                return HBBranch(parameter, [], [], False, f"no autonomous HB solution at the start (|R| = "
                                                          f"{res.residual:.2e})")
            first_Y, w, first_it = res.Y, res.w, res.iterations
    else:
        first = newton(pb, pb.linear_start(om, w) if Y0 is None else Y0, om, w)
        if not first.converged:
            return HBBranch(parameter, [], [], False, f"no HB solution at the start (|R| = {first.residual:.2e})")
        first_Y, first_it = first.Y, first.iterations
    # the length scale of the response: the clearance (a rub's amplitudes are of its order), or the no-contact
    # response where that is larger; with a smaller scale the steps crawl through a resonance peak
    if y_scale is None:
        y_scale = max(float(np.abs(pb.linear_start(om, w)).max()), 2 * abs(g0), 1e-6)
    tr = _Tracer(pb, parameter, start, stop, fixed, y_scale, autonomous, abs(w) if autonomous else 1.0, phase)
    direction = float(np.sign(stop - start))
    z = tr.pack(first_Y, start, w if autonomous else None)
    _, A, _ = tr.blocks(z)
    if start_tangent is not None:
        dY, dw, dp = start_tangent
        t = tr.pack(np.asarray(dY) + 0.0, tr.p0 + dp, dw) - tr.pack(np.zeros(pb.N), tr.p0, 0.0)
        t /= np.linalg.norm(t)
    else:
        t = tr.tangent(A, None, direction)
    pts = [tr.point(z, stability and start_tangent is None, substeps, first_it)]
    specials: list[Special] = []
    h = 0.2 * h_max
    det_sign = _bordered_sign(A, t)
    message, complete = "", False
    while len(pts) < max_points:
        z_new, A_new, its = tr.correct(z + h * t, t)
        if z_new is None:
            h *= 0.5
            if h < 1e-7:
                message = f"the corrector failed at {parameter} = {tr.unpack(z)[1]:.6g}{unit} (step below 1e-7)"
                break
            continue
        p_old, p_new = tr.unpack(z)[1], tr.unpack(z_new)[1]
        if (p_new - stop) * (start - stop) < 0:  # past the end: land on it
            e = np.zeros_like(z)
            e[-1] = 1.0
            anchor = z.copy()
            anchor[-1] = (stop - tr.p0) / tr.ps
            z_end, A_end, its_end = tr.correct(z + (stop - p_old) / (p_new - p_old) * (z_new - z), e, anchor=anchor)
            if z_end is not None:
                z_new, A_new, its = z_end, A_end, its_end
            complete = True
        t_new = tr.tangent(A_new, t, direction)
        new = tr.point(z_new, stability, substeps, its)
        sign_new = _bordered_sign(A_new, t_new)
        specials += _locate(tr, z, z_new, t, t_new, pts[-1], new, det_sign, sign_new, stability, substeps)
        pts.append(new)
        if progress is not None:
            progress(new)
        z, t, det_sign = z_new, t_new, sign_new
        reason = halt(new) if halt is not None else None
        if reason:
            message = f"stopped at {parameter} = {tr.unpack(z)[1]:.6g}{unit}: {reason}"
            complete = False
            break
        if complete:
            break
        h = min(h * (1.5 if its <= 3 else 1.0 if its <= 5 else 0.5), h_max)
    else:
        message = f"stopped after {max_points} points"
    if complete:
        message = f"reached {parameter} = {stop:.6g}{unit}"
    return HBBranch(parameter, pts, specials, complete, message)


def _bordered_sign(A: np.ndarray, t: np.ndarray) -> float:
    return float(np.linalg.slogdet(np.vstack([A, t]))[0])


def _on_step(tr: _Tracer, za: np.ndarray, zb: np.ndarray, ta: np.ndarray, s: float):
    d = float(ta @ (zb - za))
    anchor = za + s * d * ta
    z, A, _ = tr.correct(za + s * (zb - za), ta, anchor=anchor)
    return z, A


def _locate(tr: _Tracer, za, zb, ta, tb, pa: HBPoint, pb_: HBPoint, sa: float, sb: float, stability: bool,
            substeps: int) -> list[Special]:
    out: list[Special] = []
    if ta[-1] * tb[-1] < 0:  # fold

        def tp(s):
            z, A = _on_step(tr, za, zb, ta, s)
            return None if z is None else tr.tangent(A, ta, 1.0)[-1]

        s = regula_falsi(tp, 0.0, 1.0, ta[-1], tb[-1], 1e-8)
        z = None if s is None else _on_step(tr, za, zb, ta, s)[0]
        if z is not None:
            out.append(Special("fold", tr.point(z, False, substeps)))
    elif sa != sb and sa != 0 and sb != 0:  # branch point (at a fold the bordered determinant keeps its sign)

        def det(s):
            z, A = _on_step(tr, za, zb, ta, s)
            return None if z is None else _bordered_sign(A, tr.tangent(A, ta, 1.0))

        s = regula_falsi(det, 0.0, 1.0, sa, sb, 1e-6, sign_only=True)
        z = None if s is None else _on_step(tr, za, zb, ta, s)[0]
        if z is not None:
            out.append(Special("branch", tr.point(z, False, substeps)))
    if stability and pa.floquet is not None and pb_.floquet is not None and pa.stable != pb_.stable:

        def excess(s):
            z, _ = _on_step(tr, za, zb, ta, s)
            return None if z is None else tr.point(z, True, substeps).floquet.largest - 1.0

        s = regula_falsi(excess, 0.0, 1.0, pa.floquet.largest - 1.0, pb_.floquet.largest - 1.0, 1e-4, max_iter=12)
        z = None if s is None else _on_step(tr, za, zb, ta, s)[0]
        if z is not None:
            pt = tr.point(z, True, substeps)
            unstable = pb_ if not pb_.stable else pa
            out.append(Special("stability", pt, {"to": "unstable" if not pb_.stable else "stable",
                                                 "how": unstable.floquet.kind(),
                                                 "largest_multiplier": pt.floquet.largest}))
    return out
