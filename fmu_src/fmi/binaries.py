"""What a compiled FMU binary exports, read from the file itself (ELF, PE, Mach-O), whatever the host.

The native FMU's Windows and macOS binaries are cross-compiled here and cannot be loaded here;
reading their export tables is how the build checks that every FMI 2.0 co-simulation function is
there (and nothing of the kernel leaks out), without an nm for every object format.
"""

from __future__ import annotations

import struct
from pathlib import Path

FMI2_CS_FUNCTIONS = (
    "fmi2GetTypesPlatform", "fmi2GetVersion", "fmi2SetDebugLogging", "fmi2Instantiate", "fmi2FreeInstance",
    "fmi2SetupExperiment", "fmi2EnterInitializationMode", "fmi2ExitInitializationMode", "fmi2Terminate", "fmi2Reset",
    "fmi2GetReal", "fmi2GetInteger", "fmi2GetBoolean", "fmi2GetString", "fmi2SetReal", "fmi2SetInteger",
    "fmi2SetBoolean", "fmi2SetString", "fmi2GetFMUstate", "fmi2SetFMUstate", "fmi2FreeFMUstate",
    "fmi2SerializedFMUstateSize", "fmi2SerializeFMUstate", "fmi2DeSerializeFMUstate", "fmi2GetDirectionalDerivative",
    "fmi2SetRealInputDerivatives", "fmi2GetRealOutputDerivatives", "fmi2DoStep", "fmi2CancelStep", "fmi2GetStatus",
    "fmi2GetRealStatus", "fmi2GetIntegerStatus", "fmi2GetBooleanStatus", "fmi2GetStringStatus",
)


# every function of the FMI 3.0 API (fmi3Functions.h): the FMU exports them all, the ones it does not provide
# refusing with fmi3Error and a message
FMI3_FUNCTIONS = (
    "fmi3GetVersion", "fmi3SetDebugLogging", "fmi3InstantiateModelExchange", "fmi3InstantiateCoSimulation",
    "fmi3InstantiateScheduledExecution", "fmi3FreeInstance", "fmi3EnterInitializationMode",
    "fmi3ExitInitializationMode", "fmi3EnterEventMode", "fmi3Terminate", "fmi3Reset", "fmi3GetFloat32",
    "fmi3GetFloat64", "fmi3GetInt8", "fmi3GetUInt8", "fmi3GetInt16", "fmi3GetUInt16", "fmi3GetInt32",
    "fmi3GetUInt32", "fmi3GetInt64", "fmi3GetUInt64", "fmi3GetBoolean", "fmi3GetString", "fmi3GetBinary",
    "fmi3GetClock", "fmi3SetFloat32", "fmi3SetFloat64", "fmi3SetInt8", "fmi3SetUInt8", "fmi3SetInt16",
    "fmi3SetUInt16", "fmi3SetInt32", "fmi3SetUInt32", "fmi3SetInt64", "fmi3SetUInt64", "fmi3SetBoolean",
    "fmi3SetString", "fmi3SetBinary", "fmi3SetClock", "fmi3GetNumberOfVariableDependencies",
    "fmi3GetVariableDependencies", "fmi3GetFMUState", "fmi3SetFMUState", "fmi3FreeFMUState",
    "fmi3SerializedFMUStateSize", "fmi3SerializeFMUState", "fmi3DeserializeFMUState", "fmi3GetDirectionalDerivative",
    "fmi3GetAdjointDerivative", "fmi3EnterConfigurationMode", "fmi3ExitConfigurationMode", "fmi3GetIntervalDecimal",
    "fmi3GetIntervalFraction", "fmi3GetShiftDecimal", "fmi3GetShiftFraction", "fmi3SetIntervalDecimal",
    "fmi3SetIntervalFraction", "fmi3SetShiftDecimal", "fmi3SetShiftFraction", "fmi3EvaluateDiscreteStates",
    "fmi3UpdateDiscreteStates", "fmi3EnterContinuousTimeMode", "fmi3CompletedIntegratorStep", "fmi3SetTime",
    "fmi3SetContinuousStates", "fmi3GetContinuousStateDerivatives", "fmi3GetEventIndicators",
    "fmi3GetContinuousStates", "fmi3GetNominalsOfContinuousStates", "fmi3GetNumberOfEventIndicators",
    "fmi3GetNumberOfContinuousStates", "fmi3EnterStepMode", "fmi3GetOutputDerivatives", "fmi3DoStep",
    "fmi3ActivateModelPartition",
)


def _cstr(data: bytes, off: int) -> str:
    end = data.index(b"\0", off)
    return data[off:end].decode("ascii", "replace")


