"""The interface of RotorCasingContact, one definition for both FMUs.

The pythonfmu FMU registers these variables in this order (so its value references are the
indices here) and writes its model description with :func:`model_description`; the native
FMU's C variable table and model description are generated from the same list. A user swaps
one file for the other without touching a connection.

Ranges are declared for every input and parameter (min/max, inclusive as FMI says), with
nominal values and display units (rpm, mm, deg); values outside are refused with fmi2Error by
the native FMU (at the fmi2Set* call) and with a refused step by the pythonfmu one
(``fmu_src/FMU.md``). Where a range is a modelling judgement, the description says why.
"""

from __future__ import annotations

import hashlib
import math
import uuid
from dataclasses import dataclass, replace
from datetime import datetime, timezone
from xml.etree.ElementTree import Element, SubElement, tostring

MODEL_IDENTIFIER = "RotorCasingContact"
MODEL_NAME = "RotorCasingContact"
DESCRIPTION = (
    "Blade-tip / casing contact of a turbofan fan module (Parent, Thouverez & Chevillot, EURODYN 2014): "
    "38-dof bladed rotor and flexible casing in the rotating frame, 2D or 3D contact, penalty normal law and "
    "Coulomb friction. Spin speed and imbalance in; contact forces, gaps, casing load and friction torque out."
)

ENUMERATIONS = {
    "Formulation": (("2D", "point blade tip facing a cylindrical casing (eq. 1)"),
                    ("3D", "leading and trailing edges facing a conical casing, pressure along the chord (eq. 3-8)")),
    "Mode": (("transient", "explicit central differences, substeps inside each communication step"),
             ("quasi_static", "the balanced static solution at the held inputs, with its stability")),
    "Liner": (("rigid", "the paper's casing: rigid, never worn"),
              ("abradable", "an abradable liner, cut where a blade tip presses it beyond its yield force")),
}

# unit -> (SI base-unit exponents, display units {name: factor}); display value = factor * value
UNITS: dict[str, tuple[dict[str, int], dict[str, float]]] = {
    "rad/s": ({"rad": 1, "s": -1}, {"rpm": 60.0 / (2.0 * math.pi)}),
    "kg.m": ({"kg": 1, "m": 1}, {"kg.mm": 1e3}),
    "m": ({"m": 1}, {"mm": 1e3}),
    "m/s": ({"m": 1, "s": -1}, {}),
    "N/m": ({"kg": 1, "s": -2}, {}),
    "rad": ({"rad": 1}, {"deg": 180.0 / math.pi}),
    "s": ({"s": 1}, {"ms": 1e3}),
    "N": ({"kg": 1, "m": 1, "s": -2}, {"kN": 1e-3}),
    "N.m": ({"kg": 1, "m": 2, "s": -2}, {}),
    "1/s": ({"s": -1}, {}),
    "m3": ({"m": 3}, {"mm3": 1e9}),
    "J": ({"kg": 1, "m": 2, "s": -2}, {}),
    "1": ({}, {}),
}

STATUS_OK, STATUS_DIVERGED, STATUS_BAD_INPUT, STATUS_UNSTABLE = 0, 1, 2, 3
# the most substeps one communication step takes (native: fmu_model.h MODEL_MAX_SUBSTEPS); a longer step is
# refused with fmi2Error naming the longest allowed, not minutes to hours inside a call no master can cancel
MAX_SUBSTEPS = 10_000_000
STATUS_TEXT = ("0 = ok; 1 = diverged (transient: a penetration beyond max_penetration or a non-finite state) or, in "
               "quasi_static mode, no balanced solution; 2 = bad input or configuration (cause in 'message' and the "
               "log); 3 = quasi_static: the balanced solution is unstable (max_real_eig > 0)")


@dataclass(frozen=True)
class Var:
    name: str
    type: str  # Real, Integer, Enumeration, String
    causality: str  # input, parameter, output
    variability: str  # continuous, discrete, fixed, tunable
    description: str
    unit: str | None = None
    display_unit: str | None = None
    start: float | int | str | None = None
    min: float | None = None
    max: float | None = None
    nominal: float | None = None
    declared_type: str | None = None
    vr: int = -1  # value reference (the same in both flavours; see variables())

    @property
    def settable(self) -> bool:
        return self.causality in ("input", "parameter")


