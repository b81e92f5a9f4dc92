"""The compiled kernel (``rr_*.c`` behind ``rotorub_kernel.h``): loading it, and typed handles on its structs.

The shared library is found, in this order:

1. ``$ROTORUB_KERNEL``: an explicit path (a binary built elsewhere);
2. ``bin/<machine>-<os>/`` next to this file: a binary shipped with a copy of the package
   (the FMU carries one), used when its source id matches the sources here;
3. the user cache (``$ROTORUB_CACHE_DIR``, else ``$XDG_CACHE_HOME/rotorub``, else
   ``~/.cache/rotorub``): ``kernel-<source id>-<machine>-<os>.so``;
4. otherwise it is compiled once into that cache (see :mod:`.compiler`), which takes a
   second with the system compiler and a few with ziglang.

The source id is a hash of the C sources and flags, so an edited kernel is rebuilt and two versions
of the library never load each other's binary.
"""

from __future__ import annotations

import ctypes
import hashlib
import os
from functools import lru_cache
from pathlib import Path

import numpy as np

from .compiler import CFLAGS, CompilerError, compile_shared, host_platform_tag, host_suffix

HERE = Path(__file__).resolve().parent
# one concern a file (rr_internal.h lists them); the library, both FMUs and the benchmarks compile all of them
# (rr_batch: the harmonic balance's evaluation of forces and Jacobians at many samples)
SOURCES = tuple(HERE / f"rr_{name}.c" for name in ("core", "geometry", "laws", "contact", "liner", "cd", "linalg",
                                                   "static", "batch"))
HEADER = HERE / "rotorub_kernel.h"
INTERNAL_HEADER = HERE / "rr_internal.h"  # declarations shared by the sources, exported by none
MATH_HEADER = HERE / "rr_math.h"  # the elementary functions: the same bits on every platform
HEADERS = (HEADER, INTERNAL_HEADER, MATH_HEADER, HERE / "rr_batch.h")
ABI_VERSION = 9
LAW_WIDTH = 8  # F_N, M_N, dF/deta, dF/dzeta, dM/deta, dM/dzeta, chord fraction, potential
OUT_BLADE_BLOCKS = 6
OUT_GLOBALS = 8
# names of the per-blade output blocks and of the globals, in the kernel's order (rotorub_kernel.h)
OUT_BLADE_NAMES = ("F_N", "F_T", "gap_LE", "gap_TE", "gap_tip", "contact_fraction")
OUT_GLOBAL_NAMES = ("casing_force.x", "casing_force.y", "casing_force.z", "friction_torque",
                    "disk_displacement.x", "disk_displacement.y", "gap_min", "n_contact")

# arrays cross as plain addresses (c_void_p): an int from ``a.ctypes.data`` converts fastest,
# and hot callers cache it
_dp = ctypes.c_void_p
_ip = ctypes.c_void_p


# the normal laws (rotorub_kernel.h, "contact laws"): the kernel's ids, and each law's parameters in its order
LAW_IDS = {"penalty": 0, "bilinear": 1}
LAW_PARAMS = 4


class RRLaw(ctypes.Structure):
    _fields_ = [("id", ctypes.c_int), ("par", ctypes.c_double * LAW_PARAMS)]


class RRContact(ctypes.Structure):
    _fields_ = [("n", ctypes.c_int), ("nb", ctypes.c_int), ("np", ctypes.c_int), ("g0", ctypes.c_double),
                ("k_r", ctypes.c_double), ("mu", ctypes.c_double), ("chord", ctypes.c_double),
                ("v_slip", ctypes.c_double), ("law", RRLaw),
                # imported blades' tips (segments between chord stations): NULL / 0 for the built-in blades
                ("seg_len", _dp), ("seg_k", _dp), ("g_off", _dp), ("nloc", ctypes.c_int), ("cols", _ip),
                ("nb_out", ctypes.c_int), ("blade_of", _ip), ("n_rows", ctypes.c_int), ("point_row", _ip),
                ("point_share", _dp),
                ("G", _dp), ("A", _dp), ("B", _dp), ("S", _dp),
                ("points", _dp), ("normals", _dp), ("tangents", _dp), ("T2", _dp), ("work", _dp),
                ("surface", ctypes.c_void_p)]


