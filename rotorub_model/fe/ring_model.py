"""The built-in casing ring written as a finite-element model (Matrix Market files): a circle of straight
in-plane frame elements (axial and Euler-Bernoulli bending stiffness, lumped translational masses), free
(the casing's suspension is the model's, not the FE's). Its n-diameter modes tend to the thin ring's closed
form omega_n^2 = E I n^2 (n^2 - 1)^2 / (rho A R^4 (n^2 + 1)) as the elements shorten and the ring thins (its
extensibility and the facets are the differences); what :func:`rotorub_model.fe.casing_modes.casing_from_matrices`
makes of it must be the built-in ring's modal mass, stiffness and tangential ratio -1/n.

Dofs: components 1, 2 (x, y translations) and 6 (rotation about z) of every node; node i at angle 2 pi i / N,
radius R, z = 0 (the blade-tip plane).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import scipy.sparse as sp

from ..structure.casing import ring_radius
from ..structure.params import Parameters
from .matrix_market import write_matrix_market


def ring_matrices(p: Parameters, n_elements: int = 180) -> tuple[sp.csr_matrix, sp.csr_matrix, np.ndarray]:
    """(K, M, node positions (N, 3)) of the ring of ``p.casing`` on the dofs (u_x, u_y, theta_z) per node."""
    c = p.casing
    R = ring_radius(p)
    A = c.ring_thickness * c.ring_width
    I = c.ring_width * c.ring_thickness**3 / 12.0
    a = 2.0 * np.pi * np.arange(n_elements) / n_elements
    xyz = np.column_stack([R * np.cos(a), R * np.sin(a), np.zeros(n_elements)])
    n = 3 * n_elements
    K = np.zeros((n, n))
    m = np.zeros(n)
    for e in range(n_elements):
        i, j = e, (e + 1) % n_elements
        d = xyz[j, :2] - xyz[i, :2]
        L = np.hypot(*d)
        cs, sn = d / L
        EA, EI = c.E * A / L, c.E * I
        kl = np.array([[EA, 0, 0, -EA, 0, 0],
                       [0, 12 * EI / L**3, 6 * EI / L**2, 0, -12 * EI / L**3, 6 * EI / L**2],
                       [0, 6 * EI / L**2, 4 * EI / L, 0, -6 * EI / L**2, 2 * EI / L],
                       [-EA, 0, 0, EA, 0, 0],
                       [0, -12 * EI / L**3, -6 * EI / L**2, 0, 12 * EI / L**3, -6 * EI / L**2],
                       [0, 6 * EI / L**2, 2 * EI / L, 0, -6 * EI / L**2, 4 * EI / L]])
        r = np.array([[cs, sn, 0], [-sn, cs, 0], [0, 0, 1]])
        T = np.kron(np.eye(2), r)
        ke = T.T @ kl @ T
        idx = np.r_[3 * i:3 * i + 3, 3 * j:3 * j + 3]
        K[np.ix_(idx, idx)] += ke
        for k in (i, j):
            m[3 * k:3 * k + 2] += 0.5 * c.rho * A * L
    return sp.csr_matrix(K), sp.diags(m).tocsr(), xyz


def write_ring(p: Parameters, folder: str | Path, n_elements: int = 180) -> dict:
    """Write ``mass.mtx``, ``stiffness.mtx``, ``dofs.txt``, ``nodes.txt`` (SI) of the ring."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    K, M, xyz = ring_matrices(p, n_elements)
    ids = np.arange(1, n_elements + 1)
    (folder / "nodes.txt").write_text("".join(f"{i} {float(x)!r} {float(y)!r} {float(z)!r}\n"
                                              for i, (x, y, z) in zip(ids, xyz)))
    (folder / "dofs.txt").write_text("".join(f"{i}.{c}\n" for i in ids for c in (1, 2, 6)))
    write_matrix_market(folder / "mass.mtx", M, "ring mass [kg]")
    write_matrix_market(folder / "stiffness.mtx", K, "ring stiffness")
    return {"mass": folder / "mass.mtx", "stiffness": folder / "stiffness.mtx", "dofs": folder / "dofs.txt",
            "coordinates": folder / "nodes.txt", "circle_nodes": ids}
