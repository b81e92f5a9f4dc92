"""NASTRAN exports through pyyeti (the ``fe`` extra): DMIG punch files and OP4 matrices.

Why pyyeti: it reads DMIG punch/OP2 entries *with their dof map* (GRID id and component of every row) and
OP4 files (ASCII and binary, dense and sparse), is maintained (1.4.7, 2026) and installs with the numpy 2
this project uses; pyNastran 1.4 pins numpy < 2.

* DMIG (``PARAM,EXTOUT,DMIGPCH`` punch output, or hand-written): matrices named e.g. ``MAAX`` / ``KAAX``; the
  rows name GRID ids and components, so the dof map comes with them. pyyeti builds dense tables, so this
  route suits exports up to some ten thousand dofs.
* OP4: matrices without dof map; a dof-map file goes beside them (as for Matrix Market,
  :func:`rotorub_model.fe.matrix_market.read_dof_map`).

Node coordinates: GRID cards of a bulk file (basic system), or any file
:func:`rotorub_model.fe.coordinates.read_coordinates` reads.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import scipy.sparse as sp

from ..errors import FEImportError
from .coordinates import read_coordinates
from .femodel import FEModel, make_model
from .matrix_market import read_dof_map
from .units import unit_system


def _pyyeti():
    try:
        from pyyeti.nastran import bulk, op4
    except ImportError:
        raise FEImportError("NASTRAN files are read with pyyeti: pip install 'rotorub[fe]'") from None
    return bulk, op4


def read_dmig(punch: str | Path, mass: str, stiffness: list[str], coordinates: str | Path | None = None,
              units: str = "SI", speeds: list[float] | None = None,
              spin_softening_in_K: bool | None = None) -> FEModel:
    """The FE model of DMIG entries: ``mass`` and ``stiffness`` are their names (one stiffness a speed);
    coordinates from the GRID cards of ``coordinates`` (default: the punch file itself)."""
    bulk, _ = _pyyeti()
    u = unit_system(units)
    punch = Path(punch)
    if not punch.is_file():
        raise FEImportError(f"{punch}: no such file")
    speeds = [0.0] if speeds is None and len(stiffness) == 1 else speeds
    if speeds is None or len(speeds) != len(stiffness):
        raise FEImportError(f"dmig: {len(stiffness)} stiffness matrices need as many speeds")
    names = [mass, *stiffness]
    try:
        dct = bulk.rddmig(str(punch), square=True)
    except Exception as exc:  # pyyeti raises plain exceptions on malformed cards
        raise FEImportError(f"{punch}: DMIG entries cannot be read ({exc})") from None
    low = {k.lower(): v for k, v in dct.items()}  # NASTRAN names are case-blind (pyyeti lower-cases them)
    for nm in names:
        if nm.lower() not in low:
            raise FEImportError(f"{punch}: no DMIG named {nm!r}; found: {', '.join(sorted(dct)) or 'none'}")
    dct = {nm: low[nm.lower()] for nm in names}
    ref = dct[stiffness[0]].index
    nodes = np.array([int(a) for a, _ in ref], dtype=np.int64)
    comps = np.array([int(b) for _, b in ref], dtype=np.int64)
    if np.any(comps == 0):
        raise FEImportError(f"{punch}: scalar points (component 0) are not accepted; accepted: GRID dofs 1-6")

    def matrix(nm, index):
        df = dct[nm]
        if not df.index.equals(index) or not df.columns.equals(index):
            try:
                df = df.reindex(index=index, columns=index, fill_value=0.0)
            except Exception as exc:
                raise FEImportError(f"{punch}: DMIG {nm!r} is not on the dof map of {stiffness[0]!r} ({exc})") from None
        return sp.csr_matrix(df.to_numpy(dtype=float))

    Mdf = dct[mass]
    # a DMIG lists its non-zero terms only: a massless dof (a beam's rotation) has no row; the mass is read on
    # the stiffness' dofs and its own extra ones (the constrained, rigidly moving rows)
    mindex = ref.append(Mdf.index.difference(ref, sort=False))
    mnodes = np.array([int(a) for a, _ in mindex], dtype=np.int64)
    mcomps = np.array([int(b) for _, b in mindex], dtype=np.int64)
    M = matrix(mass, mindex)
    Ks = [(float(w), matrix(nm, ref)) for w, nm in zip(speeds, stiffness)]
    ids, xyz = read_coordinates(coordinates or punch)
    same = mnodes.size == nodes.size and np.all(mnodes == nodes) and np.all(mcomps == comps)
    return make_model(M, Ks, nodes, comps, ids, xyz, u, source=f"dmig:{punch.name}",
                      mass_nodes=None if same else mnodes, mass_comps=None if same else mcomps,
                      spin_softening_in_K=spin_softening_in_K)


def read_op4(path: str | Path, mass: str, stiffness: list[str], dofs: str | Path, coordinates: str | Path,
             units: str = "SI", speeds: list[float] | None = None,
             spin_softening_in_K: bool | None = None) -> FEModel:
    """The FE model of OP4 matrices named ``mass`` and ``stiffness`` (one a speed), with a dof-map file."""
    _, op4 = _pyyeti()
    u = unit_system(units)
    path = Path(path)
    if not path.is_file():
        raise FEImportError(f"{path}: no such file")
    speeds = [0.0] if speeds is None and len(stiffness) == 1 else speeds
    if speeds is None or len(speeds) != len(stiffness):
        raise FEImportError(f"op4: {len(stiffness)} stiffness matrices need as many speeds")
    try:
        dct = op4.read(str(path), sparse=True)
    except Exception as exc:
        raise FEImportError(f"{path}: not an OP4 file ({exc})") from None
    low = {k.lower(): k for k in dct}
    for nm in [mass, *stiffness]:
        if nm.lower() not in low:
            raise FEImportError(f"{path}: no matrix named {nm!r}; found: {', '.join(sorted(dct)) or 'none'}")
    nodes, comps = read_dof_map(dofs)

    def get(nm):
        A = dct[low[nm.lower()]]
        return sp.csr_matrix(A, dtype=float)

    ids, xyz = read_coordinates(coordinates)
    return make_model(get(mass), [(float(w), get(nm)) for w, nm in zip(speeds, stiffness)], nodes, comps, ids,
                      xyz, u, source=f"op4:{path.name}", spin_softening_in_K=spin_softening_in_K)
