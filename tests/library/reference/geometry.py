"""An independent numpy construction of the 2D and 3D contact geometry (the library's own before
the kernel built it in C): the tests hold the kernel's rr_contact_geometry to it.

Same physics as docs/THEORY.md section 4: a point tip facing a cylinder (2D); leading and
trailing edges facing a cone, with disk and casing rotations and blade flexure (3D).
"""

from __future__ import annotations

import numpy as np

from rotorub_model.structure.blades import blade_angles, blade_frame, blade_tip_map, skew
from rotorub_model.structure.casing import casing_point_map


def reference_geometry(model, formulation: str, theta: float = 0.0, chord: float = 0.0, rotations: bool = True):
    """(points, normals, tangents, Jb, Jc) with shapes (N, P, 3) and (N, P, 3, n)."""
    p = model.params
    N, n = p.blades.count, model.n_dofs
    R = p.blades.tip_radius
    beta = np.radians(p.blades.stagger_deg)
    T, Rot = model.disk_maps
    cs = model.slices["casing"]
    bl = model.slices["blades"]
    nb = p.blades.dofs
    P_ = 1 if formulation == "2D" else 2
    pts = np.zeros((N, P_, 3))
    nor = np.zeros((N, P_, 3))
    tan = np.zeros((N, P_, 3))
    Jb = np.zeros((N, P_, 3, n))
    Jc = np.zeros((N, P_, 3, n))
    for j, a in enumerate(blade_angles(p)):
        e_r, e_t, e_z, _ = blade_frame(a, beta)
        if formulation == "2D":
            pts[j, 0] = R * e_r
            nor[j, 0] = e_r
            tan[j, 0] = e_t
            Jb[j, 0] = T
            D = casing_point_map(p, pts[j, 0])
            D[:, 2:4] = 0.0  # no casing tilt in the 2D kinematics
            Jc[j, 0][:, cs] = D
            continue
        c_dir = np.cos(beta) * e_z - np.sin(beta) * e_t
        tip_map = blade_tip_map(p, j)
        for k, c in enumerate((-0.5 * chord, 0.5 * chord)):
            P0 = R * e_r + c * c_dir
            z = P0[2]
            alpha_p = np.arctan2(P0[1], P0[0])
            e_rho = np.array([np.cos(alpha_p), np.sin(alpha_p), 0.0])
            P = (R - z * np.tan(theta)) * e_rho + z * e_z
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
    return pts, nor, tan, Jb, Jc
