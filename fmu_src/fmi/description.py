"""Build the native FMI 3.0 co-simulation FMU: the FMI 2.0 native FMU's model and kernel behind an FMI 3.0 wrapper.

    rotorub build-fmu --native --fmi3 [--params my.toml] [--out fmus/native-fmi3] [--platforms ...]

One model, two thin wrappers: ``contact_model.c`` (the physics) and ``model_data.c`` (the generated variable
table MODEL_INFO and the model's matrices) are the FMI 2.0 FMU's, byte for byte the same generator; this FMU
adds ``fmi3_cs.c`` and a second generated table, FMI3_INFO (fmi3_vars.h), which groups the FMI 2.0 value slots
into FMI 3.0 variables:

* the per-blade outputs are arrays ``blade.F_N``, ``blade.F_T``, ``blade.gap_LE``, ``blade.gap_TE``,
  ``blade.gap_tip``, ``blade.contact_fraction`` of ``n_blades`` elements (a structural parameter, fixed by the
  build), ``wear.harmonic`` an array of 8;
* every other variable keeps its FMI 2.0 name and value reference; an array takes the value reference of its
  first element (``blade.F_N`` is 13, as ``blade[1].F_N`` is in FMI 2.0); ``time``, ``n_blades`` and the event
  indicator ``penetration_margin`` come after the FMI 2.0 numbering;
* Real -> Float64, Integer -> Int32, Enumeration and String as they are, with the same units, display units,
  ranges, nominal and start values (fmu_src/interface.py);
* event indicators: ``gap_min`` (first contact: crosses 0 downwards) and ``penetration_margin`` = gap_min +
  max_penetration (divergence: crosses 0 downwards).

The binaries are built for the same platforms and glibc 2.17 baseline as the FMI 2.0 FMU (native_compile.py),
in the FMI 3.0 folders (x86_64-linux, aarch64-linux, x86_64-windows, x86_64-darwin, aarch64-darwin); ``sources/``
has the FMI 3.0 ``buildDescription.xml`` and a CMakeLists.txt.
"""

from __future__ import annotations

import html
import json
import re
from dataclasses import dataclass, field
from datetime import datetime, timezone
from pathlib import Path
from xml.etree.ElementTree import Element, SubElement

from .. import interface
from .native_fmu import (
    FMI3_HEADERS,
    HERE,
    NATIVE,
    WRAPPER3,
    NativeBuildError,
    _c_string,
    contact_model_data,
    documentation_html,
    package_native_fmu,
    variable_table,
)

C_SOURCES3 = ("fmi3_cs.c", "fmu_core.c", "contact_model.c", "model_data.c", "rotorub_kernel.c")
TYPE3 = {"Real": "Float64", "Integer": "Int32", "Enumeration": "Enumeration", "String": "String"}
BLADE_ARRAY = re.compile(r"^blade\[(\d+)\]\.(\w+)$")
HARMONIC = re.compile(r"^wear\.harmonic\[(\d+)\]$")
ARRAY_TEXT = {
    "F_N": "Normal contact force on each blade",
    "F_T": "Tangential (friction) force on each blade: mu*F_N against its sliding over the casing (positive: "
           "against the spin)",
    "gap_LE": "Gap at the leading edge of each blade (2D: the tip gap); negative = penetration",
    "gap_TE": "Gap at the trailing edge of each blade (2D: the tip gap); negative = penetration",
    "gap_tip": "Smallest gap of each blade (2D: the tip gap; 3D: the smaller of LE and TE, the gap being linear "
               "along the chord)",
    "contact_fraction": "Fraction of the chord of each blade in contact (2D: 0 or 1)",
}


@dataclass(frozen=True)
class Var3:
    """One FMI 3.0 variable: a run of FMI 2.0 slots (``slots``), the time, the structural parameter or a sum."""

    name: str
    type: str  # Float64, Int32, UInt64, Enumeration, String
    causality: str
    variability: str
    description: str
    vr: int
    kind: str = "slots"  # slots, time, structural, sum
    slots: tuple[int, ...] = ()
    unit: str | None = None
    display_unit: str | None = None
    start: float | int | str | None = None
    min: float | None = None
    max: float | None = None
    nominal: float | None = None
    declared_type: str | None = None
    dimension: tuple[str, int] | None = None  # ("vr", n_blades' value reference) or ("start", 8)
    elements: tuple[str, ...] = field(default=(), compare=False)  # FMI 2.0 names of the elements

    @property
    def size(self) -> int:
        return len(self.slots) if self.kind == "slots" else 1


