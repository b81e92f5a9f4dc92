"""Explicit central-difference transients of eq. (12).

    M q'' + (D + G(Omega)) q' + K(Omega) q = F_nl(q) + r(t) F(Omega^2)

with the imbalance ramped in, r(t) = min(t / t_ramp, 1) (1 s by default).
Central differences (q' = (q+ - q-)/2dt, q'' = (q+ - 2q + q-)/dt^2):

    (M/dt^2 + C/(2dt)) q+ = r F + F_nl(q) - (K - 2M/dt^2) q - (M/dt^2 - C/(2dt)) q-,

C = D + G. The contact force is evaluated at the current q only, so the scheme
is explicit; the left-hand matrix is constant for a constant Omega and is
inverted once. The loop runs in the compiled kernel (``rotorub_model/kernel``): per
step three dense mat-vecs and the contact law; the outputs of each recorded state are
computed there too, so a run is one call into C.

Spin-speed histories Omega(t): Omega is held over short segments (``segment``
seconds, 1 ms by default) and the matrices are rebuilt per segment; the
angular-acceleration terms (the Euler force dOmega/dt E1 q and the tangential
imbalance force m e dOmega/dt) are included with the segment's mean acceleration.

Time step: the stability limit of central differences is dt < 2 / w_max, with
w_max the largest frequency of the linearised system with every contact closed
(all blades in full contact). By default dt = 0.5 x that limit; a user dt above the
limit is refused.

Two things a run can show, named apart everywhere (the result, every JSON file, the report, the console):

* ``penetration_limit_hit``: the run stopped because a gap fell below -``max_penetration`` (by default the
  parameter file's contact.max_penetration, 3 mm in the reference: the blade has gone through the liner, the
  penalty model is meaningless) or a value stopped being finite; the message says when;
* ``envelope_growing``: the run's oscillation grows, its envelope DIVERGENCE_GROWTH-fold or more over the second
  half at a steady exponential rate (:func:`envelope_growth`, with the fitted rate in ``envelope_growth``),
  measured about the balanced static solution where the run has one (a constant speed, no liner), else as the
  oscillation's peak-to-peak range; None for a run shorter than 4 s (no verdict rather than a false one).

``diverged`` is either: the limit was hit, or the envelope grows (None when neither can be said).
"""

from __future__ import annotations

import ctypes
import math
import mmap
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .. import kernel
from ..contact import ContactModel
from ..contact.liner import Liner
from ..errors import ParameterError
from ..plotting import pyplot
from ..structure.model import Model
from ..writing import save_result

BLOCK_MIN_DOFS = 200  # the time loop steps by blocks from this many dofs (benchmarks/bench_scale.py's crossing)


def all_closed_stiffness(contact: ContactModel, omega: float) -> np.ndarray:
    """Contact stiffness with every blade in full contact at the law's largest slope (-dF_nl/dq) at spin omega."""
    return contact.closed_stiffness(omega)


def held_substep(model: Model, contact: ContactModel, omega: float, hold: float) -> float:
    """The step the FMU takes through a communication step ``hold`` at spin speed ``omega``: hold / n, n = ceil(hold /
    cap) equal substeps, cap half the stability limit at the speed rounded up to a whole rad/s (the FMU evaluates the
    limit once per rad/s band; fmu_src/models/contact/model.c, substeps()) and at most the FMU's dt_max at its
    default, 1 ms. ``run_transient(hold=...)`` follows it interval by interval, so that the library and the FMU run
    the same steps on every configuration (a blade count whose limit crosses a multiple of hold/2 within a run-up
    changes the plan there: 14 blades, 2 -> 3 substeps)."""
    cap = min(FMU_DT_MAX, 0.5 * critical_time_step(model, contact, float(math.ceil(omega))))
    return hold / max(1, math.ceil(hold / cap * (1.0 - 1e-9)))


FMU_DT_MAX = 1e-3  # [s] the FMU's dt_max parameter at its default (fmu_src/models/contact/variables.py)


def critical_time_step(model: Model, contact: ContactModel, omega: float) -> float:
    """2 / w_max of the linearised system with all contacts closed at the law's largest slope [s]: the kernel's
    (rr_critical_step), which both FMUs call too, so all pick the same step."""
    # the limit depends on the model, the law and the speed only (every contact closed: not on g0): kept on the
    # contact model, so a study's runs at one speed compute it once
    cache = contact.__dict__.setdefault("_step_limits", {})
    key = (id(model), float(omega))
    if key in cache and cache[key][0] is model:
        return cache[key][1]
    n = model.n_dofs
    Minv = kernel.inverse(model.M)  # the kernel's LU, as the FMUs invert M
    Kw = np.ascontiguousarray(model.K_omega(omega))
    work = np.empty(contact.lib.rr_critical_step_work_size(n))
    dt = contact.lib.rr_critical_step(contact.kernel, float(omega), kernel.ptr(Minv), kernel.ptr(Kw), kernel.ptr(work))
    if not dt > 0:
        raise ParameterError("the central-difference stability limit: the eigenvalue iteration did not converge")
    cache[key] = (model, float(dt))
    return float(dt)


