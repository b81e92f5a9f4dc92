"""Node coordinates (and node sets) from the files that hold them.

* CalculiX / Abaqus input decks (``.inp``): the ``*NODE`` blocks, following ``*INCLUDE``; ``*NSET`` blocks
  give named node sets (gmsh writes one per physical group with ``Mesh.SaveGroupsOfNodes = 1``);
* gmsh meshes (``.msh``, formats 2.2 and 4.1, ASCII);
* NASTRAN bulk data (``.bdf``, ``.dat``, ``.nas``, ``.blk``): GRID cards in the basic system, through
  pyyeti (the ``fe`` extra);
* a plain table (``.txt``, ``.csv``, anything else): one node a line, ``id x y z`` (commas or blanks;
  lines starting with ``#`` are comments).

Every reader returns (ids, coordinates) in the file's length unit; the caller converts.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from ..errors import FEImportError

NASTRAN_SUFFIXES = (".bdf", ".nas", ".blk", ".pch", ".dat")


def read_coordinates(path: str | Path) -> tuple[np.ndarray, np.ndarray]:
    """(ids, xyz) of every node in ``path`` (file units)."""
    path = Path(path)
    if not path.is_file():
        raise FEImportError(f"coordinates: {path}: no such file")
    suffix = path.suffix.lower()
    if suffix == ".inp":
        ids, xyz = read_inp_nodes(path)
    elif suffix == ".msh":
        ids, xyz = read_msh_nodes(path)
    elif suffix in NASTRAN_SUFFIXES:
        ids, xyz = read_nastran_grids(path)
    else:
        ids, xyz = read_table_nodes(path)
    if ids.size == 0:
        raise FEImportError(f"coordinates: {path}: no node found (accepted: *NODE blocks of an .inp, a gmsh .msh, "
                            "NASTRAN GRID cards, or a table 'id x y z')")
    return ids, xyz


def _inp_lines(path: Path, seen: set[Path] | None = None):
    """The deck's lines, with *INCLUDE files spliced in."""
    seen = seen or set()
    if path.resolve() in seen:
        raise FEImportError(f"{path}: *INCLUDE loop")
    seen.add(path.resolve())
    try:
        text = path.read_text(errors="replace")
    except OSError as exc:
        raise FEImportError(f"{path}: cannot be read ({exc.strerror or exc})") from None
    for line in text.splitlines():
        s = line.strip()
        if s.upper().startswith("*INCLUDE"):
            m = re.search(r"INPUT\s*=\s*([^,]+)", s, re.IGNORECASE)
            if not m:
                raise FEImportError(f"{path}: *INCLUDE without INPUT=")
            yield from _inp_lines(path.parent / m.group(1).strip().strip('"'), seen)
        else:
            yield s


def read_inp(path: str | Path) -> tuple[np.ndarray, np.ndarray, dict[str, np.ndarray]]:
    """(ids, xyz, node sets) of an Abaqus/CalculiX deck. Node sets: upper-case names -> ids
    (``*NSET, GENERATE`` ranges expanded)."""
    ids: list[int] = []
    xyz: list[list[float]] = []
    sets: dict[str, list[int]] = {}
    mode = None
    cur: list[int] = []
    generate = False
    for s in _inp_lines(Path(path)):
        if not s or s.startswith("**"):
            continue
        if s.startswith("*"):
            key = s.split(",")[0].strip().upper()
            mode = None
            if key == "*NODE":
                mode = "node"
            elif key == "*NSET":
                m = re.search(r"NSET\s*=\s*([^,]+)", s, re.IGNORECASE)
                if m:
                    cur = sets.setdefault(m.group(1).strip().upper(), [])
                    generate = "GENERATE" in s.upper()
                    mode = "nset"
            continue
        parts = [t for t in s.replace(",", " ").split() if t]
        if mode == "node":
            if len(parts) < 3:
                raise FEImportError(f"{path}: *NODE line {s!r}: expected 'id, x, y[, z]'")
            try:
                ids.append(int(parts[0]))
                c = [float(t) for t in parts[1:4]]
            except ValueError:
                raise FEImportError(f"{path}: *NODE line {s!r}: not numbers") from None
            xyz.append(c + [0.0] * (3 - len(c)))
        elif mode == "nset":
            try:
                vals = [int(t) for t in parts]
            except ValueError:  # a set made of other sets: not needed here
                continue
            if generate and len(vals) >= 2:
                step = vals[2] if len(vals) > 2 else 1
                cur.extend(range(vals[0], vals[1] + 1, step))
            else:
                cur.extend(vals)
    return (np.array(ids, dtype=np.int64), np.array(xyz, dtype=float).reshape(-1, 3),
            {k: np.unique(np.array(v, dtype=np.int64)) for k, v in sets.items()})


