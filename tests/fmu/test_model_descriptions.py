"""Every FMU keeps every variable it had before issue 24's re-layout, and `fmpy validate` finds nothing in any of
them (the old descriptions: tests/fmu/data/model_descriptions/, written by the builders of commit 1d6655f):
systems and SSP packages built on the old FMUs keep working.

For each old variable, the new description has a variable of the same name with the same value reference,
causality, variability, type, unit, min, max, start and nominal. New variables are allowed only after the old ones
(value references above every old one). The GUID and the generation time are a build's and are not compared.

One difference is permitted: a declared number may be written as a person reads it (issue 24.7: the maximum
imbalance read 4.093319999999999, the product 5.8476 * 0.7's round-off; now 4.09332), where it is the same number to
1e-12 relative. And one file gains attributes: the pythonfmu spool's description was pythonfmu's own writer's;
it is now the native spool's writer's (fmu_src/fmi/description.py), which also declares the parameters' nominal
values (the native spool's, the same numbers) and the outputs' initial = "calculated" kept as before.
"""

from __future__ import annotations

import math
import zipfile
from pathlib import Path
from xml.etree import ElementTree as ET

import pytest

pytest.importorskip("fmpy")

DATA = Path(__file__).parent / "data" / "model_descriptions"
COMPARED = ("valueReference", "causality", "variability", "type", "unit", "min", "max", "start", "nominal")
NUMBERS = ("min", "max", "start", "nominal")
# attributes a file may gain (absent before, present now), with the reason in the module's docstring
GAINS = {"spool_pythonfmu": {"nominal"}}


def variables(xml: bytes) -> dict[str, dict]:
    """name -> the compared attributes of every variable (FMI 2.0: the ScalarVariable's and its type element's; FMI
    3.0: the typed element's, type = its tag)."""
    root = ET.fromstring(xml)
    out = {}
    if root.get("fmiVersion", "").startswith("3"):
        for el in root.find("ModelVariables"):
            start = el.get("start")
            if start is None and el.find("Start") is not None:
                start = el.find("Start").get("value")
            out[el.get("name")] = {**{k: el.get(k) for k in COMPARED if k not in ("type", "start")}, "type": el.tag,
                                   "start": start}
        return out
    for sv in root.iter("ScalarVariable"):
        t = next(iter(sv))
        out[sv.get("name")] = {"valueReference": sv.get("valueReference"), "causality": sv.get("causality"),
                               "variability": sv.get("variability"), "type": t.tag,
                               **{k: t.get(k) for k in ("unit", "min", "max", "start", "nominal")}}
    return out


def same_number(old: str, new: str) -> bool:
    try:
        a, b = float(old), float(new)
    except ValueError:
        return False
    return a == b or (math.isfinite(a) and abs(a - b) <= 1e-12 * abs(a))


def differences(name: str, old_xml: bytes, new_xml: bytes) -> list[str]:
    old, new = variables(old_xml), variables(new_xml)
    out = []
    for var, a in old.items():
        b = new.get(var)
        if b is None:
            out.append(f"{name}: {var} is gone")
            continue
        for k in COMPARED:
            if a[k] == b[k]:
                continue
            if a[k] is None and k in GAINS.get(name, ()):
                continue
            if k in NUMBERS and a[k] is not None and b[k] is not None and same_number(a[k], b[k]):
                continue
            out.append(f"{name}: {var}.{k} was {a[k]!r}, is {b[k]!r}")
    top = max(int(a["valueReference"]) for a in old.values())
    for var, b in new.items():
        if var not in old and int(b["valueReference"]) <= top:
            out.append(f"{name}: new variable {var} has value reference {b['valueReference']}, not after the old ones "
                       f"(<= {top})")
    return out


def _builders():
    from fmu_src.models.clearance.builder import build_clearance_fmu
    from fmu_src.models.contact.builder import build_fmu, build_native_fmu
    from fmu_src.models.spool.builder import build_native_spool_fmu, build_spool_fmu

    p = ("linux64",)
    return {
        "contact_native_fmi2_transient": lambda d: build_native_fmu(d, platforms=p)["fmu"],
        "contact_native_fmi2_quasi_static": lambda d: build_native_fmu(d, platforms=p, mode="quasi_static")["fmu"],
        "contact_native_fmi3_transient": lambda d: build_native_fmu(d, platforms=p, fmi="3.0")["fmu"],
        "contact_native_fmi3_quasi_static": lambda d: build_native_fmu(d, platforms=p, mode="quasi_static",
                                                                       fmi="3.0")["fmu"],
        "contact_pythonfmu_transient": lambda d: build_fmu(d, platforms=p)["fmu"],
        "contact_pythonfmu_quasi_static": lambda d: build_fmu(d, platforms=p, mode="quasi_static")["fmu"],
        "spool_native": lambda d: build_native_spool_fmu(d, platforms=p),
        "spool_pythonfmu": lambda d: build_spool_fmu(d),
        "clearance_native": lambda d: build_clearance_fmu(d, platforms=p),
    }


NAMES = sorted(p.stem for p in DATA.glob("*.xml"))


def test_every_old_description_is_compared():
    assert NAMES == sorted(_builders())


@pytest.mark.parametrize("name", NAMES)
def test_every_old_variable_is_kept(name, tmp_path):
    if "pythonfmu" in name:
        pytest.importorskip("pythonfmu")
    from fmpy.validation import validate_fmu

    fmu = _builders()[name](tmp_path)
    with zipfile.ZipFile(fmu) as z:
        new = z.read("modelDescription.xml")
    assert differences(name, (DATA / f"{name}.xml").read_bytes(), new) == []
    assert validate_fmu(str(fmu)) == []  # what `fmpy validate` reports


def test_the_comparison_finds_a_changed_variable():
    """The check itself: a variable renumbered, a unit or a bound changed, one gone, one inserted before the old
    ones are each found; a bound written as a person reads it is not."""
    old = (DATA / "clearance_native.xml").read_bytes()
    root = ET.fromstring(old)
    assert differences("x", old, old) == []
    svs = {sv.get("name"): sv for sv in root.iter("ScalarVariable")}
    svs["closure0"].set("valueReference", "99")
    next(iter(svs["Omega"])).set("unit", "rpm")
    next(iter(svs["c_thermal"])).set("max", "2e-06")
    next(iter(svs["tau_thermal"])).set("max", repr(1e5 * (1 + 1e-14)))  # the same number to 1e-12
    root.find("ModelVariables").remove(svs["closure_thermal"])
    new = ET.SubElement(root.find("ModelVariables"), "ScalarVariable", name="extra", valueReference="3",
                        causality="output", variability="continuous")
    ET.SubElement(new, "Real")
    found = differences("x", old, ET.tostring(root))
    assert sorted(f.split(":", 1)[1].split(" was")[0].strip() for f in found) == sorted(
        ["closure0.valueReference", "Omega.unit", "c_thermal.max", "closure_thermal is gone",
         "new variable extra has value reference 3, not after the old ones (<= 9)"]), found
