"""Typed, validated parameters of the bladed rotor / casing model (SI units).

Every field carries its accepted range in its metadata; :func:`load_parameters`
reads a TOML file, rejects unknown, missing, non-finite and out-of-range values
with a :class:`~rotorub_model.errors.ParameterError` naming ``section.field`` and
the accepted range, then checks the cross-field consistency rules.

Examples
--------
>>> from rotorub_model.structure.params import reference_parameters
>>> p = reference_parameters()
>>> p.blades.count
10
>>> round(p.blades.tip_radius, 3)
1.0
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field, fields
from pathlib import Path
from typing import Any

try:
    import tomllib
except ImportError:  # Python 3.10
    import tomli as tomllib

from ..errors import ParameterError

# next to the package, wherever it is installed or copied (the FMU carries a renamed copy)
REFERENCE_FILE = Path(__file__).resolve().parents[1] / "data" / "reference.toml"

INF = math.inf


def _f(lo: float, hi: float = INF, *, lo_open: bool = False, doc: str = "", integer: bool = False,
       default: Any = dataclasses.MISSING):
    """A dataclass field with an accepted range [lo, hi] (or (lo, hi] if lo_open); with a default,
    the field may be left out of a parameter file."""
    return field(default=default, metadata={"range": (lo, hi, lo_open), "doc": doc, "integer": integer})


@dataclass(frozen=True)
class ShaftParams:
    E: float = _f(0, lo_open=True, doc="Young's modulus [Pa]")
    rho: float = _f(0, lo_open=True, doc="density [kg/m^3]")
    outer_diameter: float = _f(0, lo_open=True, doc="outer diameter [m]")
    inner_diameter: float = _f(0, doc="inner diameter [m] (0 = solid)")
    length: float = _f(0, lo_open=True, doc="length [m]; z=0 at the fan end, +z downstream")
    n_ritz: int = _f(2, 14, integer=True, doc="component-mode Ritz functions per transverse direction")

    @property
    def area(self) -> float:
        return math.pi / 4 * (self.outer_diameter**2 - self.inner_diameter**2)

    @property
    def second_moment(self) -> float:
        return math.pi / 64 * (self.outer_diameter**4 - self.inner_diameter**4)


@dataclass(frozen=True)
class BearingParams:
    name: str
    z: float = _f(0, doc="axial position [m]")
    k: float = _f(0, lo_open=True, doc="isotropic radial stiffness [N/m]")
    c: float = _f(0, doc="isotropic radial damping [N s/m]")


@dataclass(frozen=True)
class DiskParams:
    name: str
    z: float = _f(0, doc="axial position [m]")
    mass: float = _f(0, lo_open=True, doc="mass [kg]")
    Ip: float = _f(0, doc="polar moment of inertia [kg m^2]")
    Id: float = _f(0, doc="diametral moment of inertia [kg m^2]")


@dataclass(frozen=True)
class BladeParams:
    count: int = _f(3, 200, integer=True, doc="number of blades (3 or more: with two the bladed disk is "
                                              "anisotropic, its split critical speeds bound a band where the "
                                              "rotating frame's static response is unbounded)")
    hub_radius: float = _f(0, lo_open=True, doc="clamping radius r_d on the fan disk [m]")
    length: float = _f(0, lo_open=True, doc="blade length l_b [m]")
    width: float = _f(0, lo_open=True, doc="section width (chord of the beam section) [m]")
    thickness: float = _f(0, lo_open=True, doc="section thickness (flexible direction) [m]")
    E: float = _f(0, lo_open=True, doc="Young's modulus [Pa]")
    rho: float = _f(0, lo_open=True, doc="density [kg/m^3]")
    stagger_deg: float = _f(0, 90, doc="stagger angle from the axial direction [deg]")
    n_ritz: int = _f(1, 12, integer=True, doc="polynomial Ritz functions per blade (the accuracy of its modes)")
    damping_ratio: float = _f(0, 0.5, doc="modal damping ratio of blade bending (rotating frame)")
    n_modes: int = _f(1, 12, integer=True, default=2,
                      doc="blade modes kept (the lowest cantilever modes of the n_ritz functions; at most n_ritz): "
                          "the dofs per blade, and what sets the explicit time step")

    @property
    def dofs(self) -> int:
        """Generalised coordinates per blade: the modes kept (all n_ritz functions when n_modes >= n_ritz)."""
        return min(self.n_modes, self.n_ritz)

    @property
    def tip_radius(self) -> float:
        return self.hub_radius + self.length

    @property
    def area(self) -> float:
        return self.width * self.thickness

    @property
    def second_moment(self) -> float:
        return self.width * self.thickness**3 / 12.0

    @property
    def mass(self) -> float:
        return self.rho * self.area * self.length


@dataclass(frozen=True)
class CasingParams:
    mass: float = _f(0, lo_open=True, doc="rigid-body mass of the casing [kg]")
    tilt_inertia: float = _f(0, lo_open=True, doc="diametral inertia about its centre of gravity [kg m^2]")
    z_cg: float = _f(-INF, doc="axial offset of the casing centre of gravity from the blade-tip plane [m]")
    ring_thickness: float = _f(0, lo_open=True, doc="radial thickness of the elastic ring [m]")
    ring_width: float = _f(0, lo_open=True, doc="axial width of the elastic ring [m]")
    E: float = _f(0, lo_open=True, doc="Young's modulus of the ring [Pa]")
    rho: float = _f(0, lo_open=True, doc="density of the ring [kg/m^3]")
    modes: tuple[int, ...] = field(metadata={"doc": "nodal diameters of the ring modes"})
    damping_ratio: float = _f(0, 0.5, doc="modal damping ratio of the ring modes (fixed frame)")


@dataclass(frozen=True)
class SuspensionParams:
    k_translation: float = _f(0, lo_open=True, doc="isotropic translational stiffness [N/m]")
    c_translation: float = _f(0, doc="isotropic translational damping [N s/m]")
    k_rotation: float = _f(0, lo_open=True, doc="isotropic tilt stiffness [N m/rad]")
    c_rotation: float = _f(0, doc="isotropic tilt damping [N m s/rad]")


@dataclass(frozen=True)
class ImbalanceParams:
    disk: str
    me: float = _f(0, doc="imbalance m*e [kg m]")
    angle_deg: float = _f(-360, 360, doc="angular position of the imbalance in the rotating frame [deg]")


@dataclass(frozen=True)
class ContactParams:
    # The ranges are the project's one declaration of what each parameter accepts: the parameter file, the FMUs'
    # declared min/max and the CLI read them here (accepted_range). Where a bound is a modelling judgement, the
    # doc says why; the FMU's g0 narrows its lower end to -max_penetration (deeper diverges at t = 0).
    k_r: float = _f(1e3, 1e10, doc="normal penalty stiffness of one whole blade tip [N/m] (1e3: no force to speak "
                                   "of; 1e10: the stable explicit step shrinks as 1/sqrt(k_r))")
    mu: float = _f(0, 1, doc="Coulomb friction coefficient (1: beyond dry titanium on any coating)")
    theta_deg: float = _f(0, 60, doc="inclination of the conical casing inner surface [deg] (the paper studies "
                                     "0-30; the linearised cone gap degrades towards 90)")
    chord: float = _f(1e-3, 0.5, doc="blade tip chord length l_c [m]")
    g0: float = _f(-INF, doc="nominal tip clearance [m] (negative = initial interference)")
    slip_velocity: float = _f(1e-4, 10.0, default=0.1,
                              doc="velocity scale of the friction regularisation mu tanh(v / v_slip) [m/s] "
                                  "(default 0.1 m/s: far below the tip speeds of the paper's range (30 m/s at "
                                  "Omega_ref), where friction is the exact Coulomb law, and large enough that the "
                                  "explicit scheme stays stable, docs/THEORY.md)")
    max_penetration: float = _f(1e-5, 0.05, default=3.0e-3,
                                doc="penetration beyond which a transient is declared diverged [m] (default 3 mm: "
                                    "the depth of a fan-case abradable liner; deeper, the blade cuts the case "
                                    "structure and the penalty law means nothing)")
    law: str = field(default="penalty", metadata={
        "choices": ("penalty", "bilinear"),
        "doc": "normal contact law (docs/THEORY.md 4.0): penalty (the paper's, F = k_r delta) or bilinear (a coating "
               "then a stiffer or softer layer: F = k_r delta + (stiffness_ratio - 1) k_r (delta - knee)_+)"})
    knee: float = _f(1e-6, 0.05, default=0.5e-3,
                     doc="bilinear law: the penetration where the stiffness changes [m] (default 0.5 mm: a thin "
                         "coating over a stiffer layer)")
    stiffness_ratio: float = _f(0.01, 100.0, default=4.0,
                                doc="bilinear law: the stiffness beyond the knee over k_r (> 1 stiffens, < 1 "
                                    "softens; default 4; the explicit step shrinks as 1/sqrt of the largest slope)")

    @property
    def law_params(self) -> tuple[float, ...]:
        """The law's parameters in the kernel's order (contact/laws.py)."""
        from ..contact.laws import law_params

        return law_params(self)


@dataclass(frozen=True)
class AbradableParams:
    """The casing's abradable liner (docs/THEORY.md, "Abradable liner"); off by default: the paper's casing
    is rigid, and every result of the reference stays as it is."""

    enabled: bool = field(default=False, metadata={"doc": "the casing is lined with a coating that wears (the "
                                                          "paper: false, a rigid casing)", "bool": True})
    yield_force: float = _f(1e-3, 1e7, default=100.0,
                            doc="a blade tip's normal force at which the liner starts to be removed [N] (a 3D "
                                "chord pressed uniformly yields at the same total force); default: of the order "
                                "of the reference rub's own forces, so that it wears (docs/THEORY.md 4.1); a "
                                "coating's crushing strength times the tip's footprint for a given liner")
    hardening: float = _f(0, 1e10, default=0.0, doc="linear hardening: yield force gained per metre removed [N/m] "
                                                   "(0: perfectly plastic)")
    thickness: float = _f(1e-5, 0.05, default=2.0e-3,
                          doc="liner thickness [m]: no wear beyond it (the casing's substrate)")
    n_sectors: int = _f(8, 100000, integer=True, default=720,
                        doc="cells of the liner over the circumference (fixed frame; 720: half a degree)")


@dataclass(frozen=True)
class FEBladeParams:
    """An imported finite-element blade in place of the built-in beam (docs/THEORY.md 9): a superelement file that
    ``rotorub import-blade`` wrote (the reduced blade, its rotating-frame terms, its tip nodes). Off by default:
    the built-in blades of [blades]. With it, [blades] gives the count, the tip radius (the casing's line) and the
    stagger; the beam's own fields are not used."""

    superelement: str = field(default="", metadata={"doc": "path of the superelement (.npz, relative to the "
                                                           "parameter file); empty: the built-in blades",
                                                    "path": True})
    stations: int = _f(2, 64, integer=True, default=12,
                       doc="the most chord stations the tip's nodes are gathered into (each station a point of "
                           "the 3D contact law; the segments between them carry the chord law)")


@dataclass(frozen=True)
class FECasingParams:
    """The casing's flexible modes from a finite-element modal model in place of the built-in ring's (docs/THEORY.md
    9.6): a file that ``FECasing.save`` wrote (per nodal diameter: modal mass, stiffness and the tangential and axial
    ratios of its shape on the contact circle). Off by default: the ring of [casing]. With it, [casing] gives the
    rigid mass and tilt inertia, the nodal diameters kept (``modes``) and their damping ratio; the ring's own fields
    (ring_thickness, ring_width, E, rho) are not used."""

    model: str = field(default="", metadata={"doc": "path of the FE casing's modal model (.json, relative to the "
                                                    "parameter file); empty: the built-in ring",
                                             "path": True})


@dataclass(frozen=True)
class NormalisationParams:
    omega_ref: float = _f(0, lo_open=True, doc="reference angular speed for the normalised spin speed [rad/s]")
    speed_max: float = _f(0, lo_open=True, default=12.0,
                          doc="upper end of the model's validity, normalised (default 12: the paper's range 0-10 "
                              "with a margin; the FMU refuses faster spin speeds)")


@dataclass(frozen=True)
class Parameters:
    """The whole model: one object per component, all values in SI units."""

    shaft: ShaftParams
    bearings: tuple[BearingParams, ...]
    disks: tuple[DiskParams, ...]
    blades: BladeParams
    casing: CasingParams
    suspension: SuspensionParams
    imbalance: ImbalanceParams
    contact: ContactParams
    normalisation: NormalisationParams
    abradable: AbradableParams = AbradableParams()
    fe_blade: FEBladeParams = FEBladeParams()
    fe_casing: FECasingParams = FECasingParams()

    def replace(self, **sections: dict[str, Any]) -> Parameters:
        """Return a copy with some fields of some sections replaced, validated again.

        >>> p = reference_parameters().replace(contact={"g0": 1e-3})
        >>> p.contact.g0
        0.001
        """
        data = to_dict(self)
        for sec, values in sections.items():
            if sec not in data:
                raise ParameterError(f"unknown section '{sec}'; accepted: {', '.join(data)}")
            if isinstance(data[sec], list):
                data[sec] = values
            else:
                data[sec] = {**data[sec], **values}
        return from_dict(data)

    @property
    def fan_disk(self) -> DiskParams:
        return next(d for d in self.disks if d.name == self.imbalance.disk)


_SECTIONS: dict[str, type] = {
    "shaft": ShaftParams,
    "blades": BladeParams,
    "casing": CasingParams,
    "suspension": SuspensionParams,
    "imbalance": ImbalanceParams,
    "contact": ContactParams,
    "normalisation": NormalisationParams,
    "abradable": AbradableParams,
    "fe_blade": FEBladeParams,
    "fe_casing": FECasingParams,
}
# may be left out of a parameter file: every field has its default
_OPTIONAL_SECTIONS = {"abradable", "fe_blade", "fe_casing"}
_LISTS: dict[str, type] = {"bearings": BearingParams, "disks": DiskParams}


def _range_text(lo: float, hi: float, lo_open: bool) -> str:
    left = "(" if lo_open else "["
    right = "]" if hi != INF else ")"
    return f"{left}{lo:g}, {hi:g}{right}" if hi != INF else f"{left}{lo:g}, inf)"


def _check_value(where: str, f: dataclasses.Field, value: Any) -> Any:
    meta = f.metadata
    if f.name == "modes":
        if not isinstance(value, list | tuple) or not value:
            raise ParameterError(f"{where}: expected a non-empty list of integers >= 2")
        for n in value:
            if not isinstance(n, int) or isinstance(n, bool) or n < 2:
                raise ParameterError(f"{where}: nodal diameter {n!r} out of range; accepted: integers >= 2")
        if len(set(value)) != len(value):
            raise ParameterError(f"{where}: repeated nodal diameter in {list(value)}")
        return tuple(int(n) for n in value)
    if meta.get("bool"):
        if not isinstance(value, bool):
            raise ParameterError(f"{where}: expected true or false, got {value!r}")
        return value
    if meta.get("path"):
        if not isinstance(value, str):
            raise ParameterError(f"{where}: expected a file path (a string), got {value!r}")
        return value
    if f.type in ("str", str):
        choices = meta.get("choices")
        if choices and value not in choices:
            raise ParameterError(f"{where}: {value!r} unknown; accepted: {', '.join(choices)}")
        if not isinstance(value, str) or not value:
            raise ParameterError(f"{where}: expected a non-empty string, got {value!r}")
        return value
    lo, hi, lo_open = meta["range"]
    rng = _range_text(lo, hi, lo_open)
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise ParameterError(f"{where}: expected a number in {rng}, got {value!r}")
    if meta.get("integer"):
        if not isinstance(value, int) and not float(value).is_integer():
            raise ParameterError(f"{where}: expected an integer in {rng}, got {value!r}")
        value = int(value)
    else:
        value = float(value)
    if not math.isfinite(value):
        raise ParameterError(f"{where}: value {value} is not finite; accepted range {rng}")
    if value < lo or (lo_open and value == lo) or value > hi:
        raise ParameterError(f"{where}: value {value:g} out of range; accepted range {rng}")
    return value


def _build(cls: type, where: str, data: Any) -> Any:
    if not isinstance(data, dict):
        raise ParameterError(f"{where}: expected a table of fields, got {type(data).__name__}")
    names = {f.name for f in fields(cls)}
    unknown = sorted(set(data) - names)
    if unknown:
        raise ParameterError(f"{where}.{unknown[0]}: unknown field; accepted fields: {', '.join(sorted(names))}")
    kwargs = {}
    for f in fields(cls):
        if f.name not in data:
            if f.default is not dataclasses.MISSING:
                kwargs[f.name] = f.default
                continue
            raise ParameterError(f"{where}.{f.name}: missing ({f.metadata.get('doc', 'required')})")
        kwargs[f.name] = _check_value(f"{where}.{f.name}", f, data[f.name])
    return cls(**kwargs)


def from_dict(data: dict[str, Any]) -> Parameters:
    """Build and validate :class:`Parameters` from a nested dict (as read from TOML)."""
    if not isinstance(data, dict):
        raise ParameterError("parameters: expected a table of sections")
    known = set(_SECTIONS) | set(_LISTS)
    unknown = sorted(set(data) - known)
    if unknown:
        raise ParameterError(f"{unknown[0]}: unknown section; accepted: {', '.join(sorted(known))}")
    kwargs: dict[str, Any] = {}
    for sec, cls in _SECTIONS.items():
        if sec not in data and sec in _OPTIONAL_SECTIONS:
            kwargs[sec] = cls()
            continue
        if sec not in data:
            raise ParameterError(f"{sec}: missing section")
        kwargs[sec] = _build(cls, sec, data[sec])
    for sec, cls in _LISTS.items():
        items = data.get(sec)
        if not isinstance(items, list) or not items:
            raise ParameterError(f"{sec}: missing; expected a non-empty array of tables [[{sec}]]")
        kwargs[sec] = tuple(_build(cls, f"{sec}[{i}]", d) for i, d in enumerate(items))
    p = Parameters(**kwargs)
    _check_consistency(p)
    return p


def _check_consistency(p: Parameters) -> None:
    s = p.shaft
    if s.inner_diameter >= s.outer_diameter:
        raise ParameterError(
            f"shaft.inner_diameter: {s.inner_diameter:g} m must be < shaft.outer_diameter = {s.outer_diameter:g} m"
        )
    if len(p.bearings) < 1:
        raise ParameterError("bearings: at least one bearing is needed")
    for group, items in (("bearings", p.bearings), ("disks", p.disks)):
        names = [it.name for it in items]
        if len(set(names)) != len(names):
            raise ParameterError(f"{group}: names must be unique, got {names}")
        for i, it in enumerate(items):
            if it.z > s.length:
                raise ParameterError(
                    f"{group}[{i}].z: {it.z:g} m out of range; accepted range [0, shaft.length={s.length:g}]"
                )
    if len(p.bearings) == 1:
        raise ParameterError("bearings: two or more bearings are needed to hold the shaft (got 1)")
    zs = sorted((b.z, b.name) for b in p.bearings)
    for (za, na), (zb, nb) in zip(zs, zs[1:]):
        if zb - za <= 1e-6 * s.length:
            raise ParameterError(f"bearings[{nb}].z: {zb:g} m is where bearings[{na}] is; accepted: a position of its "
                                 "own (two bearings at one point hold the shaft like one: it pivots there)")
    if p.imbalance.disk not in [d.name for d in p.disks]:
        raise ParameterError(
            f"imbalance.disk: '{p.imbalance.disk}' is not a disk; accepted: {', '.join(d.name for d in p.disks)}"
        )
    for d in p.disks:
        if d.Ip > 2 * d.Id * (1 + 1e-9):
            raise ParameterError(
                f"disks[{d.name}].Ip: {d.Ip:g} kg m^2 violates the inertia triangle inequality; "
                f"accepted range [0, 2*Id={2 * d.Id:g}]"
            )
    b = p.blades
    if b.thickness > b.width:
        raise ParameterError(
            f"blades.thickness: {b.thickness:g} m must not exceed blades.width = {b.width:g} m "
            "(the model bends the blade about its most flexible axis)"
        )
    casing_inner = b.tip_radius + max(p.contact.g0, 0.0)
    if p.contact.g0 <= -0.5 * b.length:
        raise ParameterError(f"contact.g0: {p.contact.g0:g} m out of range; accepted range (-blades.length/2, "
                             f"{INPUT_RANGES['g0_max'][1]:g}] m")
    if p.casing.ring_thickness >= casing_inner:
        raise ParameterError("casing.ring_thickness: must be smaller than the casing inner radius")
    half_chord_axial = 0.5 * p.contact.chord
    if half_chord_axial >= b.tip_radius:
        raise ParameterError(
            f"contact.chord: {p.contact.chord:g} m out of range; accepted range (0, 2*tip radius={2 * b.tip_radius:g})"
        )


# The engine's inputs on the casing: not parameter-file fields (they change during a run: the FMUs' inputs, the
# liner's set_inputs, the CLI's --closure/--offset), declared here once with the fields' ranges. Closure and offset
# up to 10 mm: an engine's thermal and centrifugal growth and a carcass or manoeuvre load, with margin; a lobe's
# amplitude likewise; g0's upper end 100 mm (its lower end is -contact.max_penetration: deeper diverges at t = 0).
INPUT_RANGES: dict[str, tuple[float, float]] = {
    "clearance_closure": (-0.01, 0.01),   # [m] uniform closure of the clearance (> 0 closes)
    "casing_offset": (-0.01, 0.01),       # [m] rigid offset of the casing centre, each fixed-frame component
    "casing_lobe_amplitude": (-0.01, 0.01),  # [m] a_n of the out-of-round casing, n = 2..8
    "casing_lobe_phase": (-2 * math.pi, 2 * math.pi),  # [rad] psi_n, where lobe n is widest
    "g0_max": (0.0, 0.1),                 # [m] the largest nominal clearance an FMU or the CLI accepts
}


def accepted_range(name: str) -> tuple[float, float]:
    """The accepted closed range [lo, hi] of parameter ``section.field`` (the one declaration, read by the
    parameter file, the FMUs' variables and the CLI); an open lower end is returned as the value itself (the
    callers that declare ranges, FMI among them, know only inclusive bounds: they refuse it separately)."""
    if name in INPUT_RANGES:
        lo, hi = INPUT_RANGES[name]
        return float(lo), float(hi)
    sec, _, fname = name.partition(".")
    cls = _SECTIONS.get(sec) or _LISTS.get(sec)
    f = next((f for f in fields(cls) if f.name == fname), None) if cls else None
    if f is None or "range" not in f.metadata:
        raise KeyError(f"{name}: no declared range")
    lo, hi, _ = f.metadata["range"]
    return float(lo), float(hi)


def describe(name: str) -> str:
    """The declared description of parameter ``section.field``."""
    sec, _, fname = name.partition(".")
    cls = _SECTIONS.get(sec) or _LISTS.get(sec)
    f = next((f for f in fields(cls) if f.name == fname), None) if cls else None
    if f is None:
        raise KeyError(f"{name}: unknown parameter")
    return f.metadata.get("doc", "")


def load_parameters(path: str | Path | None = None) -> Parameters:
    """Load and validate a parameter file; ``None`` loads the shipped reference.

    Raises
    ------
    ParameterError
        If the file cannot be read or parsed, or any value is invalid; the message
        names the file and the offending field.
    """
    if path is None:
        text = REFERENCE_FILE.read_text()
        where = "reference.toml"
    else:
        try:
            text = Path(path).read_text()
        except OSError as exc:
            raise ParameterError(f"parameter file '{path}': cannot be read ({exc.strerror or exc})") from None
        where = str(path)
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ParameterError(f"parameter file '{where}': not valid TOML ({exc})") from None
    # a superelement named relative to the parameter file: from its folder, wherever the command runs
    for section, key in (("fe_blade", "superelement"), ("fe_casing", "model")):
        fe = data.get(section) if isinstance(data, dict) else None
        if path is not None and isinstance(fe, dict) and isinstance(fe.get(key), str) and fe[key]:
            f = Path(fe[key]).expanduser()
            fe[key] = str(f if f.is_absolute() else (Path(path).resolve().parent / f))
    try:
        p = from_dict(data)
    except ParameterError as exc:
        raise ParameterError(f"{where}: {exc}") from None
    if p.contact.g0 > INPUT_RANGES["g0_max"][1]:
        # what the CLI and the FMUs accept: a file's g0 beyond it (0.5 written for 0.5 mm) was taken as metres and
        # only refused later, by rotorub static, under the name of a flag the user never gave (--g0). A file only:
        # the library itself may place a casing far away (make_contact(model, f, g0=1.0): a rotor that never touches)
        raise ParameterError(f"{where}: contact.g0: {p.contact.g0:g} m out of range; accepted range "
                             f"(-blades.length/2, {INPUT_RANGES['g0_max'][1]:g}] m (metres: 0.5 mm is 0.5e-3)")
    return p


_REFERENCE: Parameters | None = None


def reference_parameters() -> Parameters:
    """The embedded reference configuration (cached)."""
    global _REFERENCE
    if _REFERENCE is None:
        _REFERENCE = load_parameters(None)
    return _REFERENCE


def _toml_value(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        return repr(v)  # the shortest decimal that reads back to the same double; valid TOML
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(v, list | tuple):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    raise TypeError(f"no TOML form for {v!r}")


def to_toml(p: Parameters) -> str:
    """The parameters as a TOML parameter file (what :func:`load_parameters` reads back to the same values)."""
    d = to_dict(p)
    lines = ["# rotorub parameter file (SI units), written by rotorub_model.structure.params.to_toml", ""]
    for sec, val in d.items():
        if isinstance(val, list):
            for item in val:
                lines += [f"[[{sec}]]", *(f"{k} = {_toml_value(v)}" for k, v in item.items()), ""]
        else:
            lines += [f"[{sec}]", *(f"{k} = {_toml_value(v)}" for k, v in val.items()), ""]
    return "\n".join(lines)


def to_dict(p: Parameters) -> dict[str, Any]:
    """Nested plain-dict form of the parameters (round-trips through :func:`from_dict`)."""
    out: dict[str, Any] = {}
    for sec in _SECTIONS:
        d = dataclasses.asdict(getattr(p, sec))
        out[sec] = {k: (list(v) if isinstance(v, tuple) else v) for k, v in d.items()}
    for sec in _LISTS:
        out[sec] = [dataclasses.asdict(it) for it in getattr(p, sec)]
    return out