class CentralDifference:
    """A central-difference integrator with state, stepping at constant inputs.

    The FMU and :func:`run_transient` both drive this object. State: (t, q, q_prev,
    phi) with phi the rotation angle of the rotating frame (for fixed-frame outputs);
    it lives in the kernel's ``rr_cd_state`` (t, dt, phi, steps, diverged) and in the
    arrays ``q``, ``q_prev`` (updated in place: never rebind them).

    Parameters
    ----------
    dt : float or None
        Time step; None = half the stability limit at the largest speed seen so far.
    dt_limit : float or None
        The stability limit when the caller knows it (e.g. from a model that differs only by its blade count:
        the limit is the blade's and the contact's, not the count's); None: computed here by the kernel's dense
        eigen-solve (rr_critical_step, O(n^3): what the FMUs compute too).
    """

    def __init__(self, model: Model, contact: ContactModel, dt: float | None = None, t_ramp: float = 1.0,
                 max_penetration: float | None = None, omega_max_for_dt: float | None = None,
                 liner: Liner | None = None, blocks: bool | None = None, dt_limit: float | None = None):
        if t_ramp is None or not math.isfinite(t_ramp) or t_ramp < 0:
            raise ParameterError(f"t_ramp: {t_ramp} out of range; accepted range [0, inf) s")
        if max_penetration is None:  # the parameter file's (contact.max_penetration: an abradable liner's depth)
            max_penetration = model.params.contact.max_penetration
        if not math.isfinite(max_penetration) or max_penetration <= 0:
            raise ParameterError(f"max_penetration: {max_penetration} out of range; accepted range (0, inf) m")
        self.model = model
        # the step by blocks (hub, blades, casing) where the model is large enough for it to pay: its cost grows
        # linearly with the blades, the dense step's as their square (another order of sums: not the dense step's
        # bits, so the reference's 38 dofs keep the dense step)
        self.blocks = (model.n_dofs >= BLOCK_MIN_DOFS) if blocks is None else bool(blocks)
        self.user_dt = dt
        w = omega_max_for_dt if omega_max_for_dt is not None else 0.0
        if dt_limit is not None and not (math.isfinite(dt_limit) and dt_limit > 0):
            raise ParameterError(f"dt_limit: {dt_limit} out of range; accepted range (0, inf) s")
        self.dt_limit = critical_time_step(model, contact, w) if dt_limit is None else float(dt_limit)
        n = model.n_dofs
        self.q = np.zeros(n)
        self.q_prev = np.zeros(n)
        self._s = kernel.RRState(0.0, self._check_dt(dt, self.dt_limit), 0.0, float(max_penetration), 0, 0,
                                 kernel.ptr(self.q), kernel.ptr(self.q_prev))
        # one kernel job, kept: a call only changes what differs from the last one; the job keeps the contact
        # evaluation of its last state, so that a run cut into calls (held inputs) evaluates each state once
        self._job = kernel.RRJob(state=ctypes.addressof(self._s), t_ramp=float(t_ramp))
        self._cache = np.zeros(contact.lib.rr_cd_cache_size(n, contact.n_segments, contact.n_points))
        self._job.cache = kernel.ptr(self._cache)
        self._job_ref = ctypes.byref(self._job)
        self._bound: tuple = ()
        self._addresses: dict[int, tuple[np.ndarray, int]] = {}
        self._key = None
        self._mats = None
        self.liner = liner
        self.contact = contact

    # the scheme's scalars live in the kernel's state struct
    t = property(lambda self: self._s.t, lambda self, v: setattr(self._s, "t", float(v)))
    dt = property(lambda self: self._s.dt, lambda self, v: setattr(self._s, "dt", float(v)))
    phi = property(lambda self: self._s.phi, lambda self, v: setattr(self._s, "phi", float(v)))
    steps = property(lambda self: self._s.steps, lambda self, v: setattr(self._s, "steps", int(v)))
    diverged = property(lambda self: bool(self._s.diverged), lambda self, v: setattr(self._s, "diverged", int(v)))
    max_penetration = property(lambda self: self._s.max_pen)
    t_ramp = property(lambda self: self._job.t_ramp)

    @property
    def contact(self) -> ContactModel:
        return self._contact

    @contact.setter
    def contact(self, c: ContactModel) -> None:
        self._contact = c
        self._run = c.lib.rr_cd_run
        self._job.cache_valid = 0  # another contact struct: the kept evaluation is not its
        if self.liner is None:
            self._job.contact = ctypes.addressof(c.kernel)
        else:  # the loop's own view of the contact, with the liner's surface (the model's own stays rigid)
            self.liner.contact = c
            self._seen = self.liner.attach(c.kernel)
            self.use_liner(self._liner_on)

    _liner_on = True  # whether the loop sees the liner (use_liner)

    @property
    def liner_on(self) -> bool:
        return self._liner_on

    def use_liner(self, on: bool) -> None:
        """Let the loop see the liner or not. A rigid liner with no closure and no offset adds exactly 0 to every
        gap: without it the kernel runs the paper's loop (none of the surface's cost), with the same numbers."""
        self._liner_on = bool(on)
        if self.liner is not None:
            self._job.contact = ctypes.addressof(self._seen if on else self._contact.kernel)
            self._job.cache_valid = 0

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

    def set_clearance(self, g0: float) -> None:
        """Change the nominal clearance between steps (gaps are affine in g0)."""
        if not math.isfinite(g0):
            raise ParameterError(f"g0: {g0} is not finite; accepted range (-l_b/2, inf) m")
        self.contact = self.contact.with_clearance(g0)

    def _matrices(self, omega: float, omega_dot: float) -> kernel.RRMatrices:
        key = (omega, omega_dot, self.dt)
        if key != self._key:
            m, n = self.model, self.model.n_dofs
            lib = self.contact.lib
            structure = [np.ascontiguousarray(getattr(m, k), dtype=float)
                         for k in ("M", "D", "K", "G1", "C1", "N2", "S2", "E1")]
            s4 = None if m.S4 is None else np.ascontiguousarray(m.S4, dtype=float)
            s4p = None if s4 is None else kernel.ptr(s4)
            # the imbalance force per unit m e (scaled by the kernel) and the blades' own inertia
            # load under dOmega/dt (not scaled: it does not depend on the imbalance)
            f_me = np.ascontiguousarray(omega * omega * m.f_unit + omega_dot * m.f_tangential, dtype=float)
            f0 = np.ascontiguousarray(omega_dot * m.f_euler, dtype=float)
            layout = m.block_layout if self.blocks else None
            if layout is not None:
                # by blocks (hub, blades, casing): a step's cost grows linearly with the blades (rr_cd_blocks)
                ns, nb, mb, nc = layout
                store = np.zeros(lib.rr_cd_blocks_size(ns, nb, mb, nc))
                work = np.zeros(lib.rr_cd_blocks_work_size(ns, mb, nc))
                piv = np.zeros(max(ns, mb, nc), dtype=np.intc)
                blocks = kernel.RRBlocks()
                if lib.rr_cd_build_blocks(n, ns, nb, mb, nc, *map(kernel.ptr, structure), s4p, float(omega),
                                          float(omega_dot), float(self.dt), kernel.ptr(store), ctypes.byref(blocks),
                                          kernel.ptr(work), kernel.iptr(piv)) != 0:
                    raise ParameterError(f"dt: {self.dt:g} s: a block of the central-difference matrix is singular")
                arrays = (store, f_me, f0)
                mats = kernel.RRMatrices(n=n, f=kernel.ptr(f_me), f0=kernel.ptr(f0),
                                         blocks=ctypes.addressof(blocks))
                self._mats = (mats, arrays, blocks)
            else:
                Ainv, K2, Cm1 = np.empty((n, n)), np.empty((n, n)), np.empty((n, n))
                work, piv = np.empty(2 * n * n), np.empty(n, dtype=np.intc)  # named: alive during the call
                # assembled and inverted by the kernel: the FMUs build the same matrices with the same code
                if lib.rr_cd_build(
                        n, *map(kernel.ptr, structure), s4p, float(omega), float(omega_dot), float(self.dt),
                        kernel.ptr(Ainv), kernel.ptr(K2), kernel.ptr(Cm1), kernel.ptr(work), kernel.iptr(piv)) != 0:
                    raise ParameterError(f"dt: {self.dt:g} s: the central-difference matrix is singular")
                arrays = (Ainv, K2, Cm1, f_me, f0)
                mats = kernel.RRMatrices(n, *map(kernel.ptr, arrays))
                self._mats = (mats, arrays)
            self._job.mats = ctypes.addressof(mats)
            self._key = key
        return self._mats[0]

    def ensure_stable_dt(self, omega: float) -> None:
        """Re-check (and, for the automatic choice, adapt) the step at a new speed."""
        limit = critical_time_step(self.model, self.contact, omega)
        if self.user_dt is None:
            if self.dt > 0.5 * limit * 1.000001:
                self.dt = 0.5 * limit
        elif self.user_dt > limit:
            self._check_dt(self.user_dt, limit)
        self.dt_limit = min(self.dt_limit, limit)

    def bind_outputs(self, index: np.ndarray | None, dest: np.ndarray | None) -> None:
        """After every :meth:`advance`, write the outputs of the final state (fixed frame, the
        kernel's layout) to ``dest[index[k]]``: an FMU's value buffer. None unbinds."""
        self._bound = () if dest is None else (index, dest)  # keeps them alive while bound
        self._job.out_index = None if dest is None else kernel.iptr(index)
        self._job.out_dest = None if dest is None else kernel.ptr(dest)

    def record_wear(self, every: int, rows: np.ndarray | None) -> None:
        """With a liner: its profile every ``every``-th step of the run into ``rows`` (n, n_sectors), from
        its first row on (None: stop recording); :attr:`wear_records` counts the rows written."""
        self._wear_rows = rows  # kept alive while the kernel writes into it
        job = self._job
        job.rec_wear_every = int(every)
        job.rec_wear_cap = 0 if rows is None else rows.shape[0]
        job.n_rec_wear = 0
        job.rec_wear = None if rows is None else kernel.ptr(rows)

    wear_records = property(lambda self: self._job.n_rec_wear)

    def advance(self, n_steps: int, omega: float, me: float, omega_dot: float = 0.0,
                rec_every: int = 0, rec_q: np.ndarray | None = None, rec_start: int = 0,
                rec_out: np.ndarray | None = None) -> tuple[int, int]:
        """Advance n_steps at constant inputs in one kernel call; returns (steps done, records written).

        Records: every ``rec_every``-th step of the run (``rec_every < 0``: the call's last step only), q into
        ``rec_q`` and (if given) the
        outputs of the state (rotating frame, kernel layout) into ``rec_out``, from row
        ``rec_start``.
        """
        if self._s.diverged:
            return 0, rec_start
        if (omega, omega_dot, self._s.dt) != self._key:
            self._matrices(omega, omega_dot)
        job = self._job
        job.n_steps = n_steps
        job.omega = omega
        job.me = me
        if rec_q is None:
            job.rec_cap = 0
            job.n_rec = rec_start
        else:
            addr = self._address
            job.rec_every = rec_every
            job.rec_cap = rec_q.shape[0]
            job.n_rec = rec_start
            job.rec_q = addr(rec_q)
            job.rec_out = addr(rec_out)
        return self._run(self._job_ref), job.n_rec

    def _address(self, a: np.ndarray | None) -> int | None:
        # run_transient passes the same record buffers at every segment: convert each once
        if a is None:
            return None
        hit = self._addresses.get(id(a))
        if hit is None or hit[0] is not a:
            if len(self._addresses) > 32:
                self._addresses.clear()
            hit = self._addresses[id(a)] = (a, kernel.ptr(a))
        return hit[1]

    # state for rollback (FMU get/set state)
    def get_state(self) -> tuple:
        return (self.t, self.steps, self.phi, self.q.copy(), self.q_prev.copy(), self.diverged, self.dt,
                self.contact.g0, None if self.liner is None else self.liner.get_state())

    def set_state(self, state: tuple) -> None:
        t, steps, phi, q, q_prev, div, dt, g0, *rest = state
        self.t, self.steps, self.phi, self.diverged, self.dt = float(t), int(steps), float(phi), bool(div), float(dt)
        self.q[:] = q
        self.q_prev[:] = q_prev
        if g0 != self.contact.g0:
            self.set_clearance(g0)
        if self.liner is not None and rest and rest[0] is not None:
            self.liner.set_state(rest[0])
        self._key = None

    def velocity(self) -> np.ndarray:
        return (self.q - self.q_prev) / self.dt

    def restart(self, dt: float, omega: float, omega_dot: float = 0.0) -> None:
        """Go on with step dt at the current velocity (the two-step scheme restarted: q_prev = q - dt v). The
        matrices for (omega, dt) are built first: if they cannot be (ParameterError), nothing has changed."""
        old_dt, old_key = self.dt, self._key
        self._s.dt = float(dt)
        try:
            self._matrices(omega, omega_dot)
        except ParameterError:
            self._s.dt, self._key = old_dt, old_key
            raise
        v = (self.q - self.q_prev) / old_dt if old_dt != 0.0 else np.zeros_like(self.q)
        self.q_prev[:] = self.q - dt * v


