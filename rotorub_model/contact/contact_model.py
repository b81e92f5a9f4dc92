"""One contact interface for both formulations.

A formulation supplies, for every blade j and every contact point k of the blade
(the tip in 2D; LE and TE in 3D), the rest position of the point, the outward
normal n of the casing surface there, and the linear maps J_b, J_c from q to the
displacement of the blade point and of the casing point facing it. With the small
displacement kinematics of the paper (rotations linearised), the gap is affine:

    g_jk(q) = g0 - n_jk . (J_b,jk - J_c,jk) q          (positive = open)

and the relative sliding displacement along e_t is t_jk = e_t . (J_b - J_c) q.
The 3D gap of eq. (4) linearised about the rest position is exactly this with
n = cos(theta) e_rho + sin(theta) e_z (the cone's normal): the cone is kept, its
curvature terms (order d^2 / R ~ 1e-5 m for millimetre motion) are dropped.

Forces (virtual work of the pressure on the gap's derivatives; the laws run in the kernel):
the normal pressure on the blade is -p_N n, on the casing +p_N n, so its virtual
work is int p_N d gap(c) dc. The pressure is statically equivalent to point weights
w_p >= 0 at the contact points (2D: w = F_N; 3D: w_LE = F_N/2 - M_N/l, w_TE = F_N/2 + M_N/l).

Friction acts at each point against its sliding velocity. In the rotating frame the blade
point slides over the casing along e_t at

    v_p = Omega rho_p + S_p q',   rho_p = (e_z x r_p) . e_t,   S_p = e_t . (J_b - J_c)

(the rigid rotation, plus the blade's and the casing's vibration), and the friction force on
the blade is -mu tanh(v_p / v_slip) w_p e_t (on the casing the opposite). v_slip is
``contact.slip_velocity`` (0.1 m/s): at the paper's tip speeds tanh = 1 to the last bit and the
law is exact Coulomb, mu F_N against the spin; near v = 0 (start from rest, run-down,
windmilling, a vibration at Omega = 0) the friction turns with the sliding and dissipates.
The generalised force

    Q = F_N d_eta/dq + M_N d_zeta/dq - sum_p mu tanh(v_p / v_slip) w_p S_p

includes the reactions on the casing (its J_c enters with the opposite sign): action equals
reaction by construction, which the tests check on physical forces.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .. import kernel
from ..errors import ParameterError
from ..structure.model import Model
from .chord3d import geometry_3d
from .geometry import ContactGeometry
from .laws import law_record
from .point2d import geometry_2d

FORMULATIONS = ("2D", "3D")
VARIANTS = ("full", "kinematics_only", "geometry_only")


@dataclass
class ContactModel:
    """Contact forces F_nl(q) and their Jacobian for one formulation.

    Examples
    --------
    >>> from rotorub_model.structure.model import build_model
    >>> m = build_model()
    >>> c = make_contact(m, "3D")
    >>> c.gaps(np.zeros(m.n_dofs)).shape
    (10, 2)
    """

    formulation: str
    variant: str
    geometry: ContactGeometry
    g0: float
    k_r: float
    mu: float
    v_slip: float = 0.1
    law: str = "penalty"  # contact/laws.py: the normal law and its parameters in the kernel's order
    law_params: tuple[float, ...] = ()
    G: np.ndarray = field(init=False)  # (N*P, n) gap gradients (the geometry's)
    A: np.ndarray = field(init=False)  # (N, n) d eta / dq
    B: np.ndarray = field(init=False)  # (N, n) d zeta / dq
    S: np.ndarray = field(init=False)  # (N*P, n) sliding rows e_t . (J_b - J_c)

    def __post_init__(self) -> None:
        g = self.geometry
        # the kernel's 'blades' (an imported tip's segments) and the blades the outputs report
        self.n_segments, self.n_points = g.points.shape[:2]
        self.n_blades = g.tips.n_blades if g.tips is not None else self.n_segments
        self.G, self.A, self.B, self.S = g.G, g.A, g.B, g.S
        self._k = None

    # ------------------------------------------------------------------ the kernel's view
    @property
    def kernel(self) -> kernel.RRContact:
        """The kernel's rr_contact struct of this model (its arrays are pinned on the object)."""
        if self._k is None:
            g = self.geometry
            names = ("G", "A", "B", "S", "points", "normals", "tangents", "T2")
            arrays = [np.ascontiguousarray(a, dtype=float) for a in (
                self.G, self.A, self.B, self.S, g.points, g.normals, g.tangents, g.disk)]
            self._lib = kernel.load()
            work = np.zeros(self._lib.rr_work_size(self.n_dofs, self.n_segments, self.n_points))
            fields = {k: kernel.ptr(a) for k, a in zip(names, arrays)}
            pinned = [*arrays, work]
            t = g.tips
            if t is not None:  # an imported tip: its segments, compact rows, the blades its outputs report
                tip_f = [np.ascontiguousarray(a, dtype=float) for a in (t.seg_len, t.seg_k, t.g_off, t.point_share)]
                tip_i = [np.ascontiguousarray(a, dtype=np.intc) for a in (t.cols, t.blade_of, t.point_row)]
                pinned += tip_f + tip_i
                fields.update({k: kernel.ptr(a) for k, a in zip(("seg_len", "seg_k", "g_off", "point_share"),
                                                                 tip_f)})
                fields.update({k: kernel.iptr(a) for k, a in zip(("cols", "blade_of", "point_row"), tip_i)})
                fields.update(nloc=int(t.cols.shape[1]), nb_out=int(t.n_blades), n_rows=int(t.n_rows))
            self._pinned = tuple(pinned)
            self._k = kernel.RRContact(n=self.n_dofs, nb=self.n_segments, np=self.n_points, g0=float(self.g0),
                                       k_r=float(self.k_r), mu=float(self.mu),
                                       chord=float(max(self.geometry.chord, 1e-300)), v_slip=float(self.v_slip),
                                       law=law_record(self.law, self.law_params), work=kernel.ptr(work), **fields)
        return self._k

    @property
    def lib(self):
        """The loaded kernel library (ctypes)."""
        self.kernel  # noqa: B018 - loads it
        return self._lib

    def __getstate__(self) -> dict:
        # ctypes objects do not pickle: a copy in another process builds its own view
        state = {k: v for k, v in self.__dict__.items() if k not in ("_k", "_pinned", "_lib", "_step_limits")}
        state["_k"] = None
        return state

    @property
    def n_dofs(self) -> int:
        t = self.geometry.tips
        return t.n_dofs if t is not None else self.G.shape[1]

    def dense_rows(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(G, A, B, S) over all n dofs: the rows as they are, or an imported tip's compact rows (each segment's
        over its own columns) scattered to their dofs (what a projection on the contact's span needs)."""
        t = self.geometry.tips
        if t is None:
            return self.G, self.A, self.B, self.S
        n, npt = self.n_dofs, self.n_points

        def scatter(X: np.ndarray, per_segment: int) -> np.ndarray:
            out = np.zeros((X.shape[0], n))
            seg = np.arange(X.shape[0]) // per_segment
            out[np.arange(X.shape[0])[:, None], t.cols[seg]] = X
            return out

        return scatter(self.G, npt), scatter(self.A, 1), scatter(self.B, 1), scatter(self.S, npt)

    @property
    def n_rows(self) -> int:
        """Rows of the liner's worn depth: the points of a blade, or an imported tip's chord stations."""
        t = self.geometry.tips
        return t.n_rows if t is not None else self.n_points

    @property
    def n_outputs(self) -> int:
        """Number of outputs of a state (the kernel's layout, rotorub_kernel.h)."""
        return kernel.OUT_BLADE_BLOCKS * self.n_blades + kernel.OUT_GLOBALS

    def by_blade(self, a: np.ndarray) -> np.ndarray:
        """Per-point values (..., n_segments, n_points) regrouped per reported blade: (..., n_blades, points of a
        blade) (the built-in blades: as they are; an imported tip: its segments' points, leading edge first)."""
        a = np.asarray(a)
        if self.geometry.tips is None:
            return a
        return a.reshape(*a.shape[:-2], self.n_blades, -1)

    def blade_only(self, j: int) -> ContactModel:
        """The same contact restricted to blade j (its tip's segments for an imported blade; its points for the
        built-in ones): what a contact set's law is assembled from, blade by blade."""
        import dataclasses

        g = self.geometry
        t = g.tips
        if t is None:
            P = self.n_points
            rows = slice(j * P, (j + 1) * P)
            one = dataclasses.replace(g, points=g.points[j:j + 1], normals=g.normals[j:j + 1],
                                      tangents=g.tangents[j:j + 1], Jb=g.Jb[j:j + 1], Jc=g.Jc[j:j + 1],
                                      G=g.G[rows], A=g.A[j:j + 1], B=g.B[j:j + 1], S=g.S[rows])
        else:
            seg = np.flatnonzero(t.blade_of == j)
            pts = (2 * seg[:, None] + np.arange(2)).ravel()  # its segments' two points each
            tips = dataclasses.replace(t, n_blades=1, seg_len=t.seg_len[seg], seg_k=t.seg_k[seg], g_off=t.g_off[pts],
                                       cols=t.cols[seg], blade_of=np.zeros(seg.size, dtype=np.intc),
                                       point_row=t.point_row[pts], point_share=t.point_share[pts])
            one = dataclasses.replace(g, points=g.points[seg], normals=g.normals[seg], tangents=g.tangents[seg],
                                      Jb=g.Jb[seg], Jc=g.Jc[seg], G=g.G[pts], A=g.A[seg], B=g.B[seg], S=g.S[pts],
                                      tips=tips)
        return ContactModel(self.formulation, self.variant, one, self.g0, self.k_r, self.mu, self.v_slip, self.law,
                            self.law_params)

    def with_clearance(self, g0: float) -> ContactModel:
        """Same geometry, another nominal clearance (cheap: gaps are affine)."""
        return ContactModel(self.formulation, self.variant, self.geometry, g0, self.k_r, self.mu, self.v_slip,
                            self.law, self.law_params)

    def _eval(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        q = np.ascontiguousarray(q, dtype=float)
        gaps = np.empty((self.n_segments, self.n_points))
        law = np.empty((self.n_segments, kernel.LAW_WIDTH))
        k = self.kernel
        self._lib.rr_laws(k, kernel.ptr(q), kernel.ptr(gaps), kernel.ptr(law))
        return gaps, law

    def gaps(self, q: np.ndarray) -> np.ndarray:
        """Gaps (N, P) [m]: tip (2D) or LE, TE (3D); negative = penetration (an imported tip: per segment, its two
        stations)."""
        return self._eval(q)[0]

    def laws(self, q: np.ndarray) -> np.ndarray:
        """Per blade (N, 8): F_N, M_N, dF/deta, dF/dzeta, dM/deta, dM/dzeta, chord fraction, potential [J] (an
        imported tip: per segment)."""
        return self._eval(q)[1]

    @staticmethod
    def _velocity(qdot: np.ndarray | None) -> np.ndarray | None:
        return None if qdot is None else np.ascontiguousarray(qdot, dtype=float)

    def friction_factors(self, q: np.ndarray, omega: float, qdot: np.ndarray | None = None) -> np.ndarray:
        """mu tanh(v_p / v_slip) at every contact point (N, P) (0 where the blade does not touch);
        ``qdot`` None: the state is at rest in the rotating frame (a static solution)."""
        q, qd = np.ascontiguousarray(q, dtype=float), self._velocity(qdot)
        fr = np.empty((self.n_segments, self.n_points))
        k = self.kernel
        self._lib.rr_friction(k, kernel.ptr(q), None if qd is None else kernel.ptr(qd), float(omega), kernel.ptr(fr))
        return fr

    def sliding_velocity(self, omega: float, qdot: np.ndarray | None = None) -> np.ndarray:
        """v_p = Omega rho_p + S_p q' (N, P) [m/s]: how fast each blade point slides over the casing
        along e_t (positive in the spin direction), at the rest geometry (small displacements:
        the state q does not enter)."""
        g = self.geometry
        rho = g.points[..., 0] * g.tangents[..., 1] - g.points[..., 1] * g.tangents[..., 0]
        v = omega * rho
        if qdot is not None:
            qd = np.asarray(qdot, dtype=float)
            t = g.tips
            if t is None:
                v = v + (self.S @ qd).reshape(self.n_segments, self.n_points)
            else:  # compact rows: each segment's over its own columns
                S = self.S.reshape(self.n_segments, self.n_points, -1)
                v = v + np.einsum("spk,sk->sp", S, qd[t.cols])
        return v

    def forces(self, q: np.ndarray, omega: float, qdot: np.ndarray | None = None) -> np.ndarray:
        """Generalised contact force vector F_nl(q, q'; Omega) (on rotor and casing dofs)."""
        q, qd = np.ascontiguousarray(q, dtype=float), self._velocity(qdot)
        f = np.empty(self.n_dofs)
        k = self.kernel
        self._lib.rr_force(k, kernel.ptr(q), None if qd is None else kernel.ptr(qd), float(omega), kernel.ptr(f))
        return f

    def jacobians(self, q: np.ndarray, omega: float, qdot: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Analytic (d F_nl / d q, d F_nl / d q'): the stiffness (not symmetric when friction acts)
        and the damping of the regularised friction (symmetric, negative semi-definite)."""
        q, qd = np.ascontiguousarray(q, dtype=float), self._velocity(qdot)
        J, Jv = np.empty((self.n_dofs, self.n_dofs)), np.empty((self.n_dofs, self.n_dofs))
        k = self.kernel
        self._lib.rr_jacobian(k, kernel.ptr(q), None if qd is None else kernel.ptr(qd), float(omega), kernel.ptr(J),
                              kernel.ptr(Jv))
        return J, Jv

    def jacobian(self, q: np.ndarray, omega: float, qdot: np.ndarray | None = None) -> np.ndarray:
        """Analytic d F_nl / d q (not symmetric when friction acts)."""
        q, qd = np.ascontiguousarray(q, dtype=float), self._velocity(qdot)
        J = np.empty((self.n_dofs, self.n_dofs))
        k = self.kernel
        self._lib.rr_jacobian(k, kernel.ptr(q), None if qd is None else kernel.ptr(qd), float(omega), kernel.ptr(J),
                              None)
        return J

    def potential_of_gaps(self, gaps: np.ndarray) -> np.ndarray:
        """The law's strain energy, summed over the blades, of states given by their gaps (m, N, P) [J] (the
        kernel's; its gradient is -F_nl without friction). Gaps rather than states: a run against a worn liner
        records its gaps to the worn surface, which gaps(q) does not know."""
        g = np.ascontiguousarray(np.asarray(gaps, dtype=float).reshape(-1, self.n_segments * self.n_points))
        out = np.empty(g.shape[0])
        self.lib.rr_potential_batch(self.kernel, int(g.shape[0]), kernel.ptr(g), kernel.ptr(out))
        return out

    def potential(self, Q: np.ndarray) -> np.ndarray:
        """The law's strain energy of states Q (m, n) [J]."""
        return self.potential_of_gaps(self.gaps_batch(np.atleast_2d(Q)))

    def closed_stiffness(self, omega: float) -> np.ndarray:
        """-dF_nl/dq with every blade in full contact at the law's largest slope, friction at spin omega (the
        kernel's: what the explicit step and the static solver's starts assume)."""
        K = np.empty((self.n_dofs, self.n_dofs))
        self.lib.rr_closed_stiffness(self.kernel, float(omega), kernel.ptr(K))
        return K

    def gaps_batch(self, Q: np.ndarray) -> np.ndarray:
        """Gaps of many states Q (m, n): (m, N, P)."""
        Q = np.ascontiguousarray(Q, dtype=float)
        out = np.empty((Q.shape[0], self.n_segments, self.n_points))
        k = self.kernel
        self._lib.rr_gaps_batch(k, int(Q.shape[0]), kernel.ptr(Q), kernel.ptr(out))
        return out

    def blade_forces(self, q: np.ndarray, omega: float, qdot: np.ndarray | None = None) -> dict[str, np.ndarray]:
        """Per-blade outputs: F_N, F_T (friction, positive against the spin), M_N, M_T [N, N m],
        gaps, chord fraction in contact (an imported tip: its segments' sums; the gaps are its leading and trailing
        stations', the moments about the tip's mid-chord)."""
        if self.geometry.tips is not None:
            return self._tip_forces(q, omega, qdot)
        g, L = self._eval(q)
        fr = self.friction_factors(q, omega, qdot)
        w = self._weights(L)
        arm = np.array([-0.5, 0.5]) * self.geometry.chord if self.n_points == 2 else np.zeros(1)
        return {
            "F_N": L[:, 0].copy(),
            "F_T": np.sum(fr * w, axis=1),
            "M_N": L[:, 1].copy(),
            "M_T": np.sum(fr * w * arm, axis=1),
            "gap": g,
            "fraction": L[:, 6].copy(),
        }

    def _tip_forces(self, q: np.ndarray, omega: float, qdot: np.ndarray | None) -> dict[str, np.ndarray]:
        t = self.geometry.tips
        o = self.split_outputs(self.outputs_array(q, omega, None if qdot is None else np.atleast_2d(qdot)))
        g, L = self._eval(q)
        fr = self.friction_factors(q, omega, qdot)
        w = self._weights(L)
        # each point's chord coordinate, from the tip's mid-chord (segments laid end to end from the leading edge)
        starts = np.zeros(self.n_segments)
        for b in range(t.n_blades):
            s = np.flatnonzero(t.blade_of == b)
            edges = np.concatenate([[0.0], np.cumsum(t.seg_len[s])])
            starts[s] = edges[:-1] - 0.5 * edges[-1]
        arm = np.stack([starts, starts + t.seg_len], axis=1)
        M_N = np.bincount(t.blade_of, weights=(w * arm).sum(axis=1), minlength=t.n_blades)
        M_T = np.bincount(t.blade_of, weights=(fr * w * arm).sum(axis=1), minlength=t.n_blades)
        return {"F_N": o["F_N"][0], "F_T": o["F_T"][0], "M_N": M_N, "M_T": M_T, "gap": o["gap"][0],
                "fraction": o["fraction"][0]}

    def _weights(self, L: np.ndarray) -> np.ndarray:
        """Point weights w_p (N, P) of the laws L: the normal force each point carries."""
        FN, MN = L[:, 0], L[:, 1]
        if self.n_points == 2:
            t = self.geometry.tips
            chord = self.geometry.chord if t is None else t.seg_len
            return np.stack([0.5 * FN - MN / chord, 0.5 * FN + MN / chord], axis=1)
        return FN[:, None].copy()

    def outputs_array(self, Q: np.ndarray, omega: float, Qdot: np.ndarray | None = None) -> np.ndarray:
        """The kernel's outputs of states Q (m, n) or q (n) with velocities Qdot (same shape, None:
        at rest in the rotating frame) at spin speed omega, rotating frame: (m, n_outputs)."""
        Q = np.ascontiguousarray(np.atleast_2d(Q), dtype=float)
        Qd = None if Qdot is None else np.ascontiguousarray(np.atleast_2d(Qdot), dtype=float)
        if Qd is not None and Qd.shape != Q.shape:
            raise ValueError(f"Qdot: shape {Qd.shape} differs from Q's {Q.shape}")
        out = np.empty((Q.shape[0], self.n_outputs))
        k = self.kernel
        self._lib.rr_outputs_batch(k, int(Q.shape[0]), kernel.ptr(Q), None if Qd is None else kernel.ptr(Qd),
                                   float(omega), kernel.ptr(out))
        return out

    def split_outputs(self, out: np.ndarray) -> dict[str, np.ndarray]:
        """Named views of kernel outputs (m, n_outputs): per-blade (m, N) blocks, gaps (m, N, P), globals (m,)."""
        N = self.n_blades
        b = {name: out[:, i * N:(i + 1) * N] for i, name in enumerate(kernel.OUT_BLADE_NAMES)}
        at = kernel.OUT_BLADE_BLOCKS * N
        gl = {name: out[:, at + i] for i, name in enumerate(kernel.OUT_GLOBAL_NAMES)}
        gap = np.stack([b["gap_LE"], b["gap_TE"]], axis=-1) if self.n_points == 2 else b["gap_LE"][..., None]
        return {
            "F_N": b["F_N"], "F_T": b["F_T"], "fraction": b["contact_fraction"], "gap": gap, "gap_tip": b["gap_tip"],
            "casing_force": np.stack([gl["casing_force.x"], gl["casing_force.y"], gl["casing_force.z"]], axis=-1),
            "friction_torque": gl["friction_torque"],
            "disk": np.stack([gl["disk_displacement.x"], gl["disk_displacement.y"]], axis=-1),
            "gap_min": gl["gap_min"], "n_contact": gl["n_contact"].astype(int),
        }

    def write_outputs(self, q: np.ndarray, qdot: np.ndarray | None, omega: float, phi: float, index: np.ndarray,
                      dest: np.ndarray, liner=None) -> None:
        """The outputs of state (q, q') at spin omega, fixed frame at angle phi, written to
        dest[index[k]] (an FMU's value buffer; ``index``: intc array in the kernel's order,
        ``dest``: float64); with ``liner`` (contact.liner.Liner), against its surface (worn, closed, offset)."""
        q, qd = np.ascontiguousarray(q, dtype=float), self._velocity(qdot)
        k = self.kernel if liner is None else liner.attach(self.kernel)
        self._lib.rr_outputs(k, kernel.ptr(q), None if qd is None else kernel.ptr(qd), float(omega), float(phi),
                             kernel.iptr(index), kernel.ptr(dest))

    def outputs(self, q: np.ndarray, omega: float, qdot: np.ndarray | None = None) -> dict[str, np.ndarray | float]:
        """Everything an output needs at one state, with the contact law evaluated once:
        per blade F_N, F_T, gap (N, P), fraction; the casing resultant (rotating frame),
        the friction torque on the rotor (same values as :meth:`resultant_on_casing`
        and :meth:`friction_torque_on_rotor`), the fan-disk displacement, the smallest gap."""
        o = self.split_outputs(self.outputs_array(q, omega, None if qdot is None else np.atleast_2d(qdot)))
        return {k: float(v[0]) if v.ndim == 1 else v[0] for k, v in o.items()}

    def point_forces(self, q: np.ndarray, omega: float, qdot: np.ndarray | None = None) -> np.ndarray:
        """Physical forces on the blade at each contact point (N, P, 3), statically
        equivalent to the distributed pressure (linear along the chord)."""
        w = self._weights(self.laws(q))
        fr = self.friction_factors(q, omega, qdot)
        g = self.geometry
        return -(w[..., None] * g.normals) - (fr * w)[..., None] * g.tangents

    def resultant_on_casing(self, q: np.ndarray, omega: float, qdot: np.ndarray | None = None) -> np.ndarray:
        """Total contact force on the casing, rotating-frame components (3,)."""
        return -self.point_forces(q, omega, qdot).sum(axis=(0, 1))

    def friction_torque_on_rotor(self, q: np.ndarray, omega: float, qdot: np.ndarray | None = None) -> float:
        """Axial torque of the contact forces on the rotor about the spin axis [N m]
        (negative: it brakes the spin)."""
        f = self.point_forces(q, omega, qdot)
        r = self.geometry.points
        return float(np.sum(r[..., 0] * f[..., 1] - r[..., 1] * f[..., 0]))


def make_contact(model: Model, formulation: str = "3D", variant: str = "full", **overrides) -> ContactModel:
    """Contact model of ``formulation`` ('2D' or '3D') and 3D ``variant``.

    ``overrides`` replace contact parameters (g0, k_r, mu, theta_deg, chord, slip_velocity, law, knee,
    stiffness_ratio).
    Variants (paper section 4): 'full'; 'kinematics_only' (theta = 0, l_c = 1 mm);
    'geometry_only' (no disk or casing rotation, no blade flexure in the gap).
    """
    if formulation not in FORMULATIONS:
        raise ParameterError(f"formulation: '{formulation}' unknown; accepted: {', '.join(FORMULATIONS)}")
    if variant not in VARIANTS:
        raise ParameterError(f"variant: '{variant}' unknown; accepted: {', '.join(VARIANTS)}")
    if formulation == "2D" and variant != "full":
        raise ParameterError(f"variant: '{variant}' applies to the 3D formulation only; accepted for 2D: full")
    c = model.params.contact
    known = {"g0", "k_r", "mu", "theta_deg", "chord", "slip_velocity", "law", "knee", "stiffness_ratio"}
    bad = set(overrides) - known
    if bad:
        raise ParameterError(f"contact.{sorted(bad)[0]}: unknown; accepted: {', '.join(sorted(known))}")
    if overrides:
        c = model.params.replace(contact=overrides).contact
    if formulation == "2D":
        geo = geometry_2d(model)
    elif getattr(model, "fe_blade", None) is not None:  # an imported blade: its tip's chord stations
        if variant != "full":
            raise ParameterError(f"variant: '{variant}' is the paper's study of its beam blades; accepted with an "
                                 "imported blade: full")
        from .fe_tip import geometry_fe

        geo = geometry_fe(model, np.radians(c.theta_deg), model.params.fe_blade.stations)
    else:
        theta, chord = np.radians(c.theta_deg), c.chord
        if variant == "kinematics_only":
            theta, chord = 0.0, 1e-3
        geo = geometry_3d(model, theta, chord, rotations=variant != "geometry_only")
    if getattr(model, "casing_ratios", None) is not None and geo.tips is None:  # an FE casing's modes
        from .geometry import with_fe_casing

        geo = with_fe_casing(model, geo)
    return ContactModel(formulation, variant, geo, c.g0, c.k_r, c.mu, c.slip_velocity, c.law, c.law_params)