MAX_LOBES = 8  # casing distortion: lobe counts 2..MAX_LOBES (rotorub_kernel.h RR_MAX_LOBES)


class RRSurface(ctypes.Structure):
    _fields_ = [("n_sectors", ctypes.c_int), ("wears", ctypes.c_int), ("yield_force", ctypes.c_double),
                ("hardening", ctypes.c_double), ("thickness", ctypes.c_double), ("closure", ctypes.c_double),
                ("offset_x", ctypes.c_double), ("offset_y", ctypes.c_double),
                ("lobe_amp", ctypes.c_double * (MAX_LOBES + 1)), ("lobe_phase", ctypes.c_double * (MAX_LOBES + 1)),
                ("phi", ctypes.c_double),
                ("work_weight", ctypes.c_double), ("plastic_work", ctypes.c_double), ("changed", ctypes.c_int),
                ("tables", _dp), ("depth", _dp), ("cut_inputs", ctypes.c_double * (3 + 2 * (MAX_LOBES + 1)))]


WEAR_HARMONICS = 8
# rr_surface_summary's layout (rotorub_kernel.h)
WEAR_NAMES = ("depth_max", "depth_mean", "volume", "plastic_work", "lobes",
              *(f"harmonic_{h}" for h in range(1, WEAR_HARMONICS + 1)))


class RRGeometrySpec(ctypes.Structure):
    _fields_ = [("n", ctypes.c_int), ("nb", ctypes.c_int), ("np", ctypes.c_int), ("rotations", ctypes.c_int),
                ("r_tip", ctypes.c_double), ("stagger", ctypes.c_double), ("theta", ctypes.c_double),
                ("chord", ctypes.c_double), ("z_cg", ctypes.c_double), ("blade_dof0", ctypes.c_int),
                ("n_ritz", ctypes.c_int), ("psi_tip", _dp), ("casing_dof0", ctypes.c_int), ("n_modes", ctypes.c_int),
                ("modes", _ip), ("T", _dp), ("Rot", _dp)]


class RRGeometry(ctypes.Structure):
    _fields_ = [(name, _dp) for name in ("points", "normals", "tangents", "Jb", "Jc", "G", "A", "B", "S", "T2")]


class RRBlocks(ctypes.Structure):
    """The step's matrices by blocks (rotorub_kernel.h rr_cd_blocks): hub, blades of m dofs, casing."""

    _fields_ = [("ns", ctypes.c_int), ("nb", ctypes.c_int), ("m", ctypes.c_int), ("nc", ctypes.c_int),
                *[(k, _dp) for k in ("K2_hh", "K2_hb", "K2_bh", "K2_bb", "K2_cc", "C_hh", "C_hb", "C_bh", "C_bb",
                                     "C_cc", "A_hb", "Binv", "W", "Sinv", "Cinv")]]


class RRMatrices(ctypes.Structure):
    _fields_ = [("n", ctypes.c_int), ("Ainv", _dp), ("K2", _dp), ("Cm1", _dp), ("f", _dp), ("f0", _dp),
                ("blocks", ctypes.c_void_p)]


class RRState(ctypes.Structure):
    _fields_ = [("t", ctypes.c_double), ("dt", ctypes.c_double), ("phi", ctypes.c_double),
                ("max_pen", ctypes.c_double), ("steps", ctypes.c_longlong), ("diverged", ctypes.c_int),
                ("q", _dp), ("q_prev", _dp)]


class RRJob(ctypes.Structure):
    _fields_ = [("state", ctypes.c_void_p), ("contact", ctypes.c_void_p), ("mats", ctypes.c_void_p),
                ("n_steps", ctypes.c_int), ("omega", ctypes.c_double), ("me", ctypes.c_double),
                ("t_ramp", ctypes.c_double), ("rec_every", ctypes.c_int), ("rec_cap", ctypes.c_int),
                ("n_rec", ctypes.c_int), ("rec_q", _dp), ("rec_out", _dp), ("out_index", _ip), ("out_dest", _dp),
                ("done", ctypes.c_int), ("rec_wear_every", ctypes.c_int), ("rec_wear_cap", ctypes.c_int),
                ("n_rec_wear", ctypes.c_int), ("rec_wear", _dp), ("stop_on_contact", ctypes.c_int), ("cache", _dp),
                ("cache_valid", ctypes.c_int)]


