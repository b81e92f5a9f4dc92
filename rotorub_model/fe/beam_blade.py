"""The built-in beam blade written as a finite-element model (Matrix Market files): the loop closed.

The built-in blade (structure/blades.py) is an inextensible Euler-Bernoulli beam along e_r that bends along
n = cos(beta) e_t + sin(beta) e_z only, its mass a line of points. As an FE model: Hermite beam elements in
the plane (e_r, n), nodes along the span, dofs the flap translation (component 2) and the slope (component 6,
rotation about the chord) of every node but the root; lumped translational masses at the nodes. The file's
axes are x = e_r, y = n, z = c = e_r x n (the chord, right-handed), so the spin axis reads
(0, sin beta, cos beta) in them. The other translations (axial, chordwise) are constrained: they are rows of
the mass map only (``mass_dofs.txt``), which the importer moves rigidly with the disk, so the blade's whole
mass sits on the disk as the built-in's does.

K(Omega) at the given speeds: K0 + Omega^2 (K_sigma - cos^2(beta) M_flap), the geometric stiffness of the
centrifugal tension T(s) = Omega^2 int_s^l rho A (r_d + s') ds' (Gauss-integrated on each element) and the
spin softening in the stiffness, as CalculiX writes its prestressed stiffness.

Two node layouts: ``uniform`` (n elements; lumped masses rho A h, half at the ends) and ``gauss`` (nodes at
the root, at the built-in blade's own quadrature points and at the tip, with the built-in's point masses dm
at the quadrature points): with ``gauss`` the mass distribution is the built-in's to rounding, so every
rigid-body and coupling term can be compared with it exactly.

The 3D contact's tip (:func:`with_chord_ends`): the built-in 3D formulation puts its two contact points at the
ends of the tip's chord (leading and trailing edge, l_c apart along the stagger, on the casing's cone), each moving
with the disk and with the blade's tip flap deflection (no twist: the beam has none). The imported beam's tip is
given the same: two tip points at those positions, each with the tip node's recovery (a massless, rigid cap that
translates with the tip node). Tying two FE nodes there to the tip node by springs does not do it: a spring
between translations of points apart is strained by a rigid rotation of the blade (the importer refuses such a
model: its coordinates do not fit its stiffness), and the beam has no twist dof to make the tie rigid.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import scipy.sparse as sp

from ..structure.params import Parameters
from ..structure.ritz import gauss
from .blade import ReducedBlade
from .matrix_market import write_matrix_market


def beam_nodes(p: Parameters, n_elements: int, layout: str) -> tuple[np.ndarray, np.ndarray]:
    """(s, lumped mass) of the nodes along the span."""
    b = p.blades
    rhoA = b.rho * b.area
    if layout == "uniform":
        s = np.linspace(0.0, b.length, n_elements + 1)
        h = np.diff(s)
        m = np.zeros(s.size)
        m[:-1] += 0.5 * rhoA * h
        m[1:] += 0.5 * rhoA * h
        return s, m
    if layout == "gauss":
        sg, wg = gauss(0.0, b.length, b.n_ritz + 8)
        return np.concatenate([[0.0], sg, [b.length]]), np.concatenate([[0.0], rhoA * wg, [0.0]])
    raise ValueError(f"layout: {layout!r}; accepted 'uniform' or 'gauss'")


def beam_matrices(p: Parameters, s: np.ndarray, omega: float) -> sp.csr_matrix:
    """The flap-plane stiffness K0 + Omega^2 K_sigma on (v_i, v'_i) of every node (root included), without
    spin softening."""
    b = p.blades
    EI = b.E * b.second_moment
    rhoA = b.rho * b.area
    n = 2 * s.size
    K = np.zeros((n, n))
    xg, wg = np.polynomial.legendre.leggauss(4)
    for e in range(s.size - 1):
        h = s[e + 1] - s[e]
        ke = EI / h**3 * np.array([[12, 6 * h, -12, 6 * h], [6 * h, 4 * h * h, -6 * h, 2 * h * h],
                                   [-12, -6 * h, 12, -6 * h], [6 * h, 2 * h * h, -6 * h, 4 * h * h]])
        if omega:
            for x, w in zip(0.5 * (xg + 1.0), 0.5 * wg):
                sg = s[e] + x * h
                T = omega**2 * rhoA * ((b.hub_radius * b.length + 0.5 * b.length**2)
                                       - (b.hub_radius * sg + 0.5 * sg**2))
                dN = np.array([(-6 * x + 6 * x * x) / h, 1 - 4 * x + 3 * x * x, (6 * x - 6 * x * x) / h,
                               -2 * x + 3 * x * x])
                ke = ke + T * w * h * np.outer(dN, dN)
        K[2 * e:2 * e + 4, 2 * e:2 * e + 4] += ke
    return sp.csr_matrix(K)


def write_beam_blade(p: Parameters, folder: str | Path, speeds: tuple[float, ...] = (0.0,),
                     n_elements: int = 120, layout: str = "uniform", spin_softening: bool = True) -> dict:
    """Write the beam blade of ``p`` (SI): ``mass.mtx`` on ``mass_dofs.txt``, ``stiffness_{k}.mtx`` at
    ``speeds[k]`` [rad/s] on ``dofs.txt``, ``nodes.txt`` (``spin_softening``: K(Omega) holds -Omega^2 M P, as
    CalculiX's does, or not, as some codes' do not); returns the paths, speeds, the spin axis (file axes)
    and the tip node id."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    b = p.blades
    beta = np.radians(b.stagger_deg)
    s, m = beam_nodes(p, n_elements, layout)
    nn = s.size
    ids = np.arange(1, nn + 1)
    (folder / "nodes.txt").write_text("# id x y z [m]; x radial, y flap, z chord\n"
                                      + "".join(f"{i} {float(b.hub_radius + x)!r} 0.0 0.0\n" for i, x in zip(ids, s)))
    # mass rows: the three translations of every node (lumped), and the free slopes (massless)
    mrows = [(int(i), c) for i in ids for c in (1, 2, 3)] + [(int(i), 6) for i in ids[1:]]
    mvals = [float(mi) for mi in m for _ in range(3)] + [0.0] * (nn - 1)
    (folder / "mass_dofs.txt").write_text("".join(f"{a}.{c}\n" for a, c in mrows))
    write_matrix_market(folder / "mass.mtx", sp.diags(mvals), "lumped beam blade mass [kg]")
    # stiffness rows: flap translation and slope of every node but the root
    free = np.arange(2, 2 * nn)  # (v, v') of nodes 2..nn in the element ordering
    (folder / "dofs.txt").write_text("".join(f"{i}.{c}\n" for i in ids[1:] for c in (2, 6)))
    soft = np.zeros(2 * nn)
    soft[0::2] = np.cos(beta) ** 2 * m if spin_softening else 0.0
    files = []
    for k, w in enumerate(speeds):
        K = beam_matrices(p, s, w) - w * w * sp.diags(soft)
        Kf = sp.csr_matrix(K)[free][:, free]
        files.append(write_matrix_market(folder / f"stiffness_{k}.mtx", Kf, f"beam blade stiffness at {w!r} rad/s"))
    return {"mass": folder / "mass.mtx", "stiffness": files, "dofs": folder / "dofs.txt",
            "mass_dofs": folder / "mass_dofs.txt", "coordinates": folder / "nodes.txt", "speeds": list(speeds),
            "axis_direction": (0.0, float(np.sin(beta)), float(np.cos(beta))), "tip_node": int(ids[-1])}


def chord_end_points(p: Parameters, chord: float, theta_deg: float, stations: int = 2) -> np.ndarray:
    """The built-in 3D formulation's leading- and trailing-edge rest points of blade 0 (2, 3), blade frame (e_r,
    e_t, e_z): l_c apart along the stagger (cos(beta) e_z - sin(beta) e_t), on the cone R_tip - z tan(theta) (the
    kernel's rr_contact_geometry, written out); ``stations`` > 2: that many points evenly between them."""
    b = p.blades
    beta, th = np.radians(b.stagger_deg), np.radians(theta_deg)
    out = []
    for c in np.linspace(-0.5 * chord, 0.5 * chord, stations):
        P0 = np.array([b.tip_radius, -c * np.sin(beta), c * np.cos(beta)])
        ap, z = np.arctan2(P0[1], P0[0]), P0[2]
        rad = b.tip_radius - z * np.tan(th)
        out.append([rad * np.cos(ap), rad * np.sin(ap), z])
    return np.array(out)


def with_chord_ends(blade: ReducedBlade, p: Parameters, chord: float, theta_deg: float,
                    stations: int = 2) -> ReducedBlade:
    """The imported beam ``blade`` (one tip node) with its tip at the built-in 3D formulation's two chord ends
    (:func:`chord_end_points`), each with the tip node's recovery: the same two contact stations, at the same
    places, moving as the built-in's do (module docstring); ``stations`` > 2: as many evenly along the chord."""
    import dataclasses

    if blade.tip_nodes.size != 1:
        raise ValueError("with_chord_ends: a beam blade with one tip node")
    k = int(stations)
    rec = np.repeat(blade.tip_recovery, k, axis=0)
    G = blade.tip_residual
    res = np.kron(np.ones((k, k)), G) if G.size else G
    cen = np.repeat(blade.tip_centrifugal, k, axis=0)
    ids = int(blade.tip_nodes[0]) * 100 + 1 + np.arange(k)
    return dataclasses.replace(blade, tip_nodes=ids, tip_positions=chord_end_points(p, chord, theta_deg, k),
                               tip_recovery=rec, tip_residual=res, tip_centrifugal=cen)
