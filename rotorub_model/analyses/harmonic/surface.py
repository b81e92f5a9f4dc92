"""The casing surface that forces the periodic response: its rigid offset (n = 1) and its lobes (n >= 2).

The model is written in the rotating frame; the casing surface is fixed in the other one. A contact point at
rotating-frame angle alpha_p faces the fixed-frame angle theta = alpha_p + phi, phi = Omega t, and its gap
gets + n_r dR(theta) (n_r the radial part of the casing normal there), with

    dR(theta) = e_x cos theta + e_y sin theta + sum_{n >= 2} a_n cos(n (theta - psi_n)),

the rigid offset (e_x, e_y) of the casing's centre (the kernel's ``rr_surface`` offset: the gap opens where
the offset points) and n-lobe out-of-roundness of amplitude a_n > 0 whose maxima (the gap opened most) lie
at the fixed-frame angles psi_n + 2 pi j / n. The harmonic balance sets the surface's frame angle phi per
time sample (``Liner.struct.phi``): whatever the Liner describes is what the HB sees, the offset today, the
lobes where the kernel's distortion (``Liner.set_distortion({n: (a_n, psi_n)})``) is in the build.

Examples
--------
>>> f = CasingForcing(offset=(2e-4, 0.0))
>>> f.lobe_counts, f.round
((1,), False)
>>> CasingForcing(lobes={1: (1e-4, 0.0)})  # doctest: +ELLIPSIS
Traceback (most recent call last):
...
rotorub_model.errors.ParameterError: lobes: 1 is the casing's rigid offset, not a distortion; ...
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field

from ...contact import ContactModel
from ...contact.liner import Liner
from ...errors import ParameterError

MAX_LOBES = 8
# an amplitude beyond this many clearances is taken for a unit slip (metres for millimetres), not a casing
UNIT_SLIP_FACTOR = 10.0


class ForcingWarning(UserWarning):
    """A casing forcing that runs but that a user probably did not mean."""


def distortion_available() -> bool:
    """Whether this build's liner carries lobes (the kernel's casing distortion)."""
    return hasattr(Liner, "set_distortion")


@dataclass(frozen=True)
class CasingForcing:
    """The fixed-frame casing surface: ``offset`` (x, y) [m] and ``lobes`` {n: (a_n [m], psi_n [rad])}, n >= 2."""

    offset: tuple[float, float] = (0.0, 0.0)
    lobes: dict[int, tuple[float, float]] = field(default_factory=dict)

    def __post_init__(self) -> None:
        x, y = (float(v) for v in self.offset)
        if not (math.isfinite(x) and math.isfinite(y)):
            raise ParameterError(f"offset: {self.offset!r} is not finite; accepted: two finite lengths [m]")
        object.__setattr__(self, "offset", (x, y))
        clean = {}
        for n, val in dict(self.lobes).items():
            if n == 0:
                raise ParameterError("lobes: 0 is a uniform closure of the clearance, not a distortion; give it as "
                                     f"the liner's closure (CLI: --closure); accepted lobe counts 2..{MAX_LOBES}")
            if n == 1:
                raise ParameterError("lobes: 1 is the casing's rigid offset, not a distortion; give it as offset = "
                                     "(a cos psi, a sin psi) [m] (CLI: --offset-x, --offset-y); accepted lobe counts "
                                     f"2..{MAX_LOBES}")
            if not (isinstance(n, int) and 2 <= n <= MAX_LOBES):
                raise ParameterError(f"lobes: {n!r} out of range; accepted lobe counts 2..{MAX_LOBES} (integers)")
            try:
                a, psi = (float(v) for v in val)
            except (TypeError, ValueError):
                raise ParameterError(f"lobes[{n}]: {val!r}; accepted: (amplitude [m], phase [rad])") from None
            if not (math.isfinite(a) and a >= 0 and math.isfinite(psi)):
                raise ParameterError(f"lobes[{n}]: amplitude {a!r}, phase {psi!r}; accepted: amplitude in [0, inf) "
                                     "m, a finite phase [rad]")
            if a > 0:
                clean[n] = (a, psi)
        object.__setattr__(self, "lobes", clean)

    @classmethod
    def lobe(cls, n: int, amplitude: float, phase: float = 0.0) -> CasingForcing:
        """One lobe count n >= 2 (a_n, psi_n)."""
        return cls(lobes={n: (amplitude, phase)})

    @property
    def offset_amplitude(self) -> float:
        return math.hypot(*self.offset)

    @property
    def lobe_counts(self) -> tuple[int, ...]:
        """The harmonics of the spin speed the surface forces (1: the offset)."""
        return tuple(sorted(({1} if self.offset_amplitude > 0 else set()) | set(self.lobes)))

    @property
    def round(self) -> bool:
        return not self.lobe_counts

    @property
    def amplitude(self) -> float:
        """The largest radial departure from the round casing's surface [m] (a bound: the sum of the terms)."""
        return self.offset_amplitude + sum(a for a, _ in self.lobes.values())

    def check(self, g0: float) -> list[str]:
        """Refuse an amplitude that is a unit slip (beyond 10 clearances); warn where it closes the whole
        clearance (every revolution then cuts through it: a heavy rub, possibly not what was meant)."""
        scale = max(abs(g0), 1e-6)
        amp = self.amplitude
        if amp > UNIT_SLIP_FACTOR * scale:
            raise ParameterError(f"casing forcing: amplitude {amp:.4g} m is {amp / scale:.3g} clearances (g0 = "
                                 f"{g0:.4g} m); accepted up to {UNIT_SLIP_FACTOR:g} g0 = {UNIT_SLIP_FACTOR * scale:.4g}"
                                 " m (amplitudes are in metres: 0.2 mm is 2e-4)")
        notes = []
        if amp > scale:
            notes.append(f"casing forcing: amplitude {amp * 1e3:.3g} mm exceeds the clearance g0 = {g0 * 1e3:.3g} mm: "
                         "the casing cuts into the blades' circle every revolution (a heavy rub)")
            warnings.warn(notes[-1], ForcingWarning, stacklevel=2)
        return notes

    def liner(self, contact: ContactModel, wears: bool = False, model=None) -> Liner | None:
        """A liner that holds this surface: rigid (``wears`` False; None for a round casing, the paper's), or the
        parameter file's abradable liner of ``model`` (``wears`` True) on this surface."""
        if self.round and not wears:
            return None
        if self.lobes and not distortion_available():
            raise ParameterError(f"lobes: {sorted(self.lobes)} need the kernel's casing distortion "
                                 "(Liner.set_distortion), which this build does not have; accepted today: the "
                                 "rigid offset (offset = (x, y), the n = 1 term)")
        if wears:
            if model is None:
                raise ParameterError("a wearing liner needs the model (its [abradable] section)")
            liner = Liner.for_model(model, contact, wears=True, offset=self.offset)
        else:
            liner = Liner(contact, wears=False, offset=self.offset)
        if self.lobes:
            liner.set_distortion(dict(self.lobes))
        return liner

    def summary(self) -> dict:
        return {"offset_m": list(self.offset), "lobes": {str(n): {"amplitude_m": a, "phase_rad": p}
                                                         for n, (a, p) in self.lobes.items()},
                "forced_harmonics": list(self.lobe_counts)}
