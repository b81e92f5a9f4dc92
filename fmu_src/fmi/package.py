"""Build the native FMUs: FMI 2.0 co-simulation in C, no Python on the host.

    rotorub build-fmu --native [--params my.toml] [--out fmus/native] [--platforms linux64 win64 ...]

What goes in a native FMU (RotorCasingContact here; LPSpool through the same packaging,
fmu_src/engine/spool.py):

* ``modelDescription.xml``: the model's variables (for RotorCasingContact fmu_src/interface.py's, the same
  variables, value references, units and ranges as the pythonfmu FMU) with ``<SourceFiles>``;
* ``sources/``: the FMI wrapper (fmi2_cs.c, fmu_model.h), the model (contact_model.c and the rotorub kernel;
  or spool_model.c), the generated variable table and model data (model_data.c, floats as exact hex
  literals), the kernel's elementary functions (rr_math.h: the same bits on every platform), the FMI 2.0
  headers (fmpy's copy of the standard's) and a CMakeLists.txt: a user rebuilds the binary for another
  platform with CMake or with fmpy's helper (``fmpy.build.build_platform_binary``), both of which give a
  binary that needs no libm on x86_64 and aarch64 and computes the shipped numbers;
* ``binaries/<platform>/<id>.{so,dll,dylib}``: linux64 and aarch64-linux for glibc 2.17, win64, darwin64 and
  aarch64-darwin (fmu_src/build/native_compile.py);
* ``documentation/index.html`` (and the cross-check kit next to the contact FMU: crosscheck.py).
"""

from __future__ import annotations

import html
import json
import shutil
import sys
import tempfile
import zipfile
from pathlib import Path

from .. import interface
from .native_compile import NativeBuildError, compile_platforms

HERE = Path(__file__).resolve().parent.parent  # fmu_src/
NATIVE = HERE / "native"
WRAPPER = ("fmi2_cs.c", "fmu_core.c", "fmu_core.h", "fmu_model.h")
WRAPPER3 = ("fmi3_cs.c", "fmu_core.c", "fmu_core.h", "fmu_model.h", "fmi3_vars.h")
C_SOURCES = ("fmi2_cs.c", "fmu_core.c", "contact_model.c", "model_data.c", "rotorub_kernel.c")
FMI_HEADERS = ("fmi2Functions.h", "fmi2FunctionTypes.h", "fmi2TypesPlatform.h")
FMI3_HEADERS = ("fmi3Functions.h", "fmi3FunctionTypes.h", "fmi3PlatformTypes.h")

__all__ = ["NativeBuildError", "build_native_fmu", "package_native_fmu", "variable_table"]


def fmi_headers(headers: tuple[str, ...] = FMI_HEADERS) -> Path:
    """The folder of the standard's FMI headers (2.0 by default), as fmpy ships them."""
    try:
        import fmpy
    except ImportError:
        raise NativeBuildError("the native FMU build takes the FMI headers from fmpy: pip install fmpy") from None
    d = Path(fmpy.__file__).resolve().parent / "c-code"
    missing = [h for h in headers if not (d / h).exists()]
    if missing:
        raise NativeBuildError(f"fmpy's FMI headers not found ({', '.join(missing)} in {d})")
    return d


def _c_double(x: float) -> str:
    x = float(x)
    if x != x or x in (float("inf"), float("-inf")):
        raise NativeBuildError(f"non-finite value {x} in the model data")
    return x.hex() if x != 0.0 else "0.0"  # hexadecimal literals round-trip exactly (C99)


def _array(name: str, values, kind: str = "double") -> str:
    vals = [_c_double(v) for v in values] if kind == "double" else [str(int(v)) for v in values]
    body = ",\n    ".join(", ".join(vals[i:i + 4]) for i in range(0, len(vals), 4)) or "0"
    return f"static const {kind} {name}[] = {{\n    {body}\n}};\n"


def _c_string(s: str) -> str:
    return '"' + s.replace("\\", "\\\\").replace('"', '\\"') + '"'