def rotate_to_fixed(v: np.ndarray, phi: np.ndarray | float) -> np.ndarray:
    """Rotate rotating-frame (x, y, ...) components by phi to the fixed frame (last axis)."""
    c, s = np.cos(phi), np.sin(phi)
    out = np.array(v, dtype=float, copy=True)
    out[..., 0] = c * v[..., 0] - s * v[..., 1]
    out[..., 1] = s * v[..., 0] + c * v[..., 1]
    return out


# A run's records, written once front to back by the kernel, from this size on are mapped with their pages present
# (Linux's MAP_POPULATE: one call instead of a page fault at each page's first write). A 2.5 s run recording every
# 1 ms writes 2.1 MB; on this project's 2-core VM its 520 faults cost 0.6 ms of a 10 ms run (6 %), one call 0.36 ms
# for all of them (benchmarks/bench_transient.py). Below it, and where the flag does not exist, numpy's zeros. Up to
# POPULATE_UP_TO_BYTES only: populated pages are memory taken at the start, and a long run that diverges early would
# hold all of them (lazy pages cost the same faults per page written, whatever the run's length).
POPULATE_FROM_BYTES = 1 << 20
POPULATE_UP_TO_BYTES = 64 << 20


def record_arrays(n_rec: int, n_dofs: int, n_out: int) -> tuple[np.ndarray, np.ndarray]:
    """The records of a run: states (n_rec, n_dofs) and the kernel's outputs (n_rec, n_out), zeros, in one block of
    memory (see POPULATE_FROM_BYTES). The arrays keep the block alive; it is unmapped with the last of them."""
    size = n_rec * (n_dofs + n_out)
    populate = getattr(mmap, "MAP_POPULATE", None)
    if populate is None or not POPULATE_FROM_BYTES <= size * 8 <= POPULATE_UP_TO_BYTES:
        buf = np.zeros(size)
    else:
        block = mmap.mmap(-1, size * 8, flags=mmap.MAP_PRIVATE | mmap.MAP_ANONYMOUS | populate)
        buf = np.frombuffer(block, dtype=float)  # anonymous pages are zeros
    return buf[: n_rec * n_dofs].reshape(n_rec, n_dofs), buf[n_rec * n_dofs:].reshape(n_rec, n_out)


