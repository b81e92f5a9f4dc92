"""One record of an FMU variable, for FMI 2.0 and FMI 3.0 alike, and the views the builds take of a model's list.

A model declares its variables once, in its ``variables.py``, as a list of :class:`Var` in value-reference order;
everything else is derived from that list here:

* value references (:func:`numbered`): every variable takes the next free slot, an array one slot per element,
  so adding a variable at the end of the list changes no earlier reference;
* the FMI 2.0 view (:func:`scalars`): an array becomes one scalar variable per element, named and described by
  its ``element`` pattern, with consecutive value references;
* the FMI 3.0 view (:func:`declared` with the ``fmi3`` tag): an array is one variable of ``size`` elements
  whose value reference is its first element's, its dimension a structural parameter or its size;
* the C side (fmu_src/fmi/csource.py): the variable table, the FMI 3.0 table and the header of value
  references a model's C file reads (``VR_<NAME>``).

A variable may be declared in some builds only (``only``): the FMI 3.0 FMU's ``time`` and structural
parameter, or the pythonfmu flavour's ``param_file``. It keeps its value reference in every build; a build that
does not declare it leaves a gap there (FMI allows gaps), so the flavours stay interchangeable.

>>> v = numbered([Var("u", "Real", "input", "continuous", "an input", unit="m"),
...               Var("y", "Real", "output", "continuous", "outputs", size=3, element="y[{k}]",
...                   element_description="output {k}")])
>>> [(s.name, s.vr) for s in scalars(v)]
[('u', 0), ('y[1]', 1), ('y[2]', 2), ('y[3]', 3)]
>>> c_name("casing_force.x"), tidy(5.8476 * (0.4 + 0.5 * 0.6))
('CASING_FORCE_X', 4.09332)
"""

from __future__ import annotations

import re
from collections.abc import Iterable
from dataclasses import dataclass, replace

CAUSALITIES = ("input", "parameter", "output", "local", "independent", "structuralParameter")
VARIABILITIES = ("constant", "fixed", "tunable", "discrete", "continuous")
# FMI 2.0 type names (what a model declares) -> FMI 3.0's; UInt64 exists in FMI 3.0 only (structural parameters)
TYPES3 = {"Real": "Float64", "Integer": "Int32", "Enumeration": "Enumeration", "String": "String",
          "UInt64": "UInt64"}
BUILD_TAGS = ("fmi2", "fmi3", "native", "pythonfmu")


@dataclass(frozen=True)
class Var:
    """An FMU variable: a scalar, or an array of ``size`` elements (FMI 3.0: one variable; FMI 2.0: one scalar per
    element, named ``element.format(k=k)``, k = 1 .. size)."""

    name: str  # FMI 3.0 name; a scalar's name in both versions
    type: str  # Real, Integer, Enumeration, String (FMI 2.0 names; FMI 3.0: TYPES3), or UInt64 (FMI 3.0 only)
    causality: str
    variability: str
    description: str
    unit: str | None = None
    display_unit: str | None = None
    start: float | int | str | None = None
    min: float | None = None
    max: float | None = None
    nominal: float | None = None
    declared_type: str | None = None  # an Enumeration's type (the model's enumerations)
    size: int = 1
    element: str | None = None  # an array: FMI 2.0 name of element {k}, e.g. "blade[{k}].F_N"
    element_description: str | None = None  # an array: FMI 2.0 description of element {k}
    dimension: str | None = None  # an array: the structural parameter holding its size (FMI 3.0); None: the size
    # arrays declared one after the other with the same interleave name are stored element by element (blade 1's
    # F_N, F_T, ..., then blade 2's): their FMI 2.0 value references interleave, stride apart
    interleave: str | None = None
    only: str | None = None  # declared only in the builds with this tag (BUILD_TAGS); None: in every build
    feedthrough: bool = True  # an input the outputs depend on directly in a feedthrough build
    sum_of: tuple[str, str] | None = None  # a local computed as the sum of two variables (FMI 3.0)
    event_indicator: bool = False  # FMI 3.0: listed as an event indicator
    vr: int = -1  # value reference (of the first element): set by numbered()
    stride: int = 1  # between the value references of consecutive elements: set by numbered()

    @property
    def is_array(self) -> bool:
        return self.element is not None

    @property
    def settable(self) -> bool:
        return self.causality in ("input", "parameter")

    @property
    def type3(self) -> str:
        return TYPES3[self.type]

    @property
    def vrs(self) -> range:
        """The value references of its elements (FMI 2.0 slots)."""
        return range(self.vr, self.vr + self.size * self.stride, self.stride)


# FMI 3.0's independent variable (every FMI 3.0 description declares exactly one): a model lists it where it wants
# its value reference (after its FMI 2.0 variables: FMI 2.0 has no such variable and leaves the gap)
TIME = Var("time", "Real", "independent", "continuous", "Simulation time", unit="s", only="fmi3")


