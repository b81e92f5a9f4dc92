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

Forces (virtual work of the pressure on the gap's derivatives, see contact_law):
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

from ..errors import ParameterError
from ..structure.model import Model
from .chord3d import geometry_3d
from .geometry import ContactGeometry
from .laws import blade_laws
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
    G: np.ndarray = field(init=False)  # (N*P, n) gap gradients
    A: np.ndarray = field(init=False)  # (N, n) d eta / dq
    B: np.ndarray = field(init=False)  # (N, n) d zeta / dq
    C: np.ndarray = field(init=False)  # (N, n) d t_mid / dq
    D: np.ndarray = field(init=False)  # (N, n) d t_slope / dq

    def __post_init__(self) -> None:
        g = self.geometry
        rel = g.Jb - g.Jc
        Gk = -np.einsum("jpi,jpin->jpn", g.normals, rel)
        Tk = np.einsum("jpi,jpin->jpn", g.tangents, rel)
        self.n_blades, self.n_points = Gk.shape[:2]
        self.G = Gk.reshape(-1, Gk.shape[-1])
        if self.n_points == 2:
            self.A = 0.5 * (Gk[:, 0] + Gk[:, 1])
            self.B = (Gk[:, 1] - Gk[:, 0]) / g.chord
            self.C = 0.5 * (Tk[:, 0] + Tk[:, 1])
            self.D = (Tk[:, 1] - Tk[:, 0]) / g.chord
        else:
            self.A = Gk[:, 0]
            self.B = np.zeros_like(self.A)
            self.C = Tk[:, 0]
            self.D = np.zeros_like(self.A)
        self._out = np.zeros((self.n_blades, 7))
        # The casing resultant and the rotor torque are linear in (F_N, M_N) of each blade:
        # precompute those maps once so per-state outputs cost two small products.
        nc = g.normals + self.mu * g.tangents  # (N, P, 3) force direction per unit weight, on the casing
        r = g.points
        arm = -(r[..., 0] * nc[..., 1] - r[..., 1] * nc[..., 0])  # (N, P) torque on the rotor per unit weight
        if self.n_points == 2:
            c = max(g.chord, 1e-300)
            self._res_F = 0.5 * (nc[:, 0] + nc[:, 1])
            self._res_M = (nc[:, 1] - nc[:, 0]) / c
            self._tq_F = 0.5 * (arm[:, 0] + arm[:, 1])
            self._tq_M = (arm[:, 1] - arm[:, 0]) / c
        else:
            self._res_F, self._res_M = nc[:, 0], np.zeros_like(nc[:, 0])
            self._tq_F, self._tq_M = arm[:, 0], np.zeros_like(arm[:, 0])

    @property
    def n_dofs(self) -> int:
        return self.G.shape[1]

    def with_clearance(self, g0: float) -> ContactModel:
        """Same geometry, another nominal clearance (cheap: gaps are affine)."""
        return ContactModel(self.formulation, self.variant, self.geometry, g0, self.k_r, self.mu)

    def gaps(self, q: np.ndarray) -> np.ndarray:
        """Gaps (N, P) [m]: tip (2D) or LE, TE (3D); negative = penetration."""
        return (self.g0 + self.G @ q).reshape(self.n_blades, self.n_points)

    def laws(self, q: np.ndarray) -> np.ndarray:
        """Per blade (N, 7): F_N, M_N, dF/deta, dF/dzeta, dM/deta, dM/dzeta, chord fraction."""
        out = np.zeros((self.n_blades, 7))
        blade_laws(self.gaps(q), self.k_r, max(self.geometry.chord, 1e-300), self.n_points == 2, out)
        return out

    def forces(self, q: np.ndarray) -> np.ndarray:
        """Generalised contact force vector F_nl(q) (on rotor and casing dofs)."""
        L = self.laws(q)
        return self._project(L[:, 0], L[:, 1])

    def _project(self, FN: np.ndarray, MN: np.ndarray) -> np.ndarray:
        return self.A.T @ FN + self.B.T @ MN - self.mu * (self.C.T @ FN + self.D.T @ MN)

    def jacobian(self, q: np.ndarray) -> np.ndarray:
        """Analytic d F_nl / d q (not symmetric when mu > 0)."""
        L = self.laws(q)
        dF = L[:, 2, None] * self.A + L[:, 3, None] * self.B  # d F_N / dq, (N, n)
        dM = L[:, 4, None] * self.A + L[:, 5, None] * self.B  # d M_N / dq
        return self.A.T @ dF + self.B.T @ dM - self.mu * (self.C.T @ dF + self.D.T @ dM)

    def blade_forces(self, q: np.ndarray) -> dict[str, np.ndarray]:
        """Per-blade outputs: F_N, F_T, M_N, M_T [N, N m], gaps, chord fraction in contact."""
        L = self.laws(q)
        g = self.gaps(q)
        return {
            "F_N": L[:, 0].copy(),
            "F_T": self.mu * L[:, 0],
            "M_N": L[:, 1].copy(),
            "M_T": self.mu * L[:, 1],
            "gap": g,
            "fraction": L[:, 6].copy(),
        }

    def outputs(self, q: np.ndarray) -> dict[str, np.ndarray | float]:
        """Everything an output needs at one state, with the contact law evaluated once:
        per blade F_N, F_T, M_N, gap (N, P), fraction; the casing resultant (rotating frame)
        and the friction torque on the rotor (same values as :meth:`resultant_on_casing`
        and :meth:`friction_torque_on_rotor`)."""
        g = (self.g0 + self.G @ q).reshape(self.n_blades, self.n_points)
        L = self._out
        blade_laws(g, self.k_r, max(self.geometry.chord, 1e-300), self.n_points == 2, L)
        FN, MN = L[:, 0].copy(), L[:, 1].copy()
        return {
            "F_N": FN, "F_T": self.mu * FN, "M_N": MN, "gap": g, "fraction": L[:, 6].copy(),
            "casing_force": FN @ self._res_F + MN @ self._res_M,
            "friction_torque": float(FN @ self._tq_F + MN @ self._tq_M),
        }

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
