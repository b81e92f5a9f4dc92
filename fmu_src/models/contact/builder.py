"""Build fmus/RotorCasingContact.fmu from the slave script and a copy of the library.

    rotorub build-fmu [--params my.toml] [--out fmus]      (or: python fmu_src/build/pythonfmu_fmu.py [DEST])

The FMU carries, in its resources folder:

* ``rotorub_casing_contact_<h>.py``: the pythonfmu slave (fmu_src/pythonfmu/rotorub_casing_contact.py);
* ``rotorub_model_<h>/``: a verbatim copy of the ``rotorub_model`` sources and data, with
  the compiled kernel in ``kernel/bin/<machine>-<os>/`` (x86_64-linux, and x86_64-win when
  ziglang can cross-compile it: the platforms pythonfmu's binary exists for);
* ``model.npz``: the model assembled from the parameter file at build time (the host needs
  only numpy to run it; a ``param_file`` given at run time is assembled there, with scipy);
* ``reference.toml``: the parameter file used when the ``param_file`` parameter is empty
  (the embedded reference, or the file given with --params);
* ``rotorub_fmu.json``: which package/parameter file to load and the number of blades;
* ``requirements.txt``: what the host Python needs (``pythonfmu deploy`` can install it);
* ``pythonfmu/``: pythonfmu's Python side (added by pythonfmu's builder).

``<h>`` is a hash of everything above: every pythonfmu FMU in a process shares one
interpreter and one ``sys.modules``, so two different builds (or another FMU built
from this library) never load each other's modules, while two copies of the same
build share them harmlessly. The library copy is imported under that name through
relative imports only; the build refuses sources that import ``rotorub_model`` by
its absolute name.
"""

from __future__ import annotations

import ast
import hashlib
import json
import shutil
import sys
import tempfile
import zipfile
from pathlib import Path

HERE = Path(__file__).resolve().parent.parent  # fmu_src/
SCRIPT = HERE / "pythonfmu" / "rotorub_casing_contact.py"
INTERFACE = HERE / "interface.py"
import rotorub_model  # noqa: E402 - the sources that travel inside the FMU, wherever they are installed

LIB = Path(rotorub_model.__file__).resolve().parent
from .. import interface  # noqa: E402

MODEL_IDENTIFIER = "RotorCasingContact"
HOST_REQUIREMENTS = ["numpy>=1.26"]
# scipy is needed only to assemble a model from a param_file other than the one built in
OPTIONAL_REQUIREMENTS = ["scipy>=1.11"]
# pythonfmu 0.7 ships its binary for these FMI platforms; the kernel is built for each (cross: ziglang)
KERNEL_PLATFORMS = {"linux64": "x86_64-linux", "win64": "x86_64-win"}


class BuildError(Exception):
    pass


# pythonfmu 0.7.0's linux64 binary (libpythonfmu-export.so) releases its global
# std::shared_ptr<PyState> twice at process exit: the C++ static destructor of `pyState`
# (run by exit() through __cxa_atexit) frees the control block, then the ELF destructor
# onLibraryUnload() -> finalizePythonInterpreter() runs `pyState = nullptr` on the destroyed
# shared_ptr and decrements the use count inside the freed block (a 4-byte write into freed
# memory; valgrind: "Invalid read of size 4 ... inside a block of size 128 free'd"). The .so is
# never really unloaded (its STB_GNU_UNIQUE symbols make it NODELETE, so fmpy's dlclose is a no-op),
# hence both always run at exit; when the freed chunk sits in a malloc bin the write corrupts its
# link and glibc aborts later in _dl_fini ("corrupted double-linked list", 1 in 20 to 1 in 8
# processes). The static destructor alone already releases the PyState (and finalises Python in a
# native host), so the fix is one byte: onLibraryUnload's `jmp finalizePythonInterpreter` becomes
# `ret`. benchmarks/bench_exit.py counts the abnormal exits before and after.
_PYTHONFMU_SO_SHA256 = "4be156a552c16f30eb4395805c59855d8d4086056d0f165442565f6c5fbac0c9"  # 0.7.0 linux64
_ON_UNLOAD_OFFSET = 0x16F30  # onLibraryUnload: endbr64; jmp finalizePythonInterpreter@plt
_ON_UNLOAD_BYTES = bytes.fromhex("f30f1efae9")


