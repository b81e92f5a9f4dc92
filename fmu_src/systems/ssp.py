"""The engine system as an SSP 1.0 package: writing it, validating it, and running it in OSP libcosim.

* :func:`write_ssp` writes ``SystemStructure.ssd`` naming the two FMUs
  (``resources/RotorCasingContact.fmu`` as component ``contact``, ``resources/LPSpool.fmu``
  as ``spool``), their connections (spool.Omega -> contact.Omega, contact.friction_torque ->
  spool.friction_torque), units, a default experiment, and one SSV parameter set per
  component (``resources/contact.ssv``, ``resources/spool.ssv``).
* :func:`validate_ssp` checks it against the SSP 1.0 XML schemas (vendored in
  fmu_src/systems/schemas/ssp1, BSD-2-Clause, see the README there) and checks that every
  connector, connection and parameter exists in the FMUs.
* :func:`run_ssp_libcosim` runs the package as written in libcosim
  (``CosimExecution.from_ssp_file``): a second, independent co-simulation engine.
* :func:`run_ssp_native` runs it in a process with no Python: fmu_src/masters/hosts/engine_host.c, a
  fixed-step C master, given the package's components, parameter sets, connections and step.

The system carries the annotation OpenModelica's OMSimulator reads to know how to run it (type
``org.openmodelica``: a fixed-step co-simulation master, ``oms:FixedStepMaster``); without it OMSimulator
3.0 aborts on load. libcosim ignores it; both read the standard parts.
"""

from __future__ import annotations

import io
import zipfile
from functools import cache
from pathlib import Path
from xml.etree import ElementTree as ET

import numpy as np

from ..fmi.description import enumerations, read_description
from ..fmi.variables import Var
from .system import CONNECTIONS, CONTACT_ID, G0_RUB, ME_REF, PARTS, SPOOL_ID, EngineError

SCHEMA_DIR = Path(__file__).resolve().parent / "schemas" / "ssp1"
NS = {
    "ssd": "http://ssp-standard.org/SSP1/SystemStructureDescription",
    "ssc": "http://ssp-standard.org/SSP1/SystemStructureCommon",
    "ssv": "http://ssp-standard.org/SSP1/SystemStructureParameterValues",
}
MASTER_NS = "urn:rotorub:ssp:master"  # our annotation (communication step and exchange order)
OMS_NS = "https://raw.githubusercontent.com/OpenModelica/OMSimulator/master/schema/oms.xsd"  # OMSimulator's
for _p, _u in NS.items():
    ET.register_namespace(_p, _u)
ET.register_namespace("rotorub", MASTER_NS)
ET.register_namespace("oms", OMS_NS)


def _q(prefix: str, tag: str) -> str:
    return f"{{{NS[prefix]}}}{tag}"


def _fmt(v: float) -> str:
    return repr(float(v))  # shortest round-tripping decimal: a valid xs:double


def _connector(parent: ET.Element, var: Var, kind: str) -> None:
    c = ET.SubElement(parent, _q("ssd", "Connector"), name=var.name, kind=kind)
    attrs = {"unit": var.unit} if (var.type == "Real" and var.unit) else {}
    if var.type == "Enumeration":
        attrs = {"name": var.declared_type}  # declared in the SSD's Enumerations
    ET.SubElement(c, _q("ssc", var.type if var.type in ("Real", "Integer", "Boolean", "String", "Enumeration")
                        else "Real"), attrs)


def _parameter_set(name: str, values: dict, variables: dict[str, Var], units: dict) -> bytes:
    root = ET.Element(_q("ssv", "ParameterSet"), version="1.0", name=name)
    params = ET.SubElement(root, _q("ssv", "Parameters"))
    used_units = []
    for pname, value in values.items():
        var = variables[pname]
        p = ET.SubElement(params, _q("ssv", "Parameter"), name=pname)
        if var.type == "String":
            ET.SubElement(p, _q("ssv", "String"), value=str(value))
        elif var.type == "Enumeration":  # by item name (SSP 1.0: mapped to the FMU's value by the importer)
            ET.SubElement(p, _q("ssv", "Enumeration"), value=str(value))
        elif var.type == "Integer":
            ET.SubElement(p, _q("ssv", "Integer"), value=str(int(value)))
        else:
            attrs = {"value": _fmt(value)}
            if var.unit:
                attrs["unit"] = var.unit
                if var.unit not in used_units:
                    used_units.append(var.unit)
            ET.SubElement(p, _q("ssv", "Real"), attrs)
    if used_units:
        _units(ET.SubElement(root, _q("ssv", "Units")), used_units, units)
    return _xml_bytes(root)


