"""Reading FE exports (rotorub_model/fe/: calculix.py, matrix_market.py, nastran.py, coordinates.py, units.py,
femodel.py) and what bad input gets: one FEImportError line naming the file or field, nothing written.

The table of bad inputs of docs/THEORY.md section 9 is this file's ``BAD`` cases."""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest
import scipy.io
import scipy.sparse as sp

from rotorub_model.app.cli import main
from rotorub_model.errors import FEImportError, RotorubError
from rotorub_model.fe import (
    load_superelement,
    read_calculix,
    read_matrix_market,
    reduce_blade,
    unit_system,
)
from rotorub_model.fe.beam_blade import write_beam_blade
from rotorub_model.fe.coordinates import read_coordinates, read_inp
from rotorub_model.structure.params import reference_parameters


@pytest.fixture(scope="module")
def beam(tmp_path_factory):
    p = reference_parameters()
    w = p.normalisation.speed_max * p.normalisation.omega_ref
    d = tmp_path_factory.mktemp("beam")
    return p, write_beam_blade(p, d, speeds=(0.0, w / 2, w), n_elements=40)


def read(info, **kw):
    args = dict(mass=info["mass"], stiffness=info["stiffness"], dofs=info["dofs"], coordinates=info["coordinates"],
                units="SI", speeds=info["speeds"], mass_dofs=info["mass_dofs"])
    args.update(kw)
    return read_matrix_market(**args)


def reduce(fe, info, **kw):
    args = dict(axis_direction=info["axis_direction"], cutoff_hz=3000.0)
    args.update(kw)
    return reduce_blade(fe, [info["tip_node"]], **args)


def write_calculix(info, folder: Path, scale_length: float = 1.0, scale_mass: float = 1.0) -> list[Path]:
    """The beam as CalculiX matrix-storage jobs (one triangle, 1-based, 'node.direction' dof map): what ccx
    writes, in the unit system given by the scales (file unit = SI / scale)."""
    folder.mkdir(parents=True, exist_ok=True)
    dofs = Path(info["dofs"]).read_text().split()
    comps = np.array([int(d.split(".")[1]) for d in dofs])
    dl = np.where(comps <= 3, scale_length, 1.0)  # u_file = u_SI / L -> K_file = D^-1 K D^-1 / (F L)
    force = scale_mass * scale_length  # seconds kept
    M = scipy.io.mmread(str(info["mass"])).tocsr()
    mdofs = Path(info["mass_dofs"]).read_text().split()
    key = {d: i for i, d in enumerate(mdofs)}
    idx = np.array([key[d] for d in dofs])
    Mf = M[idx][:, idx]
    jobs = []
    for k, (w, f) in enumerate(zip(info["speeds"], info["stiffness"])):
        K = scipy.io.mmread(str(f)).tocsr()
        stem = folder / f"job{k}"
        for A, suffix, s in ((K, ".sti", force * scale_length), (Mf, ".mas", scale_mass * scale_length**2)):
            A = sp.triu(sp.diags(dl) @ A @ sp.diags(dl) / s).tocoo()
            stem.with_suffix(suffix).write_text("".join(f"{i + 1} {j + 1} {float(v)!r}\n" for i, j, v in
                                                        zip(A.row, A.col, A.data)))
        stem.with_suffix(".dof").write_text("\n".join(dofs) + "\n")
        load = f"EALL, CENTRIF, {float(w * w)!r}, 0., 0., 0., 0., 0., 1.\n" if w else ""
        deck = "*INCLUDE, INPUT=mesh.inp\n*STEP\n*STATIC\n*DLOAD\n" + load + "*END STEP\n"
        stem.with_suffix(".inp").write_text(deck)
        jobs.append(stem)
    ids, xyz = read_coordinates(info["coordinates"])
    (folder / "mesh.inp").write_text("*NODE, NSET=NALL\n" + "".join(
        f"{i}, {float(x / scale_length)!r}, {float(y / scale_length)!r}, {float(z / scale_length)!r}\n"
        for i, (x, y, z) in zip(ids, xyz)))
    return jobs


def test_units():
    """Named and spelled-out systems; conversion factors of N-mm-t-s."""
    s = unit_system("N-mm-t-s")
    assert (s.force, s.length, s.mass, s.time) == (1.0, 1e-3, 1e3, 1.0)
    assert unit_system("kN-mm-kg-ms").force == 1e3
    assert unit_system("lbf-in-s").mass == pytest.approx(175.126835, rel=1e-6)
    assert unit_system("mN-mm-kg-s").name == "mN-mm-kg-s"