def _patch_exit_double_release(fmu: Path) -> bool:
    """Rewrite the FMU with its linux64 binary patched (see above); False (and a warning) if the binary
    is not the known pythonfmu 0.7.0 one."""
    member = f"binaries/linux64/{MODEL_IDENTIFIER}.so"
    with zipfile.ZipFile(fmu) as z:
        infos = z.infolist()
        data = {i.filename: z.read(i.filename) for i in infos}
    so = bytearray(data.get(member, b""))
    if hashlib.sha256(so).hexdigest() != _PYTHONFMU_SO_SHA256:
        print(f"build-fmu: warning: {member} is not pythonfmu 0.7.0's known binary: its exit-time double release "
              "is not patched (processes may abort at exit; see fmu_src/build/pythonfmu_fmu.py)", file=sys.stderr)
        return False
    o = _ON_UNLOAD_OFFSET
    if so[o:o + 5] != _ON_UNLOAD_BYTES:
        raise BuildError(f"{member}: unexpected code at onLibraryUnload; not patched")
    so[o + 4] = 0xC3  # ret
    data[member] = bytes(so)
    tmp = fmu.with_suffix(".fmu.tmp")
    with zipfile.ZipFile(tmp, "w") as z:
        for i in infos:
            z.writestr(i, data[i.filename], compress_type=i.compress_type)
    tmp.replace(fmu)
    return True


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


def _documentation(doc: Path, variables: list) -> None:
    doc.mkdir(parents=True, exist_ok=True)
    (doc / "index.html").write_text(interface.documentation_html(variables, "pythonfmu", PYTHONFMU_HOST,
                                                                 PYTHONFMU_LIMITS))
    shutil.copy2(HERE / "FMU.md", doc / "FMU.md")


