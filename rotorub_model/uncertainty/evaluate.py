"""The evaluations: one chunk of samples in, the quantities and each analysis' cost out.

:func:`evaluate_chunk` is a top-level function of plain data (the study's evaluation spec as JSON, the
samples' physical values, their per-blade stiffness deviations), so that it pickles to any worker of the
project's executor (analyses/sweeps.py: a process pool, a local Dask cluster, a scheduler's workers). Each
worker builds what a spec needs once (lru cache): the nominal model, its contact model, the linear
responses at the operating speeds.

How each input enters (the cheapest exact way):

* contact.g0 and engine.closure shift every gap (the gaps are affine in them): detection reads the margin
  off the closure, the static and transient analyses run with g0 - closure;
* engine.offset: a fixed-frame offset e of the casing, swept once a revolution by every point: detection's
  closure gains max_p n_r,p e (n_r: the radial part of the point's normal); the transient runs against a
  rigid liner offset by (e, 0) (contact/liner.py); a static solution in the rotating frame has none (refused
  by the study's checks);
* imbalance.me and imbalance.angle_deg move the force only: q = me (cos d Q_u + sin d Q_t), d the angle
  from the parameter file's, Q_u, Q_t the responses to its unit force and to the unit force a quarter turn
  ahead (exact: the force is linear in (cos, sin));
* contact.k_r, mu, slip_velocity change the contact law only (detection does not see them); theta_deg and
  chord its geometry;
* the mistuning scales the blades' blocks of the tuned model (mistuning.mistuned_model);
* any other parameter rebuilds the model (0.1 s a sample at 38 dofs: the cost table says so).
"""

from __future__ import annotations

import dataclasses
import json
import math
import time
from functools import lru_cache

import numpy as np

from ..analyses.stability import RE_TOL
from ..contact import ContactModel, make_contact
from ..structure.model import Model, build_model
from ..structure.params import from_dict
from .mistuning import blade_tip_deflections, mistuned_model
from .quantities import QUANTITIES
from .targets import apply_to_params, resolve_target

CONTACT_LAW = ("k_r", "mu", "slip_velocity")
CONTACT_GEOMETRY = ("theta_deg", "chord")
SPECIAL = ("contact.g0", "engine.closure", "engine.offset", "imbalance.me", "imbalance.angle_deg")


def evaluate_chunk(spec: str, x: list, mistuning: list | None = None) -> dict[str, np.ndarray]:
    """Every quantity of ``spec`` for the samples ``x`` (n, d: the physical values of spec's inputs, in its
    order) with per-blade stiffness deviations ``mistuning`` (n, N) or None; plus ``seconds_<level>``: each
    sample's time in each analysis."""
    ctx = _context(spec)
    X = np.asarray(x, dtype=float).reshape(len(x), -1)
    D = None if mistuning is None else np.asarray(mistuning, dtype=float).reshape(len(x), -1)
    return ctx.evaluate(X, D)


@lru_cache(maxsize=4)
def _context(spec: str):
    s = json.loads(spec)
    if s["model"] == "ishigami":
        return Ishigami(s)
    return RotorubContext(s)


class Ishigami:
    """y = sin x1 + a sin^2 x2 + b x3^4 sin x1 (a = 7, b = 0.1), x_i uniform on [-pi, pi]: the sensitivity
    analysts' test function with known Sobol' indices (Ishigami & Homma 1990); what checks the pipeline."""

    A, B = 7.0, 0.1

    def __init__(self, s: dict):
        self.quantities = s["quantities"]

    def evaluate(self, X: np.ndarray, D) -> dict[str, np.ndarray]:
        t = time.perf_counter()
        y = np.sin(X[:, 0]) + self.A * np.sin(X[:, 1]) ** 2 + self.B * X[:, 2] ** 4 * np.sin(X[:, 0])
        dt = (time.perf_counter() - t) / max(len(X), 1)
        return {"y": y, "seconds_analytic": np.full(len(X), dt)}


