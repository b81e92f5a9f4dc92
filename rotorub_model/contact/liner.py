"""The casing's abradable liner, and the engine's inputs on the casing: the kernel's ``rr_surface``.

The liner is ``n_sectors`` cells over the circumference in the casing's (fixed) frame, one row per contact
point of a blade (2D: the tip; 3D: the leading and trailing edges, the worn surface linear between them
along the chord, so the chord law of eq. (5)-(8) holds as it is). A point's gap is its gap to the unworn,
centred casing plus the worn depth of the cell it faces, minus the engine's clearance closure, plus the
casing's rigid offset seen along the point's normal. The liner's law at each cell a point sweeps in a
time step (the kernel's ``rr_liner_law``):

    F = k_r (-(g + w))_+                          elastic, the contact's own penalty,
    F <= F_y + H w                                yield, with linear hardening H,
    dw = (F - F_y - H w) / (k_r + H) > 0          removal when the bound is exceeded (w <= thickness),

so a tip pushed to an incursion delta removes exactly delta - F_y / k_r without hardening. The law is a
blade tip's; the work dissipated in a cell is the law's (the integral of F_y + H w over the removed depth)
times the cell's area over the tip's footprint (blade thickness x chord): the liner's yield pressure
F_y / A_tip (with its hardening) times the volume removed, whatever the cells' count. In 3D each end
point carries half the chord (k_r / 2, F_y / 2, H / 2). Only the time loop cuts the liner; the static
analyses see no liner.
docs/THEORY.md ("Abradable liner") gives the reading of the literature behind this choice.
"""

from __future__ import annotations

import ctypes
import math
from dataclasses import dataclass, field

import numpy as np

from .. import kernel
from ..errors import ParameterError
from ..structure.model import Model
from .contact_model import ContactModel