def test_calculix_files_in_millimetres_give_the_si_blade(beam, tmp_path):
    """The same beam written as CalculiX jobs in N-mm-t-s (speeds read from the decks' CENTRIF) reduces to the
    same blade as the SI Matrix Market files: every unit conversion (coordinates, translational and rotational
    rows of K and M) is right."""
    p, info = beam
    si = reduce(read(info), info)
    jobs = write_calculix(info, tmp_path / "ccx", scale_length=1e-3, scale_mass=1e3)
    # the mass rows of the constrained directions are in the Matrix Market mass map only: use the free mass here
    fe = read_calculix(jobs, units="N-mm-t-s")
    assert np.allclose(fe.speeds, info["speeds"])
    mm = reduce(fe, info)
    for w in info["speeds"]:
        assert np.allclose(mm.frequencies(w), si.frequencies(w), rtol=1e-9)
    assert np.allclose(mm.tip_positions, si.tip_positions)


def test_coordinates_formats(tmp_path):
    """Node coordinates from an .inp with *INCLUDE and *NSET GENERATE, gmsh .msh 2.2 and 4.1, and a table."""
    (tmp_path / "nodes.inp").write_text("*NODE\n1, 0., 0., 0.\n2, 1.5, 0, 0\n3, 1, 2, 3\n")
    (tmp_path / "deck.inp").write_text("** comment\n*INCLUDE, INPUT=nodes.inp\n*NSET, NSET=tip, GENERATE\n1, 3, 2\n")
    ids, xyz, sets = read_inp(tmp_path / "deck.inp")
    assert ids.tolist() == [1, 2, 3] and xyz[2].tolist() == [1.0, 2.0, 3.0] and sets["TIP"].tolist() == [1, 3]
    (tmp_path / "a.msh").write_text("$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n2\n5 0 0 1\n7 1 0 0\n$EndNodes\n")
    assert read_coordinates(tmp_path / "a.msh")[0].tolist() == [5, 7]
    (tmp_path / "b.msh").write_text("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 2 1 9\n3 1 0 2\n8\n9\n"
                                    "0 0 0\n1 2 3\n$EndNodes\n")
    ids, xyz = read_coordinates(tmp_path / "b.msh")
    assert ids.tolist() == [8, 9] and xyz[1].tolist() == [1.0, 2.0, 3.0]
    (tmp_path / "t.csv").write_text("# id, x, y, z\n4, 1, 2, 3\n")
    assert read_coordinates(tmp_path / "t.csv")[1].tolist() == [[1.0, 2.0, 3.0]]


def test_nastran_op4_and_dmig(beam, tmp_path):
    """OP4 (with a dof map) and DMIG punch files (dof map on the cards, GRID coordinates) through pyyeti give
    the Matrix Market blade."""
    pytest.importorskip("pyyeti", reason="the fe extra (pyyeti) is not installed: pip install 'rotorub[fe]'")
    import pandas as pd
    from pyyeti.nastran import bulk, op4

    from rotorub_model.fe import read_dmig, read_op4

    p, info = beam
    ref = reduce(read(info), info)
    fe0 = read(info)
    # the OP4 route: the free-dof mass (its constrained rows dropped: they carry the rigid mass only)
    Mf = fe0.M_free.toarray()
    Ks = [K.toarray() for _, K in fe0.stiffness]
    op4.write(str(tmp_path / "b.op4"), {"MAA": Mf, "KAA0": Ks[0], "KAA1": Ks[1], "KAA2": Ks[2]})
    fe = read_op4(tmp_path / "b.op4", "MAA", ["KAA0", "KAA1", "KAA2"], info["dofs"], info["coordinates"],
                  speeds=info["speeds"])
    b = reduce(fe, info)
    assert np.allclose(b.frequencies(info["speeds"][-1]), ref.frequencies(info["speeds"][-1]), rtol=1e-9)
    # DMIG with GRID cards
    idx = pd.MultiIndex.from_arrays([fe0.dof_nodes, fe0.dof_components], names=["id", "dof"])
    dct = {"MAAX": pd.DataFrame(Mf, index=idx, columns=idx)}
    for k, K in enumerate(Ks):
        dct[f"KAAX{k}"] = pd.DataFrame(K, index=idx, columns=idx)
    with open(tmp_path / "b.pch", "w") as f:
        ids, xyz = read_coordinates(info["coordinates"])
        bulk.wtgrids(f, ids, xyz=xyz)
        bulk.wtdmig(f, dct)
    fe = read_dmig(tmp_path / "b.pch", "MAAX", ["KAAX0", "KAAX1", "KAAX2"], speeds=info["speeds"])
    b = reduce(fe, info)
    # DMIG cards hold 10 significant digits: 1.3e-6 on the first frequency of this 40-element beam
    assert np.allclose(b.frequencies(info["speeds"][-1]), ref.frequencies(info["speeds"][-1]), rtol=1e-5)


