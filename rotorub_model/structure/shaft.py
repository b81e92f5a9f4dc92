"""Shaft (Euler–Bernoulli hollow beam), rigid disks and isotropic bearings.

All three are axisymmetric, so they are built per transverse direction in the
fixed frame and transformed with :func:`rotorub_model.structure.frames.axisymmetric_to_rotating`.
Energies (per direction, Ritz u(z) = sum phi_i(z) a_i):

* beam: T = 1/2 int rho A u'^2 + rho I u_z'^2 dz, V = 1/2 int E I (u'')^2 dz,
  gyroscopic coefficient rho (2I) int phi' phi' (polar = 2 x diametral for a circle);
* disk at z_d: T = 1/2 m u^2 + 1/2 Id u_z^2, gyroscopic coefficient Ip phi'(z_d) phi'(z_d);
* bearing at z_b: V = 1/2 k u(z_b)^2, dissipation 1/2 c u(z_b)^2.

Ritz basis (component modes on a beam finite-element model): the shaft line is meshed with
Euler–Bernoulli beam elements (Hermite cubics, nodal dofs u and u', consistent translational
and rotary inertia) with a node at every disk and bearing and at most L / FE_ELEMENTS between
nodes; the n lowest free-vibration modes per direction (non-rotating) of shaft + disks +
bearings + the blades' rigid mass and inertia lumped on the fan disk are the Ritz functions
(piecewise Hermite cubics, defined at any z). The first ones are the bearing-dominated
"suspension" modes, the next ones bend the shaft and tilt the disks.

Why finite elements: a disk or a bearing between the ends puts a jump in the beam's shear
force (and, with the disk's tilt inertia, in its bending moment); a global polynomial basis
converges towards such a shape only like 1/N (with 16 Legendre polynomials the disk-tilt modes
of the reference rotor were 3-7 % off). Elements with a node at each station represent the
jumps exactly; the modes then converge like h^4 (tests/library/test_shaft_fe.py holds them to a
converged reference within 0.5 % for a disk anywhere on the shaft, at rest and at speed).

Dof names: ``shaft.a{i}.x`` / ``shaft.a{i}.y`` — amplitude of Ritz function i along
the rotating x and y axes (each function scaled to a largest nodal displacement of 1 m).
"""

from __future__ import annotations

import numpy as np

from .frames import Matrices, axisymmetric_to_rotating, pair_names
from .params import Parameters

FE_ELEMENTS = 48  # at most L / FE_ELEMENTS between nodes (modes converged to 1e-5, tests/library/test_shaft_fe.py)


def shaft_dof_names(n: int) -> list[str]:
    return pair_names("shaft.a", [str(i) for i in range(n)])


def fe_mesh(p: Parameters, n_elements: int = FE_ELEMENTS) -> np.ndarray:
    """Node positions: the shaft ends, every disk and bearing, and enough nodes between them
    that no element is longer than L / n_elements."""
    L = p.shaft.length
    stations = np.unique(np.clip([0.0, L, *(d.z for d in p.disks), *(b.z for b in p.bearings)], 0.0, L))
    nodes = [stations[:1]]
    for a, b in zip(stations[:-1], stations[1:]):
        k = max(1, int(np.ceil((b - a) / (L / n_elements) - 1e-9)))
        nodes.append(np.linspace(a, b, k + 1)[1:])
    return np.concatenate(nodes)


def hermite(xi: np.ndarray, h: float, deriv: int = 0) -> np.ndarray:
    """Cubic Hermite shape functions of an element of length h at xi in [0, 1] (or their
    z-derivatives): columns for (u_a, u'_a, u_b, u'_b), shape (len(xi), 4)."""
    x = np.atleast_1d(np.asarray(xi, dtype=float))
    if deriv == 0:
        c = [1 - 3 * x**2 + 2 * x**3, h * (x - 2 * x**2 + x**3), 3 * x**2 - 2 * x**3, h * (-(x**2) + x**3)]
    elif deriv == 1:
        c = [(-6 * x + 6 * x**2) / h, 1 - 4 * x + 3 * x**2, (6 * x - 6 * x**2) / h, -2 * x + 3 * x**2]
    elif deriv == 2:
        c = [(-6 + 12 * x) / h**2, (-4 + 6 * x) / h, (6 - 12 * x) / h**2, (-2 + 6 * x) / h]
    else:
        raise ValueError(f"deriv: {deriv}; accepted 0, 1, 2")
    return np.stack(c, axis=-1)