def _units(parent: ET.Element, names, units: dict) -> None:
    for name in names:
        u = ET.SubElement(parent, _q("ssc", "Unit"), name=name)
        exps = units.get(name, {})
        ET.SubElement(u, _q("ssc", "BaseUnit"), {k: (str(int(v)) if k not in ("factor", "offset") else _fmt(v))
                                                 for k, v in exps.items() if v != 0 or k == "factor"})


def _xml_bytes(root: ET.Element) -> bytes:
    ET.indent(root)
    return b'<?xml version="1.0" encoding="UTF-8"?>\n' + ET.tostring(root, encoding="utf-8") + b"\n"


def write_ssp(path: str | Path, contact_fmu: str | Path, spool_fmu: str | Path, *, g0: float = G0_RUB,
              imbalance: float = ME_REF, formulation: str = "3D", mode: str = "transient",
              spool_params: dict | None = None, contact_params: dict | None = None, t_end: float = 5.0,
              h: float = 1e-3, name: str = "RotorRubEngine", clearance_fmu: str | Path | None = None,
              clearance_params: dict | None = None, parts: dict[str, tuple] | None = None) -> Path:
    """Write the coupled system as an SSP 1.0 package; returns its path.

    The package holds ``SystemStructure.ssd``, ``resources/RotorCasingContact.fmu``,
    ``resources/LPSpool.fmu`` and the parameter sets ``resources/contact.ssv`` (g0,
    formulation, mode, the imbalance input's value, ``contact_params``) and
    ``resources/spool.ssv`` (the spool FMU's parameter start values updated by
    ``spool_params``). The communication step and the exchange order of
    :func:`run_coupled` are recorded in an annotation of the default experiment.

    With ``clearance_fmu`` (TipClearance.fmu, fmu_src/models/clearance/) a third component ``clearance``
    turns the spool's speed into the clearance closure the contact gets (spool.Omega -> clearance.Omega,
    clearance.closure -> contact.clearance_closure), with ``clearance_params`` in ``resources/clearance.ssv``;
    the contact then also shows its wear outputs and the clearance it keeps.

    Any part of :data:`~fmu_src.systems.system.PARTS` joins the same way: ``parts`` maps its name to ``(fmu,
    params)`` (``clearance_fmu, clearance_params`` are ``parts={"clearance": (clearance_fmu, clearance_params)}``).
    ``casing_load`` (CasingLoad.fmu, fmu_src/models/casing_load/) drives the contact's casing_lobe2 and
    casing_offset inputs. Each part is listed after the spool in PARTS' order, with its connections and
    ``resources/<name>.ssv`` (its parameters' start values updated by ``params``).
    """
    path = Path(path)
    chosen = dict(parts or {})
    if clearance_fmu is not None:
        if "clearance" in chosen:
            raise EngineError("write_ssp: the clearance part given twice (clearance_fmu and parts)")
        chosen["clearance"] = (clearance_fmu, clearance_params)
    unknown = [n for n in chosen if n not in PARTS]
    if unknown:
        raise EngineError(f"write_ssp: no part named '{unknown[0]}'; known: {', '.join(PARTS)}")
    chosen = {n: chosen[n] for n in PARTS if n in chosen}  # PARTS' order, whatever the caller's
    cvars, cunits, croot = read_description(contact_fmu)
    svars, sunits, _ = read_description(spool_fmu)
    all_units = {**sunits, **cunits}
    connections = list(CONNECTIONS)
    part_vars = {}
    for pname, (fmu, _params) in chosen.items():
        pvars, punits, _ = read_description(fmu)
        part_vars[pname] = pvars
        all_units = {**punits, **all_units}
        connections += PARTS[pname].connections
    for el, conn, ee, ec in connections:
        for comp, var in ((el, conn), (ee, ec)):
            vars_ = {"contact": cvars, "spool": svars, **part_vars}[comp]
            if var not in vars_:
                raise EngineError(f"write_ssp: the {comp} FMU has no variable '{var}'")
    spool_values = {k: float(v.start) for k, v in svars.items() if v.causality == "parameter"}
    for k, v in (spool_params or {}).items():
        if k not in spool_values:
            raise EngineError(f"write_ssp: spool parameter '{k}' unknown; known: {', '.join(spool_values)}")
        spool_values[k] = float(v)
    contact_values = {"g0": float(g0), "imbalance": float(imbalance)}
    # Enumeration parameters only when they differ from the FMU's defaults: libcosim's SSP parser (0.0.6)
    # stops at any Enumeration ("Don't know how to handle Enumeration type"), and the defaults need no value
    items = enumerations(croot)
    for pname, value in (("formulation", formulation), ("mode", mode)):
        var = cvars[pname]
        default = next((n for n, v in items.get(var.declared_type or "", []) if v == var.start), var.start)
        if str(value) != default:
            contact_values[pname] = str(value)
    for k, v in (contact_params or {}).items():
        if k not in cvars or cvars[k].causality not in ("parameter", "input"):
            raise EngineError(f"write_ssp: contact parameter '{k}' is not a parameter or input of the contact FMU")
        contact_values[k] = v

    root = ET.Element(_q("ssd", "SystemStructureDescription"), version="1.0", name=name,
                      description="Low-pressure spool of a turbofan coupled with the blade-tip/casing contact of its "
                                  "fan: the spool's speed drives the contact model, the contact's friction torque "
                                  "brakes the spool",
                      generationTool="rotorub fmu_src.systems.ssp")
    system = ET.SubElement(root, _q("ssd", "System"), name=name)
    elements = ET.SubElement(system, _q("ssd", "Elements"))
    comps = [
        ("contact", f"resources/{CONTACT_ID}.fmu", cvars, contact_values,
         [("Omega", "input"), ("imbalance", "input"), ("friction_torque", "output"), ("n_contact", "output"),
          ("gap_min", "output")]),
        ("spool", f"resources/{SPOOL_ID}.fmu", svars, spool_values,
         [("friction_torque", "input"), ("Omega", "output"), ("drive_torque", "output"),
          ("windage_torque", "output")]),
    ]
    for pname, (_fmu, params) in chosen.items():
        part, pvars = PARTS[pname], part_vars[pname]
        comps[0][4].extend(c for c in part.contact_connectors if c not in comps[0][4])
        values = {k: float(v.start) for k, v in pvars.items() if v.causality == "parameter"}
        for k, v in (params or {}).items():
            if k not in values:
                raise EngineError(f"write_ssp: {pname} parameter '{k}' unknown; known: {', '.join(values)}")
            values[k] = float(v)
        comps.append((pname, f"resources/{part.identifier}.fmu", pvars, values, list(part.connectors)))
    for cname, source, vars_, pvalues, conns in comps:
        comp = ET.SubElement(elements, _q("ssd", "Component"), name=cname, type="application/x-fmu-sharedlibrary",
                             source=source, implementation="CoSimulation")
        connectors = ET.SubElement(comp, _q("ssd", "Connectors"))
        declared = set()
        for vname, kind in conns:
            if vname in vars_:
                _connector(connectors, vars_[vname], kind)
                declared.add(vname)
        for vname in pvalues:
            if vname not in declared:
                _connector(connectors, vars_[vname], "parameter" if vars_[vname].causality == "parameter" else "input")
                declared.add(vname)
        bindings = ET.SubElement(comp, _q("ssd", "ParameterBindings"))
        ET.SubElement(bindings, _q("ssd", "ParameterBinding"), type="application/x-ssp-parameter-set",
                      source=f"resources/{cname}.ssv")
    conn_el = ET.SubElement(system, _q("ssd", "Connections"))
    for se, sc, ee, ec in connections:
        ET.SubElement(conn_el, _q("ssd", "Connection"), startElement=se, startConnector=sc, endElement=ee,
                      endConnector=ec)
    # OMSimulator: the system is a fixed-step co-simulation (its "oms-ma" master), with our step
    oms = ET.SubElement(ET.SubElement(ET.SubElement(system, _q("ssd", "Annotations")), _q("ssc", "Annotation"),
                                      type="org.openmodelica"), f"{{{OMS_NS}}}Annotations")
    ET.SubElement(ET.SubElement(oms, f"{{{OMS_NS}}}SimulationInformation"), f"{{{OMS_NS}}}FixedStepMaster",
                  description="oms-ma", stepSize=_fmt(h), absoluteTolerance="0.0001", relativeTolerance="0.0001")
    used = []
    for _c, _s, vars_, pvalues, conns in comps:
        for vname in [c for c, _k in conns] + list(pvalues):
            u = vars_[vname].unit if vname in vars_ else None
            if u and u not in used:
                used.append(u)
    enums = {v.declared_type for _c, _s, vars_, pvalues, conns in comps
             for v in vars_.values() if v.type == "Enumeration" and v.name in pvalues}
    if enums:
        en_el = ET.SubElement(root, _q("ssd", "Enumerations"))
        for name, items in enumerations(croot).items():
            if name in enums:
                e = ET.SubElement(en_el, _q("ssc", "Enumeration"), name=name)
                for item, value in items:
                    ET.SubElement(e, _q("ssc", "Item"), name=item, value=str(value))
    _units(ET.SubElement(root, _q("ssd", "Units")), used, all_units)
    de = ET.SubElement(root, _q("ssd", "DefaultExperiment"), startTime="0.0", stopTime=_fmt(t_end))
    ann = ET.SubElement(ET.SubElement(de, _q("ssd", "Annotations")), _q("ssc", "Annotation"),
                        type="org.rotorub.master")
    ET.SubElement(ann, f"{{{MASTER_NS}}}FixedStepMaster", stepSize=_fmt(h), exchange="Jacobi",
                  description="fixed communication step; at each communication point both FMUs get the other's "
                              "outputs at that point, then both step (inputs held over the step)")

    path.parent.mkdir(parents=True, exist_ok=True)
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as z:
        z.writestr("SystemStructure.ssd", _xml_bytes(root))
        z.write(contact_fmu, f"resources/{CONTACT_ID}.fmu")
        z.write(spool_fmu, f"resources/{SPOOL_ID}.fmu")
        z.writestr("resources/contact.ssv", _parameter_set("contact", contact_values, cvars, all_units))
        z.writestr("resources/spool.ssv", _parameter_set("spool", spool_values, svars, all_units))
        for pname, source, pvars, values, _conns in comps[2:]:
            z.write(chosen[pname][0], source)
            z.writestr(f"resources/{pname}.ssv", _parameter_set(pname, values, pvars, all_units))
    return path