def source_id() -> str:
    """Hash of the kernel's sources and compiler flags (names the binary; checked when loading one)."""
    h = hashlib.sha256(" ".join(CFLAGS).encode())
    for p in (*SOURCES, *HEADERS):
        h.update(p.name.encode())
        h.update(p.read_bytes().replace(b"\r\n", b"\n"))
    return h.hexdigest()[:16]


def cache_dir() -> Path:
    if os.environ.get("ROTORUB_CACHE_DIR"):
        return Path(os.environ["ROTORUB_CACHE_DIR"])
    base = os.environ.get("XDG_CACHE_HOME") or (Path.home() / ".cache")
    return Path(base) / "rotorub"


def shipped_binary(tag: str | None = None) -> Path:
    """Where a copy of the package carries a prebuilt kernel for platform ``tag``."""
    tag = tag or host_platform_tag()
    suffix = ".dll" if tag.endswith("windows") or tag.endswith("win") else host_suffix()
    return HERE / "bin" / tag / f"rotorub_kernel{suffix}"


def build(out: Path, target: str | None = None) -> Path:
    """Compile the kernel into ``out`` (``target``: an FMI platform folder, for a cross build)."""
    return compile_shared(list(SOURCES), out, target=target, defines={"RR_SOURCE_ID": f'"{source_id()}"'},
                          include=[HERE])


