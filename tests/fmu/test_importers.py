"""The FMUs in importers nobody here wrote (issue 33): fmusim 0.0.39, the Modelica Association's reference importer,
built from ../shared/hosts once (cached; skipped, with the reason, where Debian's packages are missing), runs the
FMI 2.0 and FMI 3.0 contact FMUs (the reference and a 14-blade build): the default experiment, the cross-check
kit, a divergence, a state saved and restored; and every FMU's own reference experiments (FMI-LS-REF) replayed in
fmpy and fmusim, valid against the standard's schema, failing when a host swaps two inputs."""

from __future__ import annotations

import zipfile
from pathlib import Path

import numpy as np
import pytest

from fmu_src.fmi import lsref
from fmu_src.masters import fmusim_host, replay
from fmu_src.masters.crosscheck import compare, kit_of

SCHEMAS = Path(__file__).parent / "data" / "fmi-ls-ref"
pytestmark = pytest.mark.skipif(fmusim_host.available() is not None, reason=f"fmusim: {fmusim_host.available()}")


@pytest.fixture(scope="module")
def fmusim():
    return fmusim_host.executable()


@pytest.fixture(scope="module")
def builds(tmp_path_factory, ref_params):
    """The native contact FMUs as build-fmu writes them (with kit and reference experiments): FMI 2.0 and 3.0, the
    reference and a 14-blade build."""
    pytest.importorskip("fmpy")
    from fmu_src.models.contact.builder import build_with_kit
    from rotorub_model.structure.params import to_toml

    root = tmp_path_factory.mktemp("importers")
    params14 = root / "fan14.toml"
    params14.write_text(to_toml(ref_params.replace(blades={"count": 14})))
    out = {}
    for label, params in (("ref", None), ("b14", params14)):
        for fmi3 in (False, True):
            dest = root / f"{label}-{'fmi3' if fmi3 else 'fmi2'}"
            out[(label, fmi3)] = Path(build_with_kit(dest, params, native=True, platforms=("linux64",),
                                                     fmi3=fmi3)["fmu"])
    return out


@pytest.mark.parametrize("fmi3", [False, True], ids=["fmi2", "fmi3"])
@pytest.mark.parametrize("label", ["ref", "b14"])
def test_fmusim_default_experiment_and_kit(builds, fmusim, label, fmi3):
    """The regression of issue 33: the FMI 3.0 FMU segfaulted fmusim (n_blades declared after its arrays). Now
    exit 0 on the default experiment (it rubs), and the kit agrees with the library to 1e-9 (rubbing: forces > 0)."""
    fmu = builds[(label, fmi3)]
    r = fmusim_host.run(fmu, {}, None, ["gap_min", "n_contact"], 1e-3, 2.0)
    assert r.exit_code == 0, r.log
    assert len(r.result["time"]) == 2001 and r.result["n_contact"].max() >= 1  # the default experiment rubs
    inp, ref = kit_of(fmu.parent)
    outs = [c for c in ref if c != "time"]
    k = fmusim_host.run(fmu, {}, inp, outs, 1e-3, float(inp["time"][-1]))
    assert k.exit_code == 0, k.log
    diffs = compare(k.result, fmu.parent)
    assert max(diffs.values()) < 1e-9, diffs
    assert max(float(np.max(ref[c])) for c in outs if "F_N" in c) > 100.0  # the kit compares a rub, not rest
    n_blades = 14 if label == "b14" else 10
    assert sum(1 for c in outs if "F_N" in c) == n_blades


@pytest.mark.parametrize("fmi3", [False, True], ids=["fmi2", "fmi3"])
def test_fmusim_divergence_and_state_files(builds, fmusim, tmp_path, fmi3):
    """A divergence ends the run at once with exit 0 and status 1; a state saved at 1 s and restored gives the
    long run's second second (fmusim's restart steps differ by ulps: 1e-9 of each column's largest value)."""
    fmu = builds[("ref", fmi3)]
    d = fmusim_host.run(fmu, {"g0": 0.1e-3, "imbalance": 0.5}, None, ["status", "gap_min"], 1e-3, 1.0)
    assert d.exit_code == 0, d.log
    assert d.result["status"][-1] == 1 and len(d.result["time"]) < 200, d.log
    state = tmp_path / "state.bin"
    outs = ["gap_min", "friction_torque", "disk_displacement.x"]
    whole = fmusim_host.run(fmu, {"g0": 0.5e-3}, None, outs, 1e-3, 2.0)
    first = fmusim_host.run(fmu, {"g0": 0.5e-3}, None, outs, 1e-3, 1.0, state_out=state)
    assert first.exit_code == 0 and state.stat().st_size > 0, first.log
    second = fmusim_host.run(fmu, {}, None, outs, 1e-3, 2.0, 1.0, state_in=state)
    assert second.exit_code == 0, second.log
    assert np.abs(whole.result["friction_torque"][:1000]).max() > 1.0  # the saved state carries a rub, not rest
    for c in outs:
        a, b = whole.result[c][1000:], second.result[c]
        n = min(len(a), len(b))
        assert n >= 1000
        assert np.max(np.abs(a[:n] - b[:n])) <= 1e-9 * np.max(np.abs(a)), c


