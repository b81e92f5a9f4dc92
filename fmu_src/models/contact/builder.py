"""Build RotorCasingContact.fmu in each of its flavours, from the one variable list (variables.py):

    rotorub build-fmu [--params my.toml] [--out fmus]                         the pythonfmu FMU
    rotorub build-fmu --native [--fmi3] [--mode quasi_static] [--platforms ...]   the native C FMU, FMI 2.0 or 3.0

* :func:`build_native_fmu`: model.c and the rotorub kernel behind the FMI layer's wrapper (fmu_src/fmi/), the
  structure's matrices and the contact geometry's ingredients generated into model_data.c from the parameter
  file; no Python on the host. FMI 3.0: the same model and numbers, the per-blade outputs as arrays of
  n_blades, early return at a first contact.
* :func:`build_fmu`: the pythonfmu FMU. It carries, in its resources folder, the slave (slave.py, staged as
  ``rotorub_casing_contact_<h>.py``), a verbatim copy of the ``rotorub_model`` sources and data as
  ``rotorub_model_<h>/`` with the compiled kernel in ``kernel/bin/<machine>-<os>/`` (x86_64-linux, and
  x86_64-win when ziglang can cross-compile it: the platforms pythonfmu's binary exists for), ``model.npz`` (the
  model assembled at build time: the host needs only numpy; a ``param_file`` given at run time is assembled
  there, with scipy), ``reference.toml`` (the parameter file used when ``param_file`` is empty),
  ``rotorub_fmu.json`` (the manifest: which package and parameter file to load, the variables, the constants)
  and ``requirements.txt`` (what the host Python needs; ``pythonfmu deploy`` can install it). ``<h>`` is a hash of
  all of it (fmu_src/fmi/pythonfmu.py says why); the library copy is imported under that name through relative
  imports only, and the build refuses sources that import ``rotorub_model`` by its absolute name.

The cross-check kit is written next to each FMU by ``rotorub build-fmu`` (crosscheck.py).
"""

from __future__ import annotations

import ast
import hashlib
import html
import json
import shutil
import sys
import tempfile
import zipfile
from pathlib import Path

import numpy as np

import rotorub_model

from ...fmi.compile import NativeBuildError
from ...fmi.csource import c_array, c_double
from ...fmi.description import model_description, xml_bytes
from ...fmi.package import NativeBuild, build_native, documentation_html, guid_of
from ...fmi.pythonfmu import BuildError, build_pythonfmu, pythonfmu_version
from ...fmi.variables import as_plain, declared, scalars
from . import variables as cv

HERE = Path(__file__).resolve().parent  # fmu_src/models/contact/
SLAVE = HERE / "slave.py"
LIB = Path(rotorub_model.__file__).resolve().parent  # the sources that travel inside the pythonfmu FMU
MODES = ("transient", "quasi_static")
HOST_REQUIREMENTS = ["numpy>=1.26"]
# scipy is needed only to assemble a model from a param_file other than the one built in
OPTIONAL_REQUIREMENTS = ["scipy>=1.11"]
# pythonfmu 0.7 ships its binary for these FMI platforms; the kernel is built for each (cross: ziglang)
KERNEL_PLATFORMS = {"linux64": "x86_64-linux", "win64": "x86_64-win"}

__all__ = ["BuildError", "NativeBuildError", "build_fmu", "build_native_fmu", "model_data"]


def _parameters(params_file: str | Path | None, mode: str):
    from rotorub_model.structure.params import REFERENCE_FILE, load_parameters

    if mode not in MODES:
        raise NativeBuildError(f"mode: '{mode}' unknown; accepted: {', '.join(MODES)}")
    path = Path(params_file) if params_file else REFERENCE_FILE
    return path, load_parameters(path)  # validated now, not in the master


