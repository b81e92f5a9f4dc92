"""The FMI layer's one variable record (fmu_src/fmi/variables.py) and what is generated from a model's list: value
references, the FMI 2.0 and 3.0 views, the C header and tables, the model descriptions. And the promise it makes:
adding a variable to a model is one entry in its variables.py, every build follows and no old value reference moves.
"""

from __future__ import annotations

import zipfile

import pytest

from fmu_src.fmi.csource import variables_header
from fmu_src.fmi.description import ModelInfo, model_description, read_description, xml_bytes
from fmu_src.fmi.variables import Var, by_name, c_name, declared, numbered, scalars, tidy
from fmu_src.models.contact import variables as cv


def _contact(**kw):
    from rotorub_model.structure.params import reference_parameters

    return cv.variables(cv.Defaults.from_parameters(reference_parameters()), **kw)


def test_numbering_arrays_interleaving_and_the_fmi2_view():
    v = numbered([Var("u", "Real", "input", "continuous", "u"),
                  Var("a.x", "Real", "output", "continuous", "x", size=3, element="a[{k}].x",
                      element_description="x {k}", interleave="a"),
                  Var("a.y", "Integer", "output", "discrete", "y", size=3, element="a[{k}].y",
                      element_description="y {k}", interleave="a"),
                  Var("h", "Real", "output", "discrete", "h", size=2, element="h[{k}]", element_description="h {k}"),
                  Var("t", "Real", "independent", "continuous", "time", only="fmi3"),
                  Var("z", "Real", "output", "continuous", "z")])
    named = by_name(v)
    assert [(n, named[n].vr, named[n].stride) for n in ("u", "a.x", "a.y", "h", "t", "z")] == [
        ("u", 0, 1), ("a.x", 1, 2), ("a.y", 2, 2), ("h", 7, 1), ("t", 9, 1), ("z", 10, 1)]
    two = scalars(declared(v, ("fmi2", "native")))
    assert [(s.name, s.vr) for s in two] == [("u", 0), ("a[1].x", 1), ("a[1].y", 2), ("a[2].x", 3), ("a[2].y", 4),
                                             ("a[3].x", 5), ("a[3].y", 6), ("h[1]", 7), ("h[2]", 8), ("z", 10)]
    assert [s.description for s in two if s.name.startswith("a[2]")] == ["x 2", "y 2"]
    assert [s.name for s in declared(v, ("fmi3", "native"))] == ["u", "a.x", "a.y", "h", "t", "z"]
    with pytest.raises(ValueError, match="declared twice"):
        numbered([Var("u", "Real", "input", "continuous", "u"), Var("u", "Real", "output", "continuous", "u")])
    with pytest.raises(ValueError, match="both ends"):
        numbered([Var("u", "Real", "input", "continuous", "u", min=0.0)])


def test_c_names_and_readable_bounds():
    assert c_name("casing_force.x") == "CASING_FORCE_X" and c_name("blade.F_N") == "BLADE_F_N"
    assert c_name("2D", suffix=True) == "2D"
    with pytest.raises(ValueError):
        c_name("2D")
    assert tidy(5.8476 * (0.4 + 0.5 * 0.6)) == 4.09332 and abs(tidy(5.8476 * 0.7) - 5.8476 * 0.7) <= 1e-12 * 4.1
    assert tidy(10 * 53.4) == 534.0


def test_the_contact_header_has_every_value_reference_the_model_reads():
    v = _contact()
    h = variables_header(v, cv.MODEL_IDENTIFIER, cv.ENUMERATIONS)
    for line in ("#define VR_OMEGA 0", "#define VR_G0 5", "#define VR_MAX_PENETRATION 11", "#define VR_BLADE_F_N 13",
                 "#define N_BLADE_F_N 10", "#define STRIDE_BLADE_F_N 6", "#define VR_CLEARANCE_EFFECTIVE 107",
                 "#define FORMULATION_3D 2", "#define MODE_QUASI_STATIC 2", "#define LINER_ABRADABLE 2"):
        assert line in h.splitlines() or line + " " in h, line
    assert "VR_PARAM_FILE" not in h and "VR_TIME" not in h  # not the native FMI 2.0 FMU's variables