@dataclass
class Liner:
    """An abradable liner (or a fixed surface: ``wears=False``) facing the blades of ``contact``.

    ``closure`` [m] closes the clearance uniformly (thermal and centrifugal growth from an engine model);
    ``offset`` (x, y) [m] moves the casing's centre in the fixed frame (a carcass or manoeuvre load). Both
    may change between steps (:meth:`set_inputs`). The worn depth, the frame angle of the last cut and the
    plastic work are the liner's state (:meth:`get_state`, :meth:`set_state`)."""

    contact: ContactModel
    yield_force: float = 100.0
    hardening: float = 0.0
    thickness: float = 2.0e-3
    n_sectors: int = 720
    wears: bool = True
    closure: float = 0.0
    offset: tuple[float, float] = (0.0, 0.0)
    # the casing out of round: {n: (a_n [m], psi_n [rad])}, n = 2..kernel.MAX_LOBES; its inner radius grows by
    # sum_n a_n cos(n (theta - psi_n)) at fixed-frame angle theta (psi_n: where lobe n is widest)
    distortion: dict[int, tuple[float, float]] = field(default_factory=dict)
    radius: float = 1.0  # of the casing at the tips [m] (volumes and areas)
    band: float = 0.14  # axial width of the band the tips sweep [m] (the chord's axial extent)
    tip_area: float = 2.2e-3  # a blade tip's footprint on the liner [m^2] (thickness x chord): F_y over it is
    # the liner's yield pressure, and the plastic work the yield pressure times the volume removed
    depth: np.ndarray = field(init=False)

    def __post_init__(self) -> None:
        for name, v, ok, rng in (("yield_force", self.yield_force, self.yield_force > 0, "(0, inf) N"),
                                 ("hardening", self.hardening, self.hardening >= 0, "[0, inf) N/m"),
                                 ("thickness", self.thickness, self.thickness > 0, "(0, inf) m"),
                                 ("radius", self.radius, self.radius > 0, "(0, inf) m"),
                                 ("band", self.band, self.band > 0, "(0, inf) m"),
                                 ("tip_area", self.tip_area, self.tip_area > 0, "(0, inf) m^2")):
            if not (math.isfinite(v) and ok):
                raise ParameterError(f"liner {name}: {v!r} out of range; accepted range {rng}")
        if not (isinstance(self.n_sectors, int | np.integer) and 8 <= self.n_sectors <= 100000):
            raise ParameterError(f"liner n_sectors: {self.n_sectors!r} out of range; accepted range [8, 100000]")
        c = self.contact
        lib = c.lib
        self._tables = np.zeros(lib.rr_surface_table_size(c.n_segments, c.n_points, int(self.n_sectors)))
        self.depth = np.zeros((c.n_rows, int(self.n_sectors)))
        self.struct = kernel.RRSurface(n_sectors=int(self.n_sectors), wears=int(bool(self.wears)),
                                       yield_force=float(self.yield_force), hardening=float(self.hardening),
                                       thickness=float(self.thickness), tables=kernel.ptr(self._tables),
                                       depth=kernel.ptr(self.depth), work_weight=self.cell_area / self.tip_area)
        self.set_inputs(self.closure, self.offset, self.distortion)
        if lib.rr_surface_init(c.kernel, ctypes.byref(self.struct)) != 0:
            raise ParameterError("liner: the kernel refused its parameters")

    @classmethod
    def for_model(cls, model: Model, contact: ContactModel, wears: bool | None = None, **overrides) -> Liner:
        """The parameter file's ``[abradable]`` liner for ``contact`` (``wears``: its ``enabled`` unless
        given); ``overrides``: any field (yield_force, hardening, thickness, n_sectors, closure, offset)."""
        p = model.params
        a = p.abradable
        kw = {"yield_force": a.yield_force, "hardening": a.hardening, "thickness": a.thickness,
              "n_sectors": a.n_sectors, "radius": p.blades.tip_radius,
              "band": p.contact.chord * math.cos(math.radians(p.blades.stagger_deg)),
              "tip_area": p.blades.thickness * p.contact.chord}
        t = contact.geometry.tips
        if t is not None and t.band > 0 and t.tip_area > 0:  # an imported tip: its own extent and footprint
            kw.update(band=t.band, tip_area=t.tip_area)
        kw.update(overrides)
        return cls(contact, wears=a.enabled if wears is None else bool(wears), **kw)

    def set_inputs(self, closure: float | None = None, offset: tuple[float, float] | None = None,
                   distortion: dict[int, tuple[float, float]] | None = None) -> None:
        """The engine's inputs, held from the next step on (``distortion``: see :meth:`set_distortion`)."""
        if distortion is not None:
            self.set_distortion(distortion)
        if closure is not None:
            if not math.isfinite(closure):
                raise ParameterError(f"clearance closure: {closure!r} is not finite")
            self.closure = float(closure)
            self.struct.closure = self.closure
        if offset is not None:
            x, y = (float(v) for v in offset)
            if not (math.isfinite(x) and math.isfinite(y)):
                raise ParameterError(f"casing offset: {offset!r} is not finite")
            self.offset = (x, y)
            self.struct.offset_x, self.struct.offset_y = x, y

    def set_distortion(self, lobes: dict[int, tuple[float, float]]) -> None:
        """The casing out of round, held from the next step on: ``{n: (amplitude [m], phase [rad])}`` for lobe
        counts n = 2..8 (n = 1, a rigid shift, is the offset); the inner radius grows by a_n cos(n (theta - psi_n))
        at the fixed-frame angle theta, so a blade's gap opens where a_n cos(...) > 0. Lobes not named are round.
        """
        amp = [0.0] * (kernel.MAX_LOBES + 1)
        phase = [0.0] * (kernel.MAX_LOBES + 1)
        for n, value in dict(lobes).items():
            if isinstance(n, bool) or not isinstance(n, int | np.integer) or not 2 <= n <= kernel.MAX_LOBES:
                raise ParameterError(f"casing distortion: lobe count {n!r} out of range; accepted: integers 2 to "
                                     f"{kernel.MAX_LOBES} (a lobe count of 1 is a rigid shift: the casing offset)")
            try:
                a, psi = (float(v) for v in value)
            except (TypeError, ValueError):
                raise ParameterError(f"casing distortion: lobe {n}: expected (amplitude [m], phase [rad]), got "
                                     f"{value!r}") from None
            if not (math.isfinite(a) and math.isfinite(psi)):
                raise ParameterError(f"casing distortion: lobe {n}: ({a!r}, {psi!r}) is not finite")
            amp[int(n)], phase[int(n)] = a, psi
        self.distortion = {n: (amp[n], phase[n]) for n in range(2, kernel.MAX_LOBES + 1) if amp[n] != 0.0}
        self.struct.lobe_amp[:] = amp
        self.struct.lobe_phase[:] = phase

    @property
    def is_neutral(self) -> bool:
        """A surface that adds exactly 0 to every gap: rigid, nothing worn, no closure, offset or distortion."""
        return (not self.wears and self.closure == 0.0 and self.offset == (0.0, 0.0) and not self.distortion
                and not np.any(self.depth))

    # ------------------------------------------------------------------ geometry of the cells
    @property
    def angles(self) -> np.ndarray:
        """Fixed-frame angles of the cells' centres [rad]."""
        return (np.arange(self.n_sectors) + 0.5) * (2 * np.pi / self.n_sectors)

    @property
    def cell_area(self) -> float:
        """A cell's area on the casing [m^2]: its arc at the tip radius times the band the tips sweep."""
        return self.radius * (2 * np.pi / self.n_sectors) * self.band

    @property
    def profile(self) -> np.ndarray:
        """The worn profile: the rows' mean depth at each cell [m] (3D: the mean over the chord)."""
        return self.depth.mean(axis=0)

    def summary(self) -> dict[str, float]:
        """The kernel's summary of the profile (rr_surface_summary): depths, volume, work, lobes, harmonics."""
        out = np.zeros(len(kernel.WEAR_NAMES))
        self.contact.lib.rr_surface_summary(self.contact.kernel, ctypes.byref(self.struct), self.cell_area,
                                            kernel.ptr(out))
        s = dict(zip(kernel.WEAR_NAMES, map(float, out)))
        s["lobes"] = int(s["lobes"])
        s["clearance_effective"] = float(self.contact.g0 - self.closure + s["depth_mean"])
        return s

    def summary_into(self, out: np.ndarray) -> np.ndarray:
        """The kernel's summary in its order (kernel.WEAR_NAMES) into ``out`` (float64, contiguous): the
        FMU's per-step path, no dict."""
        self.contact.lib.rr_surface_summary(self.contact.kernel, ctypes.byref(self.struct), self.cell_area,
                                            kernel.ptr(out))
        return out

    # ------------------------------------------------------------------ state
    @property
    def phi(self) -> float:
        return float(self.struct.phi)

    @property
    def plastic_work(self) -> float:
        return float(self.struct.plastic_work)

    def get_state(self) -> tuple:
        return (self.depth.copy(), float(self.struct.phi), float(self.struct.plastic_work), self.closure,
                self.offset, dict(self.distortion), tuple(self.struct.cut_inputs))

    def set_state(self, state: tuple) -> None:
        depth, phi, work, closure, offset, distortion, cut_inputs = state
        depth = np.asarray(depth, dtype=float)
        if depth.shape != self.depth.shape or not np.all(np.isfinite(depth)) or np.any(depth < 0):
            raise ParameterError(f"liner state: depth of shape {depth.shape}, expected {self.depth.shape}, finite, "
                                 ">= 0")
        self.depth[:] = depth  # in place: the kernel holds its address
        self.struct.phi, self.struct.plastic_work = float(phi), float(work)
        self.set_inputs(closure, offset, distortion)
        self.struct.cut_inputs[:] = [float(v) for v in cut_inputs]

    def attach(self, c: kernel.RRContact) -> kernel.RRContact:
        """A copy of the contact's kernel struct that sees this surface."""
        k = kernel.RRContact.from_buffer_copy(c)
        k.surface = ctypes.addressof(self.struct)
        return k
