"""Build the native FMU: RotorCasingContact as FMI 2.0 co-simulation in C, no Python on the host.

    rotorub build-fmu --native [--params my.toml] [--out fmus] [--platforms linux64 win64 ...]

What goes in ``fmus/RotorCasingContact.fmu`` (native flavour; the pythonfmu one is built by
fmu_src/build/pythonfmu_fmu.py under the same name, so the build puts this one in ``fmus/native/`` by
default):

* ``modelDescription.xml``: fmu_src/interface.py's description (the same variables, value
  references, units and ranges as the pythonfmu FMU), with ``<SourceFiles>``;
* ``sources/``: the FMI wrapper (fmi2_cs.c), the model (contact_model.c, fmu_model.h), the kernel
  (rotorub_kernel.c/.h), the model's matrices and geometry baked from the parameter file
  (model_data.c, generated here, floats as exact hex literals), the FMI 2.0 headers (from
  fmpy's copy of the standard's), a CMakeLists.txt: a user rebuilds the binary for another
  platform with fmpy's helper (``fmpy.build.build_platform_binary``) or with CMake;
* ``binaries/<platform>/RotorCasingContact.{so,dll,dylib}`` for each platform built: linux64
  with the system compiler (or ziglang), win64, darwin64 (x86_64) and aarch64-darwin (Apple
  silicon, the FMI 3 style folder name that FMPy and others look in) cross-compiled with ziglang;
* ``documentation/index.html`` and the cross-check kit next to the FMU (crosscheck.py).
"""

from __future__ import annotations

import hashlib
import json
import shutil
import subprocess
import sys
import tempfile
import uuid
import zipfile
from pathlib import Path

from .. import interface

HERE = Path(__file__).resolve().parent.parent  # fmu_src/
NATIVE = HERE / "native"
C_SOURCES = ("fmi2_cs.c", "contact_model.c", "model_data.c", "rotorub_kernel.c")
HEADERS = ("fmu_model.h", "rotorub_kernel.h", "rr_math.h")
FMI_HEADERS = ("fmi2Functions.h", "fmi2FunctionTypes.h", "fmi2TypesPlatform.h")
SUFFIX = {"linux64": ".so", "aarch64-linux": ".so", "win64": ".dll", "darwin64": ".dylib", "aarch64-darwin": ".dylib"}
ALL_PLATFORMS = ("linux64", "win64", "darwin64", "aarch64-darwin")


class NativeBuildError(Exception):
    pass


def fmi_headers() -> Path:
    """The FMI 2.0 headers of the standard, as fmpy ships them."""
    try:
        import fmpy
    except ImportError:
        raise NativeBuildError("the native FMU build takes the FMI 2.0 headers from fmpy: pip install fmpy") from None
    d = Path(fmpy.__file__).resolve().parent / "c-code"
    missing = [h for h in FMI_HEADERS if not (d / h).exists()]
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


