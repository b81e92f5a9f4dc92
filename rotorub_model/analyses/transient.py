"""Explicit central-difference transients of eq. (12).

    M q'' + (D + G(Omega)) q' + K(Omega) q = F_nl(q) + r(t) F(Omega^2)

with the imbalance ramped in, r(t) = min(t / t_ramp, 1) (1 s by default).
Central differences (q' = (q+ - q-)/2dt, q'' = (q+ - 2q + q-)/dt^2):

    (M/dt^2 + C/(2dt)) q+ = r F + F_nl(q) - (K - 2M/dt^2) q - (M/dt^2 - C/(2dt)) q-,

C = D + G. The contact force is evaluated at the current q only, so the scheme
is explicit; the left-hand matrix is constant for a constant Omega and is
inverted once. The loop runs compiled (numba): per step three dense mat-vecs and
the contact law.

Spin-speed histories Omega(t): Omega is held over short segments (``segment``
seconds, 1 ms by default) and the matrices are rebuilt per segment; the
angular-acceleration terms (the Euler force dOmega/dt E1 q and the tangential
imbalance force m e dOmega/dt) are included with the segment's mean acceleration.

Time step: the stability limit of central differences is dt < 2 / w_max, with
w_max the largest frequency of the linearised system with every contact closed
(all blades in full contact). By default dt = 0.5 x that limit; a user dt above the
limit is refused.

Divergence: the run stops when a gap falls below -``max_penetration`` (10 mm by
default: the blade has gone through the liner, the penalty model is meaningless)
or a value stops being finite; the result says so and when.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numba import njit

from ..contact import ContactModel
from ..contact.laws import blade_laws
from ..errors import ParameterError
from ..results import pyplot, save_figure, write_json
from ..structure.model import Model


@njit(cache=True)
def _cd_segment(q_prev, q, n_steps, Ainv, K2, Cm1, f_imb, t0, dt, t_ramp, me_ratio0, G, g0, A, B, Cc, Dc,
                mu, k, chord, n_pts, rec_every, step0, rec_q, rec_start, max_pen):
    """Advance n_steps; returns (steps done, records written, diverged flag)."""
    n = q.shape[0]
    nb = A.shape[0]
    gaps = np.empty((nb, n_pts))
    law = np.empty((nb, 7))
    rhs = np.empty(n)
    n_rec = rec_start
    for i in range(n_steps):
        t = t0 + i * dt
        r = 1.0 if (t_ramp <= 0.0 or t >= t_ramp) else t / t_ramp
        r *= me_ratio0
        # gaps and contact law
        for row in range(nb * n_pts):
            s = g0
            for c in range(n):
                s += G[row, c] * q[c]
            gaps[row // n_pts, row % n_pts] = s
        blade_laws(gaps, k, chord, n_pts == 2, law)
        diverged = False
        for j in range(nb):
            for p in range(n_pts):
                if not (gaps[j, p] > -max_pen):
                    diverged = True
        if diverged:
            return i, n_rec, True
        # rhs = r F + F_nl + K2 q - Cm1 q_prev
        for c in range(n):
            s = r * f_imb[c]
            for j in range(nb):
                FN = law[j, 0]
                MN = law[j, 1]
                s += A[j, c] * FN + B[j, c] * MN - mu * (Cc[j, c] * FN + Dc[j, c] * MN)
            for e in range(n):
                s += K2[c, e] * q[e] - Cm1[c, e] * q_prev[e]
            rhs[c] = s
        for c in range(n):
            q_prev[c] = q[c]
        for c in range(n):
            s = 0.0
            for e in range(n):
                s += Ainv[c, e] * rhs[e]
            q[c] = s
        if (step0 + i + 1) % rec_every == 0 and n_rec < rec_q.shape[0]:
            for c in range(n):
                rec_q[n_rec, c] = q[c]
            n_rec += 1
    return n_steps, n_rec, False


@njit(cache=True)
def _linear_cd(q_prev, q, n_steps, Ainv, K2, Cm1, f):
    """The bare linear central-difference update (benchmark reference)."""
    n = q.shape[0]
    rhs = np.empty(n)
    for _ in range(n_steps):
        for c in range(n):
            s = f[c]
            for e in range(n):
                s += K2[c, e] * q[e] - Cm1[c, e] * q_prev[e]
            rhs[c] = s
        for c in range(n):
            q_prev[c] = q[c]
        for c in range(n):
            s = 0.0
            for e in range(n):
                s += Ainv[c, e] * rhs[e]
            q[c] = s


def all_closed_stiffness(contact: ContactModel) -> np.ndarray:
    """Contact stiffness with every blade in full contact (-dF_nl/dq)."""
    return -contact.with_clearance(-1.0).jacobian(np.zeros(contact.n_dofs))


def critical_time_step(model: Model, contact: ContactModel, omega: float) -> float:
    """2 / w_max of the linearised system with all contacts closed [s]."""
    Kc = model.K_omega(omega) + all_closed_stiffness(contact)
    lam = np.linalg.eigvals(np.linalg.solve(model.M, Kc))
    return 2.0 / math.sqrt(float(np.max(np.abs(lam))))


class CentralDifference:
    """A central-difference integrator with state, stepping at constant inputs.

    The FMU and :func:`run_transient` both drive this object. State: (t, q, q_prev,
    phi) with phi the rotation angle of the rotating frame (for fixed-frame outputs).

    Parameters
    ----------
    dt : float or None
        Time step; None = half the stability limit at the largest speed seen so far.
    """

    def __init__(self, model: Model, contact: ContactModel, dt: float | None = None, t_ramp: float = 1.0,
                 max_penetration: float = 0.01, omega_max_for_dt: float | None = None):
        if t_ramp is None or not math.isfinite(t_ramp) or t_ramp < 0:
            raise ParameterError(f"t_ramp: {t_ramp} out of range; accepted range [0, inf) s")
        if not math.isfinite(max_penetration) or max_penetration <= 0:
            raise ParameterError(f"max_penetration: {max_penetration} out of range; accepted range (0, inf) m")
        self.model, self.contact = model, contact
        self.t_ramp = float(t_ramp)
        self.max_penetration = max_penetration
        self.user_dt = dt
        w = omega_max_for_dt if omega_max_for_dt is not None else 0.0
        self.dt_limit = critical_time_step(model, contact, w)
        self.dt = self._check_dt(dt, self.dt_limit)
        n = model.n_dofs
        self.t = 0.0
        self.steps = 0
        self.phi = 0.0
        self.q = np.zeros(n)
        self.q_prev = np.zeros(n)
        self.diverged = False
        self._key = None
        self._mats = None
        self._geom = None
        self._set_contact_arrays()

    @staticmethod
    def _check_dt(dt: float | None, limit: float) -> float:
        if dt is None:
            return 0.5 * limit
        if not math.isfinite(dt) or dt <= 0:
            raise ParameterError(f"dt: {dt} out of range; accepted range (0, {limit:.3e}] s")
        if dt > limit:
            raise ParameterError(
                f"dt: {dt:.3e} s exceeds the central-difference stability limit 2/w_max = {limit:.3e} s "
                f"(all contacts closed); accepted range (0, {limit:.3e}] s"
            )
        return float(dt)

    def _set_contact_arrays(self) -> None:
        c = self.contact
        self._geom = (
            np.ascontiguousarray(c.G), float(c.g0), np.ascontiguousarray(c.A), np.ascontiguousarray(c.B),
            np.ascontiguousarray(c.C), np.ascontiguousarray(c.D), float(c.mu), float(c.k_r),
            float(max(c.geometry.chord, 1e-300)), int(c.n_points),
        )

    def set_clearance(self, g0: float) -> None:
        """Change the nominal clearance between steps (gaps are affine in g0)."""
        if not math.isfinite(g0):
            raise ParameterError(f"g0: {g0} is not finite; accepted range (-l_b/2, inf) m")
        self.contact = self.contact.with_clearance(g0)
        self._set_contact_arrays()

    def _matrices(self, omega: float, omega_dot: float):
        key = (omega, omega_dot, self.dt)
        if key != self._key:
            m, dt = self.model, self.dt
            C = m.D + m.G(omega)
            K = m.K_omega(omega) + omega_dot * m.E1
            Aeff = m.M / dt**2 + C / (2 * dt)
            self._mats = (np.linalg.inv(Aeff), 2 * m.M / dt**2 - K, m.M / dt**2 - C / (2 * dt),
                          np.ascontiguousarray(m.force(omega, 1.0, omega_dot)))
            self._key = key
        return self._mats

    def ensure_stable_dt(self, omega: float) -> None:
        """Re-check (and, for the automatic choice, adapt) the step at a new speed."""
        limit = critical_time_step(self.model, self.contact, omega)
        if self.user_dt is None:
            if self.dt > 0.5 * limit * 1.000001:
                self.dt = 0.5 * limit
        elif self.user_dt > limit:
            self._check_dt(self.user_dt, limit)
        self.dt_limit = min(self.dt_limit, limit)

    def advance(self, n_steps: int, omega: float, me: float, omega_dot: float = 0.0,
                rec_every: int = 0, rec_q: np.ndarray | None = None, rec_start: int = 0) -> tuple[int, int]:
        """Advance n_steps at constant inputs; returns (steps done, records written)."""
        if self.diverged:
            return 0, rec_start
        Ainv, K2, Cm1, f = self._matrices(omega, omega_dot)
        if rec_q is None:
            rec_q = np.empty((0, self.model.n_dofs))
            rec_every = max(n_steps, 1)
        done, n_rec, div = _cd_segment(
            self.q_prev, self.q, int(n_steps), Ainv, K2, Cm1, f, self.t, self.dt, self.t_ramp, float(me),
            *self._geom, int(max(rec_every, 1)), self.steps, rec_q, int(rec_start), self.max_penetration,
        )
        self.steps += done
        self.t += done * self.dt
        self.phi += done * self.dt * omega
        self.diverged = bool(div)
        return done, n_rec

    # state for rollback (FMU get/set state)
    def get_state(self) -> tuple:
        return (self.t, self.steps, self.phi, self.q.copy(), self.q_prev.copy(), self.diverged, self.dt,
                self.contact.g0)

    def set_state(self, state: tuple) -> None:
        t, steps, phi, q, q_prev, div, dt, g0 = state
        self.t, self.steps, self.phi, self.diverged, self.dt = float(t), int(steps), float(phi), bool(div), float(dt)
        self.q[:] = q
        self.q_prev[:] = q_prev
        if g0 != self.contact.g0:
            self.set_clearance(g0)
        self._key = None

    def velocity(self) -> np.ndarray:
        return (self.q - self.q_prev) / self.dt


def rotate_to_fixed(v: np.ndarray, phi: np.ndarray | float) -> np.ndarray:
    """Rotate rotating-frame (x, y, ...) components by phi to the fixed frame (last axis)."""
    c, s = np.cos(phi), np.sin(phi)
    out = np.array(v, dtype=float, copy=True)
    out[..., 0] = c * v[..., 0] - s * v[..., 1]
    out[..., 1] = s * v[..., 0] + c * v[..., 1]
    return out


def outputs_from_q(model: Model, contact: ContactModel, q: np.ndarray, phi: np.ndarray) -> dict[str, np.ndarray]:
    """Physical outputs for states q (nt, n) at frame angles phi (nt,)."""
    nt = q.shape[0]
    N, P = contact.n_blades, contact.n_points
    FN = np.zeros((nt, N))
    frac = np.zeros((nt, N))
    gaps = np.zeros((nt, N, P))
    Fc = np.zeros((nt, 3))
    torque = np.zeros(nt)
    for i in range(nt):
        o = contact.outputs(q[i])
        FN[i], frac[i], gaps[i] = o["F_N"], o["fraction"], o["gap"]
        Fc[i] = o["casing_force"]
        torque[i] = o["friction_torque"]
    T, _ = model.disk_maps
    cs = model.slices["casing"]
    disk = (T[:2] @ q.T).T
    casing = q[:, cs][:, :2]
    return {
        "F_N": FN,
        "F_T": contact.mu * FN,
        "fraction": frac,
        "gap": gaps,
        "disk_fixed": rotate_to_fixed(disk, phi),
        "casing_fixed": rotate_to_fixed(casing, phi),
        "casing_force_fixed": rotate_to_fixed(Fc, phi),
        "friction_torque": torque,
    }


@dataclass
class TransientResult:
    formulation: str
    t: np.ndarray
    q: np.ndarray
    omega: np.ndarray  # rad/s at each record
    outputs: dict[str, np.ndarray]
    dt: float
    dt_limit: float
    diverged: bool
    t_end: float  # time reached
    message: str
    omega_ref: float

    def blades_in_contact(self, i: int = -1) -> int:
        return int(np.sum(self.outputs["F_N"][i] > 0))

    def at_time(self, t: float) -> int:
        return int(np.argmin(np.abs(self.t - t)))

    def summary(self) -> dict:
        o = self.outputs
        return {
            "formulation": self.formulation,
            "diverged": self.diverged,
            "message": self.message,
            "t_reached_s": self.t_end,
            "dt_s": self.dt,
            "dt_limit_s": self.dt_limit,
            "final_normal_forces_N": o["F_N"][-1],
            "final_chord_fractions": o["fraction"][-1],
            "max_normal_force_N": float(o["F_N"].max()) if o["F_N"].size else 0.0,
        }

    def plot(self, path: str | Path, title: str = "") -> Path:
        plt = pyplot()
        fig, axes = plt.subplots(2, 1, figsize=(8, 6), sharex=True)
        FN = self.outputs["F_N"]
        for j in range(FN.shape[1]):
            if FN[:, j].max() > 0:
                axes[0].plot(self.t, FN[:, j], lw=1, label=f"blade {j + 1}")
        axes[0].set_ylabel("normal contact force F_N [N]")
        axes[0].legend(fontsize=7, ncol=2)
        axes[0].set_title(title or f"{self.formulation} transient" + (" (diverged)" if self.diverged else ""))
        axes[1].plot(self.t, np.hypot(*self.outputs["disk_fixed"].T) * 1e3, lw=1)
        axes[1].set_ylabel("fan-disk displacement [mm]")
        axes[1].set_xlabel("time [s]")
        for ax in axes:
            ax.grid(alpha=0.3)
        return save_figure(fig, path)

    def save(self, out: str | Path, stem: str | None = None) -> dict:
        out = Path(out)
        out.mkdir(parents=True, exist_ok=True)
        stem = stem or f"transient_{self.formulation}"
        self.plot(out / f"{stem}.png")
        np.savez_compressed(out / f"{stem}.npz", t=self.t, q=self.q, omega=self.omega, **self.outputs)
        s = self.summary()
        write_json(out / f"{stem}.json", s)
        return s


def run_transient(
    model: Model,
    contact: ContactModel,
    omega: float | Callable[[float], float],
    t_end: float = 1.5,
    t_ramp: float = 1.0,
    me: float | None = None,
    dt: float | None = None,
    record_dt: float = 1e-3,
    segment: float = 1e-3,
    q0: np.ndarray | None = None,
    v0: np.ndarray | None = None,
    max_penetration: float = 0.01,
    progress: bool = False,
    hold: float | None = None,
) -> TransientResult:
    """Central-difference transient from rest (or q0, v0), imbalance ramped over t_ramp.

    ``omega`` is a constant [rad/s] or a function of time (a spin-speed history).
    Records every ``record_dt`` seconds (rounded to whole steps).

    ``hold`` [s] reproduces what a co-simulation master does with the FMU: the inputs
    (spin speed and ramped imbalance) are sampled at the start of each interval of
    length ``hold`` and held over it (zero-order hold, Euler terms off), and the step
    is the largest that divides ``hold`` within the stability cap. ``record_dt`` must
    then be a whole multiple of ``hold``.
    """
    for name, v, lo in (("t_end", t_end, 0.0), ("record_dt", record_dt, 0.0), ("segment", segment, 0.0)):
        if not math.isfinite(v) or v <= lo:
            raise ParameterError(f"{name}: {v} out of range; accepted range ({lo:g}, inf) s")
    if hold is not None:
        if not math.isfinite(hold) or hold <= 0:
            raise ParameterError(f"hold: {hold} out of range; accepted range (0, inf) s")
        ratio = record_dt / hold
        if abs(ratio - round(ratio)) > 1e-9 * ratio or round(ratio) < 1:
            raise ParameterError(f"record_dt: {record_dt} s must be a whole multiple of hold = {hold} s")
    me = model.params.imbalance.me if me is None else me
    if not math.isfinite(me) or me < 0:
        raise ParameterError(f"me: {me} out of range; accepted range [0, inf) kg m")
    omega_fn = omega if callable(omega) else (lambda _t, w=float(omega): w)
    ts = np.linspace(0.0, t_end, 201)
    speeds = np.array([omega_fn(t) for t in ts])
    if not np.all(np.isfinite(speeds)) or np.any(speeds < 0):
        raise ParameterError("omega: spin speed must be finite and >= 0 rad/s over the whole run")
    integ = CentralDifference(model, contact, dt, 0.0 if hold else t_ramp, max_penetration,
                              omega_max_for_dt=float(speeds.max()))
    if hold is not None:
        # same rule as the FMU: n = ceil(h / cap) substeps per held interval
        integ.dt = hold / max(1, math.ceil(hold / integ.dt * (1 - 1e-9)))
    elif dt is None and record_dt > integ.dt:
        # automatic step: shrink it so the records fall exactly on multiples of record_dt
        integ.dt = record_dt / math.ceil(record_dt / integ.dt)
    dt_ = integ.dt
    if q0 is not None:
        integ.q[:] = q0
        integ.q_prev[:] = q0 - (dt_ * v0 if v0 is not None else 0.0)
    n_total = int(round(t_end / dt_))
    rec_every = max(1, int(round(record_dt / dt_)))
    n_rec = n_total // rec_every
    rec_q = np.zeros((n_rec, model.n_dofs))
    constant = not callable(omega)
    seg_steps = n_total if constant else max(1, int(round(segment / dt_)))
    if hold is not None:
        seg_steps = max(1, int(round(hold / dt_)))
    phi_rec = []
    done_total, written = 0, 0
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=n_total, desc=f"{contact.formulation} transient", unit="step", unit_scale=True)
    while done_total < n_total:
        n = min(seg_steps, n_total - done_total)
        t_a, t_b = integ.t, integ.t + n * dt_
        if hold is not None:
            w_mid, w_dot = omega_fn(t_a), 0.0
            me_k = me * (1.0 if (t_ramp <= 0 or t_a >= t_ramp) else t_a / t_ramp)
        else:
            w_mid = omega_fn(0.5 * (t_a + t_b))
            w_dot = 0.0 if constant else (omega_fn(t_b) - omega_fn(t_a)) / (t_b - t_a)
            me_k = me
        before = written
        done, written = integ.advance(n, w_mid, me_k, w_dot, rec_every=rec_every, rec_q=rec_q, rec_start=written)
        if hold is not None and written > before:
            phi_rec.append(integ.phi)
        done_total += done
        if bar is not None:
            bar.update(done)
        if integ.diverged or done < n:
            break
    if bar is not None:
        bar.close()
    t_rec = (np.arange(written) + 1) * rec_every * dt_
    q_rec = rec_q[:written]
    om = np.array([omega_fn(t) for t in t_rec])
    if hold is not None:
        phi = np.array(phi_rec[:written])
        om = np.array([omega_fn(t - hold) for t in t_rec])  # the speed held over the last interval
    elif constant or written == 0:
        phi = om * t_rec
    else:  # frame angle: trapezoidal integral of the spin-speed history
        phi = om[0] * t_rec[0] + np.concatenate([[0.0], np.cumsum(0.5 * (om[1:] + om[:-1]) * np.diff(t_rec))])
    outs = outputs_from_q(model, integ.contact, q_rec, phi)
    msg = (
        f"diverged at t = {integ.t:.4f} s: penetration beyond {max_penetration * 1e3:g} mm"
        if integ.diverged
        else f"completed {t_end:g} s in {done_total} steps of {dt_:.3e} s"
    )
    return TransientResult(contact.formulation, t_rec, q_rec, om, outs, dt_, integ.dt_limit, integ.diverged,
                           integ.t, msg, model.params.normalisation.omega_ref)
