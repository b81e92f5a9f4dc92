"""Packaging a pythonfmu FMU, whatever the model: staging its slave under a hashed module name, its manifest and
its model description, pythonfmu's builder, and the fix of pythonfmu 0.7.0's exit-time crash.

A slave imports nothing of fmu_src (it runs in the host's Python from the FMU's resources): the build writes
into its resources a JSON manifest (its variables as plain data, the constants it needs) and the model
description (fmu_src/fmi/description.py, the same writer as the native FMUs'), which the slave's ``to_xml``
hands to pythonfmu's builder as it is.

Every pythonfmu FMU in a process shares one interpreter and one ``sys.modules``: a slave is staged under a
module name with the build's hash in it, so two different builds never load each other's modules, while two
copies of the same build share them harmlessly.
"""

from __future__ import annotations

import hashlib
import shutil
import sys
import tempfile
import zipfile
from pathlib import Path

from .package import stage_files

DESCRIPTION_FILE = "model_description.xml"  # in the slave's resources at build time; not shipped


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
PYTHONFMU_SO_SHA256 = "4be156a552c16f30eb4395805c59855d8d4086056d0f165442565f6c5fbac0c9"  # 0.7.0 linux64
ON_UNLOAD_OFFSET = 0x16F30  # onLibraryUnload: endbr64; jmp finalizePythonInterpreter@plt
ON_UNLOAD_BYTES = bytes.fromhex("f30f1efae9")


def pythonfmu_version() -> str:
    try:
        from pythonfmu import __version__
    except ImportError:
        raise BuildError("pythonfmu is not installed: pip install 'rotorub[fmu]'") from None
    return __version__


def _finish(fmu: Path, identifier: str) -> bool:
    """Rewrite the FMU without the staged description and with its linux64 binary patched (see above); returns
    whether it was patched (False, and a warning, if the binary is not the known pythonfmu 0.7.0 one)."""
    member = f"binaries/linux64/{identifier}.so"
    with zipfile.ZipFile(fmu) as z:
        infos = [i for i in z.infolist() if i.filename != f"resources/{DESCRIPTION_FILE}"]
        data = {i.filename: z.read(i.filename) for i in infos}
    so = bytearray(data.get(member, b""))
    patched = hashlib.sha256(so).hexdigest() == PYTHONFMU_SO_SHA256
    if not patched:
        print(f"build-fmu: warning: {member} is not pythonfmu 0.7.0's known binary: its exit-time double release "
              "is not patched (processes may abort at exit; see fmu_src/fmi/pythonfmu.py)", file=sys.stderr)
    else:
        o = ON_UNLOAD_OFFSET
        if so[o:o + 5] != ON_UNLOAD_BYTES:
            raise BuildError(f"{member}: unexpected code at onLibraryUnload; not patched")
        so[o + 4] = 0xC3  # ret
        data[member] = bytes(so)
    tmp = fmu.with_suffix(".fmu.tmp")
    with zipfile.ZipFile(tmp, "w") as z:
        for i in infos:
            z.writestr(i, data[i.filename], compress_type=i.compress_type)
    tmp.replace(fmu)
    return patched


def build_pythonfmu(out_file: Path, *, identifier: str, script: Path, module_name: str, description_xml: bytes,
                    resources: dict[str, Path | str | bytes], documentation: dict[str, Path | str]) -> bool:
    """Build ``out_file`` with pythonfmu from the slave ``script`` (staged as ``module_name``), the files of its
    ``resources`` (name -> a path, file or folder, to copy, or the text or bytes to write) and the model
    description its ``to_xml`` returns (read from resources/model_description.xml at build time). Returns
    whether the exit-time crash was patched. Undoes what pythonfmu's builder leaves in this process (the
    slave's modules, its folders on sys.path)."""
    try:
        from pythonfmu import FmuBuilder
    except ImportError:
        raise BuildError("pythonfmu is not installed: pip install 'rotorub[fmu]'") from None
    out_file = Path(out_file)
    out_file.parent.mkdir(parents=True, exist_ok=True)
    before, path_before = set(sys.modules), list(sys.path)
    with tempfile.TemporaryDirectory(prefix="rotorub_pythonfmu_") as tmp:
        stage = Path(tmp) / "stage"
        files = stage_files(stage, {**resources, DESCRIPTION_FILE: description_xml})
        staged = stage / f"{module_name}.py"
        shutil.copy2(script, staged)
        doc = Path(tmp) / "documentation"
        stage_files(doc, documentation)
        try:
            FmuBuilder.build_FMU(staged, dest=out_file, project_files=files, documentation_folder=doc,
                                 canGetAndSetFMUstate=True, canSerializeFMUstate=True)
        finally:
            # the builder imports the script (and through it what it loads) into this process and leaves its
            # folders on sys.path: undo that, the folders are about to disappear
            prefixes = {module_name, *(Path(n).stem for n in resources)}
            for m in set(sys.modules) - before:
                if m.split(".")[0] in prefixes or m.split(".")[0] == f"_doc_{module_name}":
                    sys.modules.pop(m, None)
            sys.path[:] = path_before
    return _finish(out_file, identifier)