def model_data_source(model, variables: list[interface.Var], guid: str, feedthrough: bool) -> str:
    """model_data.c: the variable table, the structure's matrices and the geometry's ingredients."""
    from rotorub_model import kernel
    from rotorub_model.contact.geometry import geometry_spec

    names = [v.name for v in variables]
    fixed = ["Omega", "imbalance", "formulation", "mode", "param_file", "g0", "k_r", "mu", "theta", "chord", "dt_max",
             "max_penetration", "slip_velocity"]
    if names[:len(fixed)] != fixed:
        raise NativeBuildError(f"interface order changed: fmu_model.h expects {fixed} first, got {names[:len(fixed)]}")
    vr = {n: i for i, n in enumerate(names)}
    nb = model.params.blades.count
    index = [vr[f"blade[{j}].{b}"] for b in kernel.OUT_BLADE_NAMES for j in range(1, nb + 1)]
    index += [vr[g] for g in kernel.OUT_GLOBAL_NAMES]
    spec = geometry_spec(model, 2, 0.0, 0.0, True)
    types = {"Real": "VT_REAL", "Integer": "VT_INTEGER", "Enumeration": "VT_ENUM", "String": "VT_STRING"}
    caus = {"input": "VC_INPUT", "parameter": "VC_PARAMETER", "output": "VC_OUTPUT"}
    var = {"continuous": "VV_CONTINUOUS", "discrete": "VV_DISCRETE", "fixed": "VV_FIXED", "tunable": "VV_TUNABLE"}
    rows = []
    for v in variables:
        has = v.min is not None
        start = v.start if isinstance(v.start, int | float) and not isinstance(v.start, bool) else 0
        rows.append(f"    {{{_c_string(v.name)}, {types[v.type]}, {caus[v.causality]}, {var[v.variability]}, "
                    f"{int(has)}, {_c_double(v.min if has else 0.0)}, {_c_double(v.max if has else 0.0)}, "
                    f"{_c_double(start)}, {_c_string(v.start if isinstance(v.start, str) else '')}}}")
    out = [
        "/* model_data.c: generated by fmu_src/build/native_fmu.py from the parameter file; do not edit. */",
        '#include "fmu_model.h"', "",
        f"static const model_var VARS[{len(variables)}] = {{", ",\n".join(rows), "};", "",
        f"const int VR_N_CONTACT = {vr['n_contact']}, VR_MAX_REAL = {vr['max_real_eig']}, "
        f"VR_STATUS = {vr['status']}, VR_MESSAGE = {vr['message']}, VR_DT_INTERNAL = {vr['dt_internal']}, "
        f"VR_N_SUBSTEPS = {vr['n_substeps']};",
        f"const int OUTPUT_INDEX[{len(index)}] = {{{', '.join(map(str, index))}}};", "",
    ]
    for key in ("M", "D", "K", "G1", "C1", "N2", "S2", "f_unit"):
        out.append(_array(key, getattr(model, key).ravel()))
    out.append(_array("PSI_TIP", spec["psi_tip"]))
    out.append(_array("MODES", spec["modes"], "int"))
    out.append(_array("T_DISK", spec["T"].ravel()))
    out.append(_array("R_DISK", spec["Rot"].ravel()))
    out.append(
        "const model_data MODEL_DATA = {\n"
        f"    {_c_string(guid)}, {len(variables)}, VARS, {int(feedthrough)}, {model.n_dofs}, {nb},\n"
        "    M, D, K, G1, C1, N2, S2, f_unit,\n"
        f"    {_c_double(spec['r_tip'])}, {_c_double(spec['stagger'])}, {_c_double(spec['z_cg'])},\n"
        f"    {spec['blade_dof0']}, {spec['n_ritz']}, {spec['casing_dof0']}, {len(spec['modes'])},\n"
        "    PSI_TIP, MODES, T_DISK, R_DISK\n};\n")
    return "\n".join(out)


CMAKE = """# Rebuild the native FMU's binary from these sources (or use fmpy.build.build_platform_binary):
#   cmake -S sources -B build -DCMAKE_BUILD_TYPE=Release && cmake --build build --config Release
# then copy build/RotorCasingContact.{so,dll,dylib} to binaries/<platform>/.
cmake_minimum_required(VERSION 3.15)
project(RotorCasingContact C)
add_library(RotorCasingContact SHARED fmi2_cs.c contact_model.c model_data.c rotorub_kernel.c)
set_target_properties(RotorCasingContact PROPERTIES PREFIX "" C_STANDARD 99 C_VISIBILITY_PRESET hidden)
target_compile_definitions(RotorCasingContact PRIVATE RR_API=)
if(NOT MSVC)
  # the same numbers on every platform: no contraction to FMA, no fast-math
  target_compile_options(RotorCasingContact PRIVATE -ffp-contract=off -fno-fast-math)
  target_link_libraries(RotorCasingContact PRIVATE m)
else()
  target_compile_options(RotorCasingContact PRIVATE /fp:precise)
endif()
"""


