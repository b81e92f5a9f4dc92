"""Packaging a native FMU, whatever the model: its GUID, generated C, sources, binaries and documentation.

What goes in a native FMU (:func:`build_native`):

* ``modelDescription.xml`` (fmu_src/fmi/description.py, FMI 2.0 or 3.0) from the model's variables;
* ``sources/``: the FMI wrapper of that version over the shared core (fmu_src/fmi/c/), the model's ``model.c``
  and ``model.h`` and any further sources it names (the contact model: the rotorub kernel), the generated
  ``variables.h`` and ``model_data.c`` (the variable tables and the model's data, floats as exact hex literals),
  the kernel's elementary functions (rr_math.h: the same bits on every platform), the standard's FMI headers
  (fmpy's copy) and a CMakeLists.txt (FMI 3.0: also buildDescription.xml): a user rebuilds the binary for another
  platform with CMake or with fmpy's helper (``fmpy.build.build_platform_binary``), both of which give a binary
  that needs no libm on x86_64 and aarch64 and computes the shipped numbers;
* ``binaries/<platform>/<id>.{so,dll,dylib}``: linux64 and aarch64-linux for glibc 2.17, win64, darwin64 and
  aarch64-darwin (fmu_src/fmi/compile.py), in the FMI 3.0 folder names for an FMI 3.0 FMU;
* ``documentation/index.html`` and the model's manual (its FMU.md).

The C files of a model are always ``model.c`` and ``model.h`` in its folder (fmu_src/models/<model>/): the
wrappers include ``model.h`` by that name, as the Modelica Reference-FMUs' wrappers include a model's config.h.
"""

from __future__ import annotations

import hashlib
import html
import json
import shutil
import tempfile
import uuid
import zipfile
from dataclasses import dataclass, field
from pathlib import Path

from .compile import NativeBuildError, compile_platforms
from .csource import fmi3_table, variable_table, variables_header
from .description import ModelInfo, model_description, xml_bytes
from .variables import Var, declared, scalars

C_DIR = Path(__file__).resolve().parent / "c"
CORE = ("fmu_core.c", "fmu_core.h", "fmu_model.h")
WRAPPERS = {"2.0": ("fmi2_cs.c",), "3.0": ("fmi3_cs.c", "fmi3_vars.h")}
FMI_HEADERS = {"2.0": ("fmi2Functions.h", "fmi2FunctionTypes.h", "fmi2TypesPlatform.h"),
               "3.0": ("fmi3Functions.h", "fmi3FunctionTypes.h", "fmi3PlatformTypes.h")}

__all__ = ["NativeBuild", "NativeBuildError", "build_native", "documentation_html", "guid_of"]


def guid_of(*parts: bytes | str) -> str:
    """A GUID derived from what makes an FMU what it is (its description, model data and sources), not from
    the build time: the same model built twice has the same GUID, any change gives another one."""
    h = hashlib.sha256()
    for p in parts:
        h.update(p.encode() if isinstance(p, str) else p)
        h.update(b"\0")
    return "{" + str(uuid.UUID(h.hexdigest()[:32])) + "}"


def fmi_headers(fmi: str = "2.0") -> Path:
    """The folder of the standard's FMI headers of that version, as fmpy ships them."""
    try:
        import fmpy
    except ImportError:
        raise NativeBuildError("the native FMU build takes the FMI headers from fmpy: pip install fmpy") from None
    d = Path(fmpy.__file__).resolve().parent / "c-code"
    missing = [h for h in FMI_HEADERS[fmi] if not (d / h).exists()]
    if missing:
        raise NativeBuildError(f"fmpy's FMI headers not found ({', '.join(missing)} in {d})")
    return d


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