@cache
def _schema(name: str):
    from lxml import etree

    return etree.XMLSchema(etree.parse(str(SCHEMA_DIR / name)))


def _schema_problems(xml: bytes, schema_file: str, where: str) -> tuple[list[str], object]:
    from lxml import etree

    try:
        doc = etree.fromstring(xml)
    except etree.XMLSyntaxError as exc:
        return [f"{where}: not well-formed XML ({exc})"], None
    schema = _schema(schema_file)
    if schema.validate(doc):
        return [], doc
    return [f"{where}:{e.line}: {e.message}" for e in schema.error_log], doc


def validate_ssp(path: str | Path) -> list[str]:
    """Problems of an SSP package (empty list: valid).

    Checks ``SystemStructure.ssd`` against the SSP 1.0 SystemStructureDescription
    schema and every ``.ssv`` parameter set it binds against the
    SystemStructureParameterValues schema (XML Schema 1.0, lxml), then that each
    component's FMU is in the package, that its connectors exist in the FMU with a
    compatible causality, that connections join declared connectors from an output
    to an input, and that every bound parameter names a variable of the FMU.
    """
    problems: list[str] = []
    try:
        z = zipfile.ZipFile(path)
    except (OSError, zipfile.BadZipFile) as exc:
        return [f"{path}: not a readable zip file ({exc})"]
    with z:
        names = set(z.namelist())
        if "SystemStructure.ssd" not in names:
            return [f"{path}: SystemStructure.ssd missing (the default SSD of an SSP)"]
        for n in sorted(names):
            if n.endswith(".ssd") and n != "SystemStructure.ssd":  # variant SSDs
                p, _ = _schema_problems(z.read(n), "SystemStructureDescription.xsd", n)
                problems += p
        p, doc = _schema_problems(z.read("SystemStructure.ssd"), "SystemStructureDescription.xsd",
                                  "SystemStructure.ssd")
        problems += p
        if doc is None:
            return problems
        ns = {"ssd": NS["ssd"], "ssc": NS["ssc"], "ssv": NS["ssv"]}
        connectors: dict[tuple[str, str], str] = {}
        for sys_el in doc.iter(_q("ssd", "System")):
            for c in sys_el.findall("ssd:Connectors/ssd:Connector", ns):
                connectors[("", c.get("name"))] = c.get("kind")
        for comp in doc.iter(_q("ssd", "Component")):
            cname, src = comp.get("name"), comp.get("source")
            if comp.get("type", "application/x-fmu-sharedlibrary") != "application/x-fmu-sharedlibrary":
                continue
            if src not in names:
                problems.append(f"component '{cname}': source '{src}' is not in the package")
                continue
            try:
                fvars, _, _ = read_description(z.read(src))
            except Exception as exc:  # noqa: BLE001 - reported
                problems.append(f"component '{cname}': {src} is not a readable FMU ({exc})")
                continue
            for c in comp.findall("ssd:Connectors/ssd:Connector", ns):
                vname, kind = c.get("name"), c.get("kind")
                connectors[(cname, vname)] = kind
                var = fvars.get(vname)
                if var is None:
                    problems.append(f"component '{cname}': connector '{vname}' is not a variable of {src}")
                elif kind != var.causality:
                    problems.append(f"component '{cname}': connector '{vname}' has kind '{kind}' but the FMU's "
                                    f"variable has causality '{var.causality}'")
            for b in comp.findall("ssd:ParameterBindings/ssd:ParameterBinding", ns):
                bsrc = b.get("source")
                if bsrc is None:
                    sets = b.findall("ssd:ParameterValues/ssv:ParameterSet", ns)
                    xmls = [ET.tostring(s) for s in sets]
                else:
                    if bsrc not in names:
                        problems.append(f"component '{cname}': parameter set '{bsrc}' is not in the package")
                        continue
                    xmls = [z.read(bsrc)]
                for xml in xmls:
                    p, sdoc = _schema_problems(xml, "SystemStructureParameterValues.xsd", bsrc or "inline ssv")
                    problems += p
                    if sdoc is None:
                        continue
                    for par in sdoc.iter(_q("ssv", "Parameter")):
                        pname = par.get("name")
                        var = fvars.get(pname)
                        if var is None or var.causality not in ("parameter", "input"):
                            problems.append(f"component '{cname}': {bsrc or 'inline ssv'} sets '{pname}', which is "
                                            f"not a parameter or input of {src}")
        for con in doc.iter(_q("ssd", "Connection")):
            s = (con.get("startElement") or "", con.get("startConnector"))
            e = (con.get("endElement") or "", con.get("endConnector"))
            for end, role, ok_kinds in ((s, "start", ("output", "parameter", "calculatedParameter", "inout")),
                                        (e, "end", ("input", "parameter", "inout"))):
                kind = connectors.get(end)
                label = f"{end[0]}.{end[1]}" if end[0] else end[1]
                if kind is None:
                    problems.append(f"connection {s[0]}.{s[1]} -> {e[0]}.{e[1]}: {role} connector {label} is not "
                                    "declared")
                elif end[0] and kind not in ok_kinds:
                    problems.append(f"connection {s[0]}.{s[1]} -> {e[0]}.{e[1]}: {role} connector {label} has kind "
                                    f"'{kind}'")
    return problems