def read_inp_nodes(path: str | Path) -> tuple[np.ndarray, np.ndarray]:
    ids, xyz, _ = read_inp(path)
    return ids, xyz


def read_msh_nodes(path: str | Path) -> tuple[np.ndarray, np.ndarray]:
    """Nodes of a gmsh ASCII mesh, format 2.2 or 4.1."""
    lines = Path(path).read_text(errors="replace").splitlines()
    try:
        fmt = float(lines[lines.index("$MeshFormat") + 1].split()[0])
        i = lines.index("$Nodes") + 1
    except (ValueError, IndexError):
        raise FEImportError(f"{path}: not a gmsh ASCII mesh ($MeshFormat and $Nodes sections expected)") from None
    ids: list[int] = []
    xyz: list[list[float]] = []
    if fmt < 3:
        n = int(lines[i])
        for s in lines[i + 1:i + 1 + n]:
            p = s.split()
            ids.append(int(p[0]))
            xyz.append([float(t) for t in p[1:4]])
    else:
        n_blocks = int(lines[i].split()[0])
        i += 1
        for _ in range(n_blocks):
            n = int(lines[i].split()[3])
            i += 1
            ids.extend(int(lines[i + k]) for k in range(n))
            xyz.extend([float(t) for t in lines[i + n + k].split()[:3]] for k in range(n))
            i += 2 * n
    return np.array(ids, dtype=np.int64), np.array(xyz, dtype=float).reshape(-1, 3)


def read_table_nodes(path: str | Path) -> tuple[np.ndarray, np.ndarray]:
    ids: list[int] = []
    xyz: list[list[float]] = []
    for k, line in enumerate(Path(path).read_text(errors="replace").splitlines()):
        s = line.strip()
        if not s or s.startswith("#"):
            continue
        p = s.replace(",", " ").split()
        try:
            ids.append(int(float(p[0])))
            xyz.append([float(t) for t in p[1:4]])
        except (ValueError, IndexError):
            raise FEImportError(f"{path}: line {k + 1} {s!r}: expected 'id x y z'") from None
        if len(xyz[-1]) != 3:
            raise FEImportError(f"{path}: line {k + 1} {s!r}: expected 'id x y z'")
    return np.array(ids, dtype=np.int64), np.array(xyz, dtype=float).reshape(-1, 3)


def read_nastran_grids(path: str | Path) -> tuple[np.ndarray, np.ndarray]:
    """GRID cards of a NASTRAN bulk file (basic coordinate system only)."""
    bulk = _pyyeti_bulk()
    g = bulk.rdgrids(str(path))
    if g is None:
        return np.zeros(0, dtype=np.int64), np.zeros((0, 3))
    g = np.atleast_2d(g)
    if np.any(g[:, 1] != 0):
        raise FEImportError(f"{path}: GRID {int(g[np.flatnonzero(g[:, 1] != 0)[0], 0])} is given in coordinate system "
                            f"{int(g[np.flatnonzero(g[:, 1] != 0)[0], 1])}; accepted: the basic system (CP = 0)")
    return g[:, 0].astype(np.int64), g[:, 2:5].astype(float)


def _pyyeti_bulk():
    try:
        from pyyeti.nastran import bulk
    except ImportError:
        raise FEImportError("NASTRAN files are read with pyyeti: pip install 'rotorub[fe]'") from None
    return bulk
