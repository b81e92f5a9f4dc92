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
work is int p_N d gap(c) dc, and the friction pressure's is -int p_T dt(c) dc:

    Q = F_N d_eta/dq + M_N d_zeta/dq - (F_T d_tmid/dq + M_T d_tslope/dq),
    F_T = mu F_N, M_T = mu M_N (k_t = mu k_r, friction opposes the blade's sliding
    along +e_t, i.e. the spin direction),

so Q includes the reactions on the casing (its J_c enters with the opposite sign):
action equals reaction by construction, which the tests check on physical forces.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .. import kernel
from ..errors import ParameterError
from ..structure.model import Model
from .chord3d import geometry_3d
from .geometry import ContactGeometry
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
    G: np.ndarray = field(init=False)  # (N*P, n) gap gradients (the geometry's)
    A: np.ndarray = field(init=False)  # (N, n) d eta / dq
    B: np.ndarray = field(init=False)  # (N, n) d zeta / dq
    C: np.ndarray = field(init=False)  # (N, n) d t_mid / dq
    D: np.ndarray = field(init=False)  # (N, n) d t_slope / dq

    def __post_init__(self) -> None:
        g = self.geometry
        self.n_blades, self.n_points = g.points.shape[:2]
        self.G, self.A, self.B, self.C, self.D = g.G, g.A, g.B, g.C, g.D
        # The casing resultant and the rotor torque are linear in (F_N, M_N) of each blade:
        # maps built once (by the kernel, with this mu) so per-state outputs cost two small products.
        N = self.n_blades
        self._res_F, self._res_M = np.zeros((N, 3)), np.zeros((N, 3))
        self._tq_F, self._tq_M = np.zeros(N), np.zeros(N)
        pts = [np.ascontiguousarray(a, dtype=float) for a in (g.points, g.normals, g.tangents)]  # alive: named
        kernel.load().rr_contact_resultants(
            N, self.n_points, float(g.chord), float(self.mu), *map(kernel.ptr, pts),
            *map(kernel.ptr, (self._res_F, self._res_M, self._tq_F, self._tq_M)))
        self._k = None

    # ------------------------------------------------------------------ the kernel's view
    @property
    def kernel(self) -> kernel.RRContact:
        """The kernel's rr_contact struct of this model (its arrays are pinned on the object)."""
        if self._k is None:
            arrays = [np.ascontiguousarray(a, dtype=float) for a in (
                self.G, self.A, self.B, self.C, self.D, self._res_F, self._res_M, self._tq_F, self._tq_M,
                self.geometry.disk)]
            self._lib = kernel.load()
            work = np.zeros(self._lib.rr_work_size(self.n_dofs, self.n_blades, self.n_points))
            self._pinned = (*arrays, work)
            self._k = kernel.RRContact(self.n_dofs, self.n_blades, self.n_points, float(self.g0), float(self.k_r),
                                       float(self.mu), float(max(self.geometry.chord, 1e-300)),
                                       *map(kernel.ptr, self._pinned))
        return self._k

    @property
    def lib(self):
        """The loaded kernel library (ctypes)."""
        self.kernel  # noqa: B018 - loads it
        return self._lib

    def __getstate__(self) -> dict:
        # ctypes objects do not pickle: a copy in another process builds its own view
        state = {k: v for k, v in self.__dict__.items() if k not in ("_k", "_pinned", "_lib")}
        state["_k"] = None
        return state

    @property
    def n_dofs(self) -> int:
        return self.G.shape[1]

    @property
    def n_outputs(self) -> int:
        """Number of outputs of a state (the kernel's layout, rotorub_kernel.h)."""
        return kernel.OUT_BLADE_BLOCKS * self.n_blades + kernel.OUT_GLOBALS

    def with_clearance(self, g0: float) -> ContactModel:
        """Same geometry, another nominal clearance (cheap: gaps are affine)."""
        return ContactModel(self.formulation, self.variant, self.geometry, g0, self.k_r, self.mu)

    def _eval(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        q = np.ascontiguousarray(q, dtype=float)
        gaps = np.empty((self.n_blades, self.n_points))
        law = np.empty((self.n_blades, kernel.LAW_WIDTH))
        k = self.kernel
        self._lib.rr_laws(k, kernel.ptr(q), kernel.ptr(gaps), kernel.ptr(law))
        return gaps, law

    def gaps(self, q: np.ndarray) -> np.ndarray:
        """Gaps (N, P) [m]: tip (2D) or LE, TE (3D); negative = penetration."""
        return self._eval(q)[0]

    def laws(self, q: np.ndarray) -> np.ndarray:
        """Per blade (N, 7): F_N, M_N, dF/deta, dF/dzeta, dM/deta, dM/dzeta, chord fraction."""
        return self._eval(q)[1]

    def forces(self, q: np.ndarray) -> np.ndarray:
        """Generalised contact force vector F_nl(q) (on rotor and casing dofs)."""
        q = np.ascontiguousarray(q, dtype=float)
        f = np.empty(self.n_dofs)
        k = self.kernel
        self._lib.rr_force(k, kernel.ptr(q), kernel.ptr(f))
        return f

    def jacobian(self, q: np.ndarray) -> np.ndarray:
        """Analytic d F_nl / d q (not symmetric when mu > 0)."""
        q = np.ascontiguousarray(q, dtype=float)
        J = np.empty((self.n_dofs, self.n_dofs))
        k = self.kernel
        self._lib.rr_jacobian(k, kernel.ptr(q), kernel.ptr(J))
        return J

    def gaps_batch(self, Q: np.ndarray) -> np.ndarray:
        """Gaps of many states Q (m, n): (m, N, P)."""
        Q = np.ascontiguousarray(Q, dtype=float)
        out = np.empty((Q.shape[0], self.n_blades, self.n_points))
        k = self.kernel
        self._lib.rr_gaps_batch(k, int(Q.shape[0]), kernel.ptr(Q), kernel.ptr(out))
        return out

    def blade_forces(self, q: np.ndarray) -> dict[str, np.ndarray]:
        """Per-blade outputs: F_N, F_T, M_N, M_T [N, N m], gaps, chord fraction in contact."""
        g, L = self._eval(q)
        return {
            "F_N": L[:, 0].copy(),
            "F_T": self.mu * L[:, 0],
            "M_N": L[:, 1].copy(),
            "M_T": self.mu * L[:, 1],
            "gap": g,
            "fraction": L[:, 6].copy(),
        }

    def outputs_array(self, Q: np.ndarray) -> np.ndarray:
        """The kernel's outputs of states Q (m, n) or q (n), rotating frame: (m, n_outputs)."""
        Q = np.ascontiguousarray(np.atleast_2d(Q), dtype=float)
        out = np.empty((Q.shape[0], self.n_outputs))
        k = self.kernel
        self._lib.rr_outputs_batch(k, int(Q.shape[0]), kernel.ptr(Q), kernel.ptr(out))
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

    def write_outputs(self, q: np.ndarray, phi: float, index: np.ndarray, dest: np.ndarray) -> None:
        """The outputs of state q, fixed frame at angle phi, written to dest[index[k]] (an FMU's
        value buffer; ``index``: intc array in the kernel's order, ``dest``: float64)."""
        q = np.ascontiguousarray(q, dtype=float)
        k = self.kernel
        self._lib.rr_outputs(k, kernel.ptr(q), float(phi), kernel.iptr(index), kernel.ptr(dest))

    def outputs(self, q: np.ndarray) -> dict[str, np.ndarray | float]:
        """Everything an output needs at one state, with the contact law evaluated once:
        per blade F_N, F_T, gap (N, P), fraction; the casing resultant (rotating frame),
        the friction torque on the rotor (same values as :meth:`resultant_on_casing`
        and :meth:`friction_torque_on_rotor`), the fan-disk displacement, the smallest gap."""
        o = self.split_outputs(self.outputs_array(q))
        return {k: float(v[0]) if v.ndim == 1 else v[0] for k, v in o.items()}

    def point_forces(self, q: np.ndarray) -> np.ndarray:
        """Physical forces on the blade at each contact point (N, P, 3), statically
        equivalent to the distributed pressure (linear along the chord)."""
        L = self.laws(q)
        FN, MN = L[:, 0], L[:, 1]
        g = self.geometry
        if self.n_points == 2:
            w = np.stack([0.5 * FN - MN / g.chord, 0.5 * FN + MN / g.chord], axis=1)
        else:
            w = FN[:, None]
        return -(w[..., None] * g.normals) - self.mu * (w[..., None] * g.tangents)

    def resultant_on_casing(self, q: np.ndarray) -> np.ndarray:
        """Total contact force on the casing, rotating-frame components (3,)."""
        return -self.point_forces(q).sum(axis=(0, 1))

    def friction_torque_on_rotor(self, q: np.ndarray) -> float:
        """Axial torque of the contact forces on the rotor about the spin axis [N m]
        (negative: it brakes the spin)."""
        f = self.point_forces(q)
        r = self.geometry.points
        return float(np.sum(r[..., 0] * f[..., 1] - r[..., 1] * f[..., 0]))


def make_contact(model: Model, formulation: str = "3D", variant: str = "full", **overrides) -> ContactModel:
    """Contact model of ``formulation`` ('2D' or '3D') and 3D ``variant``.

    ``overrides`` replace contact parameters (g0, k_r, mu, theta_deg, chord).
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
    known = {"g0", "k_r", "mu", "theta_deg", "chord"}
    bad = set(overrides) - known
    if bad:
        raise ParameterError(f"contact.{sorted(bad)[0]}: unknown; accepted: {', '.join(sorted(known))}")
    if overrides:
        c = model.params.replace(contact=overrides).contact
    if formulation == "2D":
        geo = geometry_2d(model)
    else:
        theta, chord = np.radians(c.theta_deg), c.chord
        if variant == "kinematics_only":
            theta, chord = 0.0, 1e-3
        geo = geometry_3d(model, theta, chord, rotations=variant != "geometry_only")
    return ContactModel(formulation, variant, geo, c.g0, c.k_r, c.mu)