def ssp_contents(path: str | Path) -> dict:
    """What an SSP names: {"components": {name: source}, "connections": [(se, sc, ee, ec), ...]}."""
    with zipfile.ZipFile(path) as z:
        root = ET.fromstring(z.read("SystemStructure.ssd"))
    comps = {c.get("name"): c.get("source") for c in root.iter(_q("ssd", "Component"))}
    conns = [(c.get("startElement"), c.get("startConnector"), c.get("endElement"), c.get("endConnector"))
             for c in root.iter(_q("ssd", "Connection"))]
    return {"components": comps, "connections": conns}




def run_ssp_libcosim(ssp: str | Path, t_end: float, h: float = 1e-3,
                     record: tuple[tuple[str, str], ...] = (("spool", "Omega"), ("contact", "friction_torque"))
                     ) -> dict[str, np.ndarray]:
    """Run an SSP package as written in OSP libcosim (``CosimExecution.from_ssp_file``, fixed step h).

    Returns the time points and the recorded variables ("component.variable") after each step.
    libcosim 0.0.6 reads Real, Integer, Boolean and String variables and parameter values only:
    :func:`write_ssp` leaves the contact FMU's Enumeration parameters out when they keep their
    defaults, so the default engine package runs here.
    """
    try:
        from libcosimpy.CosimExecution import CosimExecution
        from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
        from libcosimpy.CosimObserver import CosimObserver
    except ImportError:
        raise EngineError("run_ssp_libcosim: libcosimpy is not installed (pip install libcosimpy; Linux x86_64, "
                          "Python >= 3.11)") from None
    log_output_level(CosimLogLevel.ERROR)
    steps = int(round(t_end / h))
    ex = CosimExecution.from_ssp_file(str(ssp), step_size=round(h * 1e9))  # libcosim's time unit: ns
    observer = CosimObserver.create_last_value()
    if not ex.add_observer(observer):
        raise EngineError("run_ssp_libcosim: cannot add an observer")
    index = {s.name.decode(): s.index for s in ex.slave_infos()}
    refs = {}
    for comp, var in record:
        if comp not in index:
            raise EngineError(f"run_ssp_libcosim: no component '{comp}' in {ssp}")
        names = {v.name.decode(): (v.reference, v.type) for v in ex.slave_variables(index[comp])}
        if var not in names:
            raise EngineError(f"run_ssp_libcosim: component '{comp}' has no variable '{var}'")
        refs[f"{comp}.{var}"] = (index[comp], *names[var])
    out = {k: np.empty(steps) for k in refs}
    groups: dict[tuple[int, int], list[tuple[str, int]]] = {}  # one observer call per component and type
    for key, (i, ref, typ) in refs.items():  # libcosim's variable types: 0 Real, 1 Integer
        groups.setdefault((i, typ), []).append((key, ref))
    for k in range(steps):
        if not ex.step(1):
            raise EngineError(f"run_ssp_libcosim: step {k} (t = {k * h:g} s) failed; libcosim state "
                              f"{ex.status().state}")
        for (i, typ), items in groups.items():
            values = (observer.last_integer_values if typ == 1 else observer.last_real_values)(
                i, [ref for _key, ref in items])
            for (key, _ref), v in zip(items, values):
                out[key][k] = v
    del ex, observer
    return {"t": (np.arange(steps) + 1) * h, **out}