def geometry_data(model, theta: float, chord: float) -> str:
    """The contact geometries built into model_data.c (``MODEL_GEO2D``, ``MODEL_GEO3D``): where the kernel's
    rr_contact_geometry cannot build them at initialisation, the library's own arrays at cone angle ``theta``
    [rad] and chord ``chord`` [m] (the FMU's start values, as the pythonfmu FMU hands them to the library), so that
    the native FMU's contact is the library's to the bit: an imported blade's 3D tip (contact/fe_tip.py: its
    segments, compact rows, rest gap offsets, the liner's rows and shares), the built-in blades facing an FE
    casing's modes (contact/geometry.py with_fe_casing), 2D and 3D. Otherwise the null pointer."""
    import math

    from rotorub_model.contact import make_contact

    out = []
    for form in ("2D", "3D"):
        name = f"GEO{form}"
        if not ((form == "3D" and model.fe_blade is not None) or model.casing_ratios is not None):
            out.append(f"#define MODEL_{name} 0\n")
            continue
        c = make_contact(model, form, theta_deg=math.degrees(theta), chord=chord)
        g, t = c.geometry, c.geometry.tips
        arrays = {"G": g.G, "A": g.A, "B": g.B, "S": g.S, "POINTS": g.points, "NORMALS": g.normals,
                  "TANGENTS": g.tangents}
        ints = {}
        if t is not None:
            arrays.update(SEG_LEN=t.seg_len, SEG_K=t.seg_k, G_OFF=t.g_off, SHARE=t.point_share)
            ints = {"COLS": t.cols, "BLADE_OF": t.blade_of, "POINT_ROW": t.point_row}
        for key, a in arrays.items():
            out.append(c_array(f"{name}_{key}", np.asarray(a).ravel()))
        for key, a in ints.items():
            out.append(c_array(f"{name}_{key}", np.asarray(a).ravel(), "int"))

        have = {*arrays, *ints}

        def ref(keys: tuple[str, ...], name: str = name, have: set = have) -> str:
            return ", ".join(f"{name}_{k}" if k in have else "0" for k in keys)

        head = (f"{c.n_segments}, {t.cols.shape[1]}, {t.n_blades}, {t.n_rows}" if t is not None else
                f"{c.n_segments}, 0, 0, 0")
        band, area = (t.band, t.tip_area) if t is not None else (0.0, 0.0)
        out.append(
            f"static const model_geometry {name} = {{\n    {head},\n"
            f"    {c_double(max(g.chord, 1e-300))}, {c_double(band)}, {c_double(area)},\n"
            f"    {ref(('SEG_LEN', 'SEG_K', 'G_OFF', 'SHARE', 'COLS', 'BLADE_OF', 'POINT_ROW'))},\n"
            f"    {ref(('G', 'A', 'B', 'S', 'POINTS', 'NORMALS', 'TANGENTS'))}\n}};\n"
            f"#define MODEL_{name} (&{name})\n")
    return "\n".join(out)


def model_data(model, variables) -> str:
    """The contact model's part of model_data.c: where the kernel's outputs go, the structure's matrices and the
    contact geometry's ingredients (the geometries the kernel cannot build, an imported tip's or an FE casing's;
    the Omega^4 term; the block layout the time step takes from the library's BLOCK_MIN_DOFS on)."""
    from rotorub_model import kernel
    from rotorub_model.analyses.transient import BLOCK_MIN_DOFS
    from rotorub_model.contact.geometry import geometry_spec

    vr = {v.name: v.vr for v in scalars(declared(variables, ("fmi2", "native")))}
    nb = model.params.blades.count
    index = [vr[f"blade[{j}].{b}"] for b in kernel.OUT_BLADE_NAMES for j in range(1, nb + 1)]
    index += [vr[g] for g in kernel.OUT_GLOBAL_NAMES]
    spec = geometry_spec(model, 2, 0.0, 0.0, True)
    theta = next(v.start for v in variables if v.name == "theta")
    chord = next(v.start for v in variables if v.name == "chord")
    # the step by blocks where the library's CentralDifference takes it (the same dof count, the same layout)
    layout = model.block_layout if model.n_dofs >= BLOCK_MIN_DOFS else None
    blocks = layout or (0, 0, 0, 0)
    # rr_surface_summary's values in the kernel's order (depth_max, ..., lobes, harmonic_1, ...)
    wear = [vr[f"wear.harmonic[{n.rpartition('_')[2]}]" if n.startswith("harmonic_") else f"wear.{n}"]
            for n in kernel.WEAR_NAMES]
    out = [
        f"const int OUTPUT_INDEX[{len(index)}] = {{{', '.join(map(str, index))}}};",
        f"const int WEAR_INDEX[{len(wear)}] = {{{', '.join(map(str, wear))}}};",
        f"const double BLADE_THICKNESS = {c_double(model.params.blades.thickness)};", "",
    ]
    for key in ("M", "D", "K", "G1", "C1", "N2", "S2", "f_unit"):
        out.append(c_array(key, getattr(model, key).ravel()))
    out.append(c_array("S4", model.S4.ravel()) if model.S4 is not None else "#define S4 0\n")
    out.append(geometry_data(model, theta, chord))
    out.append(c_array("PSI_TIP", spec["psi_tip"]))
    out.append(c_array("MODES", spec["modes"], "int"))
    out.append(c_array("T_DISK", spec["T"].ravel()))
    out.append(c_array("R_DISK", spec["Rot"].ravel()))
    out.append(
        "const model_data MODEL_DATA = {\n"
        f"    {model.n_dofs}, {nb},\n"
        "    M, D, K, G1, C1, N2, S2, f_unit,\n"
        f"    {c_double(spec['r_tip'])}, {c_double(spec['stagger'])}, {c_double(spec['z_cg'])},\n"
        f"    {spec['blade_dof0']}, {spec['n_ritz']}, {spec['casing_dof0']}, {len(spec['modes'])},\n"
        "    PSI_TIP, MODES, T_DISK, R_DISK,\n"
        f"    S4, {blocks[0]}, {blocks[1]}, {blocks[2]}, {blocks[3]}, MODEL_GEO2D, MODEL_GEO3D\n}};\n")
    return "\n".join(out)