@dataclass(frozen=True)
class Defaults:
    """What the variable list takes from the parameter file the FMU is built with."""

    n_blades: int
    blade_length: float  # [m]
    omega_ref: float  # [rad/s]
    omega_max: float  # [rad/s] upper end of the model's validity (normalisation.speed_max * omega_ref)
    me: float  # [kg m] reference imbalance
    me_max: float  # [kg m] a blade's static moment about the axis
    g0: float
    k_r: float
    mu: float
    theta: float  # [rad]
    chord: float  # [m]
    max_penetration: float  # [m]
    slip_velocity: float  # [m/s]
    liner: bool = False  # the parameter file's abradable.enabled
    yield_force: float = 100.0  # [N]
    hardening: float = 0.0  # [N/m]
    liner_thickness: float = 2.0e-3  # [m]
    n_sectors: int = 720

    @classmethod
    def from_parameters(cls, p) -> Defaults:
        b = p.blades
        return cls(n_blades=b.count, blade_length=b.length, omega_ref=p.normalisation.omega_ref,
                   omega_max=p.normalisation.speed_max * p.normalisation.omega_ref, me=p.imbalance.me,
                   me_max=b.mass * (b.hub_radius + 0.5 * b.length), g0=p.contact.g0, k_r=p.contact.k_r,
                   mu=p.contact.mu, theta=math.radians(p.contact.theta_deg), chord=p.contact.chord,
                   max_penetration=p.contact.max_penetration, slip_velocity=p.contact.slip_velocity,
                   liner=p.abradable.enabled, yield_force=p.abradable.yield_force, hardening=p.abradable.hardening,
                   liner_thickness=p.abradable.thickness, n_sectors=p.abradable.n_sectors)


# ranges that are modelling judgements (the descriptions say why); g0's lower end is the built-in
# max_penetration: a deeper interference is a divergence at t = 0
G0_MAX = 0.1
K_R_RANGE = (1e3, 1e10)
MU_RANGE = (0.0, 1.0)
THETA_RANGE = (0.0, math.radians(60.0))
CHORD_RANGE = (1e-3, 0.5)
DT_MAX_RANGE = (1e-8, 1.0)
PENETRATION_RANGE = (1e-5, 0.05)
SLIP_RANGE = (1e-4, 10.0)
CLOSURE_RANGE = (-0.01, 0.01)  # +-10 mm: an engine's thermal and centrifugal growth, with margin
OFFSET_RANGE = (-0.01, 0.01)
YIELD_RANGE = (1e-3, 1e7)
HARDENING_RANGE = (0.0, 1e10)
THICKNESS_RANGE = (1e-5, 0.05)
SECTORS_RANGE = (8, 100000)
WEAR_HARMONICS = 8  # the kernel's RR_WEAR_HARMONICS


# the default experiment (both flavours): the paper's section-6 speed and the reference imbalance held from t = 0,
# long enough for the blades to reach the casing and settle into rubbing (tests/test_fmi_behaviour.py runs it)
DEFAULT_SPEED = 3.3  # x omega_ref
DEFAULT_EXPERIMENT = {"startTime": 0.0, "stopTime": 2.0, "stepSize": 1e-3}
FLAVOURS = ("native", "pythonfmu")


