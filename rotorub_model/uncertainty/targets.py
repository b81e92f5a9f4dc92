"""What an uncertain input changes: a parameter of the parameter file, or an input the engine sets.

A parameter is named ``section.field`` (``contact.g0``, ``imbalance.me``, ``blades.E``) or, in the lists,
``bearings.<name>.field`` / ``disks.<name>.field``; its accepted range is the field's own, read from the
metadata of :mod:`rotorub_model.structure.params` (``_f(lo, hi)``), so that a distribution whose support leaves
it is refused before any work. The engine's inputs on the casing (the liner's, contact/liner.py) are not in
the parameter file and are listed in :data:`ENGINE_INPUTS`.

How an input enters each analysis is the evaluator's (uncertainty/evaluate.py): g0, the engine's closure and
offset move the gaps only (the gaps are affine in them), the imbalance moves the force only, contact.* the
contact law only; any other parameter rebuilds the model for each sample (measured: 0.1 s a sample at 38
dofs, against microseconds for the others).

Extension point (casing distortion): an engine input is one :class:`EngineInput` entry here plus its effect
on the gaps in ``evaluate.py`` (``_engine_gap_shift``) and, for the time loop, on the liner; ovalization is
listed, refused with the reason until the casing's distortion lands.
"""

from __future__ import annotations

from dataclasses import dataclass, fields

from ..errors import ParameterError
from ..structure.params import _LISTS, _SECTIONS, Parameters, _range_text


@dataclass(frozen=True)
class EngineInput:
    name: str
    lo: float
    hi: float
    doc: str
    available: bool = True
    why_not: str = ""


ENGINE_INPUTS: dict[str, EngineInput] = {
    "engine.closure": EngineInput("engine.closure", -0.01, 0.01,
                                  "uniform clearance closure from the engine (thermal, centrifugal growth) [m], > 0 "
                                  "closes; the gap of every point minus this"),
    "engine.offset": EngineInput("engine.offset", 0.0, 0.01,
                                 "casing centre offset in the fixed frame (carcass or manoeuvre load) [m]: every "
                                 "point sweeps it once a revolution, its gap at worst minus n_r x offset"),
    "engine.ovalization": EngineInput("engine.ovalization", 0.0, 0.01,
                                      "two-lobe casing distortion amplitude [m]", available=False,
                                      why_not="the casing's distortion is not in the model yet (the lead's casing "
                                              "distortion work); accepted now: engine.closure, engine.offset"),
}


@dataclass(frozen=True)
class Target:
    """A resolved input target: its name, accepted range and where it goes."""

    name: str
    lo: float
    hi: float
    lo_open: bool
    kind: str  # "param" (section.field), "list" (bearings/disks item), "engine"
    section: str = ""
    item: str = ""  # the list item's name (bearings, disks)
    field: str = ""

    def range_text(self) -> str:
        return _range_text(self.lo, self.hi, self.lo_open)

    def accepts(self, lo: float, hi: float) -> bool:
        """Whether [lo, hi] (a support) lies within the accepted range."""
        if lo < self.lo or hi > self.hi:
            return False
        return not (self.lo_open and lo <= self.lo)


def _field_range(cls: type, name: str, where: str) -> tuple[float, float, bool]:
    for f in fields(cls):
        if f.name == name:
            if "range" not in f.metadata or f.metadata.get("integer") or f.metadata.get("bool"):
                raise ParameterError(f"{where}: not a real-valued parameter (an integer, switch, name or list "
                                     "cannot carry a distribution)")
            return f.metadata["range"]
    names = sorted(f.name for f in fields(cls) if "range" in f.metadata and not f.metadata.get("integer"))
    raise ParameterError(f"{where}: unknown parameter; accepted fields here: {', '.join(names)}")


# the built-in beam blade's own fields: an imported blade ([fe_blade]) takes its mass and stiffness from its
# superelement, so a study input on one of these would silently change nothing
BEAM_ONLY = ("width", "thickness", "E", "rho")