def build_native_fmu(dest: str | Path = "fmus/native", params_file: str | Path | None = None,
                     platforms: tuple[str, ...] | None = None, mode: str = "transient", fmi: str = "2.0") -> dict:
    """Build ``dest/RotorCasingContact.fmu`` (native C, FMI ``fmi``: "2.0" or "3.0"); returns a summary dict.

    ``platforms``: FMI platform folders by their FMI 2.0 names (default: every platform when ziglang is
    installed, this machine's otherwise). ``mode``: the default of the ``mode`` parameter, and what the model
    description declares: 'transient' (no output depends directly on an input) or 'quasi_static' (the outputs
    depend on the inputs but the casing offset: direct feedthrough).
    """
    from rotorub_model import __version__ as lib_version
    from rotorub_model import kernel
    from rotorub_model.structure.model import build_model

    params_path, params = _parameters(params_file, mode)
    model = build_model(params)
    defaults = cv.Defaults.from_parameters(params, model)
    variables = cv.variables(defaults, mode)
    three = fmi == "3.0"
    facts = (f"{'FMI 3.0. ' if three else ''}Model built in from <code>{html.escape(params_path.name)}</code>; "
             f"default mode: {mode}{f'; {defaults.n_blades} blades (n_blades)' if three else ''}. Manual: "
             f"<code>documentation/FMU.md</code>{', section FMI 3.0' if three else ''}.")
    # the kernel's sources by the names its package gives (it may be split into several files)
    out = build_native(NativeBuild(model=cv.MODEL, variables=variables, model_dir=HERE, fmi=fmi,
                                   feedthrough=mode == "quasi_static",
                                   extra_sources=(*kernel.SOURCES, *kernel.HEADERS),
                                   model_data=model_data(model, variables), facts=facts, salt=(mode,)),
                       dest, platforms, f"rotorub {lib_version}", lib_version)
    return {**out, "flavour": "native", "mode": mode, "parameters": str(params_path),
            **({"instantiation_token": out["guid"]} if three else {})}


def _library_files() -> list[Path]:
    files = [p for p in sorted(LIB.rglob("*")) if p.is_file() and "__pycache__" not in p.parts
             and "bin" not in p.relative_to(LIB).parts and p.suffix in (".py", ".toml", ".c", ".h")]
    if not (LIB / "__init__.py").exists():
        raise BuildError(f"library sources not found in {LIB}")
    return files


def _check_relative_only(path: Path, text: str) -> str:
    """The copy is imported under another name: no absolute import of rotorub_model may remain."""
    tree = ast.parse(text, str(path))
    for node in ast.walk(tree):
        if isinstance(node, ast.Import) and any(a.name.split(".")[0] == "rotorub_model" for a in node.names):
            raise BuildError(f"{path}:{node.lineno}: absolute import of rotorub_model; the FMU's copy needs "
                             "relative imports")
        absolute_from = isinstance(node, ast.ImportFrom) and node.level == 0
        if absolute_from and (node.module or "").split(".")[0] == "rotorub_model":
            raise BuildError(f"{path}:{node.lineno}: absolute import of rotorub_model; the FMU's copy needs "
                             "relative imports")
    return text