def variables(d: Defaults, mode: str = "transient", flavour: str = "native") -> list[Var]:
    """Every variable of a flavour, in value-reference order.

    Both flavours number their variables the same way, so that one FMU replaces the other without
    touching a connection: the pythonfmu flavour's ``param_file`` (value reference 4) has no
    counterpart in the native one, whose numbering keeps the gap.
    """
    if flavour not in FLAVOURS:
        raise ValueError(f"flavour: '{flavour}' unknown; accepted: {', '.join(FLAVOURS)}")
    V: list[Var] = []
    add = V.append
    add(Var("Omega", "Real", "input", "continuous",
            "Spin speed of the rotor, held over each communication step (zero-order hold). Range: 0 to the model's "
            "validity limit (normalisation.speed_max x omega_ref of the parameter file)",
            unit="rad/s", display_unit="rpm", start=DEFAULT_SPEED * d.omega_ref, min=0.0, max=d.omega_max,
            nominal=3.5 * d.omega_ref))
    add(Var("imbalance", "Real", "input", "continuous",
            "Imbalance m*e on the fan disk (angle and disk from the parameter file), held over each step. Range: 0 to "
            "one blade's static moment about the axis (beyond, a blade is missing: not this model)",
            unit="kg.m", display_unit="kg.mm", start=d.me, min=0.0, max=d.me_max, nominal=d.me))
    add(Var("formulation", "Enumeration", "parameter", "fixed", "Contact formulation: 2D or 3D",
            start=2, min=1, max=2, declared_type="Formulation"))
    add(Var("mode", "Enumeration", "parameter", "fixed",
            "transient (central differences, substeps inside each step) or quasi_static (the balanced static "
            "solution at the held inputs, warm-started from the last one, and its stability)",
            start=1 if mode == "transient" else 2, min=1, max=2, declared_type="Mode"))
    add(Var("param_file", "String", "parameter", "fixed",
            "Path of a rotorub TOML parameter file; empty: the model built into the FMU (assembled at initialisation, "
            "which needs scipy on the host)", start=""))
    add(Var("g0", "Real", "parameter", "tunable",
            "Nominal blade-tip clearance (negative: initial interference); tunable between communication steps. "
            "Range: an interference as deep as max_penetration (deeper diverges at once: refused, also when "
            "max_penetration is set smaller) to 100 mm",
            unit="m", display_unit="mm", start=d.g0, min=-d.max_penetration, max=G0_MAX, nominal=1e-3))
    add(Var("k_r", "Real", "parameter", "fixed",
            "Normal penalty stiffness of one whole blade tip. Range: 1e3 (no force to speak of) to 1e10 N/m (the "
            "stable internal step shrinks as 1/sqrt(k_r))", unit="N/m", start=d.k_r, min=K_R_RANGE[0],
            max=K_R_RANGE[1], nominal=d.k_r))
    add(Var("mu", "Real", "parameter", "fixed", "Coulomb friction coefficient", unit="1", start=d.mu,
            min=MU_RANGE[0], max=MU_RANGE[1], nominal=0.1))
    add(Var("theta", "Real", "parameter", "fixed",
            "Inclination of the conical casing inner surface (3D). Range 0 to 60 deg (the paper studies 0-30; the "
            "linearised cone gap degrades towards 90)", unit="rad", display_unit="deg", start=d.theta,
            min=THETA_RANGE[0], max=THETA_RANGE[1], nominal=0.1))
    add(Var("chord", "Real", "parameter", "fixed", "Blade-tip chord length l_c (3D)", unit="m", display_unit="mm",
            start=d.chord, min=CHORD_RANGE[0], max=CHORD_RANGE[1], nominal=0.2))
    add(Var("dt_max", "Real", "parameter", "fixed",
            "Upper limit of the internal time step (transient mode): a step h is done in n = ceil(h / min(dt_max, "
            "half the central-difference stability limit)) equal substeps", unit="s", display_unit="ms", start=1e-3,
            min=DT_MAX_RANGE[0], max=DT_MAX_RANGE[1], nominal=1e-4))
    add(Var("max_penetration", "Real", "parameter", "fixed",
            "Divergence: a run stops (fmi2Discard, status 1) at the first substep where a blade penetrates the casing "
            "deeper than this (the depth of an abradable liner: deeper, the blade cuts the case structure and the "
            "penalty law means nothing)", unit="m", display_unit="mm", start=d.max_penetration,
            min=PENETRATION_RANGE[0], max=PENETRATION_RANGE[1], nominal=3e-3))
    add(Var("slip_velocity", "Real", "parameter", "fixed",
            "Velocity scale of the friction law mu tanh(v / slip_velocity), v the sliding speed of a blade point "
            "over the casing (spin plus vibration): exact Coulomb friction at tip speeds, turning smoothly with "
            "the sliding near v = 0 (start from rest, run-down, windmilling). Range 0.1 mm/s to 10 m/s (far below "
            "the tip speeds; the smaller, the smaller the internal step the friction's damping allows)",
            unit="m/s", start=d.slip_velocity, min=SLIP_RANGE[0], max=SLIP_RANGE[1], nominal=0.1))
    for j in range(1, d.n_blades + 1):
        b = f"blade[{j}]"
        add(Var(f"{b}.F_N", "Real", "output", "continuous", f"Normal contact force on blade {j}", unit="N"))
        add(Var(f"{b}.F_T", "Real", "output", "continuous",
                f"Tangential (friction) force on blade {j}: mu*F_N against its sliding over the casing (positive: "
                "against the spin)", unit="N"))
        add(Var(f"{b}.gap_LE", "Real", "output", "continuous",
                f"Gap at the leading edge of blade {j} (2D: the tip gap); negative = penetration", unit="m",
                display_unit="mm"))
        add(Var(f"{b}.gap_TE", "Real", "output", "continuous",
                f"Gap at the trailing edge of blade {j} (2D: the tip gap); negative = penetration", unit="m",
                display_unit="mm"))
        add(Var(f"{b}.gap_tip", "Real", "output", "continuous",
                f"Smallest gap of blade {j} (2D: the tip gap; 3D: the smaller of LE and TE, the gap being linear "
                "along the chord)", unit="m", display_unit="mm"))
        add(Var(f"{b}.contact_fraction", "Real", "output", "continuous",
                f"Fraction of the chord of blade {j} in contact (2D: 0 or 1)", unit="1"))
    add(Var("n_contact", "Integer", "output", "discrete", "Number of blades in contact (F_N > 0)"))
    for ax in "xyz":
        add(Var(f"casing_force.{ax}", "Real", "output", "continuous",
                f"Resultant contact force on the casing, fixed frame, {ax} component (z: axial)", unit="N"))
    add(Var("friction_torque", "Real", "output", "continuous",
            "Axial torque of the contact forces on the rotor (negative: brakes the spin)", unit="N.m"))
    for ax in "xy":
        add(Var(f"disk_displacement.{ax}", "Real", "output", "continuous",
                f"Fan-disk centre displacement, fixed frame, {ax} component", unit="m", display_unit="mm"))
    add(Var("gap_min", "Real", "output", "continuous", "Smallest gap over all blades and contact points", unit="m",
            display_unit="mm"))
    add(Var("max_real_eig", "Real", "output", "continuous",
            "Largest real part of the eigenvalues linearised about the static solution (quasi_static mode; > 0: "
            "unstable); 0 in transient mode (not computed)", unit="1/s"))
    add(Var("status", "Integer", "output", "discrete", STATUS_TEXT))
    add(Var("message", "String", "output", "discrete",
            "Cause of the last refused call (the text also sent to the FMI logger); empty after a step that succeeded"))
    add(Var("dt_internal", "Real", "output", "discrete",
            "Internal time step of the last communication step (transient mode; 0 in quasi_static)", unit="s",
            display_unit="ms"))
    add(Var("n_substeps", "Integer", "output", "discrete",
            "Internal steps taken in the last communication step (transient mode)"))
    # the casing's liner and the engine's inputs on the casing (issue 19): after every earlier variable, so
    # that their value references, and the connections of older systems, stay as they were
    add(Var("liner", "Enumeration", "parameter", "fixed",
            "The casing's inner surface: rigid (the paper's) or an abradable liner that wears (transient mode)",
            start=2 if d.liner else 1, min=1, max=2, declared_type="Liner"))
    add(Var("yield_force", "Real", "parameter", "fixed",
            "Liner: a blade tip's normal force at which the liner starts to be removed (a 3D chord pressed "
            "uniformly yields at the same total force); below it the liner is elastic (the penalty k_r)",
            unit="N", start=d.yield_force, min=YIELD_RANGE[0], max=YIELD_RANGE[1], nominal=100.0))
    add(Var("hardening", "Real", "parameter", "fixed",
            "Liner: linear hardening, yield force gained per metre removed (0: perfectly plastic)", unit="N/m",
            start=d.hardening, min=HARDENING_RANGE[0], max=HARDENING_RANGE[1], nominal=1e5))
    add(Var("liner_thickness", "Real", "parameter", "fixed",
            "Liner thickness: no wear beyond it (the casing's substrate)", unit="m", display_unit="mm",
            start=d.liner_thickness, min=THICKNESS_RANGE[0], max=THICKNESS_RANGE[1], nominal=2e-3))
    add(Var("n_sectors", "Integer", "parameter", "fixed",
            "Liner: cells over the circumference (fixed frame) that each carry a worn depth", start=d.n_sectors,
            min=SECTORS_RANGE[0], max=SECTORS_RANGE[1]))
    add(Var("clearance_closure", "Real", "input", "continuous",
            "Closure of the tip clearance from the engine (thermal and centrifugal growth), uniform around the "
            "casing, held over each step (> 0 closes; quasi_static mode: subtracted from g0)", unit="m",
            display_unit="mm", start=0.0, min=CLOSURE_RANGE[0], max=CLOSURE_RANGE[1], nominal=1e-4))
    for ax in "xy":
        add(Var(f"casing_offset.{ax}", "Real", "input", "continuous",
                f"Rigid offset of the casing centre from a carcass or manoeuvre-load model, fixed frame, {ax} "
                "component, held over each step (transient mode; the gap opens where the offset points)", unit="m",
                display_unit="mm", start=0.0, min=OFFSET_RANGE[0], max=OFFSET_RANGE[1], nominal=1e-4))
    add(Var("wear.depth_max", "Real", "output", "discrete", "Deepest worn point of the liner", unit="m",
            display_unit="mm"))
    add(Var("wear.depth_mean", "Real", "output", "discrete",
            "Mean worn depth around the casing (3D: also over the chord)", unit="m", display_unit="mm"))
    add(Var("wear.volume", "Real", "output", "discrete", "Liner volume removed", unit="m3", display_unit="mm3"))
    add(Var("wear.plastic_work", "Real", "output", "discrete", "Work dissipated in removing the liner",
            unit="J"))
    add(Var("wear.lobes", "Integer", "output", "discrete",
            "Dominant lobe count of the worn profile: the harmonic 1-8 of largest amplitude (0: no wear, or worn "
            "evenly: no harmonic reaches 1 % of the mean depth)"))
    for h in range(1, WEAR_HARMONICS + 1):
        add(Var(f"wear.harmonic[{h}]", "Real", "output", "discrete",
                f"Amplitude of the worn profile's harmonic {h} ({h} lobes)", unit="m", display_unit="mm"))
    add(Var("clearance_effective", "Real", "output", "discrete",
            "Clearance the engine keeps: g0 - clearance_closure + the mean worn depth (what a performance model "
            "pays for)", unit="m", display_unit="mm"))
    V = [replace(v, vr=k) for k, v in enumerate(V)]
    return [v for v in V if flavour == "pythonfmu" or v.name != "param_file"]


