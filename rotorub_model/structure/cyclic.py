"""Cyclic symmetry of the bladed rotor: the blocks the free (contact-open) model splits into.

The N blades are identical and evenly spaced, and the rotor and casing are isotropic, so in travelling-wave
coordinates the model falls apart into blocks, one per nodal-diameter index: blade function k of blade j
as sum_h r_hk exp(i h alpha_j) / sqrt(N) (the discrete Fourier transform over the blades), and every
(x, y) pair of the shaft and the casing as the forward and backward whirls (x +- i y) / sqrt(2). The
transform T is unitary, so T^H X T of each matrix X is exact; the shaft bends with the disk, which moves
the blades only in the index-1 waves, and the casing, with every contact open, touches nothing. The
blocks are not assumed: they are the connected components of the transformed matrices' couplings
(entries above 1e-12 of each matrix's largest), so a model that is not cyclic (a mistuned blade, an
anisotropic support) simply makes fewer, larger blocks and stays exact.

Travelling waves rather than cos/sin patterns: a standing pattern of index h is an equal mix of +h and -h,
seen at two fixed-frame frequencies, and its label would be a coin toss; a wave has one index and one
fixed-frame frequency. The reference's 38 dofs split into two 7-dof blocks (shaft whirl with the blades'
index +-1 waves) and blocks of 1 and 2 dofs; tests/library/test_structure.py checks the blocks' eigenvalues against
the dense problem.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class CyclicBlocks:
    T: np.ndarray  # (n, n) unitary: q = T r, r the travelling-wave coordinates
    blocks: tuple[np.ndarray, ...]  # indices into r of each block, ascending
    # per block, M_b^-1 times (K, S2 + N2, C1, D, G1)_b: the first-order matrix at any speed W is
    # [[0, I], [-(K + W^2 Ks + W K1), -(C0 + W C1)]] from these (analyses/linear.py); an imported blade's
    # prestress beyond the quadratic adds W^4 K4 (``quartic``, M_b^-1 S4_b; None for the built-in blades)
    parts: tuple[tuple[np.ndarray, ...], ...]
    # per block, the index of its complex-conjugate block (its own for a real one: index 0 and N/2 waves,
    # dofs without a pair): the model is real, so a block's conjugate holds the conjugate eigenvalues and
    # modes, and only one of the two needs solving
    conjugate: tuple[int, ...]
    quartic: tuple[np.ndarray, ...] | None = None


def wave_transform(model) -> tuple[np.ndarray, np.ndarray]:
    """The unitary change to travelling-wave coordinates (columns: the coordinates' patterns), and for each
    coordinate the one whose pattern is its complex conjugate."""
    n = model.n_dofs
    T = np.eye(n, dtype=complex)
    conj = np.arange(n)
    for i, name in enumerate(model.dofs):
        if name.endswith(".x") and i + 1 < n and model.dofs[i + 1] == name[:-2] + ".y":
            T[:, i] = 0.0
            T[:, i + 1] = 0.0
            T[i, i], T[i + 1, i] = 1 / np.sqrt(2), 1j / np.sqrt(2)
            T[i, i + 1], T[i + 1, i + 1] = 1 / np.sqrt(2), -1j / np.sqrt(2)
            conj[i], conj[i + 1] = i + 1, i
    sl = model.slices["blades"]
    N, nb = model.params.blades.count, model.blade_dofs
    a = 2.0 * np.pi * np.arange(N) / N
    F = np.exp(1j * np.outer(a, np.arange(N))) / np.sqrt(N)
    T[sl, sl] = np.kron(F, np.eye(nb))  # blade dofs are blade-major: q[sl].reshape(N, nb)
    h, f = np.divmod(np.arange(N * nb), nb)
    conj[sl] = sl.start + ((N - h) % N) * nb + f  # exp(i h a) and exp(i (N - h) a) are conjugates
    return T, conj


def cyclic_blocks(model) -> CyclicBlocks:
    """The travelling-wave transform and the blocks of the contact-open model."""
    from scipy.sparse import csr_matrix
    from scipy.sparse.csgraph import connected_components

    n = model.n_dofs
    T, conj = wave_transform(model)
    mats = (model.M, model.K, model.S2 + model.N2, model.C1, model.D, model.G1)
    S4 = getattr(model, "S4", None)
    if S4 is not None:
        mats = (*mats, S4)
    coupled = np.zeros((n, n), dtype=bool)
    for X in mats:
        Y = T.conj().T @ X @ T
        scale = np.abs(Y).max()
        if scale > 0:
            coupled |= np.abs(Y) > 1e-12 * scale
    _, label = connected_components(csr_matrix(coupled | coupled.T), directed=False)
    blocks = sorted((np.flatnonzero(label == k) for k in range(label.max() + 1)), key=lambda b: (-len(b), int(b[0])))
    parts, quartic = [], []
    for b in blocks:
        Tb = T[:, b]
        Mb, *rest = (Tb.conj().T @ X @ Tb for X in mats)
        Mi = np.linalg.inv(Mb)
        prod = [Mi @ X for X in rest]
        parts.append(tuple(prod[:5]))
        quartic.append(prod[5] if S4 is not None else None)
    of = {int(i): k for k, b in enumerate(blocks) for i in b}
    return CyclicBlocks(T, tuple(blocks), tuple(parts), tuple(of[int(conj[b[0]])] for b in blocks),
                        tuple(quartic) if S4 is not None else None)