PYTHONFMU_HOST = """<p>This is a <a href="https://github.com/NTNU-IHB/PythonFMU">pythonfmu</a> FMU: its binary
embeds the host's CPython and does <b>not</b> link libpython.</p>
<ul><li>CPython 3.10 or newer, 64-bit, with <b>numpy</b> importable (resources/requirements.txt). That is all for
the model built in; scipy too if <code>param_file</code> names another parameter file. The compiled kernel
travels in resources/ (linux64, and win64 when it was cross-compiled).</li>
<li>A Python master (fmpy, libcosimpy, ...) in that Python: nothing else. A native master: preload the shared
libpython and set PYTHONHOME / PYTHONPATH (docs/FMU-hosts.md in the repository), or use the native FMU.</li></ul>"""
PYTHONFMU_LIMITS = """<li>pythonfmu can return only fmi2OK, fmi2Discard (from fmi2DoStep) and fmi2Fatal (an
exception): a misuse the native FMU refuses with fmi2Error at the call (out-of-range value, setting an output,
a bad configuration or FMU state) is logged here and refused at the next fmi2DoStep, with fmi2Discard.</li>"""


def _kernel_binaries(pkg: Path, platforms: tuple[str, ...] | None) -> list[str]:
    """Compile the kernel into the library copy for each FMI platform; returns the platforms built.

    ``platforms=None``: this machine's, plus the cross builds ziglang can make (a warning, not an
    error, when it cannot: the FMU then runs where it was built and on any host with a compiler).
    """
    from rotorub_model import kernel
    from rotorub_model.kernel.compiler import CompilerError, host_platform_tag, zig_command

    from ...fmi.compile import progress

    host = host_platform_tag()
    host_fmi = next((f for f, tag in KERNEL_PLATFORMS.items() if tag == host), None)
    wanted = list(platforms) if platforms is not None else [f for f in KERNEL_PLATFORMS if f == host_fmi
                                                            or zig_command() is not None]
    built = []
    for fmi in wanted:
        if fmi not in KERNEL_PLATFORMS:
            raise BuildError(f"platform '{fmi}': unknown; accepted: {', '.join(KERNEL_PLATFORMS)}")
        tag = KERNEL_PLATFORMS[fmi]
        out = pkg / "kernel" / "bin" / tag / ("rotorub_kernel" + (".dll" if tag.endswith("win") else ".so"))
        try:
            if fmi == host_fmi:
                kernel.load()  # built (or found) in the user cache: copy that one
                out.parent.mkdir(parents=True, exist_ok=True)
                shutil.copy2(kernel.cache_dir() / f"kernel-{kernel.source_id()}-{tag}.so", out)
            else:
                with progress("pythonfmu FMU kernel", fmi, "with ziglang"):
                    kernel.build(out, target=fmi)
        except CompilerError as exc:
            if platforms is not None:
                raise BuildError(f"kernel for {fmi}: {exc}") from None
            print(f"build-fmu: warning: no kernel binary for {fmi} ({exc})", file=sys.stderr)
            continue
        built.append(fmi)
    return built