def _element_mass(E: float, I: float, rho: float, A: float, h: float) -> tuple[np.ndarray, np.ndarray]:
    """Euler–Bernoulli element: translational + rotary mass, gyroscopic (rho 2I)."""
    Mt = rho * A * h / 420 * np.array([[156, 22 * h, 54, -13 * h], [22 * h, 4 * h * h, 13 * h, -3 * h * h],
                                         [54, 13 * h, 156, -22 * h], [-13 * h, -3 * h * h, -22 * h, 4 * h * h]])
    R = 1.0 / (30 * h) * np.array([[36, 3 * h, -36, 3 * h], [3 * h, 4 * h * h, -3 * h, -h * h],
                                    [-36, -3 * h, 36, -3 * h], [3 * h, -h * h, -3 * h, 4 * h * h]])
    return Mt + rho * I * R, rho * 2 * I * R


def stiffness_root(p: Parameters, nodes: np.ndarray) -> np.ndarray:
    """L with K = L^T L: rows sqrt(EI w_g) u''(z_g) at two Gauss points per element (exact: u'' is
    linear on an element) and sqrt(k) u(z_b) per bearing.

    Why a root: a rigid motion has u'' = 0, so L keeps its energy exact to rounding of u'' itself,
    where K q loses eps |K| |q| (a nearly rigid shaft on soft bearings would lose the bearings'
    stiffness in that rounding)."""
    s = p.shaft
    xg = np.array([0.5 - 0.5 / np.sqrt(3.0), 0.5 + 0.5 / np.sqrt(3.0)])
    rows = []
    nd = 2 * len(nodes)
    for e in range(len(nodes) - 1):
        h = nodes[e + 1] - nodes[e]
        B = hermite(xg, h, 2)
        r = np.zeros((2, nd))
        r[:, 2 * e:2 * e + 4] = np.sqrt(s.E * s.second_moment * 0.5 * h) * B
        rows.append(r)
    at = {float(z): 2 * i for i, z in enumerate(nodes)}
    for b in p.bearings:
        r = np.zeros((1, nd))
        r[0, at[float(b.z)]] = np.sqrt(b.k)
        rows.append(r)
    return np.vstack(rows)


def fe_matrices(p: Parameters, nodes: np.ndarray, blades_on_fan: bool = False):
    """Per-direction FE matrices (M, C, K, Gp) of shaft + disks + bearings on the mesh ``nodes``
    (dofs u_0, u'_0, u_1, ...); ``blades_on_fan``: add the blades' rigid mass and inertia on the fan disk."""
    s = p.shaft
    nd = 2 * len(nodes)
    M, C, Gp = (np.zeros((nd, nd)) for _ in range(3))
    for e in range(len(nodes) - 1):
        Me, Ge = _element_mass(s.E, s.second_moment, s.rho, s.area, nodes[e + 1] - nodes[e])
        sl = slice(2 * e, 2 * e + 4)
        M[sl, sl] += Me
        Gp[sl, sl] += Ge
    at = {float(z): 2 * i for i, z in enumerate(nodes)}
    for d in p.disks:
        i = at[float(d.z)]
        M[i, i] += d.mass
        M[i + 1, i + 1] += d.Id
        Gp[i + 1, i + 1] += d.Ip
    for b in p.bearings:
        C[at[float(b.z)], at[float(b.z)]] += b.c
    if blades_on_fan:
        b = p.blades
        i = at[float(p.fan_disk.z)]
        M[i, i] += b.count * b.mass
        M[i + 1, i + 1] += 0.5 * b.count * b.rho * b.area * ((b.tip_radius**3 - b.hub_radius**3) / 3.0)
    L = stiffness_root(p, nodes)
    return M, C, L.T @ L, Gp


