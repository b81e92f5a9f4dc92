"""RotorCasingContact's variables: the one list every build of the contact FMU is written from.

The native FMI 2.0 and FMI 3.0 FMUs and the pythonfmu FMU declare these variables with these value references,
units, ranges and start values (fmu_src/fmi/variables.py numbers them, writes the FMI 2.0 and 3.0 views and
the C tables), so a user swaps one file for the other without touching a connection. The per-blade outputs and
the wear harmonics are arrays: one FMI 3.0 variable each (``blade.F_N`` of n_blades elements), one FMI 2.0 scalar
per element (``blade[1].F_N``, ...).

Ranges are declared for every input and parameter (min/max, inclusive as FMI says), with nominal values and
display units (rpm, mm, deg); values outside are refused with fmi2Error by the native FMU (at the fmi2Set* call)
and with a refused step by the pythonfmu one (FMU.md next to this file). Where a range is a modelling
judgement, the description says why.

Adding a variable is one entry at the end of :func:`variables` (after every earlier one: their value references,
and the connections of older systems, stay as they are); the builds, the C header ``variables.h`` (``VR_<NAME>``)
and the model descriptions follow. FMU.md says how, for a parameter, an input and a per-blade output.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from rotorub_model.structure.params import accepted_range

from ...fmi.description import ModelInfo
from ...fmi.variables import TIME, Var, numbered, tidy

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
    "Law": (("penalty", "the paper's penalty law: F = k_r delta"),
            ("bilinear", "a coating then a stiffer or softer layer: F = k_r delta + (stiffness_ratio - 1) k_r "
                         "(delta - knee)_+")),
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
    law: str = "penalty"  # the parameter file's contact.law
    knee: float = 0.5e-3  # [m]
    stiffness_ratio: float = 4.0
    # an imported blade or an FE casing: the contact geometry is built in at the file's theta and chord (fixed)
    geometry_built_in: bool = False

    @classmethod
    def from_parameters(cls, p, model=None) -> Defaults:
        """From the parameter file; with ``model``, an imported blade's (``[fe_blade]``) mass and tip chord, and
        whether the contact geometry is built in (an imported tip's stations, an FE casing's modes: at the file's
        cone angle and chord)."""
        b = p.blades
        moment, chord, imported = b.mass * (b.hub_radius + 0.5 * b.length), p.contact.chord, False
        if model is not None and model.casing_ratios is not None:
            imported = True
        if model is not None and model.fe_blade is not None:
            from rotorub_model.contact import make_contact

            fe = model.fe_blade
            first = fe.basis_mass[:3, 3:6]  # -m skew(x_cg): the blade's first moments about the disk's centre
            moment = math.hypot(float(first[1, 2]), float(first[2, 0]))  # m times the centre of mass' radius
            chord, imported = float(make_contact(model, "3D").geometry.chord), True
        # the two computed bounds are range limits (a judgement): written as a person reads them (fmi.variables.tidy)
        return cls(n_blades=b.count, blade_length=b.length, omega_ref=p.normalisation.omega_ref,
                   omega_max=tidy(p.normalisation.speed_max * p.normalisation.omega_ref), me=p.imbalance.me,
                   me_max=tidy(moment), g0=p.contact.g0, k_r=p.contact.k_r,
                   mu=p.contact.mu, theta=math.radians(p.contact.theta_deg), chord=chord, geometry_built_in=imported,
                   max_penetration=p.contact.max_penetration, slip_velocity=p.contact.slip_velocity,
                   liner=p.abradable.enabled, yield_force=p.abradable.yield_force, hardening=p.abradable.hardening,
                   liner_thickness=p.abradable.thickness, n_sectors=p.abradable.n_sectors, law=p.contact.law,
                   knee=p.contact.knee, stiffness_ratio=p.contact.stiffness_ratio)


# ranges: the library's one declaration (rotorub_model.structure.params, field metadata and INPUT_RANGES), read here
# as the parameter file and the CLI read it; g0's lower end is the built-in max_penetration (a deeper interference
# diverges at t = 0); dt_max's is the FMU's own (no parameter-file counterpart)
G0_MAX = accepted_range("g0_max")[1]
K_R_RANGE = accepted_range("contact.k_r")
MU_RANGE = accepted_range("contact.mu")
THETA_RANGE = tuple(math.radians(v) for v in accepted_range("contact.theta_deg"))
CHORD_RANGE = accepted_range("contact.chord")
DT_MAX_RANGE = (1e-8, 1.0)
PENETRATION_RANGE = accepted_range("contact.max_penetration")
SLIP_RANGE = accepted_range("contact.slip_velocity")
CLOSURE_RANGE = accepted_range("clearance_closure")
OFFSET_RANGE = accepted_range("casing_offset")
YIELD_RANGE = accepted_range("abradable.yield_force")
HARDENING_RANGE = accepted_range("abradable.hardening")
THICKNESS_RANGE = accepted_range("abradable.thickness")
SECTORS_RANGE = tuple(int(v) for v in accepted_range("abradable.n_sectors"))
KNEE_RANGE = accepted_range("contact.knee")
RATIO_RANGE = accepted_range("contact.stiffness_ratio")
LOBE_AMPLITUDE_RANGE = accepted_range("casing_lobe_amplitude")
LOBE_PHASE_RANGE = accepted_range("casing_lobe_phase")
FMU_LOBES = (2, 3, 4)  # the casing's lobes an engine can drive (the kernel has up to 8: the library takes them all)
WEAR_HARMONICS = 8  # the kernel's RR_WEAR_HARMONICS


# the default experiment (both flavours): the paper's section-6 speed and the reference imbalance held from t = 0,
# long enough for the blades to reach the casing and settle into rubbing (tests/fmu/test_fmi2.py runs it)
DEFAULT_SPEED = 3.3  # x omega_ref
DEFAULT_EXPERIMENT = {"startTime": 0.0, "stopTime": 2.0, "stepSize": 1e-3}
FLAVOURS = ("native", "pythonfmu")
# the FMI 3.0 descriptions of the per-blade arrays (the FMI 2.0 elements are described blade by blade below)
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


def variables(d: Defaults, mode: str = "transient") -> list[Var]:
    """Every variable of every build, numbered (fmu_src/fmi/variables.py): the pythonfmu flavour's ``param_file``
    (value reference 4) has no counterpart in the native FMUs, whose numbering keeps the gap; ``time``, ``n_blades``
    and ``penetration_margin`` are the FMI 3.0 FMU's."""
    if mode not in ("transient", "quasi_static"):
        raise ValueError(f"mode: '{mode}' unknown; accepted: transient, quasi_static")
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
            "which needs scipy on the host)", start="", only="pythonfmu"))
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
    built_in = (" Built in (imported blades' tips or an FE casing's modes, from finite-element models: the contact "
                "geometry is made at the parameter file's cone angle and chord); another value needs a rebuild with "
                "--params.")
    theta_range, chord_range = (d.theta, d.theta), (d.chord, d.chord)
    if not d.geometry_built_in:
        theta_range, chord_range, built_in = THETA_RANGE, CHORD_RANGE, ""
    add(Var("theta", "Real", "parameter", "fixed",
            "Inclination of the conical casing inner surface (3D). Range 0 to 60 deg (the paper studies 0-30; the "
            "linearised cone gap degrades towards 90)" + built_in, unit="rad", display_unit="deg", start=d.theta,
            min=theta_range[0], max=theta_range[1], nominal=0.1))
    add(Var("chord", "Real", "parameter", "fixed", "Blade-tip chord length l_c (3D)" + built_in,
            unit="m", display_unit="mm", start=d.chord, min=chord_range[0], max=chord_range[1], nominal=0.2))
    add(Var("dt_max", "Real", "parameter", "fixed",
            "Upper limit of the internal time step (transient mode): a step h is done in n = ceil(h / min(dt_max, "
            "half the central-difference stability limit)) equal substeps", unit="s", display_unit="ms", start=1e-3,
            min=DT_MAX_RANGE[0], max=DT_MAX_RANGE[1], nominal=1e-4))
    add(Var("max_penetration", "Real", "parameter", "fixed",
            "Divergence: a run ends (status 1; FMI 2.0 fmi2Discard, FMI 3.0 terminateSimulation) at the first "
            "substep where a blade penetrates the casing "
            "deeper than this (the depth of an abradable liner: deeper, the blade cuts the case structure and the "
            "penalty law means nothing)", unit="m", display_unit="mm", start=d.max_penetration,
            min=PENETRATION_RANGE[0], max=PENETRATION_RANGE[1], nominal=3e-3))
    add(Var("slip_velocity", "Real", "parameter", "fixed",
            "Velocity scale of the friction law mu tanh(v / slip_velocity), v the sliding speed of a blade point "
            "over the casing (spin plus vibration): exact Coulomb friction at tip speeds, turning smoothly with "
            "the sliding near v = 0 (start from rest, run-down, windmilling). Range 0.1 mm/s to 10 m/s (far below "
            "the tip speeds; the smaller, the smaller the internal step the friction's damping allows)",
            unit="m/s", start=d.slip_velocity, min=SLIP_RANGE[0], max=SLIP_RANGE[1], nominal=0.1))
    # per blade, blade 1's six outputs, then blade 2's, ... (their FMI 2.0 value references interleave)
    for name, text2, unit, disp in (
            ("F_N", "Normal contact force on blade {k}", "N", None),
            ("F_T", "Tangential (friction) force on blade {k}: mu*F_N against its sliding over the casing (positive: "
                    "against the spin)", "N", None),
            ("gap_LE", "Gap at the leading edge of blade {k} (2D: the tip gap); negative = penetration", "m", "mm"),
            ("gap_TE", "Gap at the trailing edge of blade {k} (2D: the tip gap); negative = penetration", "m", "mm"),
            ("gap_tip", "Smallest gap of blade {k} (2D: the tip gap; 3D: the smaller of LE and TE, the gap being "
                        "linear along the chord)", "m", "mm"),
            ("contact_fraction", "Fraction of the chord of blade {k} in contact (2D: 0 or 1)", "1", None)):
        add(Var(f"blade.{name}", "Real", "output", "continuous", ARRAY_TEXT[name] + " (element j: blade j)",
                unit=unit, display_unit=disp, size=d.n_blades, element=f"blade[{{k}}].{name}",
                element_description=text2, dimension="n_blades", interleave="blade"))
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
            display_unit="mm", event_indicator=True))  # FMI 3.0: a first contact crosses 0 downwards
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
                display_unit="mm", start=0.0, min=OFFSET_RANGE[0], max=OFFSET_RANGE[1], nominal=1e-4,
                # quasi_static: a balanced solution of the rotating frame cannot hold an offset fixed in the other
                feedthrough=False))
    add(Var("wear.depth_max", "Real", "output", "discrete", "Deepest worn point of the liner", unit="m",
            display_unit="mm"))
    add(Var("wear.depth_mean", "Real", "output", "discrete",
            "Mean worn depth around the casing (3D: also over the chord)", unit="m", display_unit="mm"))
    add(Var("wear.volume", "Real", "output", "discrete", "Liner volume removed", unit="m3", display_unit="mm3"))
    add(Var("wear.plastic_work", "Real", "output", "discrete", "Work dissipated in removing the liner",
            unit="J"))
    add(Var("wear.lobes", "Integer", "output", "discrete",
            "Dominant lobe count of the worn profile (0: no wear; worn evenly, every harmonic below 5 % of the mean "
            "depth; or no harmonic at least twice every harmonic that is not its multiple)"))
    add(Var("wear.harmonic", "Real", "output", "discrete",
            "Amplitudes of the worn profile's harmonics 1 to 8 (element h: h lobes): the worn profile as a fixed, "
            "small set of outputs whatever n_sectors", unit="m", display_unit="mm", size=WEAR_HARMONICS,
            element="wear.harmonic[{k}]",
            element_description="Amplitude of the worn profile's harmonic {k} ({k} lobes)"))
    add(Var("clearance_effective", "Real", "output", "discrete",
            "Clearance the engine keeps: g0 - clearance_closure + the mean worn depth (what a performance model "
            "pays for)", unit="m", display_unit="mm"))
    # the FMI 3.0 FMU's own: after every FMI 2.0 variable, as they have always been
    add(TIME)
    add(Var("n_blades", "UInt64", "structuralParameter", "fixed",
            "Number of blades: the size of the per-blade arrays, fixed by the parameter file the FMU was built with "
            "(another blade count: rebuild with --params)", start=d.n_blades, min=d.n_blades, max=d.n_blades,
            only="fmi3"))
    add(Var("penetration_margin", "Real", "local", "continuous",
            "gap_min + max_penetration: how far the deepest blade is from the divergence depth (the event indicator "
            "of a divergence: it crosses 0 downwards when the run diverges)", unit="m", display_unit="mm",
            sum_of=("gap_min", "max_penetration"), event_indicator=True, only="fmi3"))
    # the normal law (issue 24) and the casing out of round (issue 27): after every earlier variable
    add(Var("law", "Enumeration", "parameter", "fixed",
            "Normal contact law: penalty (the paper's) or bilinear (stiffness k_r up to the knee penetration, "
            "stiffness_ratio x k_r beyond)", start=1 + ("penalty", "bilinear").index(d.law), min=1, max=2,
            declared_type="Law"))
    add(Var("knee", "Real", "parameter", "fixed",
            "Bilinear law: the penetration where the stiffness changes", unit="m", display_unit="mm", start=d.knee,
            min=KNEE_RANGE[0], max=KNEE_RANGE[1], nominal=5e-4))
    add(Var("stiffness_ratio", "Real", "parameter", "fixed",
            "Bilinear law: the stiffness beyond the knee over k_r (> 1 stiffens, < 1 softens; the internal step "
            "shrinks as 1/sqrt of the largest slope)", unit="1", start=d.stiffness_ratio, min=RATIO_RANGE[0],
            max=RATIO_RANGE[1], nominal=1.0))
    for n in FMU_LOBES:
        add(Var(f"casing_lobe{n}.amplitude", "Real", "input", "continuous",
                f"The casing out of round with {n} lobes (from the engine: thermal gradients, mounts, manoeuvre "
                f"loads): its inner radius grows by amplitude cos({n} (theta - phase)), theta the fixed-frame angle; "
                "> 0 opens the gap at the lobes' maxima. Held over each step (transient mode)", unit="m",
                display_unit="mm", start=0.0, min=LOBE_AMPLITUDE_RANGE[0], max=LOBE_AMPLITUDE_RANGE[1],
                nominal=1e-4, feedthrough=False))
        add(Var(f"casing_lobe{n}.phase", "Real", "input", "continuous",
                f"Fixed-frame angle of a maximum of the casing's {n}-lobe out-of-roundness", unit="rad",
                display_unit="deg", start=0.0, min=LOBE_PHASE_RANGE[0], max=LOBE_PHASE_RANGE[1], nominal=1.0,
                feedthrough=False))
    # new variables go here, after every earlier one (their value references stay as they are)
    return numbered(V)


MODEL = ModelInfo(identifier=MODEL_IDENTIFIER, name=MODEL_NAME, description=DESCRIPTION, units=UNITS,
                  default_experiment=DEFAULT_EXPERIMENT, enumerations=ENUMERATIONS, might_return_early=True)

# what the pythonfmu slave reads from its manifest (it imports nothing of fmu_src)
SLAVE_CONSTANTS = {"ENUMERATIONS": ENUMERATIONS, "STATUS_OK": STATUS_OK, "STATUS_DIVERGED": STATUS_DIVERGED,
                   "STATUS_BAD_INPUT": STATUS_BAD_INPUT, "STATUS_UNSTABLE": STATUS_UNSTABLE,
                   "MAX_SUBSTEPS": MAX_SUBSTEPS, "WEAR_HARMONICS": WEAR_HARMONICS}