def build_fmu(dest: str | Path = "fmus", params_file: str | Path | None = None,
              platforms: tuple[str, ...] | None = None, mode: str = "transient") -> dict:
    """Build ``dest/RotorCasingContact.fmu`` with pythonfmu; returns a summary dict.

    ``platforms``: FMI platforms to compile the kernel for (default: this one, plus win64 when ziglang is
    installed). ``mode``: the default of the ``mode`` parameter and what the model description declares
    ('transient': no output depends directly on an input; 'quasi_static': direct feedthrough).
    """
    from rotorub_model import __version__ as lib_version
    from rotorub_model.structure.model import build_model, save_model
    from rotorub_model.structure.params import to_dict

    version = pythonfmu_version()
    try:
        params_path, params = _parameters(params_file, mode)
    except NativeBuildError as exc:
        raise BuildError(str(exc)) from None
    files = _library_files()
    model = build_model(params)
    variables = cv.variables(cv.Defaults.from_parameters(params, model), mode)
    own = scalars(declared(variables, ("fmi2", "pythonfmu")))
    h = hashlib.sha256()
    for p in [SLAVE, params_path, *files]:
        h.update(str(p.relative_to(LIB) if p.is_relative_to(LIB) else p.name).encode())
        h.update(p.read_bytes())
    h.update(json.dumps([as_plain(v) for v in own]).encode())
    h.update(version.encode())
    h.update(mode.encode())
    tag = h.hexdigest()[:10]
    guid = guid_of("pythonfmu", h.hexdigest())  # from everything the FMU carries, not the build time
    lib_name = f"rotorub_model_{tag}"
    manifest = {"library": lib_name, "library_version": lib_version, "parameters": "reference.toml",
                "model": "model.npz", "mode": mode, "feedthrough": mode == "quasi_static",
                "n_blades": params.blades.count, "build": tag, "guid": guid, "pythonfmu": version,
                "host_requirements": HOST_REQUIREMENTS, "optional_requirements": OPTIONAL_REQUIREMENTS,
                "variables": [as_plain(v) for v in own], "constants": cv.SLAVE_CONSTANTS}
    md = model_description(cv.MODEL, variables, fmi="2.0", token=guid, flavour="pythonfmu",
                           generation_tool=f"rotorub {lib_version} (PythonFMU {version})", version=lib_version,
                           feedthrough=mode == "quasi_static")
    with tempfile.TemporaryDirectory(prefix="rotorub_fmu_") as tmp:
        pkg = Path(tmp) / lib_name
        for p in files:
            out = pkg / p.relative_to(LIB)
            out.parent.mkdir(parents=True, exist_ok=True)
            if p.suffix == ".py":
                out.write_text(_check_relative_only(p, p.read_text()))
            else:
                shutil.copy2(p, out)
        save_model(model, Path(tmp) / "model.npz")
        manifest["n_dofs"] = model.n_dofs
        manifest["parameter_values"] = to_dict(params)  # read without a TOML parser (Python 3.10 has none)
        manifest["kernel_platforms"] = _kernel_binaries(pkg, platforms)
        out_file = Path(dest) / f"{cv.MODEL_IDENTIFIER}.fmu"
        doc = documentation_html(cv.MODEL_IDENTIFIER, "FMI 2.0 co-simulation (pythonfmu)", cv.DESCRIPTION,
                                 scalars(declared(variables, ("fmi2", "pythonfmu"))),
                                 f"<h2>What the host needs</h2>\n{PYTHONFMU_HOST}\n<h2>Behaviour</h2>\n"
                                 f"<ul><li>{html.escape(cv.STATUS_TEXT)}</li>\n{PYTHONFMU_LIMITS}</ul>\n"
                                 "<p>The manual: <code>documentation/FMU.md</code>.</p>")
        patched = build_pythonfmu(
            out_file, identifier=cv.MODEL_IDENTIFIER, script=SLAVE, module_name=f"rotorub_casing_contact_{tag}",
            description_xml=xml_bytes(md),
            resources={lib_name: pkg, "reference.toml": params_path, "model.npz": Path(tmp) / "model.npz",
                       "rotorub_fmu.json": json.dumps(manifest, indent=1),
                       "requirements.txt": "\n".join(HOST_REQUIREMENTS) + "\n"},
            documentation={"index.html": doc, "FMU.md": HERE / "FMU.md"})
    with zipfile.ZipFile(out_file) as z:
        names = z.namelist()
    return {"fmu": str(out_file), "guid": guid, "size_bytes": out_file.stat().st_size, "files": len(names),
            "variables": len(own), "blades": params.blades.count, "build": tag, "flavour": "pythonfmu",
            "mode": mode, "parameters": str(params_path), "host_requirements": HOST_REQUIREMENTS,
            "kernel_platforms": manifest["kernel_platforms"], "exit_double_release_patched": patched}


def build_with_kit(dest: str | Path, params: str | Path | None = None, native: bool = False,
                   mode: str = "transient", platforms: tuple[str, ...] | None = None, fmi3: bool = False) -> dict:
    """Build one flavour of RotorCasingContact.fmu into ``dest`` and write its cross-check kit next to it
    (``fmi3``: the native FMI 3.0 FMU and its kit): what ``rotorub build-fmu`` and the main job build."""
    from rotorub_model.structure.params import load_parameters

    from ...fmi.compile import NativeBuildError
    from . import crosscheck

    if fmi3 and not native:
        raise NativeBuildError("--fmi3: the FMI 3.0 FMU is the native one: add --native (pythonfmu 0.7 writes FMI "
                               "2.0 only)")
    if native:
        out = build_native_fmu(dest, params, platforms, mode, fmi="3.0" if fmi3 else "2.0")
    else:
        out = build_fmu(dest, params, platforms, mode)
    p = load_parameters(params) if params else None
    kit = crosscheck.write_kit(Path(out["fmu"]).parent, p, fmi="3.0" if fmi3 else "2.0")
    # the reference experiments inside the FMU (FMI-LS-REF): replayed in any importer by rotorub fmu-check
    from ...fmi import lsref

    refs = crosscheck.ref_experiments(p, "3.0" if fmi3 else "2.0")
    lsref.embed(out["fmu"], cv.MODEL_IDENTIFIER, refs)
    return {**out, "crosscheck_kit": sorted(str(p) for p in kit.values()),
            "reference_experiments": [e.name for e in refs]}