def _declare(lib: ctypes.CDLL) -> ctypes.CDLL:
    c = ctypes.POINTER(RRContact)
    lib.rr_abi_version.restype = ctypes.c_int
    lib.rr_source_id.restype = ctypes.c_char_p
    lib.rr_work_size.argtypes = [ctypes.c_int, ctypes.c_int, ctypes.c_int]
    lib.rr_work_size.restype = ctypes.c_int
    lib.rr_contact_geometry.argtypes = [ctypes.c_void_p, ctypes.c_void_p]
    lib.rr_contact_geometry.restype = ctypes.c_int
    lib.rr_lu.argtypes = [ctypes.c_int, _dp, _ip]
    lib.rr_lu.restype = ctypes.c_int
    lib.rr_lu_solve.argtypes = [ctypes.c_int, _dp, _ip, _dp]
    lib.rr_lu_solve.restype = None
    lib.rr_inverse.argtypes = [ctypes.c_int, _dp, _dp, _dp, _ip]
    lib.rr_inverse.restype = ctypes.c_int
    lib.rr_eigenvalues.argtypes = [ctypes.c_int, _dp, _dp, _dp, _dp]
    lib.rr_eigenvalues.restype = ctypes.c_int
    lib.rr_cd_build.argtypes = [ctypes.c_int, *[_dp] * 9, ctypes.c_double, ctypes.c_double, ctypes.c_double,
                                _dp, _dp, _dp, _dp, _ip]
    lib.rr_cd_build.restype = ctypes.c_int
    lib.rr_static_work_size.argtypes = [ctypes.c_int]
    lib.rr_static_work_size.restype = ctypes.c_int
    lib.rr_static_solve.argtypes = [ctypes.POINTER(RRContact), ctypes.c_double, _dp, _dp, _dp, ctypes.c_double,
                                    ctypes.c_int, _dp,
                                    ctypes.POINTER(ctypes.c_double), ctypes.POINTER(ctypes.c_int), _dp, _ip]
    lib.rr_static_solve.restype = ctypes.c_int
    lib.rr_static_newton.argtypes = [ctypes.POINTER(RRContact), ctypes.c_double, _dp, _dp, ctypes.c_double,
                                     ctypes.c_int, _dp, ctypes.POINTER(ctypes.c_double), ctypes.POINTER(ctypes.c_int),
                                     _dp, _ip]
    lib.rr_static_newton.restype = ctypes.c_int
    law = ctypes.POINTER(RRLaw)
    lib.rr_blade_law.argtypes = [law, ctypes.c_int, ctypes.c_double, ctypes.c_double, ctypes.c_double,
                                 ctypes.c_double, _dp]
    lib.rr_law_check.argtypes = [law]
    lib.rr_law_check.restype = ctypes.c_int
    lib.rr_law_max_slope.argtypes = [law]
    lib.rr_law_max_slope.restype = ctypes.c_double
    lib.rr_potential_batch.argtypes = [c, ctypes.c_int, _dp, _dp]
    lib.rr_closed_stiffness.argtypes = [c, ctypes.c_double, _dp]
    lib.rr_k_omega.argtypes = [ctypes.c_int, _dp, _dp, _dp, _dp, _dp, ctypes.c_double, _dp]
    lib.rr_critical_step.argtypes = [c, ctypes.c_double, _dp, _dp, _dp]
    lib.rr_critical_step.restype = ctypes.c_double
    lib.rr_critical_step_work_size.argtypes = [ctypes.c_int]
    lib.rr_critical_step_work_size.restype = ctypes.c_int
    lib.rr_cd_cache_size.argtypes = [ctypes.c_int, ctypes.c_int, ctypes.c_int]
    lib.rr_cd_cache_size.restype = ctypes.c_int
    lib.rr_cd_blocks_size.argtypes = [ctypes.c_int] * 4
    lib.rr_cd_blocks_size.restype = ctypes.c_int
    lib.rr_cd_blocks_work_size.argtypes = [ctypes.c_int] * 3
    lib.rr_cd_blocks_work_size.restype = ctypes.c_int
    lib.rr_cd_build_blocks.argtypes = [ctypes.c_int] * 5 + [_dp] * 9 + [ctypes.c_double] * 3 + [
        _dp, ctypes.c_void_p, _dp, _ip]
    lib.rr_cd_build_blocks.restype = ctypes.c_int
    lib.rr_laws.argtypes = [c, _dp, _dp, _dp]
    lib.rr_friction.argtypes = [c, _dp, _dp, ctypes.c_double, _dp]
    lib.rr_force.argtypes = [c, _dp, _dp, ctypes.c_double, _dp]
    lib.rr_jacobian.argtypes = [c, _dp, _dp, ctypes.c_double, _dp, _dp]
    lib.rr_gaps_batch.argtypes = [c, ctypes.c_int, _dp, _dp]
    lib.rr_outputs.argtypes = [c, _dp, _dp, ctypes.c_double, ctypes.c_double, _ip, _dp]
    lib.rr_outputs_batch.argtypes = [c, ctypes.c_int, _dp, _dp, ctypes.c_double, _dp]
    lib.rr_elementary.argtypes = [ctypes.c_int, ctypes.c_int, _dp, _dp, _dp]
    lib.rr_elementary.restype = None
    lib.rr_cd_run.argtypes = [ctypes.c_void_p]
    lib.rr_cd_run.restype = ctypes.c_int
    lib.rr_surface_table_size.argtypes = [ctypes.c_int, ctypes.c_int, ctypes.c_int]
    lib.rr_surface_table_size.restype = ctypes.c_int
    lib.rr_surface_init.argtypes = [c, ctypes.c_void_p]
    lib.rr_surface_init.restype = ctypes.c_int
    lib.rr_liner_law.argtypes = [law] + [ctypes.c_double] * 5 + [ctypes.c_int, ctypes.POINTER(ctypes.c_double),
                                                                 ctypes.POINTER(ctypes.c_double)]
    lib.rr_liner_law.restype = ctypes.c_double
    lib.rr_surface_summary.argtypes = [c, ctypes.c_void_p, ctypes.c_double, _dp]
    lib.rr_surface_summary.restype = None
    for name in ("rr_blade_law", "rr_laws", "rr_friction", "rr_force", "rr_jacobian", "rr_gaps_batch", "rr_outputs",
                 "rr_outputs_batch", "rr_potential_batch", "rr_closed_stiffness", "rr_k_omega"):
        getattr(lib, name).restype = None
    return lib


