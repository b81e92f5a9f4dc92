"""Matrix Market exports (ANSYS, Code_Aster and most codes write them; read with scipy.io).

The matrices carry no dof map, so one goes beside them: a text file with one row a line, either
``node.component`` (CalculiX's .dof) or ``node component`` (blank or comma separated; ``#`` comments).
Components 1-3 are the translations along x, y, z, 4-6 the rotations. A ``symmetric`` Matrix Market
file holds one triangle; a ``general`` one both (they must agree).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import scipy.sparse as sp

from ..errors import FEImportError
from .coordinates import read_coordinates
from .femodel import FEModel, make_model
from .units import unit_system


def read_dof_map(path: str | Path) -> tuple[np.ndarray, np.ndarray]:
    """(nodes, components) of a dof-map file: ``node.component`` or ``node component`` a line."""
    path = Path(path)
    if not path.is_file():
        raise FEImportError(f"dof map: {path}: no such file")
    nodes, comps = [], []
    for k, line in enumerate(path.read_text(errors="replace").splitlines()):
        s = line.split("#")[0].strip()
        if not s:
            continue
        p = s.replace(",", " ").split()
        try:
            if len(p) == 1 and "." in p[0]:
                a, b = p[0].split(".")
                nodes.append(int(a))
                comps.append(int(b))
            elif len(p) == 2:
                nodes.append(int(p[0]))
                comps.append(int(p[1]))
            else:
                raise ValueError
        except ValueError:
            raise FEImportError(f"dof map: {path}: line {k + 1} {s!r}: expected 'node.component' or "
                                "'node component'") from None
    if not nodes:
        raise FEImportError(f"dof map: {path}: empty")
    return np.array(nodes, dtype=np.int64), np.array(comps, dtype=np.int64)


def read_mm(path: str | Path) -> sp.csr_matrix:
    import scipy.io

    path = Path(path)
    if not path.is_file():
        raise FEImportError(f"{path}: no such file")
    try:
        A = scipy.io.mmread(str(path))
    except (ValueError, OSError, IndexError) as exc:
        raise FEImportError(f"{path}: not a Matrix Market file ({exc})") from None
    A = sp.csr_matrix(A)
    if np.iscomplexobj(A.data):
        raise FEImportError(f"{path}: complex entries; accepted: a real matrix")
    return A.astype(float)


def read_matrix_market(mass: str | Path, stiffness: list[str | Path], dofs: str | Path,
                       coordinates: str | Path, units: str = "SI", speeds: list[float] | None = None,
                       mass_dofs: str | Path | None = None, spin_softening_in_K: bool | None = None) -> FEModel:
    """The FE model of Matrix Market files: one mass, stiffness matrices at ``speeds`` (rad per time unit;
    default: one stiffness, at rest), the dof map of the stiffness rows (and of the mass rows, when the mass
    has the root's rows too), node coordinates."""
    u = unit_system(units)
    if not stiffness:
        raise FEImportError("matrix market: no stiffness file given")
    speeds = [0.0] if speeds is None and len(stiffness) == 1 else speeds
    if speeds is None or len(speeds) != len(stiffness):
        raise FEImportError(f"matrix market: {len(stiffness)} stiffness files need as many speeds (got "
                            f"{None if speeds is None else len(speeds)}); accepted: one speed a stiffness file")
    nodes, comps = read_dof_map(dofs)
    mnodes, mcomps = read_dof_map(mass_dofs) if mass_dofs is not None else (None, None)
    M = read_mm(mass)
    Ks = [(float(w), read_mm(f)) for w, f in zip(speeds, stiffness)]
    ids, xyz = read_coordinates(coordinates)
    return make_model(M, Ks, nodes, comps, ids, xyz, u, source=f"matrix-market:{Path(mass).name}",
                      mass_nodes=mnodes, mass_comps=mcomps, spin_softening_in_K=spin_softening_in_K)


def write_matrix_market(path: str | Path, A: sp.spmatrix, comment: str = "") -> Path:
    """One triangle of a symmetric matrix, 17 significant digits (what :func:`read_mm` reads back exactly)."""
    import scipy.io

    path = Path(path)
    scipy.io.mmwrite(str(path), sp.coo_matrix(A), comment=comment, symmetry="symmetric", precision=17)
    return path
