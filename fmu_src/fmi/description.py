"""The model description of any model, FMI 2.0 or FMI 3.0 co-simulation, from its one list of variables; and the
reading of a built FMU's description back into the same record.

What differs between the two versions is here and only here: the root's token attribute (``guid`` /
``instantiationToken``), the co-simulation capability flags, the enumeration types (``SimpleType`` /
``EnumerationType``), the variables (``ScalarVariable`` with a type child / one element per type, arrays with
their ``Dimension``) and the model structure (outputs by index / by value reference, event indicators).

Numbers are written with Python's ``repr`` (the shortest text that reads back as the same double); a bound that
is a product of parameters is rounded where it is declared (fmu_src/fmi/variables.py ``tidy``), not here.
"""

from __future__ import annotations

import io
import zipfile
from dataclasses import dataclass, field
from datetime import datetime, timezone
from pathlib import Path
from xml.etree.ElementTree import Element, SubElement, fromstring, tostring

from .variables import Var, by_name, declared, scalars

LOG_CATEGORIES = ("logStatusWarning", "logStatusDiscard", "logStatusError", "logStatusFatal", "logAll")


@dataclass(frozen=True)
class ModelInfo:
    """What a model description says about a model besides its variables."""

    identifier: str
    description: str
    units: dict[str, tuple[dict[str, int], dict[str, float]]]  # unit -> (SI exponents, {display unit: factor})
    default_experiment: dict[str, float]
    enumerations: dict[str, tuple[tuple[str, str], ...]] = field(default_factory=dict)  # type -> ((item, text),)
    name: str | None = None  # modelName (default: the identifier)
    author: str = "rotorub developers"
    # the initial outputs depend on the parameters alone, not on the inputs (the spool's initial speed is its
    # Omega0 whatever torque it is given): declared, so that a master that propagates initial values (OMSimulator)
    # sees no algebraic loop at initialisation; otherwise an initial output declares no dependencies
    initial_from_parameters: bool = False
    # FMI 3.0: fmi3DoStep may end early (at an event of the model)
    might_return_early: bool = False


def fmt(v: float | int) -> str:
    """A number as the model description writes it: the shortest text that reads back as the same value."""
    return repr(float(v)) if isinstance(v, float) else str(v)


