"""The C a native build generates from a model's variable list: the header of value references the model's C file
reads (``variables.h``), the variable table the wrappers check every call against (``MODEL_INFO``,
fmu_model.h) and the FMI 3.0 table (``FMI3_INFO``, fmi3_vars.h). Nothing here is written by hand in C: a
variable added to a model's ``variables.py`` reaches the C side in the next build.

>>> from fmu_src.fmi.variables import Var, numbered
>>> print(variables_header(numbered([Var("u", "Real", "input", "continuous", "u"),
...                                  Var("y", "Real", "output", "continuous", "y", size=2, element="y[{k}]",
...                                      element_description="y {k}")]), "M", {}).splitlines()[3])
#define VR_U 0
"""

from __future__ import annotations

from .variables import Var, by_name, c_name, declared, scalars

TYPES = {"Real": "VT_REAL", "Integer": "VT_INTEGER", "Enumeration": "VT_ENUM", "String": "VT_STRING"}
CAUSALITY = {"input": "VC_INPUT", "parameter": "VC_PARAMETER", "output": "VC_OUTPUT"}
VARIABILITY = {"continuous": "VV_CONTINUOUS", "discrete": "VV_DISCRETE", "fixed": "VV_FIXED",
               "tunable": "VV_TUNABLE"}
TYPES3 = {"Float64": "V3_FLOAT64", "Int32": "V3_INT32", "UInt64": "V3_UINT64", "Enumeration": "V3_ENUM",
          "String": "V3_STRING"}
NATIVE2 = ("fmi2", "native")  # the slots the C model works on: the native FMI 2.0 view


class CSourceError(ValueError):
    pass


def c_double(x: float) -> str:
    x = float(x)
    if x != x or x in (float("inf"), float("-inf")):
        raise CSourceError(f"non-finite value {x} in the model data")
    return x.hex() if x != 0.0 else "0.0"  # hexadecimal literals round-trip exactly (C99)


def c_array(name: str, values, kind: str = "double") -> str:
    vals = [c_double(v) for v in values] if kind == "double" else [str(int(v)) for v in values]
    body = ",\n    ".join(", ".join(vals[i:i + 4]) for i in range(0, len(vals), 4)) or "0"
    return f"static const {kind} {name}[] = {{\n    {body}\n}};\n"


def c_string(s: str) -> str:
    return '"' + s.replace("\\", "\\\\").replace('"', '\\"') + '"'


def variables_header(variables: list[Var], identifier: str, enumerations: dict, source: str = "") -> str:
    """variables.h: ``#define VR_<NAME>`` for every variable of the native FMI 2.0 view (an array: its first element,
    and ``N_<NAME>`` its size) and ``#define <TYPE>_<ITEM>`` for every enumeration item."""
    lines = [f"/* variables.h: {identifier}'s value references, generated from {source or 'its variables.py'} by "
             "fmu_src/fmi/csource.py; do not edit. */",
             f"#ifndef {c_name(identifier)}_VARIABLES_H", f"#define {c_name(identifier)}_VARIABLES_H"]
    seen: dict[str, str] = {}
    for v in declared(variables, NATIVE2):
        ident = c_name(v.name)
        if ident in seen:
            raise CSourceError(f"variables '{seen[ident]}' and '{v.name}' have the same C name VR_{ident}")
        seen[ident] = v.name
        lines.append(f"#define VR_{ident} {v.vr}" + (f" /* {v.name}: first of N_{ident} elements */"
                                                      if v.is_array else ""))
        if v.is_array:
            lines.append(f"#define N_{ident} {v.size}")
        if v.stride > 1:
            lines.append(f"#define STRIDE_{ident} {v.stride}")
    for tname, items in enumerations.items():
        for k, (item, _desc) in enumerate(items, start=1):
            lines.append(f"#define {c_name(tname)}_{c_name(item, suffix=True)} {k}")
    lines += ["#endif", ""]
    return "\n".join(lines)


