"""Fixed-frame axisymmetric components written in the frame rotating at Omega.

A component whose dofs come in (x, y) pairs, each pair the cos/sin amplitudes of a
field with n nodal diameters (n = 1 for translations and tilts), obeys in the fixed
frame  M X'' + (C + Omega Gf) X' + K X = F  with M, C, K isotropic (M1 kron I2) and
Gf = Gp kron [[0, 1], [-1, 0]].  With X = R(n Omega t) x this becomes, in the rotating
frame (X'' = R (x'' + 2 Omega S x' + Omega^2 S^2 x + dOmega/dt S x), S = n J),

    M x'' + (C + Omega (2n M1 - Gp) kron J) x'
          + (K + Omega n C1 kron J + Omega^2 (n Gp - n^2 M1) kron I) x = R^T F,

J = [[0, -1], [1, 0]].  The Omega term in the stiffness is the circulation matrix
(fixed-frame damping seen from the rotating frame); the Omega^2 term is the spin
softening (minus mass) plus the gyroscopic stiffening of tilts (Ip Omega^2).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

MATRIX_KEYS = ("M", "D", "K", "G1", "C1", "N2", "S2", "E1")
J2 = np.array([[0.0, -1.0], [1.0, 0.0]])
I2 = np.eye(2)


@dataclass
class Matrices:
    """Rotating-frame matrices of one component on its own dofs.

    G(Omega) = Omega G1, C(Omega) = Omega C1 (circulation), N(Omega) = Omega^2 N2
    (spin softening), K_s(Omega^2) = Omega^2 S2 (stress stiffening).
    """

    dofs: list[str]
    M: np.ndarray
    D: np.ndarray
    K: np.ndarray
    G1: np.ndarray
    C1: np.ndarray
    N2: np.ndarray
    S2: np.ndarray = field(default=None)  # type: ignore[assignment]
    E1: np.ndarray = field(default=None)  # type: ignore[assignment]

    def __post_init__(self) -> None:
        if self.S2 is None:
            self.S2 = np.zeros_like(self.M)
        if self.E1 is None:
            self.E1 = np.zeros_like(self.M)


def pair_names(prefix: str, labels: list[str]) -> list[str]:
    """Interleaved dof names: for labels a, b -> prefix.a.x, prefix.a.y, ..."""
    return [f"{prefix}{lab}.{c}" for lab in labels for c in ("x", "y")]


def axisymmetric_to_rotating(
    M1: np.ndarray, C1: np.ndarray, K1: np.ndarray, Gp: np.ndarray, n: int, dofs: list[str]
) -> Matrices:
    """Rotating-frame matrices of an axisymmetric fixed-frame component with harmonic n."""
    return Matrices(
        dofs=dofs,
        M=np.kron(M1, I2),
        D=np.kron(C1, I2),
        K=np.kron(K1, I2),
        G1=np.kron(2 * n * M1 - Gp, J2),
        C1=n * np.kron(C1, J2),
        N2=np.kron(n * Gp - n * n * M1, I2),
        E1=n * np.kron(M1, J2),
    )


def block_diag(parts: list[Matrices]) -> Matrices:
    """Stack independent components (no coupling) into one."""
    from scipy.linalg import block_diag as bd

    names = [d for p in parts for d in p.dofs]
    return Matrices(
        dofs=names,
        **{k: bd(*[getattr(p, k) for p in parts]) for k in MATRIX_KEYS},
    )