def variables3(d: interface.Defaults, mode: str = "transient") -> list[Var3]:
    """The FMI 3.0 variables in value-reference order, from the FMI 2.0 native list."""
    v2 = interface.variables(d, mode, flavour="native")
    n_slots = max(v.vr for v in v2) + 1
    vr_time, vr_nb, vr_margin = n_slots, n_slots + 1, n_slots + 2
    out: list[Var3] = [
        Var3("time", "Float64", "independent", "continuous", "Simulation time", vr_time, kind="time", unit="s"),
        Var3("n_blades", "UInt64", "structuralParameter", "fixed",
             "Number of blades: the size of the per-blade arrays, fixed by the parameter file the FMU was built with "
             "(another blade count: rebuild with --params)", vr_nb, kind="structural", start=d.n_blades,
             min=d.n_blades, max=d.n_blades)]
    groups: dict[str, list[interface.Var]] = {}
    for v in v2:
        m = BLADE_ARRAY.match(v.name)
        h = HARMONIC.match(v.name)
        key = f"blade.{m.group(2)}" if m else "wear.harmonic" if h else None
        if key is None:
            out.append(Var3(v.name, TYPE3[v.type], v.causality, v.variability, v.description, v.vr,
                            slots=(v.vr,), unit=v.unit, display_unit=v.display_unit, start=v.start, min=v.min,
                            max=v.max, nominal=v.nominal, declared_type=v.declared_type, elements=(v.name,)))
            continue
        if key not in groups:
            groups[key] = []
            out.append(Var3(key, "", "", "", "", -1))  # placeholder: filled below, in its first element's place
        groups[key].append(v)
    for k, placeholder in enumerate(out):
        if placeholder.vr != -1:
            continue
        elems = groups[placeholder.name]
        first = elems[0]
        if placeholder.name == "wear.harmonic":
            text, dim = ("Amplitudes of the worn profile's harmonics 1 to 8 (element h: h lobes): the worn profile "
                         "as a fixed, small set of outputs whatever n_sectors"), ("start", len(elems))
        else:
            text, dim = ARRAY_TEXT[placeholder.name.split(".", 1)[1]] + " (element j: blade j)", ("vr", vr_nb)
        if len(elems) != (d.n_blades if dim[0] == "vr" else interface.WEAR_HARMONICS):
            raise NativeBuildError(f"{placeholder.name}: {len(elems)} elements in the FMI 2.0 interface")
        out[k] = Var3(placeholder.name, TYPE3[first.type], first.causality, first.variability, text, first.vr,
                      slots=tuple(e.vr for e in elems), unit=first.unit, display_unit=first.display_unit,
                      dimension=dim, elements=tuple(e.name for e in elems))
    vr2 = {v.name: v.vr for v in v2}
    out.append(Var3("penetration_margin", "Float64", "local", "continuous",
                    "gap_min + max_penetration: how far the deepest blade is from the divergence depth (the event "
                    "indicator of a divergence: it crosses 0 downwards when the run diverges)", vr_margin, kind="sum",
                    slots=(vr2["gap_min"], vr2["max_penetration"]), unit="m", display_unit="mm"))
    return out


def _fmt(v: float | int) -> str:
    return repr(float(v)) if isinstance(v, float) else str(v)