def stage_sources(dest: Path, model_data: str) -> None:
    dest.mkdir(parents=True, exist_ok=True)
    from rotorub_model import kernel

    for name in ("fmi2_cs.c", "contact_model.c", "fmu_model.h"):
        shutil.copy2(NATIVE / name, dest / name)
    for src in (*kernel.SOURCES, *kernel.HEADERS):
        shutil.copy2(src, dest / src.name)
    hdr = fmi_headers()
    for name in FMI_HEADERS:
        shutil.copy2(hdr / name, dest / name)
    (dest / "model_data.c").write_text(model_data)
    (dest / "CMakeLists.txt").write_text(CMAKE)


def compile_binary(sources: Path, out: Path, platform: str | None) -> Path:
    """Compile the staged sources into ``out`` for an FMI platform folder (None: this machine)."""
    from rotorub_model.kernel.compiler import CFLAGS, ZIG_TARGETS, Compiler, CompilerError, find_compiler, zig_command

    if platform is None:
        compiler, triple = find_compiler(), []
    else:
        zig = zig_command()
        if zig is None:
            raise NativeBuildError(f"building for {platform} needs the ziglang package (pip install ziglang)")
        compiler, triple = Compiler(tuple(zig), "zig"), ["-target", ZIG_TARGETS[platform]]
    win = platform == "win64"
    out.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="rotorub_cc_") as work:
        # in a folder of its own: a Windows build also leaves an import library and debug data behind
        target = Path(work) / out.name
        cmd = [*compiler.command, *triple, *CFLAGS, "-shared", "-DRR_API=", *([] if win else ["-fPIC"]),
               f"-I{sources}", "-o", str(target), *(str(sources / s) for s in C_SOURCES), *([] if win else ["-lm"])]
        r = subprocess.run(cmd, capture_output=True, text=True, cwd=work)
        if r.returncode != 0 or not target.exists():
            raise CompilerError(f"native FMU for {platform or 'this machine'}: {compiler.name} failed:\n"
                                f"{r.stderr.strip()[-4000:]}")
        shutil.move(str(target), out)
    return out


def host_platform() -> str:
    from rotorub_model.kernel.compiler import host_platform_tag

    return {"x86_64-linux": "linux64", "x86_64-win": "win64", "x86_64-darwin": "darwin64",
            "aarch64-darwin": "aarch64-darwin", "aarch64-linux": "aarch64-linux"}[host_platform_tag()]