def _ssp_model(z: zipfile.ZipFile, where: Path) -> dict:
    """What a master needs from a package: components (name, unzipped FMU, model identifier, value references),
    their parameter values (from the bound .ssv files), connections, the communication step."""
    root = ET.fromstring(z.read("SystemStructure.ssd"))
    comps = []
    for comp in root.iter(_q("ssd", "Component")):
        name, src = comp.get("name"), comp.get("source")
        d = where / name
        with zipfile.ZipFile(io.BytesIO(z.read(src))) as fz:
            fz.extractall(d)
        fvars, _, froot = read_description(d)
        md_vr = {sv.get("name"): int(sv.get("valueReference")) for sv in froot.iter("ScalarVariable")}
        items = enumerations(froot)
        values = []
        for b in comp.findall("ssd:ParameterBindings/ssd:ParameterBinding", NS):
            sv = ET.fromstring(z.read(b.get("source")))
            for par in sv.iter(_q("ssv", "Parameter")):
                pname, val = par.get("name"), next(iter(par))
                kind = val.tag.rpartition("}")[2]
                if kind == "Real":
                    values.append(("p", md_vr[pname], float(val.get("value"))))
                elif kind == "Integer":
                    values.append(("I", md_vr[pname], int(val.get("value"))))
                elif kind == "Enumeration":
                    values.append(("I", md_vr[pname], dict(items[fvars[pname].declared_type])[val.get("value")]))
                else:
                    raise EngineError(f"run_ssp_native: {name}.{pname}: {kind} parameters are not supported")
        comps.append({"name": name, "dir": d, "model": froot.find("CoSimulation").get("modelIdentifier"),
                      "vr": md_vr, "values": values, "types": {k: v.type for k, v in fvars.items()}})
    conns = [(c.get("startElement"), c.get("startConnector"), c.get("endElement"), c.get("endConnector"))
             for c in root.iter(_q("ssd", "Connection"))]
    steps = [float(el.get("stepSize")) for ns in (OMS_NS, MASTER_NS) for el in root.iter(f"{{{ns}}}FixedStepMaster")]
    return {"components": comps, "connections": conns, "step": steps[0] if steps else None}