def variable_table(variables: list[Var], guid: str, identifier: str, feedthrough: bool) -> str:
    """The C variable table MODEL_INFO (fmu_model.h) of the native FMI 2.0 view: one entry per value reference, gaps
    (a variable of another build) as entries without a name. The wrapper keeps no String but the 'message'
    output."""
    slots = scalars(declared(variables, NATIVE2))
    by_vr = {v.vr: v for v in slots}
    if len(by_vr) != len(slots) or min(by_vr) < 0:
        raise CSourceError("variable_table: value references must be distinct and >= 0")
    names = {v.name for v in slots}
    bad = [v.name for v in slots if v.type == "String" and v.name != "message"]
    if bad or "message" not in names or "status" not in names:
        raise CSourceError(f"variable_table: a native model has a 'status' and a 'message' output and no other "
                           f"String (got {bad or 'none missing'})")
    rows = []
    for k in range(max(by_vr) + 1):
        v = by_vr.get(k)
        if v is None:
            rows.append("    {0, VT_REAL, VC_OUTPUT, VV_CONTINUOUS, 0, 0.0, 0.0, 0.0, 0, 0}")
            continue
        has = v.min is not None
        start = v.start if isinstance(v.start, int | float) and not isinstance(v.start, bool) else 0
        rows.append(f"    {{{c_string(v.name)}, {TYPES[v.type]}, {CAUSALITY[v.causality]}, "
                    f"{VARIABILITY[v.variability]}, {int(has)}, {c_double(v.min if has else 0.0)}, "
                    f"{c_double(v.max if has else 0.0)}, {c_double(start)}, "
                    f"{c_string(v.start if isinstance(v.start, str) else '')}, {c_string(v.unit or '')}}}")
    vr = {v.name: v.vr for v in slots}
    return "\n".join([
        f"static const model_var VARS[{len(rows)}] = {{", ",\n".join(rows), "};",
        f"const model_info MODEL_INFO = {{{c_string(guid)}, {c_string(identifier)}, {len(rows)}, VARS, "
        f"{int(feedthrough)}, {vr['status']}, {vr['message']}}};", ""])


def fmi3_table(variables: list[Var]) -> str:
    """The C table FMI3_INFO (fmi3_vars.h): each FMI 3.0 variable as the FMI 2.0 slots of its elements (or the time,
    a structural parameter's fixed value, a sum of two slots), and the value-reference index."""
    kind = {"slots": "K3_SLOTS", "time": "K3_TIME", "structural": "K3_STRUCTURAL", "sum": "K3_SUM"}
    vars3 = declared(variables, ("fmi3", "native"))
    named = by_name(vars3)
    lines, rows = ["#include \"fmi3_vars.h\"", ""], []
    for k, v in enumerate(vars3):
        if v.causality == "independent":
            what, slots, fixed = "time", (), 0
        elif v.causality == "structuralParameter":
            what, slots, fixed = "structural", (), int(v.start)
        elif v.sum_of:
            what, slots, fixed = "sum", tuple(named[n].vr for n in v.sum_of), 0
        else:
            what, slots, fixed = "slots", tuple(v.vrs), 0
        ref = "0"
        if slots:
            lines.append(f"static const int SLOTS_{k}[{len(slots)}] = {{{', '.join(map(str, slots))}}};")
            ref = f"SLOTS_{k}"
        size = v.size if what == "slots" else 1
        rows.append(f"    {{{v.vr}u, {c_string(v.name)}, {TYPES3[v.type3]}, {kind[what]}, {size}, {ref}, {fixed}ull}}")
    max_vr = max(v.vr for v in vars3)
    index = [-1] * (max_vr + 1)
    for k, v in enumerate(vars3):
        if index[v.vr] != -1:
            raise CSourceError(f"FMI 3.0 value reference {v.vr} given twice ({v.name})")
        index[v.vr] = k
    lines += [f"static const fmi3_var VARS3[{len(rows)}] = {{", ",\n".join(rows), "};",
              f"static const int BY_VR[{len(index)}] = {{{', '.join(map(str, index))}}};",
              f"const fmi3_info FMI3_INFO = {{{len(rows)}, VARS3, {max_vr}u, BY_VR}};", ""]
    return "\n".join(lines)
