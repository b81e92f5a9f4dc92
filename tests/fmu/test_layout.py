"""fmu_src's layout and import rules (docs/FMU-layout.md), read from the sources with ast, so that a change that breaks
them fails here rather than in a reviewer's head:

| layer | may import (inside fmu_src) |
|---|---|
| ``fmi/`` | ``fmi/`` |
| ``models/<m>/`` | ``fmi/`` and its own folder (never another model, a master or a system) |
| ``masters/`` | ``fmi/`` and ``masters/`` |
| ``systems/`` | ``fmi/``, ``models/``, ``masters/``, ``systems/`` |
| ``cli.py``, ``reproduce.py`` | anything |

and: no cycle between fmu_src's sub-packages; the library (``rotorub_model``) never imports ``fmu_src``; a pythonfmu
slave imports neither (it runs from the FMU's resources); the FMI layer's C includes no model's header but the
``model.h`` and ``variables.h`` every model provides; every model folder has the same file names; no package is
named ``build``.
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
FMU = ROOT / "fmu_src"
LAYERS = ("fmi", "models", "masters", "systems")
ALLOWED = {"fmi": {"fmi"}, "models": {"fmi", "models"}, "masters": {"fmi", "masters"},
           "systems": {"fmi", "models", "masters", "systems"}, "top": {"fmi", "models", "masters", "systems", "top"}}
MODEL_FILES = {"__init__.py", "variables.py", "model.c", "model.h", "builder.py", "crosscheck.py", "FMU.md"}  # in each


def _module(path: Path) -> str:
    rel = path.relative_to(ROOT).with_suffix("")
    parts = rel.parts[:-1] if rel.name == "__init__" else rel.parts
    return ".".join(parts)


def imports(path: Path) -> list[tuple[int, str]]:
    """(line, absolute module) of every import in a file, relative ones resolved."""
    tree = ast.parse(path.read_text(), str(path))
    package = _module(path) if path.name == "__init__.py" else _module(path).rpartition(".")[0]
    out = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            out += [(node.lineno, a.name) for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                base = base[:len(base) - node.level + 1]
                mod = ".".join(base + ([node.module] if node.module else []))
                names = [f"{mod}.{a.name}" for a in node.names] if not node.module else [mod]
                out += [(node.lineno, n) for n in names]
            else:
                out.append((node.lineno, node.module or ""))
    return out


def layer(module: str) -> str | None:
    """The fmu_src layer of a module (None: not fmu_src)."""
    parts = module.split(".")
    if parts[0] != "fmu_src":
        return None
    return parts[1] if len(parts) > 1 and parts[1] in LAYERS else "top"


def model_of(module: str) -> str | None:
    parts = module.split(".")
    return parts[2] if len(parts) > 2 and parts[1] == "models" else None


def violations(files: list[Path]) -> list[str]:
    out = []
    for f in files:
        me = _module(f)
        mine = layer(me)
        for line, target in imports(f):
            theirs = layer(target)
            where = f"{f.relative_to(ROOT)}:{line}: {me} imports {target}"
            if mine is None:
                if theirs is not None:
                    out.append(f"{where} (the library never imports fmu_src)")
                continue
            if theirs is None:
                continue
            if theirs not in ALLOWED[mine]:
                out.append(f"{where} ({mine}/ may import {', '.join(sorted(ALLOWED[mine]))} only)")
            elif mine == "models" and theirs == "models" and model_of(target) not in (None, model_of(me)):
                out.append(f"{where} (a model imports no other model)")
    return out


def test_import_rules_hold():
    files = sorted(p for p in FMU.rglob("*.py") if "__pycache__" not in p.parts)
    files += sorted(p for p in (ROOT / "rotorub_model").rglob("*.py") if "__pycache__" not in p.parts)
    assert violations(files) == []


def test_no_cycle_between_sub_packages():
    edges: dict[str, set[str]] = {}
    for f in FMU.rglob("*.py"):
        a = layer(_module(f))
        for _, target in imports(f):
            b = layer(target)
            if b and b != a:
                edges.setdefault(a, set()).add(b)

    def reaches(a: str, b: str, seen: set[str]) -> bool:
        return any(n == b or (n not in seen and reaches(n, b, seen | {n})) for n in edges.get(a, ()))

    assert [a for a in edges if reaches(a, a, set())] == [], edges


def test_slaves_import_nothing_of_the_project():
    """A pythonfmu slave runs from the FMU's resources, in the host's Python: neither fmu_src nor rotorub_model (the
    contact slave loads its own copy of the library under a build-specific name, relative imports only)."""
    for slave in FMU.glob("models/*/slave.py"):
        bad = [t for _, t in imports(slave) if t.split(".")[0] in ("fmu_src", "rotorub_model")]
        assert bad == [], slave


def test_the_fmi_layers_c_knows_no_model():
    """fmu_src/fmi/c includes the standard's headers, its own, and the two every model provides by name."""
    own = {p.name for p in (FMU / "fmi" / "c").iterdir()}
    allowed = own | {"model.h", "variables.h"} | {f"fmi{v}{n}.h" for v in "23" for n in
                                                   ("Functions", "FunctionTypes", "TypesPlatform", "PlatformTypes")}
    for f in (FMU / "fmi" / "c").iterdir():
        for inc in re.findall(r'#include\s+"([^"]+)"', f.read_text()):
            assert inc in allowed, (f.name, inc)
        text = f.read_text().lower()
        for word in ("blade", "spool", "rotorcasingcontact", "lpspool", "tipclearance", "rotorub_kernel"):
            assert word not in text, (f.name, word)


