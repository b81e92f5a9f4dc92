"""3D contact geometry (eq. 3-4): leading and trailing edges facing a conical casing.

Blade j's tip chord runs from LE (c = -l_c/2) to TE (c = +l_c/2) along
c_dir = cos(beta) e_z - sin(beta) e_t (stagger beta from the axis; the TE trails
in the spin direction and lies downstream). The tip is cut parallel to the casing:
each edge sits at the normal distance g0 from the cone, whose radius decreases
downstream as R(z) = R_tip + g0/cos(theta) - z tan(theta) (theta = 0: a cylinder).

The edge positions follow eq. (3) linearised: disk translation, disk tilt (about
the disk centre, lever arm = the edge's position), blade tip deflection along the
flexible direction n_j; casing translation, casing tilt about its centre of
gravity, and the ring's radial (normal) deformation at the edge's initial angle
(eq. 4's u(alpha(P)) with the cos(theta) projection).
"""

from __future__ import annotations

import numpy as np

from ..structure.blades import blade_angles, blade_frame, blade_tip_map, skew
from ..structure.casing import casing_point_map
from ..structure.model import Model
from .geometry import ContactGeometry


def geometry_3d(model: Model, theta: float, chord: float, rotations: bool = True) -> ContactGeometry:
    """Geometry of the LE/TE points; ``rotations=False`` is the paper's 'geometry only'
    variant (no disk or casing rotation, no blade flexure in the gap)."""
    p = model.params
    N, n = p.blades.count, model.n_dofs
    R = p.blades.tip_radius
    beta = np.radians(p.blades.stagger_deg)
    T, Rot = model.disk_maps
    cs = model.slices["casing"]
    bl = model.slices["blades"]
    nb = p.blades.n_ritz
    pts = np.zeros((N, 2, 3))
    nor = np.zeros((N, 2, 3))
    tan = np.zeros((N, 2, 3))
    Jb = np.zeros((N, 2, 3, n))
    Jc = np.zeros((N, 2, 3, n))
    for j, a in enumerate(blade_angles(p)):
        e_r, e_t, e_z, _ = blade_frame(a, beta)
        c_dir = np.cos(beta) * e_z - np.sin(beta) * e_t
        tip_map = blade_tip_map(p, j)
        for k, c in enumerate((-0.5 * chord, 0.5 * chord)):
            P0 = R * e_r + c * c_dir
            z = P0[2]
            alpha_p = np.arctan2(P0[1], P0[0])
            e_rho = np.array([np.cos(alpha_p), np.sin(alpha_p), 0.0])
            P = (R - z * np.tan(theta)) * e_rho + z * e_z  # tip cut parallel to the cone
            pts[j, k] = P
            nor[j, k] = np.cos(theta) * e_rho + np.sin(theta) * e_z
            tan[j, k] = [-np.sin(alpha_p), np.cos(alpha_p), 0.0]
            Jb[j, k] = T
            D = casing_point_map(p, P)
            if rotations:
                Jb[j, k] -= skew(P) @ Rot
                Jb[j, k][:, bl.start + j * nb: bl.start + (j + 1) * nb] = tip_map
            else:
                D[:, 2:4] = 0.0
            Jc[j, k][:, cs] = D
    return ContactGeometry(pts, nor, tan, Jb, Jc, chord, np.ascontiguousarray(T[:2]))