def outputs_from_q(model: Model, contact: ContactModel, q: np.ndarray, phi: np.ndarray,
                   rotating: np.ndarray | None = None, omega: float = 0.0,
                   qdot: np.ndarray | None = None) -> dict[str, np.ndarray]:
    """Physical outputs for states q (nt, n) at frame angles phi (nt,).

    ``rotating``: the kernel's outputs of these states (rotating frame), if already
    computed (the transient records them as it goes); else one batched kernel call at spin
    ``omega`` with velocities ``qdot`` (None: at rest in the rotating frame).
    """
    o = contact.split_outputs(contact.outputs_array(q, omega, qdot) if rotating is None else rotating)
    cs = model.slices["casing"]
    casing = q[:, cs][:, :2]
    return {
        "F_N": o["F_N"],
        "F_T": o["F_T"],
        "fraction": o["fraction"],
        "gap": o["gap"],
        "disk_fixed": rotate_to_fixed(o["disk"], phi),
        "casing_fixed": rotate_to_fixed(casing, phi),
        "casing_force_fixed": rotate_to_fixed(o["casing_force"], phi),
        "friction_torque": o["friction_torque"],
    }


@dataclass(frozen=True)
class TransientState:
    """Where a run stopped, for the next run to go on from (``run_transient(..., start=state)``): the time, the
    scheme's two states, the frame angle (the rotor's angle against the casing: a worn liner is met where it was
    left), the step, and the liner's state when it had one (its worn profile, inputs and last cut)."""

    t: float  # [s]
    q: np.ndarray  # (n) displacements at t
    q_prev: np.ndarray  # (n) displacements at t - dt
    phi: float  # [rad] frame angle at t
    steps: int
    dt: float  # [s] the step that produced q from q_prev
    liner: tuple | None = None  # Liner.get_state()

    @property
    def velocity(self) -> np.ndarray:
        return (self.q - self.q_prev) / self.dt