def _kernel_binaries(pkg: Path, platforms: tuple[str, ...] | None) -> list[str]:
    """Compile the kernel into the library copy for each FMI platform; returns the platforms built.

    ``platforms=None``: this machine's, plus the cross builds ziglang can make (a warning, not an
    error, when it cannot: the FMU then runs where it was built and on any host with a compiler).
    """
    from rotorub_model import kernel
    from rotorub_model.kernel.compiler import CompilerError, host_platform_tag, zig_command

    from .native_compile import progress

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
    """Build ``dest/RotorCasingContact.fmu``; returns a summary dict. Needs pythonfmu.

    ``platforms``: FMI platforms to compile the kernel for (default: this one, plus win64 when
    ziglang is installed). ``mode``: the default of the ``mode`` parameter and what the model
    description declares ('transient': no output depends directly on an input;
    'quasi_static': the outputs follow Omega and imbalance, direct feedthrough).
    """
    try:
        from pythonfmu import FmuBuilder
        from pythonfmu import __version__ as pythonfmu_version
    except ImportError:
        raise BuildError("pythonfmu is not installed: pip install 'rotorub[fmu]'") from None
    from rotorub_model import __version__ as lib_version
    from rotorub_model.structure.model import build_model, save_model
    from rotorub_model.structure.params import load_parameters, to_dict

    params_path = Path(params_file) if params_file else LIB / "data" / "reference.toml"
    params = load_parameters(params_path)  # validated now, not in the master
    dest = Path(dest)
    dest.mkdir(parents=True, exist_ok=True)

    files = _library_files()
    h = hashlib.sha256()
    if mode not in ("transient", "quasi_static"):
        raise BuildError(f"mode: '{mode}' unknown; accepted: transient, quasi_static")
    for p in [SCRIPT, INTERFACE, params_path, *files]:
        h.update(str(p.relative_to(LIB) if p.is_relative_to(LIB) else p.name).encode())
        h.update(p.read_bytes())
    h.update(pythonfmu_version.encode())
    h.update(mode.encode())
    tag = h.hexdigest()[:10]
    guid = interface.guid_of("pythonfmu", h.hexdigest())  # from everything the FMU carries, not the build time
    lib_name = f"rotorub_model_{tag}"
    module_name = f"rotorub_casing_contact_{tag}"
    interface_name = f"rotorub_fmu_interface_{tag}"
    manifest = {"library": lib_name, "library_version": lib_version, "parameters": "reference.toml",
                "model": "model.npz", "interface": interface_name, "mode": mode,
                "feedthrough": mode == "quasi_static", "n_blades": params.blades.count, "build": tag, "guid": guid,
                "pythonfmu": pythonfmu_version, "host_requirements": HOST_REQUIREMENTS,
                "optional_requirements": OPTIONAL_REQUIREMENTS}

    added_modules = set()
    before = set(sys.modules)
    path_before = list(sys.path)
    with tempfile.TemporaryDirectory(prefix="rotorub_fmu_") as tmp:
        stage = Path(tmp) / "stage"
        stage.mkdir()
        pkg = stage / lib_name
        for p in files:
            rel = p.relative_to(LIB)
            out = pkg / rel
            out.parent.mkdir(parents=True, exist_ok=True)
            if p.suffix == ".py":
                out.write_text(_check_relative_only(p, p.read_text()))
            else:
                shutil.copy2(p, out)
        shutil.copy2(params_path, stage / "reference.toml")
        model = build_model(params)
        save_model(model, stage / "model.npz")
        manifest["n_dofs"] = model.n_dofs
        manifest["parameter_values"] = to_dict(params)  # read without a TOML parser (Python 3.10 has none)
        shutil.copy2(INTERFACE, stage / f"{interface_name}.py")
        manifest["kernel_platforms"] = _kernel_binaries(pkg, platforms)
        (stage / "rotorub_fmu.json").write_text(json.dumps(manifest, indent=1))
        (stage / "requirements.txt").write_text("\n".join(HOST_REQUIREMENTS) + "\n")
        script = stage / f"{module_name}.py"
        shutil.copy2(SCRIPT, script)
        _documentation(Path(tmp) / "documentation",
                       interface.variables(interface.Defaults.from_parameters(params), mode, flavour="pythonfmu"))
        out_file = dest / f"{MODEL_IDENTIFIER}.fmu"
        try:
            FmuBuilder.build_FMU(
                script, dest=out_file,
                project_files=[pkg, stage / "reference.toml", stage / "model.npz", stage / "rotorub_fmu.json",
                               stage / "requirements.txt", stage / f"{interface_name}.py"],
                documentation_folder=Path(tmp) / "documentation",
                canGetAndSetFMUstate=True, canSerializeFMUstate=True,
            )
        finally:
            # the builder imports the script (and through it the library copy) into this process
            # and leaves its folders on sys.path: undo that, the folders are about to disappear
            added_modules = set(sys.modules) - before
            for m in added_modules:
                if m.split(".")[0] in (module_name, lib_name, interface_name, f"_doc_{module_name}"):
                    sys.modules.pop(m, None)
            sys.path[:] = path_before
    exit_patch = _patch_exit_double_release(out_file)
    with zipfile.ZipFile(out_file) as z:
        names = z.namelist()
        md = z.read("modelDescription.xml").decode()
    return {"fmu": str(out_file), "guid": guid, "size_bytes": out_file.stat().st_size, "files": len(names),
            "variables": md.count("<ScalarVariable"), "blades": params.blades.count, "build": tag,
            "parameters": str(params_path), "host_requirements": HOST_REQUIREMENTS,
            "kernel_platforms": manifest["kernel_platforms"], "exit_double_release_patched": exit_patch}


def main(argv: list[str] | None = None) -> int:
    import argparse

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("dest", nargs="?", default="fmus")
    ap.add_argument("--params", default=None)
    ns = ap.parse_args(argv)
    try:
        print(json.dumps(build_fmu(ns.dest, ns.params), indent=1))
    except BuildError as exc:
        print(f"build-fmu: error: {exc}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