def check(variables: Iterable[Var]) -> None:
    """Refuse a list no build could write (one line naming the variable and what is wrong)."""
    seen: set[str] = set()
    for v in variables:
        names = [v.element.format(k=k) for k in range(1, v.size + 1)] if v.is_array else [v.name]
        for n in (v.name, *names) if v.is_array else names:
            if n in seen:
                raise ValueError(f"variable '{n}' declared twice")
            seen.add(n)
        if v.type not in TYPES3:
            raise ValueError(f"{v.name}: type '{v.type}' unknown; accepted: {', '.join(TYPES3)}")
        if v.causality not in CAUSALITIES or v.variability not in VARIABILITIES:
            raise ValueError(f"{v.name}: causality '{v.causality}' or variability '{v.variability}' unknown")
        if v.only is not None and v.only not in BUILD_TAGS:
            raise ValueError(f"{v.name}: only = '{v.only}' unknown; accepted: {', '.join(BUILD_TAGS)}")
        if v.size < 1 or (v.size > 1) != v.is_array or (v.is_array and "{k}" not in v.element):
            raise ValueError(f"{v.name}: an array has size > 1 and an element pattern with {{k}}")
        if (v.min is None) != (v.max is None):
            raise ValueError(f"{v.name}: a range has both ends (min and max)")


def numbered(variables: Iterable[Var]) -> list[Var]:
    """The variables with their value references: each takes the next free slot, an array one per element (a run
    of arrays with the same ``interleave`` name: element 1 of each, then element 2 of each, ...)."""
    out: list[Var] = []
    slot = 0
    variables = list(variables)
    check(variables)
    i = 0
    while i < len(variables):
        v = variables[i]
        run = [v]
        while v.interleave and i + len(run) < len(variables) and variables[i + len(run)].interleave == v.interleave:
            run.append(variables[i + len(run)])
        if len({a.size for a in run}) != 1:
            raise ValueError(f"interleaved arrays '{v.interleave}' must have one size")
        for k, a in enumerate(run):
            out.append(replace(a, vr=slot + k, stride=len(run)))
        slot += len(run) * v.size
        i += len(run)
    return out


def declared(variables: Iterable[Var], tags: Iterable[str]) -> list[Var]:
    """The variables a build declares: those without ``only``, and those whose ``only`` is among the build's tags
    ({"fmi2", "native"}, {"fmi3", "native"}, {"fmi2", "pythonfmu"})."""
    tags = set(tags)
    return [v for v in variables if v.only is None or v.only in tags]


def scalars(variables: Iterable[Var]) -> list[Var]:
    """The FMI 2.0 view, in value-reference order: every array as one scalar per element (named and described by
    its patterns); scalars as they are."""
    out = []
    for v in variables:
        if not v.is_array:
            out.append(v)
            continue
        for k, vr in enumerate(v.vrs, start=1):
            out.append(replace(v, name=v.element.format(k=k), description=v.element_description.format(k=k),
                               size=1, element=None, element_description=None, dimension=None, interleave=None,
                               vr=vr, stride=1))
    return sorted(out, key=lambda v: v.vr)


def by_name(variables: Iterable[Var]) -> dict[str, Var]:
    return {v.name: v for v in variables}


def c_name(name: str, suffix: bool = False) -> str:
    """The C identifier of a variable's name: letters, digits and underscores, upper case (``suffix``: a part
    that follows a prefix, such as an enumeration's item "2D" in FORMULATION_2D, may start with a digit)."""
    out = re.sub(r"[^0-9A-Za-z]+", "_", name).strip("_").upper()
    if not out or (out[0].isdigit() and not suffix):
        raise ValueError(f"variable '{name}': no C identifier can be derived from it")
    return out


def tidy(x: float) -> float:
    """A bound computed from a parameter file written as a person reads it: 12 significant digits, which removes
    the product's round-off (5.8476 * 0.7 is 4.093319999999999, this 4.09332) and moves the value by less than
    1e-12 relative. For bounds that are modelling judgements (a range limit), never for a physical constant."""
    return float(f"{x:.12g}")


def default_nominal(start: float, rng: tuple[float, float] | None) -> float:
    """A parameter's or input's nominal value where none is given: its start value's magnitude, or for a start of 0,
    1 in its unit unless its range is smaller (a closure of range +-10 mm is nominal 10 mm, not 1 m)."""
    return abs(start) or min(1.0, max(abs(rng[0]), abs(rng[1])) if rng else 1.0) or 1.0


def ranged(name: str, unit: str, rng: tuple[float, float], description: str, start: float,
           causality: str = "parameter", variability: str = "fixed") -> Var:
    """A Real parameter (or input) with its unit, declared range and start value, its nominal the default one."""
    return Var(name, "Real", causality, variability, description, unit=unit, start=float(start), min=rng[0],
               max=rng[1], nominal=default_nominal(float(start), rng))


def as_plain(v: Var) -> dict:
    """A variable as JSON-ready data (what a pythonfmu slave reads from its manifest: it imports nothing of
    fmu_src)."""
    return {k: getattr(v, k) for k in ("name", "type", "causality", "variability", "description", "unit",
                                       "display_unit", "start", "min", "max", "nominal", "declared_type", "vr")}