# The growth verdict (envelope_growth, envelope_grows): the envelope grows 1.5-fold or more over the run's second
# half at a steady exponential rate. Measured on 7 configurations x 2D/3D at their transient points (20 s runs): the
# stable static solutions' runs reach at most 1.14 (a 3D run with a ten times stiffer contact), the unstable ones
# whose rate shows in 20 s at least 1.6; the log-linear fits have R^2 >= 0.97 both ways, so the R^2 bound only keeps
# a limit cycle's flat, noisy envelope from counting.
DIVERGENCE_GROWTH = 1.5
DIVERGENCE_FIT_R2 = 0.9
GROWTH_MIN_RUN_S = 4.0  # a run shorter than this gets no growth verdict (its second half is mostly ringing)
NO_GROWTH = {"rate_per_s": None, "factor": None, "window_s": None, "fit_r2": None}


def envelope_growth(t: np.ndarray, y: np.ndarray, t_from: float | None = None, kind: str = "max",
                    t_start: float = 0.0) -> dict:
    """Growth of the envelope of a signal at the end of a run: rate [1/s] and factor.

    The envelope is y's largest value (``kind="max"``) or its peak-to-peak range (``"ptp"``) over
    windows of 0.25 s; the rate a least-squares fit of its log over the second half of the run (from
    ``t_from``, default max(half the run, 2 s)): by then the ringing the ramp left has decayed at the
    stable modes' rates and what remains grows, or decays, at the rate of the static solution's leading
    eigenvalue, whatever the ringing's size. (Dividing the end's envelope by the one at 2 s, as this did,
    took an 18-blade rotor growing 10x at +0.16 1/s for settled: its ringing at 2 s was larger still.)
    ``factor`` = exp(rate x window): the growth over that window. None where the run (from ``t_start``, its
    first instant: a continued run's) is shorter than 4 s.

    >>> t = np.arange(0.0, 10.0, 1e-3)
    >>> round(envelope_growth(t, np.exp(0.2 * t) * np.abs(np.cos(50 * t)))["rate_per_s"], 2)
    0.2
    """
    if len(t) < 4 or t[-1] - t_start < GROWTH_MIN_RUN_S:
        return dict(NO_GROWTH)
    t0 = t_start + max(0.5 * (float(t[-1]) - t_start), 2.0) if t_from is None else float(t_from)
    edges = np.arange(t0, t[-1] + 1e-12, 0.25)
    env, tc = [], []
    for a, b in zip(edges[:-1], edges[1:]):
        sel = (t >= a) & (t < b)
        if sel.any():
            env.append(np.ptp(y[sel], axis=0) if kind == "ptp" else y[sel].max(axis=0))
            tc.append(0.5 * (a + b))
    if len(env) < 4:
        return dict(NO_GROWTH)
    env_a = np.array(env)
    if env_a.ndim == 2:  # peak-to-peak of each component, then their norm
        env_a = np.linalg.norm(env_a, axis=1)
    log_env = np.log(np.maximum(env_a, 1e-300))
    (rate, c0) = np.polyfit(tc, log_env, 1)
    res = log_env - (rate * np.asarray(tc) + c0)
    ss = float(np.sum((log_env - log_env.mean()) ** 2))
    window = float(tc[-1] - tc[0])
    return {"rate_per_s": float(rate), "factor": float(np.exp(rate * window)),
            "window_s": [float(tc[0]), float(tc[-1])], "fit_r2": float(1.0 - np.sum(res**2) / ss) if ss > 0 else 0.0}


def envelope_grows(growth: dict) -> bool | None:
    """The growth verdict on an :func:`envelope_growth`: the envelope grows by DIVERGENCE_GROWTH or more over the
    second half at a steady exponential rate (log-linear fit R^2 >= DIVERGENCE_FIT_R2); None where it was not
    measured. A limit cycle (flat envelope) or ringing that decays does not grow, however large."""
    f, r2 = growth.get("factor"), growth.get("fit_r2")
    if f is None:
        return None
    return bool(f >= DIVERGENCE_GROWTH and (r2 or 0.0) >= DIVERGENCE_FIT_R2)


def run_growth(t: np.ndarray, q: np.ndarray, q_static: np.ndarray | None, t_start: float = 0.0) -> dict:
    """The envelope growth of a run's states: of |q - q_static| (the distance to the balanced static solution)
    when there is one, else of the states' peak-to-peak range (an oscillation about wherever the run is);
    ``about`` says which."""
    if len(t) < 4:
        return {**NO_GROWTH, "about": None}
    if q_static is not None:
        return {**envelope_growth(t, np.linalg.norm(q - q_static, axis=1), t_start=t_start),
                "about": "the static solution"}
    return {**envelope_growth(t, q, kind="ptp", t_start=t_start), "about": "the oscillation (peak to peak)"}


# a run still oscillating at its end (TransientResult.force_swing): a blade's normal force swinging by more than 5 %
# of its highest value over the last 2 s (the reference's settled 3D run: 0.1 %; a limit cycle: 50 %)
SWING_WINDOW_S = 2.0
SWING_MIN_REL = 0.05


def force_swing(t: np.ndarray, F_N: np.ndarray | None) -> tuple[float, float] | None:
    """(lowest, highest) normal force [N] of the blade whose force swings most over a run's last SWING_WINDOW_S,
    where that swing exceeds SWING_MIN_REL of its highest value (the run still oscillates: a limit cycle or ringing
    not yet gone); None where the forces have settled, or the run is too short. ``F_N``: (records, blades), at the
    times ``t`` (the library's runs and the FMU harnesses' alike)."""
    if F_N is None or F_N.size == 0 or t[-1] - t[0] < 2 * SWING_WINDOW_S:
        return None
    last = F_N[t >= t[-1] - SWING_WINDOW_S]
    j = int(np.argmax(np.ptp(last, axis=0)))
    lo, hi = float(last[:, j].min()), float(last[:, j].max())
    return (lo, hi) if hi > 0.0 and hi - lo > SWING_MIN_REL * hi else None