def _mutated_mm(info, tmp_path, what):
    """Copies of the beam's files with one defect."""
    d = tmp_path / what
    d.mkdir()
    new = dict(info)
    for key in ("mass", "dofs", "mass_dofs", "coordinates"):
        new[key] = d / Path(info[key]).name
        shutil.copy(info[key], new[key])
    new["stiffness"] = []
    for f in info["stiffness"]:
        shutil.copy(f, d / Path(f).name)
        new["stiffness"].append(d / Path(f).name)
    return new


def mm_write(path, A, symmetry="general"):
    scipy.io.mmwrite(str(path), sp.coo_matrix(A), symmetry=symmetry, precision=17)


BAD = [
    # (name, how to make it, message fragment)
    ("unknown units", lambda i, t: read(i, units="furlong-fortnight"), "unknown unit system"),
    ("inconsistent units", lambda i, t: read(i, units="N-mm-kg-s"), "not a consistent unit system"),
    ("dof map shorter than the matrices", "short_dofs", "but the dof map has"),
    ("dof twice in the dof map", "dup_dof", "appears twice"),
    ("component 7", "comp7", "has component 7"),
    ("non-symmetric stiffness", "asym", "not symmetric"),
    ("indefinite stiffness", "indefinite", "indefinite"),
    ("NaN in the mass", "nan", "NaN"),
    ("root not clamped", "free_root", "the root is not clamped"),
    ("coordinates of another model (ids missing)", "coords_missing", "has no coordinates"),
    ("coordinates of another model (same ids, other places)", "coords_shuffled", "not those of the matrices"),
    ("no stiffness at rest", lambda i, t: read(i, speeds=[10.0, 20.0, 30.0]), "no stiffness at rest"),
    ("a speed twice", lambda i, t: read(i, speeds=[0.0, 20.0, 20.0]), "given twice"),
    ("fewer speeds than the identification needs", "two_speeds_order2", "cannot identify"),
    ("tip node not in the model", lambda i, t: reduce(read(i), i, tip_nodes=None) if False else
     reduce_blade(read(i), [999], axis_direction=i["axis_direction"]), "not in the model"),
    ("tip node twice", lambda i, t: reduce_blade(read(i), [i["tip_node"], i["tip_node"]],
                                                 axis_direction=i["axis_direction"]), "given twice"),
    ("tip node clamped (the root)", lambda i, t: reduce_blade(read(i), [1], axis_direction=i["axis_direction"]),
     "no free translation"),
    ("no tip node", lambda i, t: reduce_blade(read(i), [], axis_direction=i["axis_direction"]), "none given"),
    ("prestress about another axis than declared", lambda i, t: reduce_blade(read(i), [i["tip_node"]],
                                                                             axis_direction=(0.0, 0.0, 1.0)),
     "of the spin softening"),
    ("negative mass", "neg_mass", "mass is not positive"),
    ("missing file", lambda i, t: read(i, mass=t / "nothing.mtx"), "no such file"),
    ("CalculiX jobs of two meshes", "ccx_two_meshes", "dof map differs"),
    ("unclamped-mass job of another mesh", "ccx_free_other", "mass on the free dofs differs"),
    ("superelement with a field missing", "se_missing", "missing"),
]