def build_description(identifier: str, c_files: tuple[str, ...]) -> str:
    """sources/buildDescription.xml: the FMI 3.0 build description (what fmpy's build_platform_binary reads)."""
    files = "\n".join(f'      <SourceFile name="{f}"/>' for f in c_files)
    return f"""<?xml version="1.0" encoding="UTF-8"?>
<fmiBuildDescription fmiVersion="3.0">
  <BuildConfiguration modelIdentifier="{identifier}" description="the native FMU: no libm needed on
    x86_64 and aarch64 (rr_math.h); build without FMA contraction or fast-math to get the shipped numbers">
    <SourceFileSet language="C99" compilerOptions="-ffp-contract=off -fno-fast-math">
{files}
      <PreprocessorDefinition name="RR_API" value=""/>
    </SourceFileSet>
  </BuildConfiguration>
</fmiBuildDescription>
"""


def documentation_html(title: str, subtitle: str, description: str, variables: list[Var], sections: str) -> str:
    """documentation/index.html of an FMU: what it is, ``sections`` (HTML: what the host needs, behaviour), and the
    table of its variables (those of its description, arrays as arrays)."""
    def rng(v: Var) -> str:
        return "" if v.min is None else f"[{v.min!r}, {v.max!r}]"

    rows = "\n".join(
        f"<tr><td><code>{html.escape(v.name)}</code>{f' [{v.size}]' if v.is_array else ''}</td><td>{v.causality}</td>"
        f"<td>{html.escape(v.unit or '')}{' (' + v.display_unit + ')' if v.display_unit else ''}</td>"
        f"<td>{rng(v)}</td><td>{html.escape(v.description)}</td></tr>" for v in variables)
    return f"""<!DOCTYPE html>
<html><head><meta charset="utf-8"><title>{html.escape(title)} ({html.escape(subtitle)})</title></head><body>
<h1>{html.escape(title)} &mdash; {html.escape(subtitle)}</h1>
<p>{html.escape(description)}</p>
{sections}
<h2>Variables</h2>
<table border="1" cellspacing="0" cellpadding="3">
<tr><th>name</th><th>causality</th><th>unit (display)</th><th>range</th><th>description</th></tr>
{rows}
</table></body></html>
"""


@dataclass
class NativeBuild:
    """One native FMU of a model: what :func:`build_native` needs besides the FMI layer's own files."""

    model: ModelInfo
    variables: list[Var]  # numbered, every build's
    model_dir: Path  # the model's folder: model.c, model.h, FMU.md
    fmi: str = "2.0"
    feedthrough: bool = False
    extra_sources: tuple[Path, ...] = ()  # further C sources and headers (the kernel's), copied as they are
    model_data: str = ""  # the model's part of model_data.c (its matrices, output maps)
    facts: str = ""  # HTML for the documentation page: what this build is
    salt: tuple[str, ...] = ()  # what else makes this FMU what it is (a mode), for its GUID
    extra_docs: dict[str, Path | str] = field(default_factory=dict)