def not_settled_words(swing: tuple[float, float] | None) -> str:
    """'; not settled: F_N still swings a-b N over the last 2 s' after a verdict, for a :func:`force_swing`; ''
    for None (the library's verdict and the FMU harnesses' say it alike)."""
    return (f"; not settled: F_N still swings {swing[0]:.3g}-{swing[1]:.3g} N over the last {SWING_WINDOW_S:g} s"
            if swing else "")


@dataclass
class TransientResult:
    formulation: str
    t: np.ndarray
    q: np.ndarray
    omega: np.ndarray  # rad/s at each record
    outputs: dict[str, np.ndarray]
    dt: float
    dt_limit: float
    penetration_limit_hit: bool  # the run stopped: a gap below -max_penetration, or a value not finite
    t_end: float  # time reached
    message: str
    omega_ref: float
    wear: dict | None = None  # with a liner: t, angles, profiles (nt, n_sectors), depth (rows), summary
    final_state: TransientState | None = None  # where the run stopped: the next run's ``start``
    # the envelope's growth over the run's second half (run_growth: rate_per_s, factor, window_s, fit_r2, about)
    envelope_growth: dict = field(default_factory=lambda: {**NO_GROWTH, "about": None})

    @property
    def envelope_growing(self) -> bool | None:
        """The oscillation grows (:func:`envelope_grows`); None for a run too short to say (< 4 s)."""
        return envelope_grows(self.envelope_growth)

    @property
    def diverged(self) -> bool | None:
        """Either: the penetration limit was hit, or the envelope grows; None when neither can be said."""
        return True if self.penetration_limit_hit else self.envelope_growing

    def blades_in_contact(self, i: int = -1) -> int:
        return int(np.sum(self.outputs["F_N"][i] > 0))

    def at_time(self, t: float) -> int:
        return int(np.argmin(np.abs(self.t - t)))

    def verdict(self) -> str:
        """The run's outcome in words (the figure's title and the console's line)."""
        g = self.envelope_growth
        if self.penetration_limit_hit:
            # the run's message already says "diverged at t = ..." ("diverged: diverged at" read as a stutter)
            return self.message if self.message.startswith("diverged") else f"diverged: {self.message}"
        if g.get("factor") is None:
            return f"no growth verdict (a run shorter than {GROWTH_MIN_RUN_S:g} s)"
        what = (f"envelope about {g['about']} ×{g['factor']:.3g} over {g['window_s'][0]:.3g}-{g['window_s'][1]:.3g} s "
                f"({g['rate_per_s']:+.3g} 1/s)")
        if self.envelope_growing:
            return "diverged: " + what
        swing = self.force_swing()
        # a flat envelope is not a settled rub: a limit cycle that swings a blade's force 90-181 N for ever read
        # "not diverging" like a run at rest on its static solution
        return "not diverging: " + what + not_settled_words(swing)

    def force_swing(self) -> tuple[float, float] | None:
        """(lowest, highest) normal force [N] of the blade whose force swings most over the run's last
        SWING_WINDOW_S (:func:`force_swing`)."""
        return force_swing(self.t, self.outputs.get("F_N"))

    def summary(self) -> dict:
        o = self.outputs
        return {
            "formulation": self.formulation,
            "diverged": self.diverged,
            "penetration_limit_hit": self.penetration_limit_hit,
            "envelope_growing": self.envelope_growing,
            "envelope_growth": self.envelope_growth,
            "diverged_definition": "penetration_limit_hit (a gap below -max_penetration: the run stopped) or "
                                   f"envelope_growing (the envelope grows {DIVERGENCE_GROWTH:g}-fold or more over the "
                                   f"run's second half at a steady rate, fit R^2 >= {DIVERGENCE_FIT_R2:g}); null when "
                                   f"neither can be said (a run shorter than {GROWTH_MIN_RUN_S:g} s)",
            "message": self.message,
            "t_reached_s": self.t_end,
            "dt_s": self.dt,
            "dt_limit_s": self.dt_limit,
            "final_normal_forces_N": o["F_N"][-1] if len(o["F_N"]) else [],
            "final_chord_fractions": o["fraction"][-1] if len(o["fraction"]) else [],
            "max_normal_force_N": float(o["F_N"].max()) if o["F_N"].size else 0.0,
            # [lowest, highest] F_N [N] of the blade swinging most over the last 2 s where it still swings; null
            # where the forces have settled
            "force_swing_last_s_N": list(sw) if (sw := self.force_swing()) else None,
        }

    def figure(self, title: str = ""):
        """Forces per blade over the fan disk's displacement, the verdict in the title."""
        from ..plotting import legend_outside, plot_blade_forces

        plt = pyplot()
        fig, axes = plt.subplots(2, 1, figsize=(9, 6), sharex=True)
        plot_blade_forces(axes[0], self.t, self.outputs["F_N"])
        axes[0].set_ylabel("normal contact force F_N [N]")
        axes[0].set_title(title or f"{self.formulation} transient: {self.verdict()}", fontsize=9)
        axes[1].plot(self.t, np.hypot(*self.outputs["disk_fixed"].T) * 1e3, lw=1, color="0.2")
        axes[1].set_ylabel("fan-disk displacement [mm]")
        axes[1].set_xlabel("time [s]")
        w = self.envelope_growth.get("window_s")
        for ax in axes:
            ax.grid(alpha=0.3)
            if w:
                ax.axvspan(w[0], w[1], color="0.85", zorder=0, lw=0,
                           label="window of the growth fit" if ax is axes[1] else None)
            legend_outside(ax)
        return fig

    def save(self, out: str | Path, stem: str | None = None) -> dict:
        stem = stem or f"transient_{self.formulation}"
        s = save_result(self, out, stem)
        np.savez_compressed(Path(out) / f"{stem}.npz", t=self.t, q=self.q, omega=self.omega, **self.outputs)
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
    max_penetration: float | None = None,
    progress: bool = False,
    hold: float | None = None,
    liner: Liner | None = None,
    wear_record_dt: float = 0.05,
    start: TransientState | None = None,
) -> TransientResult:
    """Central-difference transient from rest (or q0, v0), imbalance ramped over t_ramp.

    ``omega`` is a constant [rad/s] or a function of time (a spin-speed history).
    Records every ``record_dt`` seconds (rounded to whole steps).

    ``hold`` [s] reproduces what a co-simulation master does with the FMU: the inputs
    (spin speed and ramped imbalance) are sampled at the start of each interval of
    length ``hold`` and held over it (zero-order hold, Euler terms off), and each interval
    is stepped as the FMU steps it (:func:`held_substep`: hold / n within half the stability
    limit at the held speed, restarted at the same velocity where n changes; with ``dt``
    given, or a liner, n = ceil(hold / dt) throughout). ``record_dt`` must then be a whole
    multiple of ``hold``; records fall at the ends of the intervals.

    ``liner`` (contact/liner.py): the casing's abradable liner, cut as the run goes (its state is the
    liner's: a second run goes on from the profile the first left); its profile is recorded every
    ``wear_record_dt`` seconds into ``result.wear``.

    ``start``: a previous run's ``final_state``: this run goes on from it (time, both states, the frame angle,
    the liner's worn profile; the engine's inputs are the liner's own, set on it between runs), for ``t_end``
    more seconds; the imbalance ramp and a spin-speed history
    read the continued time. Without it the run starts from rest at t = 0 (or from ``q0``, ``v0``).
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
    ts = np.linspace(0.0, t_end, 201) if callable(omega) else np.zeros(1)
    speeds = np.array([omega_fn(t) for t in ts])
    if not np.all(np.isfinite(speeds)) or np.any(speeds < 0):
        raise ParameterError("omega: spin speed must be finite and >= 0 rad/s over the whole run")
    if liner is not None and not (math.isfinite(wear_record_dt) and wear_record_dt > 0):
        raise ParameterError(f"wear_record_dt: {wear_record_dt} out of range; accepted range (0, inf) s")
    integ = CentralDifference(model, contact, dt, 0.0 if hold else t_ramp, max_penetration,
                              omega_max_for_dt=float(speeds.max()), liner=liner)
    plan = None
    if hold is not None and dt is None and liner is None:
        # the FMU's plan, interval by interval (what a master sees of the FMU, step for step; see held_substep)
        def plan(w: float) -> float:
            return held_substep(model, contact, w, hold)

        integ.dt = plan(omega_fn(0.0 if start is None else start.t))
    elif hold is not None:
        # a step given (or a liner: its profile records count steps): n = ceil(h / dt) substeps throughout
        integ.dt = hold / max(1, math.ceil(hold / integ.dt * (1 - 1e-9)))
    elif dt is None and record_dt > integ.dt:
        # automatic step: shrink it so the records fall exactly on multiples of record_dt
        integ.dt = record_dt / math.ceil(record_dt / integ.dt)
    dt_ = integ.dt
    for name, a in (("q0", q0), ("v0", v0)):
        if a is not None and (np.shape(a) != (model.n_dofs,) or not np.all(np.isfinite(a))):
            raise ParameterError(f"{name}: expected {model.n_dofs} finite values (the model's dofs), got shape "
                                 f"{np.shape(a)}{'' if np.all(np.isfinite(a)) else ' with non-finite values'}")
    if q0 is not None:
        integ.q[:] = q0
        integ.q_prev[:] = q0 - (dt_ * v0 if v0 is not None else 0.0)
    if start is not None:
        if q0 is not None or v0 is not None:
            raise ParameterError("start: a run goes on from a previous run's final state or from q0, v0, not both")
        if not isinstance(start, TransientState) or np.shape(start.q) != (model.n_dofs,):
            raise ParameterError(f"start: expected a TransientState of this model ({model.n_dofs} dofs)")
        if (start.liner is None) != (liner is None):
            raise ParameterError("start: the previous run " + ("had a liner: pass it (liner=...) to go on"
                                                              if liner is None else "had no liner; this one has"))
        integ.t, integ.steps, integ.phi = start.t, start.steps, start.phi
        integ.q[:] = start.q
        # the scheme's velocity carries over; the step may differ (another speed's limit): q_prev = q - dt v
        integ.q_prev[:] = start.q - dt_ * start.velocity
        if liner is not None:  # what the rub left; the engine's inputs stay the liner's own (set between runs)
            inputs = (liner.closure, liner.offset, dict(liner.distortion))
            liner.set_state(start.liner)
            liner.set_inputs(*inputs)
    t0 = integ.t
    n_total = int(round(t_end / dt_))
    rec_every = max(1, int(round(record_dt / dt_)))
    n_rec = n_total // rec_every
    rec_q, rec_out = record_arrays(n_rec, model.n_dofs, contact.n_outputs)
    constant = not callable(omega)
    seg_steps = n_total if constant else max(1, int(round(segment / dt_)))
    if liner is not None:  # the kernel copies the profile every wear_every steps as it goes
        wear_every = max(1, int(round(wear_record_dt / dt_)))
        wear_rows = np.zeros((n_total // wear_every, liner.n_sectors))
        integ.record_wear(wear_every, wear_rows)
    phi_rec = []
    done_total, written = 0, 0
    bar = None
    if progress:
        from tqdm import tqdm

        bar = tqdm(total=n_total, desc=f"{contact.formulation} transient", unit="step", unit_scale=True)
    steps_used = {integ.dt}
    if hold is not None:  # one held interval at a time, recorded at its end, as a master reads the FMU
        n_held, rec_held = int(round(t_end / hold)), max(1, int(round(record_dt / hold)))
        plans: dict[int, float] = {}
        if bar is not None:
            bar.total = n_total  # in the first interval's steps: the plan may change them
        for k in range(n_held):
            t_a = integ.t
            w_k = omega_fn(t_a)
            me_k = me * (1.0 if (t_ramp <= 0 or t_a >= t_ramp) else t_a / t_ramp)
            if plan is not None:
                band = math.ceil(w_k)  # the FMU's limit is per whole rad/s: so is its plan
                dt_k = plans.get(band)
                if dt_k is None:
                    dt_k = plans[band] = plan(w_k)
                if dt_k != integ.dt:
                    integ.restart(dt_k, w_k)  # at the same velocity, as the FMU
                    steps_used.add(integ.dt)
            n = max(1, int(round(hold / integ.dt)))
            if (k + 1) % rec_held == 0 and written < n_rec:  # the interval's last step recorded (rec_every < 0)
                before = written
                done, written = integ.advance(n, w_k, me_k, rec_every=-1, rec_q=rec_q, rec_start=written,
                                              rec_out=rec_out)
                if written > before:
                    phi_rec.append(integ.phi)
            else:
                done = integ.advance(n, w_k, me_k)[0]
            done_total += done
            if bar is not None:
                bar.update(done)
            if integ.diverged or done < n:
                break
    while hold is None and done_total < n_total:
        n = min(seg_steps, n_total - done_total)
        t_a, t_b = integ.t, integ.t + n * dt_
        w_mid = omega_fn(0.5 * (t_a + t_b))
        w_dot = 0.0 if constant else (omega_fn(t_b) - omega_fn(t_a)) / (t_b - t_a)
        done, written = integ.advance(n, w_mid, me, w_dot, rec_every=rec_every, rec_q=rec_q, rec_start=written,
                                      rec_out=rec_out)
        done_total += done
        if bar is not None:
            bar.update(done)
        if integ.diverged or done < n:
            break
    if bar is not None:
        bar.close()
    t_rec = t0 + (np.arange(written) + 1) * rec_every * dt_
    q_rec = rec_q[:written]
    if constant:
        om = np.full(written, float(omega))
    else:  # with hold: the speed held over the interval that ends at the record
        om = np.array([omega_fn(t - hold if hold is not None else t) for t in t_rec])
    phi0 = 0.0 if start is None else start.phi
    if hold is not None:
        phi = np.array(phi_rec[:written])  # the held intervals' angles, recorded as the run went
    elif constant or written == 0:
        phi = phi0 + om * (t_rec - t0)
    else:  # frame angle: trapezoidal integral of the spin-speed history
        phi = phi0 + om[0] * (t_rec[0] - t0) + np.concatenate(
            [[0.0], np.cumsum(0.5 * (om[1:] + om[:-1]) * np.diff(t_rec))])
    outs = outputs_from_q(model, integ.contact, q_rec, phi, rotating=rec_out[:written])
    msg = (
        f"diverged at t = {integ.t:.4f} s: penetration beyond {integ.max_penetration * 1e3:g} mm"
        if integ.diverged
        else f"completed {t_end:g} s in {done_total} steps of {dt_:.3e} s" if len(steps_used) == 1
        else (f"completed {t_end:g} s in {done_total} steps of {min(steps_used):.3e}-{max(steps_used):.3e} s (the "
              f"FMU's plan: each held {hold:g} s in steps within half the stability limit at its speed)")
    )
    wear = None
    if liner is not None:
        k = integ.wear_records
        integ.record_wear(0, None)
        wear = {"t": t0 + (np.arange(k) + 1) * wear_every * dt_, "angles": liner.angles,
                "profiles": wear_rows[:k].copy(), "depth": liner.depth.copy(), "summary": liner.summary()}
    final = TransientState(integ.t, integ.q.copy(), integ.q_prev.copy(), integ.phi, integ.steps, integ.dt,
                           None if liner is None else liner.get_state())
    growth = {**NO_GROWTH, "about": None}
    if not integ.diverged and written >= 4 and t_rec[-1] - t0 >= GROWTH_MIN_RUN_S:
        growth = run_growth(t_rec, q_rec, _static_reference(model, contact, omega, me, liner), t0)
    return TransientResult(contact.formulation, t_rec, q_rec, om, outs, min(steps_used), integ.dt_limit, integ.diverged,
                           integ.t, msg, model.params.normalisation.omega_ref, wear, final, growth)


def _static_reference(model: Model, contact: ContactModel, omega, me: float, liner: Liner | None) -> np.ndarray | None:
    """The balanced static solution the run's envelope is measured about, where it has one: a constant speed and
    the model's own casing (no liner: a worn, offset or closing surface moves the equilibrium, which the static
    solver does not see). None otherwise, or where Newton finds none."""
    if callable(omega) or liner is not None:
        return None
    from .static import solve_static

    st = solve_static(model, contact, float(omega), me)
    return st.q if st.converged else None