_BASIS_CACHE: dict = {}


def shaft_basis(p: Parameters) -> tuple[np.ndarray, np.ndarray]:
    """(nodes, Phi): the FE mesh and the nodal values (2 x nodes, n) of the n Ritz functions."""
    key = (p.shaft, p.bearings, p.disks, p.blades)
    if key in _BASIS_CACHE:
        return _BASIS_CACHE[key]
    from scipy.linalg import cholesky, solve_triangular

    nodes = fe_mesh(p)
    M = fe_matrices(p, nodes, blades_on_fan=True)[0]
    # K v = w^2 M v through the SVD of L C^-1 (K = L^T L, M = C^T C): the small singular values
    # come out accurate relative to the largest one, sqrt(cond) better than eigh(K, M) does for
    # a stiff shaft on soft bearings (the lowest modes carry the physics)
    C = cholesky(M)
    A = solve_triangular(C, stiffness_root(p, nodes).T, trans="T").T
    _, _, vt = np.linalg.svd(A)
    vec = solve_triangular(C, vt[::-1][: p.shaft.n_ritz].T)
    disp = vec[0::2]
    vec = vec / disp[np.argmax(np.abs(disp), axis=0), np.arange(vec.shape[1])]
    _BASIS_CACHE[key] = (nodes, vec)
    return nodes, vec


def shaft_functions(p: Parameters, z: np.ndarray | float, deriv: int = 0) -> np.ndarray:
    """Ritz functions (or their z-derivatives, up to 2) at z, shape (len(z), n_ritz)."""
    nodes, phi = shaft_basis(p)
    z = np.atleast_1d(np.asarray(z, dtype=float))
    e = np.clip(np.searchsorted(nodes, z, side="right") - 1, 0, len(nodes) - 2)
    h = nodes[e + 1] - nodes[e]
    out = np.empty((z.size, phi.shape[1]))
    for k in range(z.size):
        N = hermite((z[k] - nodes[e[k]]) / h[k], h[k], deriv)[0]
        out[k] = N @ phi[2 * e[k]:2 * e[k] + 4]
    return out


def shaft_per_direction(p: Parameters) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Fixed-frame per-direction matrices (M1, C1, K1, Gp) of shaft + disks + bearings, on the
    Ritz functions (the FE matrices projected on the component modes; K1 from the root of K)."""
    nodes, phi = shaft_basis(p)
    M, C, _, Gp = fe_matrices(p, nodes)
    LP = stiffness_root(p, nodes) @ phi
    return phi.T @ M @ phi, phi.T @ C @ phi, LP.T @ LP, phi.T @ Gp @ phi


def shaft_matrices(p: Parameters) -> Matrices:
    """Rotating-frame matrices of the shaft line (harmonic n = 1)."""
    M1, C1, K1, Gp = shaft_per_direction(p)
    return axisymmetric_to_rotating(M1, C1, K1, Gp, 1, shaft_dof_names(p.shaft.n_ritz))


def station_maps(p: Parameters, z: float) -> tuple[np.ndarray, np.ndarray]:
    """Maps from shaft dofs to the translation and rotation of the section at z.

    Returns (T, R), each of shape (3, 2n): translation = T q_shaft (z component 0),
    rotation vector = R q_shaft with rotation (-w', u', 0) (small angles: the section
    turns about y by u' and about x by -w').
    """
    n = p.shaft.n_ritz
    f = shaft_functions(p, z)[0]
    df = shaft_functions(p, z, 1)[0]
    T = np.zeros((3, 2 * n))
    R = np.zeros((3, 2 * n))
    T[0, 0::2] = f
    T[1, 1::2] = f
    R[0, 1::2] = -df
    R[1, 0::2] = df
    return T, R