def build_native(b: NativeBuild, dest: str | Path, platforms: tuple[str, ...] | None, generation_tool: str,
                 version: str) -> dict:
    """Generate, stage, compile and zip ``dest/<identifier>.fmu``; returns a summary (its file, GUID, platforms)."""
    ident = b.model.identifier
    if b.fmi not in WRAPPERS:
        raise NativeBuildError(f"fmi: '{b.fmi}' unknown; accepted: {', '.join(WRAPPERS)}")
    model_files = [b.model_dir / "model.c", b.model_dir / "model.h"]
    own = [*(C_DIR / n for n in (*CORE, *WRAPPERS[b.fmi])), *model_files, *b.extra_sources]
    header = variables_header(b.variables, ident, b.model.enumerations,
                              f"fmu_src/models/{b.model_dir.name}/variables.py")
    # the GUID names this exact FMU: its variables, data and every source (another build's state is refused)
    guid = guid_of(f"fmi {b.fmi}", json.dumps([v.__dict__ for v in b.variables], sort_keys=True, default=str),
                   b.model_data, header, *(p.read_bytes() for p in own), *b.salt)
    c_files = (WRAPPERS[b.fmi][0], "fmu_core.c", "model.c", "model_data.c",
               *(p.name for p in b.extra_sources if p.suffix == ".c"))
    data = (f"/* model_data.c: {ident}'s tables, generated by fmu_src/fmi/package.py from "
            f"fmu_src/models/{b.model_dir.name}/; do not edit. */\n#include \"model.h\"\n\n"
            + variable_table(b.variables, guid, ident, b.feedthrough) + b.model_data
            + ("\n" + fmi3_table(b.variables) if b.fmi == "3.0" else ""))
    tool = f"{generation_tool} (native C{', FMI 3.0' if b.fmi == '3.0' else ''})"
    md = model_description(b.model, b.variables, fmi=b.fmi, token=guid, generation_tool=tool, version=version,
                           feedthrough=b.feedthrough, source_files=None if b.fmi == "3.0" else list(c_files))
    sources: dict[str, Path | str] = {p.name: p for p in own}
    sources.update({"variables.h": header, "model_data.c": data, "CMakeLists.txt": cmakelists(ident, c_files)})
    if b.fmi == "3.0":
        sources["buildDescription.xml"] = build_description(ident, c_files)
    from rotorub_model import kernel

    sources[kernel.MATH_HEADER.name] = kernel.MATH_HEADER
    sources.update({n: fmi_headers(b.fmi) / n for n in FMI_HEADERS[b.fmi]})
    shown = declared(b.variables, ("fmi3" if b.fmi == "3.0" else "fmi2", "native"))
    doc = documentation_html(ident, f"FMI {b.fmi} co-simulation, native C", b.model.description,
                             shown if b.fmi == "3.0" else scalars(shown),
                             f"<p>{b.facts} The sources to rebuild for another platform are in <code>sources/</code> "
                             "(CMakeLists.txt, or <code>fmpy.build.build_platform_binary</code>). No Python or other "
                             "runtime on the host: the binary links the C runtime only (Linux binaries: glibc 2.17 "
                             "or newer).</p>")
    docs: dict[str, Path | str] = {"index.html": doc, **b.extra_docs}
    if (b.model_dir / "FMU.md").exists():
        docs["FMU.md"] = b.model_dir / "FMU.md"
    out_file = Path(dest) / f"{ident}.fmu"
    built = package(out_file, identifier=ident, sources=sources, c_files=c_files, description_xml=xml_bytes(md),
                    documentation=docs, platforms=platforms, fmi=b.fmi)
    return {"fmu": str(out_file), "guid": guid, "platforms": built, "fmi": b.fmi,
            "variables": len(shown if b.fmi == "3.0" else scalars(shown)), "size_bytes": out_file.stat().st_size}


def stage_files(folder: Path, files: dict[str, Path | str | bytes]) -> list[Path]:
    """Write ``files`` (name -> a path, file or folder, to copy; or the text or bytes to write) into ``folder``."""
    folder.mkdir(parents=True, exist_ok=True)
    out = []
    for name, what in files.items():
        target = folder / name
        if isinstance(what, Path):
            (shutil.copytree if what.is_dir() else shutil.copy2)(what, target)
        elif isinstance(what, bytes):
            target.write_bytes(what)
        else:
            target.write_text(what)
        out.append(target)
    return out


def package(out_file: Path, *, identifier: str, sources: dict[str, Path | str], c_files: tuple[str, ...],
            description_xml: bytes, documentation: dict[str, Path | str], platforms: tuple[str, ...] | None,
            fmi: str = "2.0") -> list[str]:
    """Stage an FMU's ``sources`` (file name in sources/ -> a path to copy or the text to write), compile
    ``c_files`` for ``platforms`` and zip the FMU into ``out_file``; returns the platforms built."""
    out_file = Path(out_file)
    out_file.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="rotorub_native_") as tmp:
        root = Path(tmp) / "fmu"
        stage_files(root / "sources", sources)
        built = compile_platforms(root / "sources", c_files, identifier, root / "binaries", platforms,
                                  what=identifier, fmi=fmi)
        (root / "modelDescription.xml").write_bytes(description_xml)
        stage_files(root / "documentation", documentation)
        tmp_zip = out_file.with_suffix(".fmu.tmp")
        with zipfile.ZipFile(tmp_zip, "w", zipfile.ZIP_DEFLATED) as z:
            for f in sorted(root.rglob("*")):
                if f.is_file():
                    z.write(f, f.relative_to(root).as_posix())
        tmp_zip.replace(out_file)
    return built