def variable_table(variables: list[interface.Var], guid: str, identifier: str, feedthrough: bool) -> str:
    """The C variable table MODEL_INFO (fmu_model.h) of a model: one entry per value reference, gaps as
    entries without a name. The wrapper keeps no String but the 'message' output."""
    types = {"Real": "VT_REAL", "Integer": "VT_INTEGER", "Enumeration": "VT_ENUM", "String": "VT_STRING"}
    caus = {"input": "VC_INPUT", "parameter": "VC_PARAMETER", "output": "VC_OUTPUT"}
    var = {"continuous": "VV_CONTINUOUS", "discrete": "VV_DISCRETE", "fixed": "VV_FIXED", "tunable": "VV_TUNABLE"}
    by_vr = {v.vr: v for v in variables}
    if len(by_vr) != len(variables) or min(by_vr) < 0:
        raise NativeBuildError("variable_table: value references must be distinct and >= 0")
    bad = [v.name for v in variables if v.type == "String" and v.name != "message"]
    if bad or "message" not in {v.name for v in variables} or "status" not in {v.name for v in variables}:
        raise NativeBuildError(f"variable_table: a native model has a 'status' and a 'message' output and no other "
                               f"String (got {bad or 'none missing'})")
    rows = []
    for k in range(max(by_vr) + 1):
        v = by_vr.get(k)
        if v is None:
            rows.append("    {0, VT_REAL, VC_OUTPUT, VV_CONTINUOUS, 0, 0.0, 0.0, 0.0, 0}")
            continue
        has = v.min is not None
        start = v.start if isinstance(v.start, int | float) and not isinstance(v.start, bool) else 0
        rows.append(f"    {{{_c_string(v.name)}, {types[v.type]}, {caus[v.causality]}, {var[v.variability]}, "
                    f"{int(has)}, {_c_double(v.min if has else 0.0)}, {_c_double(v.max if has else 0.0)}, "
                    f"{_c_double(start)}, {_c_string(v.start if isinstance(v.start, str) else '')}}}")
    vr = {v.name: v.vr for v in variables}
    return "\n".join([
        f"static const model_var VARS[{len(rows)}] = {{", ",\n".join(rows), "};",
        f"const model_info MODEL_INFO = {{{_c_string(guid)}, {_c_string(identifier)}, {len(rows)}, VARS, "
        f"{int(feedthrough)}, {vr['status']}, {vr['message']}}};", ""])


def contact_model_data(model, variables: list[interface.Var]) -> str:
    """The contact model's part of model_data.c: the structure's matrices and the geometry's ingredients."""
    from rotorub_model import kernel
    from rotorub_model.contact.geometry import geometry_spec

    vr = {v.name: v.vr for v in variables}
    fixed = ["Omega", "imbalance", "formulation", "mode", None, "g0", "k_r", "mu", "theta", "chord", "dt_max",
             "max_penetration", "slip_velocity"]
    got = [next((v.name for v in variables if v.vr == k), None) for k in range(len(fixed))]
    if got != fixed:
        raise NativeBuildError(f"interface order changed: contact_model.h expects {fixed} first, got {got}")
    nb = model.params.blades.count
    index = [vr[f"blade[{j}].{b}"] for b in kernel.OUT_BLADE_NAMES for j in range(1, nb + 1)]
    index += [vr[g] for g in kernel.OUT_GLOBAL_NAMES]
    spec = geometry_spec(model, 2, 0.0, 0.0, True)
    wear = [vr[f"wear.{k}"] for k in ("depth_max", "depth_mean", "volume", "plastic_work", "lobes")]
    wear += [vr[f"wear.harmonic[{h}]"] for h in range(1, interface.WEAR_HARMONICS + 1)]
    out = [
        f"const int VR_N_CONTACT = {vr['n_contact']}, VR_MAX_REAL = {vr['max_real_eig']}, "
        f"VR_DT_INTERNAL = {vr['dt_internal']}, VR_N_SUBSTEPS = {vr['n_substeps']};",
        f"const int OUTPUT_INDEX[{len(index)}] = {{{', '.join(map(str, index))}}};",
        f"const int VR_LINER = {vr['liner']}, VR_YIELD = {vr['yield_force']}, VR_HARDENING = {vr['hardening']}, "
        f"VR_THICKNESS = {vr['liner_thickness']}, VR_N_SECTORS = {vr['n_sectors']}, "
        f"VR_CLOSURE = {vr['clearance_closure']}, VR_OFFSET_X = {vr['casing_offset.x']}, "
        f"VR_OFFSET_Y = {vr['casing_offset.y']}, VR_CLEARANCE_EFFECTIVE = {vr['clearance_effective']};",
        f"const int WEAR_INDEX[{len(wear)}] = {{{', '.join(map(str, wear))}}};",
        f"const double BLADE_THICKNESS = {_c_double(model.params.blades.thickness)};", "",
    ]
    for key in ("M", "D", "K", "G1", "C1", "N2", "S2", "f_unit"):
        out.append(_array(key, getattr(model, key).ravel()))
    out.append(_array("PSI_TIP", spec["psi_tip"]))
    out.append(_array("MODES", spec["modes"], "int"))
    out.append(_array("T_DISK", spec["T"].ravel()))
    out.append(_array("R_DISK", spec["Rot"].ravel()))
    out.append(
        "const model_data MODEL_DATA = {\n"
        f"    {model.n_dofs}, {nb},\n"
        "    M, D, K, G1, C1, N2, S2, f_unit,\n"
        f"    {_c_double(spec['r_tip'])}, {_c_double(spec['stagger'])}, {_c_double(spec['z_cg'])},\n"
        f"    {spec['blade_dof0']}, {spec['n_ritz']}, {spec['casing_dof0']}, {len(spec['modes'])},\n"
        "    PSI_TIP, MODES, T_DISK, R_DISK\n};\n")
    return "\n".join(out)