def model_description(model: ModelInfo, variables: list[Var], *, fmi: str, token: str, generation_tool: str,
                      version: str, flavour: str = "native", feedthrough: bool = False,
                      source_files: list[str] | None = None) -> Element:
    """The co-simulation model description (an ElementTree element) of ``variables`` (a numbered list, every build's
    variables) for FMI ``fmi`` ("2.0" or "3.0") and ``flavour`` ("native": no tool needed on the host;
    "pythonfmu": needs the host's Python).

    ``feedthrough``: the outputs depend directly on the inputs (a quasi-static build: its outputs are the algebraic
    solution at the current inputs) but those declared ``feedthrough=False``; otherwise they depend on no input
    (outputs follow the state: no algebraic loop with a connected FMU).
    """
    if fmi not in ("2.0", "3.0"):
        raise ValueError(f"fmi: '{fmi}' unknown; accepted: 2.0, 3.0")
    three = fmi == "3.0"
    tags = {"fmi3" if three else "fmi2", flavour}
    own = declared(variables, tags)
    vars_ = own if three else scalars(own)
    if three:
        # structural parameters first: fmusim 0.0.39 (the reference importer) resolves an array's <Dimension
        # valueReference> while it reads, and crashed on a dimension declared after the arrays using it. FMI 3.0
        # does not forbid the order; every Reference-FMU declares them first. Value references do not change.
        vars_ = ([v for v in vars_ if v.causality == "structuralParameter"]
                 + [v for v in vars_ if v.causality != "structuralParameter"])
    if three and [v.causality for v in own].count("independent") != 1:
        raise ValueError(f"{model.identifier}: an FMI 3.0 description declares exactly one independent variable "
                         "(fmu_src.fmi.variables.TIME in the model's list)")
    root = Element("fmiModelDescription", {
        "fmiVersion": fmi, "modelName": model.name or model.identifier,
        ("instantiationToken" if three else "guid"): token,
        "description": model.description, "author": model.author, "version": version, "license": "MIT",
        "copyright": model.author, "generationTool": generation_tool,
        "generationDateAndTime": datetime.now(timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ"),
        "variableNamingConvention": "structured", **({} if three else {"numberOfEventIndicators": "0"})})
    _capabilities(root, model, three, flavour, source_files)
    _units(root, model, vars_)
    _types(root, model, three)
    logs = SubElement(root, "LogCategories")
    for cat in LOG_CATEGORIES:
        what = "all messages" if cat == "logAll" else f"messages with fmi{fmi[0]}{cat[9:]} status"
        SubElement(logs, "Category", name=cat, description=f"Log {what}.")
    SubElement(root, "DefaultExperiment", {k: fmt(float(v)) for k, v in model.default_experiment.items()})
    mv = SubElement(root, "ModelVariables")
    for v in vars_:
        (_variable3 if three else _variable2)(mv, v, by_name(own))
    (_structure3 if three else _structure2)(root, model, vars_, feedthrough)
    return root


def _capabilities(root: Element, model: ModelInfo, three: bool, flavour: str, source_files) -> None:
    common = {"modelIdentifier": model.identifier,
              "needsExecutionTool": "true" if flavour == "pythonfmu" else "false",
              "canBeInstantiatedOnlyOncePerProcess": "false"}
    if three:
        SubElement(root, "CoSimulation", {
            **common, "canGetAndSetFMUState": "true", "canSerializeFMUState": "true",
            "providesDirectionalDerivatives": "false", "providesAdjointDerivatives": "false",
            "providesPerElementDependencies": "false", "canHandleVariableCommunicationStepSize": "true",
            "maxOutputDerivativeOrder": "0", "providesIntermediateUpdate": "false",
            "mightReturnEarlyFromDoStep": str(model.might_return_early).lower(),
            "canReturnEarlyAfterIntermediateUpdate": "false", "hasEventMode": "false",
            "providesEvaluateDiscreteStates": "false"})
        return
    cs = SubElement(root, "CoSimulation", {
        "modelIdentifier": model.identifier, "needsExecutionTool": common["needsExecutionTool"],
        "canHandleVariableCommunicationStepSize": "true", "canInterpolateInputs": "false",
        "maxOutputDerivativeOrder": "0", "canRunAsynchronuously": "false",
        "canBeInstantiatedOnlyOncePerProcess": "false", "canNotUseMemoryManagementFunctions": "true",
        "canGetAndSetFMUstate": "true", "canSerializeFMUstate": "true", "providesDirectionalDerivative": "false"})
    if source_files:
        sf = SubElement(cs, "SourceFiles")
        for f in source_files:
            SubElement(sf, "File", name=f)


def _units(root: Element, model: ModelInfo, vars_: list[Var]) -> None:
    used = {v.unit for v in vars_ if v.unit}
    unknown = sorted(used - set(model.units))
    if unknown:
        raise ValueError(f"unit(s) {', '.join(unknown)} used but not defined in the model's UNITS")
    defs = SubElement(root, "UnitDefinitions")
    for name, (base, displays) in model.units.items():
        if name not in used:
            continue
        u = SubElement(defs, "Unit", name=name)
        SubElement(u, "BaseUnit", {k: str(e) for k, e in base.items()})
        for dname, factor in displays.items():
            SubElement(u, "DisplayUnit", name=dname, factor=repr(factor))


def _types(root: Element, model: ModelInfo, three: bool) -> None:
    if not model.enumerations:
        return
    types = SubElement(root, "TypeDefinitions")
    for tname, items in model.enumerations.items():
        if three:
            en = SubElement(types, "EnumerationType", name=tname)
        else:
            en = SubElement(SubElement(types, "SimpleType", name=tname), "Enumeration")
        for k, (item, desc) in enumerate(items, start=1):
            SubElement(en, "Item", name=item, value=str(k), description=desc)


def _initial(v: Var) -> str | None:
    if v.causality in ("output", "local"):
        return "calculated"
    if v.causality in ("parameter", "structuralParameter"):
        return "exact"
    return None


def _has_start(v: Var) -> bool:
    return v.start is not None and v.causality not in ("output", "local", "independent")


def _variable2(mv: Element, v: Var, _own: dict[str, Var]) -> None:
    attrs = {"name": v.name, "valueReference": str(v.vr), "description": v.description, "causality": v.causality,
             "variability": v.variability}
    if _initial(v):
        attrs["initial"] = _initial(v)
    t = SubElement(SubElement(mv, "ScalarVariable", attrs), v.type)
    for key, val in (("declaredType", v.declared_type), ("unit", v.unit), ("displayUnit", v.display_unit)):
        if val:
            t.set(key, val)
    for key in ("min", "max", "nominal"):
        if getattr(v, key) is not None:
            t.set(key, fmt(getattr(v, key)))
    if _has_start(v):
        t.set("start", v.start if isinstance(v.start, str) else fmt(v.start))


def _variable3(mv: Element, v: Var, own: dict[str, Var]) -> None:
    attrs = {"name": v.name, "valueReference": str(v.vr), "description": v.description, "causality": v.causality,
             "variability": v.variability}
    if _initial(v):
        attrs["initial"] = _initial(v)
    for key, val in (("declaredType", v.declared_type), ("unit", v.unit), ("displayUnit", v.display_unit)):
        if val:
            attrs[key] = val
    for key in ("min", "max", "nominal"):
        if getattr(v, key) is not None:
            attrs[key] = fmt(getattr(v, key))
    if _has_start(v) and v.type != "String":
        attrs["start"] = fmt(v.start)
    el = SubElement(mv, v.type3, attrs)
    if _has_start(v) and v.type == "String":
        SubElement(el, "Start", value=str(v.start))
    if v.is_array:
        if v.dimension:
            SubElement(el, "Dimension", valueReference=str(own[v.dimension].vr))
        else:
            SubElement(el, "Dimension", start=str(v.size))


def _inputs(vars_: list[Var], feedthrough: bool) -> list[Var]:
    return [v for v in vars_ if v.causality == "input" and v.feedthrough] if feedthrough else []


def _structure2(root: Element, model: ModelInfo, vars_: list[Var], feedthrough: bool) -> None:
    ms = SubElement(root, "ModelStructure")
    index = {v.name: str(i + 1) for i, v in enumerate(vars_)}  # FMI 2.0 refers to a variable by its position
    deps = [index[v.name] for v in _inputs(vars_, feedthrough)]
    outs = SubElement(ms, "Outputs")
    for v in vars_:
        if v.causality == "output":
            attrs = {"index": index[v.name], "dependencies": " ".join(deps)}
            if feedthrough:
                attrs["dependenciesKind"] = " ".join("dependent" for _ in deps)
            SubElement(outs, "Unknown", attrs)
    init = SubElement(ms, "InitialUnknowns")
    params = " ".join(index[v.name] for v in vars_ if v.causality == "parameter")
    for v in vars_:
        if v.causality == "output":
            attrs = {"index": index[v.name]}
            if model.initial_from_parameters:
                attrs["dependencies"] = params
            SubElement(init, "Unknown", attrs)


def _structure3(root: Element, model: ModelInfo, vars_: list[Var], feedthrough: bool) -> None:
    ms = SubElement(root, "ModelStructure")
    deps = [str(v.vr) for v in _inputs(vars_, feedthrough)]
    if not deps:
        # an output that depends on no input says so with the independent variable, not with dependencies="":
        # legal, but OMSimulator's FMI 3.0 reader (fmi4c) crashes on the empty attribute; and leaving the attribute
        # out would mean "depends on every input" (a false algebraic loop). At a communication point the outputs
        # follow the state, i.e. time: true, and no input.
        deps = [str(v.vr) for v in vars_ if v.causality == "independent"]
    for v in vars_:
        if v.causality == "output":
            attrs = {"valueReference": str(v.vr), "dependencies": " ".join(deps),
                     "dependenciesKind": " ".join("dependent" for _ in deps)}
            SubElement(ms, "Output", attrs)
    params = " ".join(str(v.vr) for v in vars_ if v.causality == "parameter")
    for v in vars_:
        if v.causality == "output":
            attrs = {"valueReference": str(v.vr)}
            if model.initial_from_parameters and params:
                attrs["dependencies"] = params
            SubElement(ms, "InitialUnknown", attrs)
    for v in vars_:
        if v.event_indicator:
            SubElement(ms, "EventIndicator", valueReference=str(v.vr))


def xml_bytes(root: Element) -> bytes:
    from xml.dom import minidom

    return minidom.parseString(tostring(root, encoding="utf-8")).toprettyxml(indent="  ", encoding="UTF-8")


# ---------------------------------------------------------------------------------------------- reading one back
def description_xml(source) -> bytes:
    """modelDescription.xml of an FMU file, FMU bytes or extracted folder."""
    if isinstance(source, bytes | bytearray):
        with zipfile.ZipFile(io.BytesIO(source)) as z:
            return z.read("modelDescription.xml")
    p = Path(source)
    if p.is_dir():
        return (p / "modelDescription.xml").read_bytes()
    with zipfile.ZipFile(p) as z:
        return z.read("modelDescription.xml")


def _number(text: str | None, typ: str) -> float | int | str | None:
    if text is None:
        return None
    if typ in ("Real", "Float64", "Float32"):
        return float(text)
    if typ == "String":
        return text
    return int(text)


def read_description(source) -> tuple[dict[str, Var], dict[str, dict[str, float]], Element]:
    """(variables by name, unit name -> base-unit exponents, root) of an FMU's description (FMI 2.0 or 3.0), the
    variables as :class:`Var` (an FMI 3.0 array as one Var of its declared size, when that size is a start)."""
    root = fromstring(description_xml(source))
    out: dict[str, Var] = {}
    fmi3 = root.get("fmiVersion", "").startswith("3")
    from_3 = {v: k for k, v in {"Real": "Float64", "Integer": "Int32", "Boolean": "Boolean"}.items()}
    elements = ([(el, el, el.tag) for el in root.find("ModelVariables")] if fmi3 else
                [(sv, next(iter(sv)), next(iter(sv)).tag) for sv in root.iter("ScalarVariable")])
    for sv, typ_el, tag in elements:
        typ = from_3.get(tag, tag) if fmi3 else tag
        start = typ_el.get("start")
        if start is None and typ_el.find("Start") is not None:
            start = typ_el.find("Start").get("value")
        dim = typ_el.find("Dimension") if fmi3 else None
        size = int(dim.get("start")) if dim is not None and dim.get("start") else 1
        out[sv.get("name")] = Var(
            sv.get("name"), typ, sv.get("causality", "local"), sv.get("variability", "continuous"),
            sv.get("description", ""), unit=typ_el.get("unit"), display_unit=typ_el.get("displayUnit"),
            start=_number(start, typ), min=_number(typ_el.get("min"), typ), max=_number(typ_el.get("max"), typ),
            nominal=_number(typ_el.get("nominal"), typ), declared_type=typ_el.get("declaredType"),
            size=size, vr=int(sv.get("valueReference")))
    units = {}
    for u in root.iter("Unit"):
        bu = u.find("BaseUnit")
        units[u.get("name")] = {} if bu is None else {k: float(v) for k, v in bu.attrib.items()}
    return out, units, root


def enumerations(root: Element) -> dict[str, list[tuple[str, int]]]:
    """The Enumeration types of a model description (FMI 2.0 or 3.0): name -> [(item name, value), ...]."""
    out = {}
    for st in root.iter("SimpleType"):
        en = st.find("Enumeration")
        if en is not None:
            out[st.get("name")] = [(it.get("name"), int(it.get("value"))) for it in en.findall("Item")]
    for en in root.iter("EnumerationType"):
        out[en.get("name")] = [(it.get("name"), int(it.get("value"))) for it in en.findall("Item")]
    return out