def _open(path: Path, expect_id: str | None) -> ctypes.CDLL | None:
    try:
        lib = ctypes.CDLL(str(path))
    except OSError:
        return None
    lib.rr_abi_version.restype = ctypes.c_int
    lib.rr_source_id.restype = ctypes.c_char_p
    if lib.rr_abi_version() != ABI_VERSION:
        return None
    if expect_id is not None and lib.rr_source_id().decode() != expect_id:
        return None
    return _declare(lib)


@lru_cache(maxsize=1)
def load() -> ctypes.CDLL:
    """The kernel library of this process (built into the user cache on first use)."""
    sid = source_id()
    explicit = os.environ.get("ROTORUB_KERNEL")
    if explicit:
        lib = _open(Path(explicit), None)
        if lib is None:
            raise CompilerError(f"ROTORUB_KERNEL={explicit}: not a loadable rotorub kernel of ABI {ABI_VERSION}")
        return lib
    shipped = shipped_binary()
    if shipped.exists():
        lib = _open(shipped, sid)
        if lib is not None:
            return lib
    cached = cache_dir() / f"kernel-{sid}-{host_platform_tag()}{host_suffix()}"
    if cached.exists():
        lib = _open(cached, sid)
        if lib is not None:
            return lib
    import sys

    print(f"[rotorub] compiling the C kernel once into {cached.parent} (a second with the system compiler, up to "
          "a quarter of a minute with ziglang the first time)", file=sys.stderr, flush=True)
    build(cached)
    lib = _open(cached, sid)
    if lib is None:
        raise CompilerError(f"the kernel built at {cached} cannot be loaded")
    return lib


def make_law(name: str = "penalty", params: tuple[float, ...] = ()) -> RRLaw:
    """The kernel's law record of law ``name`` with its parameters (in the law's order, contact/laws.py)."""
    if name not in LAW_IDS:
        raise ValueError(f"law: '{name}' unknown; accepted: {', '.join(LAW_IDS)}")
    par = [float(v) for v in params] + [0.0] * (LAW_PARAMS - len(params))
    return RRLaw(LAW_IDS[name], (ctypes.c_double * LAW_PARAMS)(*par))


PENALTY = make_law()


def blade_law(g_le: float, g_te: float, k: float, l: float, law: RRLaw = PENALTY, np_: int = 2) -> tuple[float, ...]:
    """The kernel's law of one blade (np_ = 2: the chord law; 1: the point law at g_le): F_N, M_N, dF/deta,
    dF/dzeta, dM/deta, dM/dzeta, chord fraction, potential."""
    out = (ctypes.c_double * LAW_WIDTH)()
    load().rr_blade_law(ctypes.byref(law), int(np_), float(g_le), float(g_te), float(k), float(l), out)
    return tuple(out)


def chord_law(g_le: float, g_te: float, k: float, l: float, law: RRLaw = PENALTY) -> tuple[float, ...]:
    """The kernel's chord law of one blade: (F_N, M_N, dF/deta, dF/dzeta, dM/deta, dM/dzeta, fraction)."""
    return blade_law(g_le, g_te, k, l, law, 2)[:7]


def point_law(g: float, k: float, law: RRLaw = PENALTY) -> tuple[float, float]:
    """The kernel's point law: (F_N, dF/dg)."""
    out = blade_law(g, 0.0, k, 1.0, law, 1)
    return out[0], out[2]


def liner_law(g: float, k: float, fy: float, h: float, thickness: float, depth: float = 0.0,
              wears: bool = True, law: RRLaw = PENALTY) -> tuple[float, float, float]:
    """The kernel's abradable-liner law at one cell: (force, depth after the cut, work dissipated)."""
    d, w = ctypes.c_double(float(depth)), ctypes.c_double(0.0)
    f = load().rr_liner_law(ctypes.byref(law), float(g), float(k), float(fy), float(h), float(thickness),
                            int(bool(wears)), ctypes.byref(d), ctypes.byref(w))
    return f, d.value, w.value