def cmakelists(identifier: str, c_files: tuple[str, ...]) -> str:
    return f"""# Rebuild this FMU's binary from these sources (or use fmpy.build.build_platform_binary):
#   cmake -S sources -B build -DCMAKE_BUILD_TYPE=Release && cmake --build build --config Release
# then copy build/{identifier}.{{so,dll,dylib}} to binaries/<platform>/. On x86_64 and aarch64 the binary
# needs no libm (the elementary functions are rr_math.h's); the flags below keep the numbers of the
# shipped binaries (no contraction to FMA, no fast-math).
cmake_minimum_required(VERSION 3.15)
project({identifier} C)
add_library({identifier} SHARED {' '.join(c_files)})
set_target_properties({identifier} PROPERTIES PREFIX "" C_STANDARD 99 C_VISIBILITY_PRESET hidden)
target_compile_definitions({identifier} PRIVATE RR_API=)
if(NOT MSVC)
  target_compile_options({identifier} PRIVATE -ffp-contract=off -fno-fast-math)
  target_link_libraries({identifier} PRIVATE m)
else()
  target_compile_options({identifier} PRIVATE /fp:precise)
endif()
"""


def documentation_html(title: str, description: str, variables: list[interface.Var], facts: str) -> str:
    rows = "\n".join(
        f"<tr><td><code>{html.escape(v.name)}</code></td><td>{v.causality}</td><td>{html.escape(v.unit or '')}</td>"
        f"<td>{'' if v.min is None else f'[{v.min!r}, {v.max!r}]'}</td><td>{html.escape(v.description)}</td></tr>"
        for v in variables)
    return f"""<!DOCTYPE html>
<html><head><meta charset="utf-8"><title>{html.escape(title)} (native)</title></head><body>
<h1>{html.escape(title)} &mdash; FMI 2.0 co-simulation, native C</h1>
<p>{html.escape(description)}</p>
<p>{facts} The sources to rebuild for another platform are in <code>sources/</code> (CMakeLists.txt, or
<code>fmpy.build.build_platform_binary</code>). No Python or other runtime on the host: the binary links the C
runtime only (Linux binaries: glibc 2.17 or newer).</p>
<table border="1" cellspacing="0" cellpadding="3">
<tr><th>name</th><th>causality</th><th>unit</th><th>range</th><th>description</th></tr>
{rows}
</table></body></html>
"""


def package_native_fmu(out_file: Path, *, identifier: str, variables: list[interface.Var], guid: str,
                       model_sources: dict[str, Path | str], c_files: tuple[str, ...], description_xml: bytes,
                       documentation: dict[str, Path | str], platforms: tuple[str, ...] | None,
                       fmi: str = "2.0") -> list[str]:
    """Stage a native FMU's sources, compile them for ``platforms`` and zip the FMU into ``out_file``.

    ``model_sources``: file name in sources/ -> a path to copy or the text to write (the model's C files
    and its model_data.c); the wrapper of that FMI version (``fmi``: "2.0" or "3.0"), rr_math.h, the FMI
    headers and a CMakeLists.txt are added here. ``documentation``: file name in documentation/ -> a path
    or a text. Returns the platforms built.
    """
    from rotorub_model import kernel

    out_file = Path(out_file)
    out_file.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="rotorub_native_") as tmp:
        root = Path(tmp) / "fmu"
        src = root / "sources"
        src.mkdir(parents=True)
        wrapper, headers = (WRAPPER3, FMI3_HEADERS) if fmi == "3.0" else (WRAPPER, FMI_HEADERS)
        files: dict[str, Path | str] = {**{n: NATIVE / n for n in wrapper}, kernel.MATH_HEADER.name: kernel.MATH_HEADER,
                                        **{n: fmi_headers(headers) / n for n in headers}, **model_sources,
                                        "CMakeLists.txt": cmakelists(identifier, c_files)}
        for name, what in files.items():
            if isinstance(what, Path):
                shutil.copy2(what, src / name)
            else:
                (src / name).write_text(what)
        built = compile_platforms(src, c_files, identifier, root / "binaries", platforms, what=identifier, fmi=fmi)
        (root / "modelDescription.xml").write_bytes(description_xml)
        doc = root / "documentation"
        doc.mkdir()
        for name, what in documentation.items():
            if isinstance(what, Path):
                shutil.copy2(what, doc / name)
            else:
                (doc / name).write_text(what)
        tmp_zip = out_file.with_suffix(".fmu.tmp")
        with zipfile.ZipFile(tmp_zip, "w", zipfile.ZIP_DEFLATED) as z:
            for f in sorted(root.rglob("*")):
                if f.is_file():
                    z.write(f, f.relative_to(root).as_posix())
        tmp_zip.replace(out_file)
    return built