def _fmt(v: float | int) -> str:
    return repr(float(v)) if isinstance(v, float) else str(v)


def guid_of(*parts: bytes | str) -> str:
    """A GUID derived from what makes an FMU what it is (its description, model data and sources), not from
    the build time: the same model built twice has the same GUID, any change gives another one."""
    h = hashlib.sha256()
    for p in parts:
        h.update(p.encode() if isinstance(p, str) else p)
        h.update(b"\0")
    return "{" + str(uuid.UUID(h.hexdigest()[:32])) + "}"


def model_description(vars_: list[Var], *, guid: str, generation_tool: str, version: str,
                      needs_execution_tool: bool, feedthrough: bool, source_files: list[str] | None = None,
                      author: str = "rotorub developers", model_name: str = MODEL_NAME,
                      model_identifier: str = MODEL_IDENTIFIER, description: str = DESCRIPTION,
                      units: dict | None = None, enumerations: dict | None = None,
                      default_experiment: dict | None = None, initial_from_parameters: bool = False) -> Element:
    """The FMI 2.0 co-simulation model description of ``vars_`` (an ElementTree element); the contact
    FMU's by default, any other model's (the LP spool) with its names, units and experiment.

    ``feedthrough``: the outputs depend directly on the inputs (the quasi_static build: its
    outputs are the algebraic solution at the current inputs); otherwise they depend on no
    input (the transient build: outputs follow the state, no algebraic loop with the spool).

    ``initial_from_parameters``: the initial outputs depend on the parameters alone, not on the inputs (the
    spool's initial speed is its Omega0 whatever torque it is given): declared, so that a master that
    propagates initial values (OMSimulator) sees no algebraic loop at initialisation. Otherwise an initial
    output declares no dependencies: it may depend on everything, as FMI 2.0 reads that.
    """
    units = UNITS if units is None else units
    enumerations = ENUMERATIONS if enumerations is None else enumerations
    experiment = DEFAULT_EXPERIMENT if default_experiment is None else default_experiment
    root = Element("fmiModelDescription", {
        "fmiVersion": "2.0", "modelName": model_name, "guid": guid,
        "description": description, "author": author, "version": version, "license": "MIT",
        "copyright": author, "generationTool": generation_tool,
        "generationDateAndTime": datetime.now(timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ"),
        "variableNamingConvention": "structured", "numberOfEventIndicators": "0"})
    cs = SubElement(root, "CoSimulation", {
        "modelIdentifier": model_identifier, "needsExecutionTool": str(needs_execution_tool).lower(),
        "canHandleVariableCommunicationStepSize": "true", "canInterpolateInputs": "false",
        "maxOutputDerivativeOrder": "0", "canRunAsynchronuously": "false",
        "canBeInstantiatedOnlyOncePerProcess": "false", "canNotUseMemoryManagementFunctions": "true",
        "canGetAndSetFMUstate": "true", "canSerializeFMUstate": "true", "providesDirectionalDerivative": "false"})
    if source_files:
        sf = SubElement(cs, "SourceFiles")
        for f in source_files:
            SubElement(sf, "File", name=f)
    used = {v.unit for v in vars_ if v.unit}
    unit_defs = SubElement(root, "UnitDefinitions")
    for name, (base, displays) in units.items():
        if name not in used:
            continue
        u = SubElement(unit_defs, "Unit", name=name)
        SubElement(u, "BaseUnit", {k: str(e) for k, e in base.items()})
        for dname, factor in displays.items():
            SubElement(u, "DisplayUnit", name=dname, factor=repr(factor))
    types = SubElement(root, "TypeDefinitions") if enumerations else None
    for tname, items in enumerations.items():
        st = SubElement(types, "SimpleType", name=tname)
        en = SubElement(st, "Enumeration")
        for k, (item, desc) in enumerate(items, start=1):
            SubElement(en, "Item", name=item, value=str(k), description=desc)
    logs = SubElement(root, "LogCategories")
    for cat, desc in (("logStatusWarning", "Log messages with fmi2Warning status."),
                      ("logStatusDiscard", "Log messages with fmi2Discard status."),
                      ("logStatusError", "Log messages with fmi2Error status."),
                      ("logStatusFatal", "Log messages with fmi2Fatal status."),
                      ("logAll", "Log all messages.")):
        SubElement(logs, "Category", name=cat, description=desc)
    SubElement(root, "DefaultExperiment", {k: _fmt(float(v)) for k, v in experiment.items()})
    mv = SubElement(root, "ModelVariables")
    for k, v in enumerate(vars_):
        vr = v.vr if v.vr >= 0 else k
        attrs = {"name": v.name, "valueReference": str(vr), "description": v.description, "causality": v.causality,
                 "variability": v.variability}
        if v.causality == "output":
            attrs["initial"] = "calculated"
        elif v.causality == "parameter":
            attrs["initial"] = "exact"
        sv = SubElement(mv, "ScalarVariable", attrs)
        t = SubElement(sv, v.type)
        if v.declared_type:
            t.set("declaredType", v.declared_type)
        if v.unit:
            t.set("unit", v.unit)
        if v.display_unit:
            t.set("displayUnit", v.display_unit)
        for key in ("min", "max", "nominal"):
            val = getattr(v, key)
            if val is not None:
                t.set(key, _fmt(val))
        if v.start is not None and v.causality != "output":
            t.set("start", v.start if isinstance(v.start, str) else _fmt(v.start))
    ms = SubElement(root, "ModelStructure")
    outs = SubElement(ms, "Outputs")
    # the quasi_static solution depends on the inputs but the casing's offset (a transient-mode input: a
    # balanced solution of the rotating frame cannot hold a casing offset fixed in the other frame)
    inputs = [str(i + 1) for i, v in enumerate(vars_)
              if v.causality == "input" and not v.name.startswith("casing_offset")]
    for i, v in enumerate(vars_):
        if v.causality == "output":
            attrs = {"index": str(i + 1)}
            attrs["dependencies"] = " ".join(inputs) if feedthrough else ""
            if feedthrough:
                attrs["dependenciesKind"] = " ".join("dependent" for _ in inputs)
            SubElement(outs, "Unknown", attrs)
    init = SubElement(ms, "InitialUnknowns")
    params = " ".join(str(i + 1) for i, v in enumerate(vars_) if v.causality == "parameter")
    for i, v in enumerate(vars_):
        if v.causality == "output":
            attrs = {"index": str(i + 1)}
            if initial_from_parameters:
                attrs["dependencies"] = params
            SubElement(init, "Unknown", attrs)
    return root


def xml_bytes(root: Element) -> bytes:
    from xml.dom import minidom

    return minidom.parseString(tostring(root, encoding="utf-8")).toprettyxml(indent="  ", encoding="UTF-8")


def documentation_html(vars_: list[Var], flavour: str, host_needs: str, details: str) -> str:
    """documentation/index.html of an FMU: what it is, what the host needs, the variables."""
    import html

    rows = "\n".join(
        f"<tr><td><code>{html.escape(v.name)}</code></td><td>{v.causality}</td><td>{html.escape(v.unit or '')}"
        f"{' (' + v.display_unit + ')' if v.display_unit else ''}</td>"
        f"<td>{'' if v.min is None else f'[{v.min:g}, {v.max:g}]'}</td><td>{html.escape(v.description)}</td></tr>"
        for v in vars_)
    return f"""<!DOCTYPE html>
<html><head><meta charset="utf-8"><title>{MODEL_IDENTIFIER} ({flavour})</title></head><body>
<h1>{MODEL_IDENTIFIER} &mdash; blade-tip / casing contact, FMI 2.0 co-simulation ({flavour})</h1>
<p>{html.escape(DESCRIPTION)}</p>
<h2>What the host needs</h2>
{host_needs}
<h2>Behaviour</h2>
<ul>
<li>Inputs are held over each communication step (zero-order hold); variable step sizes are accepted. A step h
is n = ceil(h / min(dt_max, half the central-difference stability limit)) equal substeps (transient mode).</li>
<li>quasi_static mode: the balanced static solution at the held inputs and the largest real part of the
eigenvalues of the linearised system; status 3 when it is unstable.</li>
<li>fmi2Get/SetFMUstate and their serialisation restore the whole solver state (rollback); fmi2Reset returns to
the instantiated state.</li>
<li>{STATUS_TEXT}</li>
{details}
</ul>
<p>The manual: <code>documentation/FMU.md</code>.</p>
<h2>Variables</h2>
<table border="1" cellspacing="0" cellpadding="3">
<tr><th>name</th><th>causality</th><th>unit (display)</th><th>range</th><th>description</th></tr>
{rows}
</table></body></html>
"""