def test_every_model_folder_has_the_same_file_names():
    folders = [d for d in (FMU / "models").iterdir() if d.is_dir() and d.name != "__pycache__"]
    assert {d.name for d in folders} == {"contact", "spool", "clearance", "casing_load"}
    for d in folders:
        assert MODEL_FILES <= {p.name for p in d.iterdir()}, d.name
        extra = {p.name for p in d.iterdir() if p.is_file()} - MODEL_FILES - {"slave.py"}  # where it has one
        assert not extra, (d.name, extra)


def test_no_package_is_named_build():
    """pytest's norecursedirs, the common .gitignore template and structure tools take a folder named build for
    generated output."""
    assert not [p for p in FMU.rglob("build") if p.is_dir()]


def test_the_checker_finds_a_broken_rule(tmp_path, monkeypatch):
    """The checker itself: a master importing a model, a model importing another model, the library importing
    fmu_src are each found."""
    cases = {"fmu_src/masters/bad.py": "from ..models.contact import variables\n",
             "fmu_src/models/spool/bad.py": "from ..contact.variables import MODEL\n",
             "fmu_src/fmi/bad.py": "from fmu_src.systems import ssp\n",
             "rotorub_model/bad.py": "import fmu_src.cli\n",
             "fmu_src/systems/good.py": "from ..models.contact import builder\nfrom ..masters import fmi2\n"}
    monkeypatch.setattr(__import__(__name__), "ROOT", tmp_path)
    files = []
    for rel, text in cases.items():
        p = tmp_path / rel
        p.parent.mkdir(parents=True, exist_ok=True)
        p.write_text(text)
        files.append(p)
    found = violations(files)
    assert len(found) == 4 and not any("good.py" in f for f in found), found


@pytest.mark.parametrize("model", ["spool", "clearance"])
def test_the_fmi_layer_builds_any_model_in_both_versions(model, tmp_path):
    """The wrappers know no model: the spool and the clearance model, written for FMI 2.0, build as FMI 3.0 FMUs from
    the same model.c (the defaults cover what they do not write: events), validate, and compute the FMI 2.0 FMU's
    numbers bit for bit."""
    pytest.importorskip("fmpy")
    from fmpy.validation import validate_fmu

    from fmu_src.masters.fmi2 import Slave
    from fmu_src.masters.fmi3 import OK, Slave3, fmi3_available

    if fmi3_available():
        pytest.skip(fmi3_available())
    if model == "spool":
        from fmu_src.models.spool.builder import build_native_spool_fmu as build

        start, probe = {"friction_torque": -500.0}, "Omega"
    else:
        from fmu_src.models.clearance.builder import build_clearance_fmu as build

        start, probe = {"Omega": 200.0}, "closure"
    f2 = build(tmp_path / "2", platforms=("linux64",))
    f3 = build(tmp_path / "3", platforms=("linux64",), fmi="3.0")
    assert validate_fmu(str(f3)) == []
    with Slave(f2, **start) as a, Slave3(f3) as b:
        assert b.init(**start) == OK
        for k in range(300):
            a.step(k * 1e-2, 1e-2)
            assert b.step(1e-2)[0] == OK
            assert a.get(probe) == b.get(probe), k