def run_ssp_native(ssp: str | Path, t_end: float, h: float | None = None,
                   record: tuple[tuple[str, str], ...] = (("spool", "Omega"), ("contact", "friction_torque"))
                   ) -> dict[str, np.ndarray]:
    """Run an SSP package in fmu_src/masters/hosts/engine_host.c: a C process with no Python in it (no libpython
    loaded, an environment without Python's variables), as a native master would; the Python side only reads
    the package into the host's command line. Jacobi exchange at a fixed step (the package's FixedStepMaster
    step unless ``h`` is given). Returns the time points after each step and the recorded variables
    ("component.variable")."""
    import subprocess
    import tempfile

    from ..masters import native_host

    host = native_host.cached_host("engine_host.c")
    with tempfile.TemporaryDirectory(prefix="rotorub_ssp_") as tmp, zipfile.ZipFile(ssp) as z:
        m = _ssp_model(z, Path(tmp))
        h = h or m["step"]
        if not h:
            raise EngineError(f"run_ssp_native: {ssp} gives no communication step; pass h")
        by = {c["name"]: c for c in m["components"]}
        args = [str(host), "-q", "-n", str(int(round(t_end / h))), "-s", repr(h)]
        for c in m["components"]:
            args += ["-F", f"{c['name']}={c['dir']}:{c['model']}"]
            args += [a for flag, vr, v in c["values"] for a in (f"-{flag}", f"{c['name']}:{vr}={v!r}")]
        for se, sc, ee, ec in m["connections"]:
            args += ["-c", f"{se}:{by[se]['vr'][sc]}={ee}:{by[ee]['vr'][ec]}"]
        for comp, var in record:
            if comp not in by or var not in by[comp]["vr"]:
                raise EngineError(f"run_ssp_native: no variable {comp}.{var} in {ssp}")
            flag = "-i" if by[comp]["types"].get(var) in ("Integer", "Enumeration") else "-o"
            args += [flag, f"{comp}:{by[comp]['vr'][var]}"]
        proc = subprocess.run(args, capture_output=True, text=True, timeout=1800, env={"PATH": "/usr/bin:/bin"})
    if proc.returncode != 0:
        raise EngineError(f"run_ssp_native: engine_host exit status {proc.returncode}", proc.stderr.splitlines()[-5:])
    head, rows = native_host.read_csv(proc.stdout)
    out = {"t": rows[1:, 0]}
    for comp, var in record:  # the host's columns: NAME:rVR (reals) then NAME:iVR (integers)
        kind = "i" if by[comp]["types"].get(var) in ("Integer", "Enumeration") else "r"
        out[f"{comp}.{var}"] = rows[1:, head.index(f"{comp}:{kind}{by[comp]['vr'][var]}")]
    return out