def _make(kind, info, t):
    if callable(kind):
        return kind(info, t)
    i = _mutated_mm(info, t, kind)
    if kind == "short_dofs":
        lines = Path(i["dofs"]).read_text().splitlines()
        Path(i["dofs"]).write_text("\n".join(lines[:-1]) + "\n")
    elif kind == "dup_dof":
        lines = Path(i["dofs"]).read_text().splitlines()
        lines[-1] = lines[0]
        Path(i["dofs"]).write_text("\n".join(lines) + "\n")
    elif kind == "comp7":
        lines = Path(i["dofs"]).read_text().splitlines()
        lines[0] = lines[0].split(".")[0] + ".7"
        Path(i["dofs"]).write_text("\n".join(lines) + "\n")
    elif kind == "asym":
        K = scipy.io.mmread(str(i["stiffness"][0])).toarray()
        K[0, 2] *= 1.01
        mm_write(i["stiffness"][0], K)
    elif kind == "indefinite":
        K = scipy.io.mmread(str(i["stiffness"][0])).toarray()
        K[-2:, -2:] *= -1.0
        mm_write(i["stiffness"][0], K, "symmetric")
    elif kind == "nan":
        M = scipy.io.mmread(str(i["mass"])).toarray()
        M[0, 0] = np.nan
        mm_write(i["mass"], M, "symmetric")
    elif kind == "neg_mass":
        M = scipy.io.mmread(str(i["mass"])).toarray()
        mm_write(i["mass"], -M, "symmetric")
        return reduce(read(i), i)
    elif kind == "free_root":
        p = reference_parameters()
        from rotorub_model.fe.beam_blade import beam_matrices, beam_nodes

        s, _ = beam_nodes(p, 40, "uniform")
        for f in i["stiffness"]:
            mm_write(f, beam_matrices(p, s, 0.0), "symmetric")
        Path(i["dofs"]).write_text("".join(f"{n}.{c}\n" for n in range(1, 42) for c in (2, 6)))
        Path(i["mass_dofs"]).write_text("".join(f"{n}.{c}\n" for n in range(1, 42) for c in (1, 2, 3))
                                        + "".join(f"{n}.6\n" for n in range(1, 42)))
        mvals = np.diag(scipy.io.mmread(str(i["mass"])).toarray())
        mm_write(i["mass"], np.diag(np.concatenate([mvals[:123], np.zeros(41)])), "symmetric")
        return reduce(read(i, speeds=[0.0, 1.0, 2.0]), i)
    elif kind == "coords_missing":
        lines = Path(i["coordinates"]).read_text().splitlines()
        Path(i["coordinates"]).write_text("\n".join(lines[:-3]) + "\n")
    elif kind == "coords_shuffled":
        ids, xyz = read_coordinates(i["coordinates"])
        xyz = xyz.copy()
        xyz[:, 0] = xyz[::-1, 0]  # the same node ids, the span reversed: another model's geometry
        Path(i["coordinates"]).write_text("".join(f"{a} {float(x)!r} {float(y)!r} {float(z)!r}\n"
                                                  for a, (x, y, z) in zip(ids, xyz)))
        return reduce(read(i), i)
    elif kind == "two_speeds_order2":
        return reduce(read(i, stiffness=i["stiffness"][:2], speeds=i["speeds"][:2]), i, order=2)
    elif kind == "ccx_two_meshes":
        jobs = write_calculix(info, t / "ccx")
        lines = jobs[1].with_suffix(".dof").read_text().splitlines()
        jobs[1].with_suffix(".dof").write_text("\n".join(lines[2:] + lines[:2]) + "\n")
        return read_calculix(jobs)
    elif kind == "ccx_free_other":
        jobs = write_calculix(info, t / "ccx")
        free = t / "ccx" / "free"
        for suffix in (".dof", ".sti"):
            free.with_suffix(suffix).write_text(jobs[0].with_suffix(suffix).read_text())
        rows = [line.split() for line in jobs[0].with_suffix(".mas").read_text().splitlines()]
        free.with_suffix(".mas").write_text("".join(f"{a} {b} {1.1 * float(v)!r}\n" for a, b, v in rows))
        return read_calculix(jobs, mass_free=free)
    elif kind == "se_missing":
        b = reduce(read(info), info)
        b.save(t / "b.npz")
        with np.load(t / "b.npz") as d:
            kept = {k: d[k] for k in d.files if k != "basis_coriolis"}
        np.savez(t / "bad.npz", **kept)
        return load_superelement(t / "bad.npz")
    return reduce(read(i), i)


@pytest.mark.parametrize("name,kind,fragment", BAD, ids=[b[0] for b in BAD])
def test_bad_input_gets_one_clear_line(beam, tmp_path, name, kind, fragment):
    _, info = beam
    with pytest.raises(FEImportError) as exc:
        _make(kind, info, tmp_path)
    msg = str(exc.value)
    assert fragment in msg and "\n" not in msg, msg
    assert isinstance(exc.value, RotorubError)


def test_cli_bad_input_exits_2_and_writes_nothing(beam, tmp_path, capsys):
    _, info = beam
    out = tmp_path / "out"
    rc = main(["import-blade", "--fe", str(info["mass"]), *map(str, info["stiffness"]), "--units", "SI",
               "--dofs", str(info["dofs"]), "--mass-dofs", str(info["mass_dofs"]), "--coordinates",
               str(info["coordinates"]), "--speeds", *map(str, info["speeds"]), "--tip-nodes", "999",
               "--axis-direction", *map(str, info["axis_direction"]), "--out", str(out)])
    err = capsys.readouterr().err
    assert rc == 2 and err.count("\n") == 1 and "tip_nodes: node 999" in err
    assert not out.exists()
    rc = main(["import-blade", "--fe", str(info["mass"]), *map(str, info["stiffness"]), "--units", "SI",
               "--dofs", str(info["dofs"]), "--mass-dofs", str(info["mass_dofs"]), "--coordinates",
               str(info["coordinates"]), "--speeds", *map(str, info["speeds"]), "--tip-nodes", str(info["tip_node"]),
               "--axis-direction", *map(str, info["axis_direction"]), "--cutoff-hz", "6000", "--out", str(out)])
    assert rc == 0 and (out / "blade.npz").is_file() and (out / "import_blade.png").is_file()
    assert capsys.readouterr().out.startswith("OK: ")  # the verdict line (--json prints the summary)