def _elf(data: bytes) -> tuple[str, set[str]]:
    if data[4] != 2:
        raise ValueError("32-bit ELF")
    e = "<" if data[5] == 1 else ">"
    machine = struct.unpack_from(e + "H", data, 18)[0]
    shoff, = struct.unpack_from(e + "Q", data, 40)
    shentsize, shnum = struct.unpack_from(e + "HH", data, 58)
    sections = [struct.unpack_from(e + "IIQQQQIIQQ", data, shoff + k * shentsize) for k in range(shnum)]
    out = set()
    for sh in sections:
        if sh[1] != 11:  # SHT_DYNSYM
            continue
        strtab = sections[sh[6]]
        for k in range(sh[5] // 24):
            name, info, _other, shndx = struct.unpack_from(e + "IBBH", data, sh[4] + k * 24)
            bind, vis = info >> 4, _other & 3
            if shndx != 0 and bind in (1, 2) and vis == 0 and name:  # defined, global or weak, default visibility
                out.add(_cstr(data, strtab[4] + name))
    return {62: "x86_64", 183: "aarch64"}.get(machine, f"machine {machine}"), out


def elf_version_needs(path: str | Path) -> dict[str, list[str]]:
    """The symbol versions an ELF shared library needs, per library it links ({"libc.so.6": ["GLIBC_2.2.5",
    "GLIBC_2.14"]}): read from its .gnu.version_r section, as the dynamic loader checks them. The newest
    GLIBC_x.y there is the oldest glibc the binary loads on."""
    data = Path(path).read_bytes()
    if data[:4] != b"\x7fELF" or data[4] != 2:
        raise ValueError(f"{path}: not a 64-bit ELF file")
    e = "<" if data[5] == 1 else ">"
    shoff, = struct.unpack_from(e + "Q", data, 40)
    shentsize, shnum = struct.unpack_from(e + "HH", data, 58)
    sections = [struct.unpack_from(e + "IIQQQQIIQQ", data, shoff + k * shentsize) for k in range(shnum)]
    out: dict[str, list[str]] = {}
    for sh in sections:
        if sh[1] != 0x6FFFFFFE:  # SHT_GNU_verneed
            continue
        strtab = sections[sh[6]][4]
        at, count = sh[4], sh[7]  # sh_info: the number of entries
        for _ in range(count):
            _ver, cnt, file_, aux, nxt = struct.unpack_from(e + "HHIII", data, at)
            lib = _cstr(data, strtab + file_)
            a = at + aux
            for _ in range(cnt):
                _hash, _flags, _other, name, anext = struct.unpack_from(e + "IHHII", data, a)
                out.setdefault(lib, []).append(_cstr(data, strtab + name))
                a += anext
            at += nxt
    return out


def newest_glibc(path: str | Path) -> tuple[int, ...]:
    """The newest GLIBC_x.y version a Linux binary needs (the oldest glibc it loads on); () if none."""
    versions = [tuple(int(x) for x in v.split("_", 1)[1].split("."))
                for vs in elf_version_needs(path).values() for v in vs if v.startswith("GLIBC_2")]
    return max(versions, default=())


def _pe(data: bytes) -> tuple[str, set[str]]:
    pe, = struct.unpack_from("<I", data, 0x3C)
    machine, nsec, _t, _p, _n, optsize = struct.unpack_from("<HHIIIH", data, pe + 4)
    opt = pe + 24
    magic, = struct.unpack_from("<H", data, opt)
    ddir = opt + (112 if magic == 0x20B else 96)
    exp_rva, _size = struct.unpack_from("<II", data, ddir)
    secs = [struct.unpack_from("<8sIIII", data, opt + optsize + 40 * k) for k in range(nsec)]

    def off(rva: int) -> int:
        for _n, vsize, va, rsize, raw in secs:
            if va <= rva < va + max(vsize, rsize):
                return raw + rva - va
        raise ValueError(f"RVA {rva:#x} outside every section")

    out = set()
    if exp_rva:
        d = off(exp_rva)
        n_names, = struct.unpack_from("<I", data, d + 24)
        names_rva, = struct.unpack_from("<I", data, d + 32)
        for k in range(n_names):
            rva, = struct.unpack_from("<I", data, off(names_rva) + 4 * k)
            out.add(_cstr(data, off(rva)))
    return {0x8664: "x86_64", 0xAA64: "aarch64"}.get(machine, f"machine {machine:#x}"), out


def _macho(data: bytes, base: int = 0) -> tuple[str, set[str]]:
    magic, cputype, _sub, _ft, ncmds, _size, _flags = struct.unpack_from("<IiiIIII", data, base)
    if magic != 0xFEEDFACF:
        raise ValueError("not a 64-bit little-endian Mach-O")
    at, out = base + 32, set()
    for _ in range(ncmds):
        cmd, cmdsize = struct.unpack_from("<II", data, at)
        if cmd == 0x2:  # LC_SYMTAB
            symoff, nsyms, stroff, _strsize = struct.unpack_from("<IIII", data, at + 8)
            for k in range(nsyms):
                strx, ntype, _sect, _desc, _value = struct.unpack_from("<IBBHQ", data, base + symoff + 16 * k)
                if ntype & 0x01 and (ntype & 0x0E) == 0x0E:  # N_EXT, N_SECT: defined and external
                    name = _cstr(data, base + stroff + strx)
                    out.add(name[1:] if name.startswith("_") else name)
        at += cmdsize
    return {0x01000007: "x86_64", 0x0100000C: "aarch64"}.get(cputype, f"cpu {cputype:#x}"), out


def exported_symbols(path: str | Path) -> list[tuple[str, set[str]]]:
    """[(architecture, exported function names)] of a shared library (one entry per slice of a fat Mach-O)."""
    data = Path(path).read_bytes()
    if data[:4] == b"\x7fELF":
        return [_elf(data)]
    if data[:2] == b"MZ":
        return [_pe(data)]
    if data[:4] == b"\xca\xfe\xba\xbe":  # fat Mach-O (big-endian header)
        n, = struct.unpack_from(">I", data, 4)
        return [_macho(data, struct.unpack_from(">iiIII", data, 8 + 20 * k)[2]) for k in range(n)]
    return [_macho(data)]


def missing_fmi_functions(path: str | Path, fmi: str = "2.0") -> dict[str, list[str]]:
    """Per architecture, the FMI 2.0 co-simulation functions (``fmi = "3.0"``: the FMI 3.0 API's) the binary
    does not export (empty: all there)."""
    wanted = FMI3_FUNCTIONS if fmi == "3.0" else FMI2_CS_FUNCTIONS
    return {arch: [f for f in wanted if f not in names] for arch, names in exported_symbols(path)}
