"""Where an imported blade's tip nodes are, and how the bladed disk's dofs move them: the structure's side of the
contact contract (numpy only: the pythonfmu FMU's host has no scipy). :mod:`rotorub_model.contact.fe_tip` gathers
the nodes into the contact's stations; :func:`rotorub_model.fe.tip_point_maps` is the public name."""

from __future__ import annotations

import numpy as np

from .shaft import station_maps


def tip_node_maps(p, blade) -> tuple[np.ndarray, np.ndarray]:
    """(points (N, n_t, 3), Jb (N, n_t, 3, n)): every tip node's rest position in the rotating frame (origin at
    the fan disk's centre, z axial from the disk's station) and the map from the bladed disk's dofs [shaft,
    blades] to its displacement: t + theta x rho0 + Rz(alpha_j) (tip_recovery @ q_j). ``blade``: anything with
    ``tip_positions`` (n_t, 3), ``tip_recovery`` (n_t, 3, m) and ``m`` (a ReducedBlade, or a saved model's
    :class:`~rotorub_model.structure.model.ImportedTip`); numpy only (the pythonfmu FMU's host has no scipy)."""
    ns = 2 * p.shaft.n_ritz
    m = blade.m
    N = p.blades.count
    n = ns + N * m
    T, Rm = station_maps(p, p.fan_disk.z)
    nt = blade.tip_positions.shape[0]
    points = np.zeros((N, nt, 3))
    Jb = np.zeros((N, nt, 3, n))
    for j in range(N):
        a = 2.0 * np.pi * j / N
        c, s = np.cos(a), np.sin(a)
        R = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
        for i in range(nt):
            rho0 = R @ blade.tip_positions[i]
            points[j, i] = rho0
            Jb[j, i, :, :ns] = T - np.cross(rho0[:, None], Rm, axis=0)
            Jb[j, i, :, ns + j * m:ns + (j + 1) * m] = R @ blade.tip_recovery[i]
    return points, Jb