def build_native_fmu(dest: str | Path = "fmus/native", params_file: str | Path | None = None,
                     platforms: tuple[str, ...] | None = None, mode: str = "transient") -> dict:
    """Build ``dest/RotorCasingContact.fmu`` (native); returns a summary dict.

    ``platforms``: FMI platform folders (default: this machine's, plus every cross target when
    ziglang is installed). ``mode``: the default of the ``mode`` parameter, and what the model
    description declares: 'transient' (no output depends directly on an input) or
    'quasi_static' (the outputs depend on Omega and imbalance: direct feedthrough).
    """
    from rotorub_model import __version__ as lib_version
    from rotorub_model.kernel.compiler import zig_command
    from rotorub_model.structure.model import build_model
    from rotorub_model.structure.params import REFERENCE_FILE, load_parameters

    if mode not in ("transient", "quasi_static"):
        raise NativeBuildError(f"mode: '{mode}' unknown; accepted: transient, quasi_static")
    params_path = Path(params_file) if params_file else REFERENCE_FILE
    params = load_parameters(params_path)
    model = build_model(params)
    variables = interface.variables(interface.Defaults.from_parameters(params), mode)
    host = host_platform()
    if platforms is None:
        platforms = (host, *(p for p in ALL_PLATFORMS if p != host)) if zig_command() else (host,)
    unknown = [p for p in platforms if p not in SUFFIX]
    if unknown:
        raise NativeBuildError(f"platform '{unknown[0]}': unknown; accepted: {', '.join(SUFFIX)}")
    # the GUID names this exact build: variables, model data and sources
    h = hashlib.sha256(json.dumps([v.__dict__ for v in variables], sort_keys=True, default=str).encode())
    for key in ("M", "D", "K", "G1", "C1", "N2", "S2", "f_unit"):
        h.update(getattr(model, key).tobytes())
    for p in (*(NATIVE / n for n in ("fmi2_cs.c", "contact_model.c", "fmu_model.h")),):
        h.update(p.read_bytes())
    guid = "{" + str(uuid.UUID(h.hexdigest()[:32])) + "}"
    feedthrough = mode == "quasi_static"
    dest = Path(dest)
    dest.mkdir(parents=True, exist_ok=True)
    out_file = dest / f"{interface.MODEL_IDENTIFIER}.fmu"
    built = []
    with tempfile.TemporaryDirectory(prefix="rotorub_native_") as tmp:
        root = Path(tmp) / "fmu"
        stage_sources(root / "sources", model_data_source(model, variables, guid, feedthrough))
        for plat in platforms:
            compile_binary(root / "sources", root / "binaries" / plat / f"{interface.MODEL_IDENTIFIER}{SUFFIX[plat]}",
                           None if plat == host else plat)
            built.append(plat)
        md = interface.model_description(variables, guid=guid, generation_tool=f"rotorub {lib_version} (native C)",
                                         version=lib_version, needs_execution_tool=False, feedthrough=feedthrough,
                                         source_files=list(C_SOURCES))
        (root / "modelDescription.xml").write_bytes(interface.xml_bytes(md))
        doc = root / "documentation"
        doc.mkdir()
        (doc / "index.html").write_text(_documentation(variables, params_path, built, mode))
        shutil.copy2(HERE / "FMU.md", doc / "FMU.md")
        tmp_zip = out_file.with_suffix(".fmu.tmp")
        with zipfile.ZipFile(tmp_zip, "w", zipfile.ZIP_DEFLATED) as z:
            for f in sorted(root.rglob("*")):
                if f.is_file():
                    z.write(f, f.relative_to(root).as_posix())
        tmp_zip.replace(out_file)
    return {"fmu": str(out_file), "flavour": "native", "guid": guid, "platforms": built, "mode": mode,
            "variables": len(variables), "parameters": str(params_path), "size_bytes": out_file.stat().st_size}


def _documentation(variables: list[interface.Var], params_path: Path, platforms: list[str], mode: str) -> str:
    import html

    rows = "\n".join(
        f"<tr><td><code>{html.escape(v.name)}</code></td><td>{v.causality}</td><td>{html.escape(v.unit or '')}</td>"
        f"<td>{'' if v.min is None else f'[{v.min:g}, {v.max:g}]'}</td><td>{html.escape(v.description)}</td></tr>"
        for v in variables)
    return f"""<!DOCTYPE html>
<html><head><meta charset="utf-8"><title>{interface.MODEL_IDENTIFIER} (native)</title></head><body>
<h1>{interface.MODEL_IDENTIFIER} &mdash; blade-tip / casing contact, FMI 2.0 co-simulation, native C</h1>
<p>{html.escape(interface.DESCRIPTION)}</p>
<p>Model built in from <code>{html.escape(params_path.name)}</code>; binaries: {', '.join(platforms)};
the sources to rebuild for another platform are in <code>sources/</code> (CMakeLists.txt, or
<code>fmpy.build.build_platform_binary</code>). No Python or other runtime on the host: the binary links
the C runtime and libm only. Default mode: {mode}. Manual: <code>documentation/FMU.md</code>.</p>
<table border="1" cellspacing="0" cellpadding="3">
<tr><th>name</th><th>causality</th><th>unit</th><th>range</th><th>description</th></tr>
{rows}
</table></body></html>
"""


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