def test_structural_parameters_first_and_no_empty_dependencies(builds):
    """What broke fmusim (a dimension read before its structural parameter) and fmi4c (dependencies="")."""
    from xml.etree import ElementTree as ET

    with zipfile.ZipFile(builds[("ref", True)]) as z:
        root = ET.fromstring(z.read("modelDescription.xml"))
    seen = set()
    for v in root.find("ModelVariables"):
        for dim in v.findall("Dimension"):
            assert dim.get("valueReference") is None or dim.get("valueReference") in seen, v.get("name")
        seen.add(v.get("valueReference"))
    time_vr = next(v.get("valueReference") for v in root.find("ModelVariables") if v.get("causality") ==
                   "independent")
    for el in root.find("ModelStructure"):
        assert el.get("dependencies", "x") != "", el.attrib
        if el.tag == "Output":  # a transient build: outputs follow the state (time), no input feedthrough
            assert el.get("dependencies") == time_vr


def test_reference_experiments_valid_against_the_schema(builds):
    etree = pytest.importorskip("lxml.etree")
    manifest_schema = etree.XMLSchema(etree.parse(str(SCHEMAS / "fmi3LayeredStandardReferenceManifest.xsd")))
    exp_schema = etree.XMLSchema(etree.parse(str(SCHEMAS / "v1.0.0-alpha.1" /
                                                 "fmi3LayeredStandardReferenceExperiments.xsd")))
    for fmu in builds.values():
        with zipfile.ZipFile(fmu) as z:
            m = etree.fromstring(z.read(lsref.MANIFEST))
            x = etree.fromstring(z.read(lsref.EXPERIMENTS))
            names = set(z.namelist())
        assert manifest_schema.validate(m), manifest_schema.error_log
        assert exp_schema.validate(x), exp_schema.error_log
        # libxml2 does not enforce the schema's fixed values: checked here
        ns = "{http://fmi-standard.org/fmi-ls-manifest}"
        assert m.get(ns + "fmi-ls-name") == lsref.LS_NAME and m.get(ns + "fmi-ls-description") == lsref.LS_DESCRIPTION
        for rel in m.findall("Related"):
            assert lsref.FOLDER + rel.get("source") in names
    experiments = lsref.read(builds[("ref", False)])
    names = {e.name for e in experiments}
    assert {"section6_3D", "section6_2D", "run_up", "oval_casing", "wear", "divergence"} <= names
    for e in experiments:
        assert len(e.outputs) <= 10
        moving = [c for c in e.inputs if c != "time" and np.ptp(e.inputs[c]) > 0]
        if e.name != "divergence":  # every input moves (a diverged run ends before the later moves)
            assert len(moving) == len(e.inputs) - 1, (e.name, set(e.inputs) - set(moving))
        if e.name in ("section6_3D", "section6_2D", "run_up", "oval_casing", "wear"):
            assert np.nanmax(e.reference["casing_force.x"] ** 2 + e.reference["casing_force.y"] ** 2) > 1e2  # rub
    div = next(e for e in experiments if e.name == "divergence")
    assert div.reference["status"][-1] == 1 and div.stop < 0.3


@pytest.mark.parametrize("host", ["fmpy", "fmusim"])
@pytest.mark.parametrize("fmi3", [False, True], ids=["fmi2", "fmi3"])
def test_fmu_check_passes_every_experiment(builds, host, fmi3):
    for label in ("ref", "b14"):
        outcomes = replay.check(builds[(label, fmi3)], host)
        assert len(outcomes) == 6
        assert all(o.verdict == "passed" for o in outcomes), [o.line() for o in outcomes]


def test_a_mis_wired_host_fails(builds):
    """Two inputs swapped by the host (the lobe phases, the offsets): the experiments see it."""
    fmu = builds[("ref", False)]
    for swap in (("casing_lobe3.phase", "casing_lobe4.phase"), ("casing_offset.x", "casing_offset.y")):
        outcomes = replay.check(fmu, "fmusim", swap=swap, only=["run_up", "oval_casing"])
        assert all(o.verdict == "FAILED" for o in outcomes), (swap, [o.line() for o in outcomes])


def test_fmu_check_command(builds, tmp_path):
    from rotorub_model.app.cli import main

    fmu = str(builds[("ref", True)])
    assert main(["fmu-check", fmu, "--host", "fmusim", "--only", "run_up", "--record", str(tmp_path)]) == 0
    assert list(tmp_path.rglob("passed")) and list(tmp_path.rglob("results.json"))
    assert main(["fmu-check", fmu, "--only", "run_up", "--swap-inputs", "Omega", "imbalance"]) == 1
    assert main(["fmu-check", str(tmp_path / "none.fmu")]) == 2
    assert main(["fmu-check", fmu, "--only", "nothing"]) == 2


def test_readme_host_table_is_the_compatibility_folder():
    """The README's compatibility table is generated from compatibility/ (python -m fmu_src.masters.compatibility)."""
    from fmu_src.masters import compatibility

    readme = (Path(__file__).resolve().parents[2] / "README.md").read_text()
    start = readme.index("<!-- compatibility table: generated by python -m fmu_src.masters.compatibility -->\n")
    block = readme[start:readme.index("<!-- end of compatibility table -->")].split("\n", 1)[1]
    assert block == compatibility.table()
    rows = compatibility.collect()
    assert len({r["importer"] for r in rows}) >= 4  # fmpy, fmusim, libcosim, ecos