def run_ssp_fmpy(ssp: str | Path, t_end: float, h: float | None = None,
                 record: tuple[tuple[str, str], ...] = (("spool", "Omega"), ("contact", "friction_torque"))
                 ) -> dict[str, np.ndarray]:
    """Run an SSP package as written with fmpy's FMU2Slave: every component, its bound parameter values set in
    initialization mode, its connections, Jacobi exchange at a fixed step (the package's unless ``h`` is
    given), as :func:`run_ssp_native` and libcosim do. Returns the time points after each step and the
    recorded variables ("component.variable"); a refused step raises :class:`EngineError` with the FMUs'
    messages."""
    import tempfile

    from fmpy.fmi1 import FMICallException

    from ..masters.fmi2 import FMUError, Slave

    with tempfile.TemporaryDirectory(prefix="rotorub_ssp_") as tmp, zipfile.ZipFile(ssp) as z:
        m = _ssp_model(z, Path(tmp))
        h = h or m["step"]
        if not h:
            raise EngineError(f"run_ssp_fmpy: {ssp} gives no communication step; pass h")
        steps = int(round(t_end / h))
        slaves: dict[str, Slave] = {}
        try:
            for c in m["components"]:
                s = slaves[c["name"]] = Slave(c["dir"], instance_name=c["name"], unzip_dir=c["dir"], initialize=False)
                f = s.fmu
                f.setupExperiment(startTime=0.0, stopTime=t_end)
                f.enterInitializationMode()
                for flag, vr, v in c["values"]:
                    (f.setReal if flag == "p" else f.setInteger)([vr], [v])
            by = {c["name"]: c for c in m["components"]}
            links = [(slaves[se].fmu, by[se]["vr"][sc], slaves[ee].fmu, by[ee]["vr"][ec])
                     for se, sc, ee, ec in m["connections"]]
            # the connections' initial values, as libcosim, OMSimulator and run_ssp_native propagate them: one
            # Jacobi pass per component carries a value down any chain
            for _ in slaves:
                values = [src.getReal([vr])[0] for src, vr, _d, _v in links]
                for (_s, _vr, dst, dvr), v in zip(links, values):
                    dst.setReal([dvr], [v])
            for s in slaves.values():
                s.fmu.exitInitializationMode()
            for comp, var in record:
                if comp not in by or var not in by[comp]["vr"]:
                    raise EngineError(f"run_ssp_fmpy: no variable {comp}.{var} in {ssp}")
            probes: dict[tuple[str, bool], list[tuple[int, int]]] = {}  # one get per component and type
            for j, (comp, var) in enumerate(record):
                probes.setdefault((comp, slaves[comp].variables[var].type == "Real"), []).append(
                    (j, by[comp]["vr"][var]))
            out = np.empty((steps, len(record)))
            for k in range(steps):
                values = [src.getReal([vr])[0] for src, vr, _d, _v in links]  # Jacobi: every output at t_k first
                for (_s, _vr, dst, dvr), v in zip(links, values):
                    dst.setReal([dvr], [v])
                try:
                    for s in slaves.values():
                        s.fmu.doStep(currentCommunicationPoint=k * h, communicationStepSize=h)
                except FMICallException as exc:
                    msgs = [f"{n}: {msg}" for n, s in slaves.items() for msg in s.log.problems(0)]
                    raise EngineError(f"run_ssp_fmpy: step at t = {k * h:g} s refused ({exc})", msgs) from None
                for (comp, real), items in probes.items():
                    f = slaves[comp].fmu
                    out[k, [j for j, _vr in items]] = (f.getReal if real else f.getInteger)([vr for _j, vr in items])
        except FMUError as exc:
            raise EngineError(f"run_ssp_fmpy: {exc}", exc.messages) from None
        finally:
            for s in slaves.values():
                s.close()
    return {"t": (np.arange(steps) + 1) * h, **{f"{c}.{v}": out[:, j] for j, (c, v) in enumerate(record)}}