@dataclasses.dataclass
class Sample:
    """One sample's inputs, split by where they enter."""

    g0: float
    closure: float
    offset: float
    me: float
    angle_deg: float
    contact: dict  # contact-law and geometry overrides
    rebuild: tuple  # values of the targets that rebuild the model
    delta: np.ndarray | None

    def key(self, with_mistuning: bool = True) -> tuple:
        d = tuple(self.delta) if (with_mistuning and self.delta is not None) else ()
        return (self.g0, self.closure, self.offset, self.me, self.angle_deg, tuple(sorted(self.contact.items())),
                self.rebuild, d)


class RotorubContext:
    def __init__(self, s: dict):
        self.spec = s
        self.params = from_dict(s["params"])
        self.model0 = build_model(self.params)
        self.formulation = s["formulation"]
        self.speeds = np.asarray(s["speeds"], dtype=float)
        self.omegas = self.speeds * self.params.normalisation.omega_ref
        self.quantities = s["quantities"]
        self.levels = {QUANTITIES[q].level for q in self.quantities}
        self.targets = [resolve_target("input", t, self.params) for t in s["targets"]]
        self.rebuild_targets = [t for t in self.targets if t.kind == "list" or (
            t.kind == "param" and t.name not in SPECIAL and t.section != "contact")]
        self.t_end, self.t_ramp = float(s.get("t_end", 4.0)), float(s.get("t_ramp", 1.0))
        self.contact0 = make_contact(self.model0, self.formulation)
        self._models: dict = {}
        self._tuned: dict = {}
        self._bases: dict = {}

    # ------------------------------------------------------------------ samples
    def sample(self, row: np.ndarray, delta: np.ndarray | None) -> Sample:
        p = self.params
        v = {t.name: float(x) for t, x in zip(self.targets, row)}
        contact = {t.field: v[t.name] for t in self.targets if t.section == "contact" and t.field != "g0"}
        return Sample(v.get("contact.g0", p.contact.g0), v.get("engine.closure", 0.0), v.get("engine.offset", 0.0),
                      v.get("imbalance.me", p.imbalance.me), v.get("imbalance.angle_deg", p.imbalance.angle_deg),
                      contact, tuple(v[t.name] for t in self.rebuild_targets), delta)

    def structure(self, smp: Sample, tuned: bool = False) -> Model:
        """The sample's model before its imbalance angle: rebuilt for structural inputs, then mistuned."""
        key = smp.rebuild
        base = self._models.get(key)
        if base is None:
            base = self.model0 if not key else build_model(apply_to_params(self.params, self.rebuild_targets, key))
            if len(self._models) > 64:
                self._models.clear()
            self._models[key] = base
        return base if tuned or smp.delta is None else mistuned_model(base, smp.delta)

    def imbalance(self, model: Model, smp: Sample) -> Model:
        """The model with its imbalance at the sample's angle (force vectors only)."""
        d = math.radians(smp.angle_deg - model.params.imbalance.angle_deg)
        if d == 0.0:
            return model
        c, s = math.cos(d), math.sin(d)
        return dataclasses.replace(model, f_unit=c * model.f_unit + s * model.f_tangential,
                                   f_tangential=-s * model.f_unit + c * model.f_tangential)

    def contact(self, model: Model, smp: Sample, g0: float) -> ContactModel:
        geo = {k: v for k, v in smp.contact.items() if k in CONTACT_GEOMETRY}
        if geo or smp.rebuild:  # the geometry is the parameters' (mistuning does not move it)
            c = make_contact(model, self.formulation, **geo)
        else:
            c = self.contact0
        law = {k: smp.contact.get(k, getattr(c, {"slip_velocity": "v_slip"}.get(k, k))) for k in CONTACT_LAW}
        return ContactModel(c.formulation, c.variant, c.geometry, float(g0), law["k_r"], law["mu"],
                            law["slip_velocity"])

    # ------------------------------------------------------------------ detection
    def basis(self, model: Model, contact: ContactModel) -> tuple[np.ndarray, ...]:
        """(C_u, C_t, n_r, Q): closures per unit m e of the unit force and of the one a quarter turn ahead
        (S, P), each contact point's radial normal component (P,), and the responses Q (S, n, 2): the solve of
        analyses/detection.linear_responses, for both force directions at once."""
        w = self.omegas
        K = model.K[None] + (w * w)[:, None, None] * (model.S2 + model.N2)[None] + w[:, None, None] * model.C1[None]
        if model.S4 is not None:  # an imported blade's prestress beyond the quadratic
            K = K + ((w * w) ** 2)[:, None, None] * model.S4[None]
        F = np.stack([(w * w)[:, None] * model.f_unit[None], (w * w)[:, None] * model.f_tangential[None]], axis=-1)
        Q = np.linalg.solve(K, F)  # (S, n, 2)
        c0 = contact.with_clearance(0.0)
        cu = -c0.gaps_batch(Q[..., 0]).reshape(len(w), -1)
        ct = -c0.gaps_batch(Q[..., 1]).reshape(len(w), -1)
        n = contact.geometry.normals.reshape(-1, 3)
        return cu, ct, np.hypot(n[:, 0], n[:, 1]), Q

    def margin(self, smp: Sample, basis) -> float:
        cu, ct, nr, _ = basis
        d = math.radians(smp.angle_deg - self.params.imbalance.angle_deg)
        clo = smp.me * (math.cos(d) * cu + math.sin(d) * ct) + smp.offset * nr[None, :]
        return float(smp.g0 - smp.closure - clo.max())

    def linear_q(self, smp: Sample, basis) -> np.ndarray:
        """The linear response at the (first) operating speed, for the sample's imbalance."""
        Q = basis[3][0]
        d = math.radians(smp.angle_deg - self.params.imbalance.angle_deg)
        return smp.me * (math.cos(d) * Q[:, 0] + math.sin(d) * Q[:, 1])

    def basis_for(self, smp: Sample, tuned: bool = False):
        mistuned = not tuned and smp.delta is not None
        if mistuned:  # every mistuned sample is a disk of its own: nothing to keep
            m = self.structure(smp)
            return self.basis(m, self.contact(m, smp, 0.0))
        key = (smp.rebuild, tuple(sorted((k, v) for k, v in smp.contact.items() if k in CONTACT_GEOMETRY)))
        b = self._bases.get(key)
        if b is None:
            m = self.structure(smp, tuned)
            b = self.basis(m, self.contact(m, smp, 0.0))
            if len(self._bases) > 64:
                self._bases.clear()
            self._bases[key] = b
        return b

    # ------------------------------------------------------------------ static and transient
    def static(self, smp: Sample, tuned: bool = False):
        from ..analyses.maps import ContactSetStarts
        from ..analyses.stability import stability_indicators
        from ..analyses.static import solve_static

        m = self.imbalance(self.structure(smp, tuned), smp)
        g0 = smp.g0 - smp.closure
        c = self.contact(m, smp, g0)
        w = float(self.omegas[0])
        st = solve_static(m, c, w)
        if not st.converged:  # past a fold: the maps' contact-set starts (analyses/maps.py)
            found, _ = ContactSetStarts(m, c.with_clearance(0.0), w).find(g0, None)
            st = found if found is not None else st
        mr = stability_indicators(m, c, w, st.q)[0] if st.converged else math.nan
        return st, mr

    def transient(self, smp: Sample, tuned: bool = False, wear: bool = False):
        from ..analyses.transient import run_transient
        from ..contact.liner import Liner

        m = self.imbalance(self.structure(smp, tuned), smp)
        c = self.contact(m, smp, smp.g0 - smp.closure)
        liner = None
        if wear or smp.offset:
            liner = Liner.for_model(m, c, wears=wear, offset=(smp.offset, 0.0))
        return run_transient(m, c, float(self.omegas[0]), t_end=self.t_end, t_ramp=self.t_ramp, liner=liner), m

    # ------------------------------------------------------------------ one chunk
    def evaluate(self, X: np.ndarray, D: np.ndarray | None) -> dict[str, np.ndarray]:
        n = len(X)
        out = {q: np.full(n, np.nan) for q in self.quantities}
        secs = {lv: np.zeros(n) for lv in self.levels}
        want = set(self.quantities)
        for i in range(n):
            smp = self.sample(X[i], None if D is None else D[i])
            if "detection" in self.levels:
                t = time.perf_counter()
                b = self.basis_for(smp)
                if want & {"margin", "rub"}:
                    mg = self.margin(smp, b)
                    if "margin" in want:
                        out["margin"][i] = mg
                    if "rub" in want:
                        out["rub"][i] = float(mg < 0.0)
                if "amp_linear" in want:
                    r = self.tips(smp, self.linear_q(smp, b)).max()
                    r0 = self.tips(smp, self.linear_q(smp, self.basis_for(smp, True))).max()
                    out["amp_linear"][i] = r / r0 if r0 > 0 else math.nan
                secs["detection"][i] = time.perf_counter() - t
            if "static" in self.levels:
                t = time.perf_counter()
                st, mr = self.static(smp)
                if st.converged:
                    if "static_max_force" in want:
                        out["static_max_force"][i] = float(st.forces_N.max())
                    if "static_blades_in_contact" in want:
                        out["static_blades_in_contact"][i] = float(st.n_contact)
                    if "static_max_real" in want:
                        out["static_max_real"][i] = mr
                    if "static_unstable" in want:
                        out["static_unstable"][i] = float(mr > RE_TOL)
                    if want & {"amp_contact", "amp_force"}:
                        st0, _ = self._cached_tuned("static", smp, lambda s=smp: self.static(s, tuned=True))
                        if st0.converged:
                            r0 = self.tips(smp, st0.q).max()
                            f0 = float(st0.forces_N.max())
                            if "amp_contact" in want and r0 > 0:
                                out["amp_contact"][i] = self.tips(smp, st.q).max() / r0
                            if "amp_force" in want and f0 > 0:
                                out["amp_force"][i] = float(st.forces_N.max()) / f0
                secs["static"][i] = time.perf_counter() - t
            if "transient" in self.levels or "wear" in self.levels:
                t = time.perf_counter()
                self._transient_quantities(smp, i, out, want)
                secs["wear" if "wear" in self.levels else "transient"][i] = time.perf_counter() - t
        for lv, v in secs.items():
            out[f"seconds_{lv}"] = v
        return out

    def tips(self, smp: Sample, Q: np.ndarray) -> np.ndarray:
        """Blade tip deflections of states Q with the sample's blades (a structural input may change them)."""
        return blade_tip_deflections(self.structure(smp, tuned=True), Q)

    def _cached_tuned(self, what: str, smp: Sample, make):
        key = (what, smp.key(with_mistuning=False))
        hit = self._tuned.get(key)
        if hit is None:
            if len(self._tuned) > 256:
                self._tuned.clear()
            hit = self._tuned[key] = make()
        return hit

    def _transient_quantities(self, smp: Sample, i: int, out: dict, want: set) -> None:
        from ..app.studies import growth_after_ramp, verdict

        wear = "wear_depth" in want
        run, m = self.transient(smp, wear=wear)
        F = run.outputs["F_N"]
        if "peak_force" in want:
            out["peak_force"][i] = float(F.max()) if F.size else 0.0
        if "wear_depth" in want:
            out["wear_depth"][i] = float(run.wear["summary"]["depth_max"])
        if "diverged" in want:
            st, _ = self.static(smp)
            g = growth_after_ramp(run, st.q) if st.converged else {"factor": None}
            v = verdict(run, g)
            out["diverged"][i] = math.nan if v is None else float(v)
        if "amp_contact_transient" in want:
            def peak(r):
                after = r.t >= self.t_ramp
                return self.tips(smp, r.q[after]).max() if after.any() else math.nan

            r0 = self._cached_tuned("transient", smp,
                                    lambda: peak(self.transient(smp, tuned=True, wear=wear)[0]))
            out["amp_contact_transient"][i] = peak(run) / r0 if r0 > 0 else math.nan