def model_description3(vars3: list[Var3], *, token: str, generation_tool: str, version: str,
                       feedthrough: bool) -> Element:
    """The FMI 3.0 co-simulation model description of the contact FMU (an ElementTree element)."""
    root = Element("fmiModelDescription", {
        "fmiVersion": "3.0", "modelName": interface.MODEL_NAME, "instantiationToken": token,
        "description": interface.DESCRIPTION, "author": "rotorub developers", "version": version, "license": "MIT",
        "copyright": "rotorub developers", "generationTool": generation_tool,
        "generationDateAndTime": datetime.now(timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ"),
        "variableNamingConvention": "structured"})
    SubElement(root, "CoSimulation", {
        "modelIdentifier": interface.MODEL_IDENTIFIER, "needsExecutionTool": "false",
        "canBeInstantiatedOnlyOncePerProcess": "false", "canGetAndSetFMUState": "true",
        "canSerializeFMUState": "true", "providesDirectionalDerivatives": "false",
        "providesAdjointDerivatives": "false", "providesPerElementDependencies": "false",
        "canHandleVariableCommunicationStepSize": "true", "maxOutputDerivativeOrder": "0",
        "providesIntermediateUpdate": "false", "mightReturnEarlyFromDoStep": "true",
        "canReturnEarlyAfterIntermediateUpdate": "false", "hasEventMode": "false",
        "providesEvaluateDiscreteStates": "false"})
    used = {v.unit for v in vars3 if v.unit}
    units = SubElement(root, "UnitDefinitions")
    for name, (base, displays) in interface.UNITS.items():
        if name not in used:
            continue
        u = SubElement(units, "Unit", name=name)
        SubElement(u, "BaseUnit", {k: str(e) for k, e in base.items()})
        for dname, factor in displays.items():
            SubElement(u, "DisplayUnit", name=dname, factor=repr(factor))
    types = SubElement(root, "TypeDefinitions")
    for tname, items in interface.ENUMERATIONS.items():
        et = SubElement(types, "EnumerationType", name=tname)
        for k, (item, desc) in enumerate(items, start=1):
            SubElement(et, "Item", name=item, value=str(k), description=desc)
    logs = SubElement(root, "LogCategories")
    for cat, desc in (("logStatusWarning", "Log messages with fmi3Warning status."),
                      ("logStatusDiscard", "Log messages with fmi3Discard status."),
                      ("logStatusError", "Log messages with fmi3Error status."),
                      ("logStatusFatal", "Log messages with fmi3Fatal status."),
                      ("logAll", "Log all messages.")):
        SubElement(logs, "Category", name=cat, description=desc)
    SubElement(root, "DefaultExperiment", {k: _fmt(float(v)) for k, v in interface.DEFAULT_EXPERIMENT.items()})
    mv = SubElement(root, "ModelVariables")
    for v in vars3:
        attrs = {"name": v.name, "valueReference": str(v.vr), "description": v.description,
                 "causality": v.causality, "variability": v.variability}
        if v.causality in ("output", "local"):
            attrs["initial"] = "calculated"
        elif v.causality in ("parameter", "structuralParameter"):
            attrs["initial"] = "exact"
        for key, val in (("declaredType", v.declared_type), ("unit", v.unit), ("displayUnit", v.display_unit)):
            if val:
                attrs[key] = val
        for key in ("min", "max", "nominal"):
            val = getattr(v, key)
            if val is not None:
                attrs[key] = _fmt(val)
        has_start = v.start is not None and v.causality not in ("output", "local", "independent")
        if has_start and v.type != "String":
            attrs["start"] = _fmt(v.start)
        el = SubElement(mv, v.type, attrs)
        if has_start and v.type == "String":
            SubElement(el, "Start", value=str(v.start))
        if v.dimension:
            key, val = v.dimension
            SubElement(el, "Dimension", {"valueReference" if key == "vr" else "start": str(val)})
    ms = SubElement(root, "ModelStructure")
    # the quasi_static solution depends on the inputs but the casing's offset (a transient-mode input: a balanced
    # solution of the rotating frame cannot hold a casing offset fixed in the other frame)
    inputs = [str(v.vr) for v in vars3 if v.causality == "input" and not v.name.startswith("casing_offset")]
    for v in vars3:
        if v.causality == "output":
            attrs = {"valueReference": str(v.vr), "dependencies": " ".join(inputs) if feedthrough else ""}
            if feedthrough:
                attrs["dependenciesKind"] = " ".join("dependent" for _ in inputs)
            SubElement(ms, "Output", attrs)
    for v in vars3:
        if v.causality == "output":
            SubElement(ms, "InitialUnknown", valueReference=str(v.vr))
    by_name = {v.name: v for v in vars3}
    for name in ("gap_min", "penetration_margin"):
        SubElement(ms, "EventIndicator", valueReference=str(by_name[name].vr))
    return root


def build_description(c_files: tuple[str, ...]) -> str:
    """sources/buildDescription.xml: the FMI 3.0 build description (what fmpy's build_platform_binary reads)."""
    files = "\n".join(f'      <SourceFile name="{f}"/>' for f in c_files)
    return f"""<?xml version="1.0" encoding="UTF-8"?>
<fmiBuildDescription fmiVersion="3.0">
  <BuildConfiguration modelIdentifier="{interface.MODEL_IDENTIFIER}" description="the native FMU: no libm needed on
    x86_64 and aarch64 (rr_math.h); build without FMA contraction or fast-math to get the shipped numbers">
    <SourceFileSet language="C99" compilerOptions="-ffp-contract=off -fno-fast-math">
{files}
      <PreprocessorDefinition name="RR_API" value=""/>
    </SourceFileSet>
  </BuildConfiguration>
</fmiBuildDescription>
"""


def fmi3_table(vars3: list[Var3]) -> str:
    """The C table FMI3_INFO (fmi3_vars.h): each FMI 3.0 variable as its slots, and the value-reference index."""
    ctype = {"Float64": "V3_FLOAT64", "Int32": "V3_INT32", "UInt64": "V3_UINT64", "Enumeration": "V3_ENUM",
             "String": "V3_STRING"}
    kind = {"slots": "K3_SLOTS", "time": "K3_TIME", "structural": "K3_STRUCTURAL", "sum": "K3_SUM"}
    lines, rows = ["#include \"fmi3_vars.h\"", ""], []
    for k, v in enumerate(vars3):
        slots = "0"
        if v.slots:
            lines.append(f"static const int SLOTS_{k}[{len(v.slots)}] = {{{', '.join(map(str, v.slots))}}};")
            slots = f"SLOTS_{k}"
        fixed = int(v.start) if v.kind == "structural" else 0
        rows.append(f"    {{{v.vr}u, {_c_string(v.name)}, {ctype[v.type]}, {kind[v.kind]}, {v.size}, {slots}, "
                    f"{fixed}ull}}")
    max_vr = max(v.vr for v in vars3)
    by_vr = [-1] * (max_vr + 1)
    for k, v in enumerate(vars3):
        if by_vr[v.vr] != -1:
            raise NativeBuildError(f"FMI 3.0 value reference {v.vr} given twice ({v.name})")
        by_vr[v.vr] = k
    lines += [f"static const fmi3_var VARS3[{len(rows)}] = {{", ",\n".join(rows), "};",
              f"static const int BY_VR[{len(by_vr)}] = {{{', '.join(map(str, by_vr))}}};",
              f"const fmi3_info FMI3_INFO = {{{len(rows)}, VARS3, {max_vr}u, BY_VR}};", ""]
    return "\n".join(lines)


def build_native_fmu3(dest: str | Path = "fmus/native-fmi3", params_file: str | Path | None = None,
                      platforms: tuple[str, ...] | None = None, mode: str = "transient") -> dict:
    """Build ``dest/RotorCasingContact.fmu`` (FMI 3.0, native); returns a summary dict (as build_native_fmu)."""
    from rotorub_model import __version__ as lib_version
    from rotorub_model import kernel
    from rotorub_model.structure.model import build_model
    from rotorub_model.structure.params import REFERENCE_FILE, load_parameters

    if mode not in ("transient", "quasi_static"):
        raise NativeBuildError(f"mode: '{mode}' unknown; accepted: transient, quasi_static")
    params_path = Path(params_file) if params_file else REFERENCE_FILE
    params = load_parameters(params_path)
    model = build_model(params)
    defaults = interface.Defaults.from_parameters(params)
    variables = interface.variables(defaults, mode, flavour="native")
    vars3 = variables3(defaults, mode)
    feedthrough = mode == "quasi_static"
    data = contact_model_data(model, variables)
    table3 = fmi3_table(vars3)
    model_c = [NATIVE / n for n in ("contact_model.c", "contact_model.h")]
    token = interface.guid_of("fmi3", json.dumps([v.__dict__ for v in vars3], sort_keys=True, default=str), data,
                              *(p.read_bytes() for p in (*model_c, *(NATIVE / n for n in WRAPPER3), *kernel.SOURCES,
                                                         *kernel.HEADERS)), mode)
    md = model_description3(vars3, token=token, generation_tool=f"rotorub {lib_version} (native C, FMI 3.0)",
                            version=lib_version, feedthrough=feedthrough)
    out_file = Path(dest) / f"{interface.MODEL_IDENTIFIER}.fmu"
    sources: dict[str, Path | str] = {p.name: p for p in (*model_c, *kernel.SOURCES, *kernel.HEADERS)}
    sources["model_data.c"] = ("/* model_data.c: generated by fmu_src/build/native_fmu3.py from the parameter file; "
                               "do not edit. */\n#include \"contact_model.h\"\n\n"
                               + variable_table(variables, token, interface.MODEL_IDENTIFIER, feedthrough) + data
                               + "\n" + table3)
    sources["buildDescription.xml"] = build_description(C_SOURCES3)
    facts = (f"FMI 3.0. Model built in from <code>{html.escape(params_path.name)}</code>; default mode: {mode}; "
             f"{defaults.n_blades} blades (n_blades). Manual: <code>documentation/FMU.md</code>, section FMI 3.0.")
    doc = documentation_html(interface.MODEL_IDENTIFIER, interface.DESCRIPTION, vars3, facts)  # type: ignore[arg-type]
    doc = doc.replace("FMI 2.0 co-simulation, native C", "FMI 3.0 co-simulation, native C")
    built = package_native_fmu(
        out_file, identifier=interface.MODEL_IDENTIFIER, variables=variables, guid=token, model_sources=sources,
        c_files=C_SOURCES3, description_xml=interface.xml_bytes(md), platforms=platforms, fmi="3.0",
        documentation={"index.html": doc, "FMU.md": HERE / "FMU.md"})
    return {"fmu": str(out_file), "flavour": "native", "fmi": "3.0", "instantiation_token": token, "platforms": built,
            "mode": mode, "variables": len(vars3), "parameters": str(params_path),
            "size_bytes": out_file.stat().st_size}


__all__ = ["C_SOURCES3", "FMI3_HEADERS", "Var3", "build_description", "build_native_fmu3", "fmi3_table",
           "model_description3", "variables3"]