def resolve_target(where: str, name: str, params: Parameters | None) -> Target:
    """The :class:`Target` named ``name`` (``where``: the study file's place, for the message)."""
    if not isinstance(name, str) or not name:
        raise ParameterError(f"{where}: expected a parameter name such as 'contact.g0', got {name!r}")
    if name in ENGINE_INPUTS:
        e = ENGINE_INPUTS[name]
        if not e.available:
            raise ParameterError(f"{where}: '{name}' not available: {e.why_not}")
        return Target(name, e.lo, e.hi, False, "engine")
    parts = name.split(".")
    if parts[0] == "engine":
        ok = [k for k, e in ENGINE_INPUTS.items() if e.available]
        raise ParameterError(f"{where}: '{name}' unknown; accepted engine inputs: {', '.join(ok)}")
    if parts[0] in _SECTIONS and len(parts) == 2:
        lo, hi, lo_open = _field_range(_SECTIONS[parts[0]], parts[1], f"{where}: '{name}'")
        if parts[0] == "blades" and parts[1] in BEAM_ONLY and params is not None and params.fe_blade.superelement:
            # an imported blade's mass and stiffness are its superelement's: a beam field would change nothing
            raise ParameterError(f"{where}: '{name}' is a field of the built-in beam blade, which an imported blade "
                                 f"([fe_blade] {params.fe_blade.superelement}) does not use; accepted for an imported "
                                 "blade: blades.damping_ratio, or mistuning ([mistuning]) for its stiffness")
        return Target(name, lo, hi, lo_open, "param", parts[0], field=parts[1])
    if parts[0] in _LISTS and len(parts) == 3:
        items = [it.name for it in getattr(params, parts[0])] if params is not None else []
        if params is not None and parts[1] not in items:
            raise ParameterError(f"{where}: '{name}': no {parts[0][:-1]} named '{parts[1]}'; accepted: "
                                 f"{', '.join(items)}")
        lo, hi, lo_open = _field_range(_LISTS[parts[0]], parts[2], f"{where}: '{name}'")
        return Target(name, lo, hi, lo_open, "list", parts[0], parts[1], parts[2])
    accepted = sorted(_SECTIONS) + [f"{s}.<name>" for s in _LISTS] + ["engine"]
    raise ParameterError(f"{where}: '{name}' unknown; accepted: section.field with a section among "
                         f"{', '.join(accepted)} (e.g. contact.g0, imbalance.me, bearings.front.k, engine.closure)")


def check_support(where: str, target: Target, support: tuple[float, float], describe: str) -> None:
    """One line when the distribution can leave the parameter's accepted range."""
    lo, hi = support
    if not target.accepts(lo, hi):
        sup = f"[{lo:g}, {hi:g}]".replace("inf]", "inf)").replace("[-inf", "(-inf")
        raise ParameterError(f"{where}: {describe} has support {sup}, which leaves the accepted range of "
                             f"{target.name}, {target.range_text()}; bound it (truncnormal, uniform, triangular) "
                             "within the range")


def apply_to_params(params: Parameters, targets: list[Target], values) -> Parameters:
    """The parameters with the ``param`` and ``list`` targets set to ``values`` (validated again)."""
    from ..structure.params import to_dict

    sections: dict = {}
    lists: dict = {}
    for t, v in zip(targets, values):
        if t.kind == "param":
            sections.setdefault(t.section, {})[t.field] = float(v)
        elif t.kind == "list":
            lists.setdefault(t.section, {}).setdefault(t.item, {})[t.field] = float(v)
    if not sections and not lists:
        return params
    if lists:
        d = to_dict(params)
        for sec, by_item in lists.items():
            sections[sec] = [{**it, **by_item.get(it["name"], {})} for it in d[sec]]
    return params.replace(**sections)


__all__ = ["ENGINE_INPUTS", "EngineInput", "Target", "apply_to_params", "check_support", "resolve_target"]