def test_one_variable_list_gives_both_descriptions():
    """The FMI 2.0 and 3.0 descriptions of one list agree on every scalar, and an FMI 3.0 array is its FMI 2.0
    elements (read back with the reader systems use)."""
    v = _contact()
    d2 = xml_bytes(model_description(cv.MODEL, v, fmi="2.0", token="{x}", generation_tool="t", version="1"))
    d3 = xml_bytes(model_description(cv.MODEL, v, fmi="3.0", token="{x}", generation_tool="t", version="1"))
    two, _, _ = read_description(_zip(d2))
    three, _, root3 = read_description(_zip(d3))
    # value references 0 to 107 but the pythonfmu flavour's 4, then (after the FMI 3.0 FMU's own 108-110) the normal
    # law's three parameters and the casing's lobes 2-4 (111-119)
    assert len(two) == 116 and "param_file" not in two
    for name, w in three.items():
        if name in ("time", "n_blades", "penetration_margin"):
            continue
        if w.size > 1 or name.startswith("blade."):
            first = two[f"blade[1].{name.split('.', 1)[1]}"] if name.startswith("blade.") else two[f"{name}[1]"]
            assert first.vr == w.vr and first.unit == w.unit, name
            continue
        x = two[name]
        assert (x.vr, x.causality, x.unit, x.min, x.max, x.start, x.nominal) == \
               (w.vr, w.causality, w.unit, w.min, w.max, w.start, w.nominal), name
    assert [e.get("valueReference") for e in root3.iter("EventIndicator")] == [str(three["gap_min"].vr),
                                                                                 str(three["penetration_margin"].vr)]


def _zip(xml: bytes) -> bytes:
    import io

    b = io.BytesIO()
    with zipfile.ZipFile(b, "w") as z:
        z.writestr("modelDescription.xml", xml)
    return b.getvalue()


EXTRA = [  # FMU.md's example: a scalar parameter, a scalar input, a per-blade array output
    Var("example_law", "Enumeration", "parameter", "fixed", "An example law", start=1, min=1, max=2,
        declared_type="ExampleLaw"),
    Var("casing_distortion", "Real", "input", "continuous", "Ovalisation of the casing, held over each step",
        unit="m", display_unit="mm", start=0.0, min=-0.01, max=0.01, nominal=1e-4, feedthrough=False),
    Var("blade.F_wear", "Real", "output", "continuous", "Wear force on each blade (element j: blade j)", unit="N",
        size=10, element="blade[{k}].F_wear", element_description="Wear force on blade {k}", dimension="n_blades"),
]


def test_adding_a_variable_is_one_entry_and_every_build_follows(tmp_path, monkeypatch):
    """Three variables appended to the contact's list (nothing else changed): the native FMI 2.0 and 3.0 FMUs build
    and validate, declare them after every old variable (the old ones as the descriptions of before issue 24 had
    them), and variables.h has their value references."""
    pytest.importorskip("fmpy")
    from fmpy.validation import validate_fmu
    from test_model_descriptions import DATA, differences

    from fmu_src.models.contact import builder

    original = cv.variables

    def more(d, mode="transient"):
        return numbered([*(original(d, mode)), *EXTRA])

    monkeypatch.setattr(cv, "variables", more)
    monkeypatch.setattr(cv, "ENUMERATIONS", {**cv.ENUMERATIONS,
                                             "ExampleLaw": (("penalty", "linear"), ("power", "F = k g^p"))})
    monkeypatch.setattr(cv, "MODEL", ModelInfo(**{**cv.MODEL.__dict__, "enumerations": cv.ENUMERATIONS}))
    for fmi in ("2.0", "3.0"):
        fmu = builder.build_native_fmu(tmp_path / fmi, platforms=("linux64",), fmi=fmi)["fmu"]
        assert validate_fmu(fmu) == [], fmi
        with zipfile.ZipFile(fmu) as z:
            xml = z.read("modelDescription.xml")
            header = z.read("sources/variables.h").decode()
        name = f"contact_native_fmi{fmi[0]}_transient"
        assert differences(name, (DATA / f"{name}.xml").read_bytes(), xml) == []
        new, _, root = read_description(fmu)
        # after the last variable of the list (issue 27's casing_lobe4.phase, value reference 119)
        assert new["example_law"].vr == 120 and new["casing_distortion"].vr == 121
        assert ("blade.F_wear" if fmi == "3.0" else "blade[10].F_wear") in new
        assert "#define VR_EXAMPLE_LAW 120" in header and "#define VR_BLADE_F_WEAR 122" in header
        assert "#define EXAMPLELAW_POWER 2" in header
        if fmi == "3.0":
            assert new["blade.F_wear"].vr == 122
            dims = [d.get("valueReference") for d in root.iter("Float64") if d.get("name") == "blade.F_wear"
                    for d in d.iter("Dimension")]
            assert dims == [str(new["n_blades"].vr)]
        else:
            assert [new[f"blade[{k}].F_wear"].vr for k in (1, 10)] == [122, 131]