def build_native_fmu(dest: str | Path = "fmus/native", params_file: str | Path | None = None,
                     platforms: tuple[str, ...] | None = None, mode: str = "transient") -> dict:
    """Build ``dest/RotorCasingContact.fmu`` (native); returns a summary dict.

    ``platforms``: FMI platform folders (default: every platform when ziglang is installed, this
    machine's otherwise). ``mode``: the default of the ``mode`` parameter, and what the model
    description declares: 'transient' (no output depends directly on an input) or
    'quasi_static' (the outputs depend on Omega and imbalance: direct feedthrough).
    """
    from rotorub_model import __version__ as lib_version
    from rotorub_model import kernel
    from rotorub_model.structure.model import build_model
    from rotorub_model.structure.params import REFERENCE_FILE, load_parameters

    if mode not in ("transient", "quasi_static"):
        raise NativeBuildError(f"mode: '{mode}' unknown; accepted: transient, quasi_static")
    params_path = Path(params_file) if params_file else REFERENCE_FILE
    params = load_parameters(params_path)
    model = build_model(params)
    variables = interface.variables(interface.Defaults.from_parameters(params), mode, flavour="native")
    feedthrough = mode == "quasi_static"
    data = contact_model_data(model, variables)
    model_c = [NATIVE / n for n in ("contact_model.c", "contact_model.h")]
    # the GUID names this exact model: its variables, data and every source
    guid = interface.guid_of(json.dumps([v.__dict__ for v in variables], sort_keys=True, default=str), data,
                             *(p.read_bytes() for p in (*model_c, *(NATIVE / n for n in WRAPPER), *kernel.SOURCES,
                                                        *kernel.HEADERS)), mode)
    md = interface.model_description(variables, guid=guid, generation_tool=f"rotorub {lib_version} (native C)",
                                     version=lib_version, needs_execution_tool=False, feedthrough=feedthrough,
                                     source_files=list(C_SOURCES))
    out_file = Path(dest) / f"{interface.MODEL_IDENTIFIER}.fmu"
    sources: dict[str, Path | str] = {p.name: p for p in (*model_c, *kernel.SOURCES, *kernel.HEADERS)}
    sources["model_data.c"] = ("/* model_data.c: generated by fmu_src/build/native_fmu.py from the parameter file; "
                               "do not edit. */\n#include \"contact_model.h\"\n\n"
                               + variable_table(variables, guid, interface.MODEL_IDENTIFIER, feedthrough) + data)
    facts = (f"Model built in from <code>{html.escape(params_path.name)}</code>; default mode: {mode}. Manual: "
             "<code>documentation/FMU.md</code>.")
    built = package_native_fmu(
        out_file, identifier=interface.MODEL_IDENTIFIER, variables=variables, guid=guid, model_sources=sources,
        c_files=C_SOURCES, description_xml=interface.xml_bytes(md), platforms=platforms,
        documentation={"index.html": documentation_html(interface.MODEL_IDENTIFIER, interface.DESCRIPTION, variables,
                                                        facts), "FMU.md": HERE / "FMU.md"})
    return {"fmu": str(out_file), "flavour": "native", "guid": guid, "platforms": built, "mode": mode,
            "variables": len(variables), "parameters": str(params_path), "size_bytes": out_file.stat().st_size}


def main(argv: list[str] | None = None) -> int:
    import argparse

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("dest", nargs="?", default="fmus/native")
    ap.add_argument("--params", default=None)
    ap.add_argument("--platforms", nargs="+", default=None)
    ap.add_argument("--mode", default="transient", choices=["transient", "quasi_static"])
    ns = ap.parse_args(argv)
    try:
        print(json.dumps(build_native_fmu(ns.dest, ns.params, tuple(ns.platforms) if ns.platforms else None, ns.mode),
                         indent=1))
    except (NativeBuildError, Exception) as exc:  # noqa: BLE001 - one line for the user
        print(f"build-fmu --native: error: {exc}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