def k_omega(K: np.ndarray, S2: np.ndarray, N2: np.ndarray, C1: np.ndarray, omega: float,
            S4: np.ndarray | None = None) -> np.ndarray:
    """The kernel's K(Omega) = K + Omega^2 (S2 + N2) + Omega C1 (+ Omega^4 S4) (the FMUs' and the time loop's bits)."""
    n = K.shape[0]
    arrays = [np.ascontiguousarray(a, dtype=float) for a in (K, S2, N2, C1)]
    s4 = None if S4 is None else np.ascontiguousarray(S4, dtype=float)
    out = np.empty((n, n))
    load().rr_k_omega(n, *map(ptr, arrays), None if s4 is None else ptr(s4), float(omega), ptr(out))
    return out


def eigenvalues(A: np.ndarray) -> np.ndarray:
    """The kernel's eigenvalues of a real square matrix (balancing, Hessenberg, double-shift QR): what
    the FMUs compute in C, so the library's step limits and stability indicators match theirs."""
    n = A.shape[0]
    a = np.array(A, dtype=float, order="C")
    wr, wi, work = np.empty(n), np.empty(n), np.empty(n)
    if load().rr_eigenvalues(n, ptr(a), ptr(wr), ptr(wi), ptr(work)) != 0:
        raise np.linalg.LinAlgError("eigenvalues: the QR iteration did not converge")
    return wr + 1j * wi


def inverse(A: np.ndarray) -> np.ndarray:
    """The kernel's inverse (LU with partial pivoting)."""
    n = A.shape[0]
    a = np.ascontiguousarray(A, dtype=float)
    out, work, piv = np.empty((n, n)), np.empty((n, n)), np.empty(n, dtype=np.intc)
    if load().rr_inverse(n, ptr(a), ptr(out), ptr(work), iptr(piv)) != 0:
        raise np.linalg.LinAlgError("inverse: singular matrix")
    return out


ELEMENTARY = ("sin", "cos", "tan", "atan2", "tanh", "exp", "sqrt", "floor", "ceil")  # rr_elementary's codes


def elementary(name: str, x, y=None) -> np.ndarray:
    """The kernel's own elementary function ``name`` (rr_math.h) on an array: what every platform's build
    computes bit for bit (atan2: ``elementary("atan2", y, x)``, C's argument order)."""
    if name not in ELEMENTARY:
        raise ValueError(f"elementary: '{name}' unknown; accepted: {', '.join(ELEMENTARY)}")
    a = np.ascontiguousarray(x, dtype=float).ravel()
    b = np.ascontiguousarray(a if y is None else np.broadcast_to(y, np.shape(x)), dtype=float).ravel()
    out = np.empty_like(a)
    load().rr_elementary(ELEMENTARY.index(name), a.size, ptr(a), ptr(b), ptr(out))
    return out.reshape(np.shape(x))


def ptr(a: np.ndarray) -> int:
    """Address of a C-contiguous float64 array, for a double* argument (the array must outlive its use)."""
    if a.dtype != np.float64 or not a.flags.c_contiguous:
        raise TypeError("kernel arrays are C-contiguous float64")
    return a.ctypes.data


def iptr(a: np.ndarray) -> int:
    """Address of a C-contiguous C-int array, for an int* argument."""
    if a.dtype != np.intc or not a.flags.c_contiguous:
        raise TypeError("kernel index arrays are C-contiguous intc")
    return a.ctypes.data


__all__ = [
    "ABI_VERSION", "CompilerError", "LAW_IDS", "LAW_WIDTH", "MAX_LOBES", "OUT_BLADE_NAMES", "PENALTY", "RRLaw",
    "blade_law", "k_omega", "liner_law", "make_law", "OUT_GLOBAL_NAMES", "RRContact", "RRGeometry",
    "RRGeometrySpec", "RRJob", "RRMatrices", "RRState", "build", "cache_dir", "chord_law", "eigenvalues", "elementary",
    "inverse",
    "iptr", "load", "point_law", "ptr", "source_id",
]
