"""CalculiX's ``*FREQUENCY, SOLVER=MATRIXSTORAGE`` exports.

A job ``name`` writes ``name.sti`` (stiffness) and ``name.mas`` (mass), one triangle, one entry a line,
``i j value`` with 1-based indices, and ``name.dof``, one ``node.direction`` a line for each row: the free
dofs only (the ``*BOUNDARY`` ones are left out). After a ``*STATIC`` step with a ``*DLOAD ... CENTRIF``
load, a ``*STEP, PERTURBATION`` frequency step stores the prestressed stiffness: CalculiX's K(Omega)
holds the stress stiffening *and* the spin softening -Omega^2 M P (measured on its matrices, see
:mod:`rotorub_model.fe.rotating`). A job's spin speed is read from its deck (``name.inp``, the CENTRIF
magnitude is Omega^2) when it is there, or given.

CalculiX's own eigenvalues (the ``*FREQUENCY`` step without matrix storage) are read from ``name.dat``
(:func:`read_dat_frequencies`): what an import is checked against.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import scipy.sparse as sp

from ..errors import FEImportError
from .coordinates import read_coordinates
from .femodel import FEModel, make_model, symmetric_from_triangle
from .units import unit_system


def _stem(job: str | Path) -> Path:
    p = Path(job)
    return p.with_suffix("") if p.suffix.lower() in (".sti", ".mas", ".dof", ".inp", ".dat") else p


def read_dof(path: str | Path) -> tuple[np.ndarray, np.ndarray]:
    """(nodes, components) of a CalculiX .dof file (``node.direction`` a line)."""
    path = Path(path)
    if not path.is_file():
        raise FEImportError(f"{path}: no such file (CalculiX writes it with *FREQUENCY, SOLVER=MATRIXSTORAGE)")
    nodes, comps = [], []
    for k, line in enumerate(path.read_text(errors="replace").split()):
        a, _, b = line.partition(".")
        try:
            nodes.append(int(a))
            comps.append(int(b))
        except ValueError:
            raise FEImportError(f"{path}: entry {k + 1} {line!r}: expected 'node.direction'") from None
    if not nodes:
        raise FEImportError(f"{path}: empty dof map")
    return np.array(nodes, dtype=np.int64), np.array(comps, dtype=np.int64)


def read_triplets(path: str | Path, n: int) -> sp.csr_matrix:
    """A symmetric matrix of ``n`` rows from a CalculiX .sti / .mas file."""
    path = Path(path)
    if not path.is_file():
        raise FEImportError(f"{path}: no such file (CalculiX writes it with *FREQUENCY, SOLVER=MATRIXSTORAGE)")
    try:
        data = np.fromstring(path.read_bytes().decode(errors="replace"), sep=" ")
    except ValueError:
        data = np.zeros(1)
    if data.size % 3 or not data.size:
        raise FEImportError(f"{path}: expected lines 'i j value' (1-based), got {data.size} numbers")
    d = data.reshape(-1, 3)
    i, j = d[:, 0].astype(np.int64) - 1, d[:, 1].astype(np.int64) - 1
    return symmetric_from_triangle(i, j, d[:, 2], n, str(path))


def job_speed(job: str | Path) -> float | None:
    """The spin speed of a job from its deck's CENTRIF load (magnitude Omega^2), None without deck;
    0 for a deck without CENTRIF."""
    deck = _stem(job).with_suffix(".inp")
    if not deck.is_file():
        return None
    w2 = []
    for line in deck.read_text(errors="replace").splitlines():
        if re.search(r",\s*CENTRIF\s*,", line, re.IGNORECASE):
            try:
                w2.append(float(line.split(",")[2]))
            except (IndexError, ValueError):
                raise FEImportError(f"{deck}: CENTRIF line {line.strip()!r}: expected "
                                    "'set, CENTRIF, omega^2, ...'") from None
    if len(set(w2)) > 1:
        raise FEImportError(f"{deck}: several CENTRIF speeds {w2}: one spin speed a job")
    return float(np.sqrt(w2[0])) if w2 else 0.0


def read_calculix(jobs: list[str | Path], coordinates: str | Path | None = None, units: str = "SI",
                  speeds: list[float] | None = None, mass_free: str | Path | None = None) -> FEModel:
    """The FE model of CalculiX matrix-storage jobs: one at rest and any number at speed (their decks' CENTRIF
    loads give the speeds, or ``speeds`` in rad per time unit, one a job). ``coordinates``: the mesh deck or
    .msh (default: the first job's deck). ``mass_free``: a matrix-storage job of the unconstrained blade,
    whose mass rows include the root's."""
    if not jobs:
        raise FEImportError("calculix: no job given")
    u = unit_system(units)
    stems = [_stem(j) for j in jobs]
    if speeds is not None and len(speeds) != len(stems):
        raise FEImportError(f"calculix: {len(speeds)} speeds for {len(stems)} jobs; accepted: one speed a job")
    nodes, comps = read_dof(stems[0].with_suffix(".dof"))
    n = nodes.size
    stiff = []
    for k, s in enumerate(stems):
        if k:
            nk, ck = read_dof(s.with_suffix(".dof"))
            if nk.size != n or np.any(nk != nodes) or np.any(ck != comps):
                raise FEImportError(f"{s.with_suffix('.dof')}: its dof map differs from "
                                    f"{stems[0].with_suffix('.dof')}'s (another model, or other boundary "
                                    "conditions); accepted: jobs of one mesh with one clamp")
        w = speeds[k] if speeds is not None else job_speed(s)
        if w is None:
            raise FEImportError(f"calculix: job {s}: no deck {s.with_suffix('.inp')} to read its spin speed from; give "
                                "the speeds")
        stiff.append((float(w), read_triplets(s.with_suffix(".sti"), n)))
    M = read_triplets(stems[0].with_suffix(".mas"), n)
    mnodes = mcomps = None
    if mass_free is not None:
        mf = _stem(mass_free)
        mnodes, mcomps = read_dof(mf.with_suffix(".dof"))
        Mf = read_triplets(mf.with_suffix(".mas"), mnodes.size)
        # the free block of the unconstrained mass must be the constrained job's mass: same mesh
        key = {(a, b): i for i, (a, b) in enumerate(zip(mnodes.tolist(), mcomps.tolist()))}
        try:
            idx = np.array([key[(a, b)] for a, b in zip(nodes.tolist(), comps.tolist())])
        except KeyError as exc:
            raise FEImportError(f"{mf.with_suffix('.dof')}: no row for dof {exc.args[0][0]}.{exc.args[0][1]} of the "
                                "clamped job (the unconstrained job must be of the same mesh)") from None
        diff = abs(Mf[idx][:, idx] - M).max()
        if diff > 1e-6 * abs(M).max():
            raise FEImportError(f"{mf.with_suffix('.mas')}: its mass on the free dofs differs from "
                                f"{stems[0].with_suffix('.mas')} by {diff:.3g} (another mesh or material)")
        M = Mf
    if coordinates is None:
        coordinates = stems[0].with_suffix(".inp")
    ids, xyz = read_coordinates(coordinates)
    return make_model(M, stiff, nodes, comps, ids, xyz, u, source=f"calculix:{stems[0].name}",
                      mass_nodes=mnodes, mass_comps=mcomps, spin_softening_in_K=True)


def read_dat_frequencies(path: str | Path) -> np.ndarray:
    """CalculiX's own eigenfrequencies [Hz, cycles per time unit] of the last *FREQUENCY step in a .dat file."""
    path = Path(path)
    if not path.is_file():
        raise FEImportError(f"{path}: no such file")
    lines = path.read_text(errors="replace").splitlines()
    start = [k for k, s in enumerate(lines) if "E I G E N V A L U E   O U T P U T" in s]
    if not start:
        raise FEImportError(f"{path}: no eigenvalue output (a *FREQUENCY step without matrix storage writes it)")
    out = []
    for s in lines[start[-1] + 1:]:
        p = s.split()
        if len(p) == 5 and p[0].isdigit():
            out.append(float(p[3]))
        elif out and not s.strip():
            break
    return np.array(out)
