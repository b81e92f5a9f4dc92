"""Unit systems of finite-element exports, and their conversion to SI.

An FE code works in one *consistent* system: its force unit is its mass unit times its length unit over
its time unit squared (N-mm-t-s: 1 t x 1 mm / 1 s^2 = 1000 kg x 0.001 m / s^2 = 1 N). The matrices it
writes carry no unit, so the user declares the system, as ``FORCE-LENGTH-MASS-TIME`` or by one of the
names below, and every quantity is converted once, on reading:

* coordinates: x_SI = L x;
* a dof vector: u_file = D u_SI, D = diag(1/L for a translation, 1 for a rotation [rad]);
* energies are F L: K_SI = F L D K D and M_SI = m L^2 D M D (translation rows: N/m and kg; rotation rows:
  N m/rad and kg m^2; mixed rows: N/rad and kg m);
* spin speeds: Omega_SI = Omega_file / T (rad per time unit).

A declared system that is not consistent is refused: its matrices could not have come out of one solve
(the centrifugal prestress of an FE code is m Omega^2 r in the code's own units).

>>> s = unit_system("N-mm-t-s")
>>> s.length, s.mass, s.force, s.time
(0.001, 1000.0, 1.0, 1.0)
>>> unit_system("si").name
'SI'
"""

from __future__ import annotations

from dataclasses import dataclass

from ..errors import FEImportError

FORCES = {"N": 1.0, "kN": 1.0e3, "mN": 1.0e-3, "lbf": 4.4482216152605}
LENGTHS = {"m": 1.0, "mm": 1.0e-3, "cm": 1.0e-2, "in": 0.0254, "ft": 0.3048}
MASSES = {"kg": 1.0, "t": 1.0e3, "g": 1.0e-3, "slug": 14.593902937206364, "lbf-s2/in": 175.12683524647636}
TIMES = {"s": 1.0, "ms": 1.0e-3}

# the systems the FE codes use, by the names their users know them by (all consistent)
NAMED: dict[str, tuple[str, str, str, str]] = {
    "SI": ("N", "m", "kg", "s"),
    "N-m-kg-s": ("N", "m", "kg", "s"),
    "N-mm-t-s": ("N", "mm", "t", "s"),       # Abaqus/CalculiX/NASTRAN metric practice, ANSYS MPA
    "mN-mm-kg-s": ("mN", "mm", "kg", "s"),   # ANSYS NMM
    "kN-mm-kg-ms": ("kN", "mm", "kg", "ms"),  # explicit codes' habit (LS-DYNA, Radioss)
    "lbf-in-s": ("lbf", "in", "lbf-s2/in", "s"),  # NASTRAN US practice: mass in lbf s^2/in
    "lbf-ft-slug-s": ("lbf", "ft", "slug", "s"),
}


@dataclass(frozen=True)
class UnitSystem:
    """SI value of one unit of each base quantity of a consistent system."""

    name: str
    force: float
    length: float
    mass: float
    time: float


def accepted_text() -> str:
    return ("one of " + ", ".join(NAMED) + ", or FORCE-LENGTH-MASS-TIME with force in " + "/".join(FORCES)
            + ", length in " + "/".join(LENGTHS) + ", mass in " + "/".join(m for m in MASSES if "/" not in m)
            + ", time in " + "/".join(TIMES) + " (consistent: force = mass x length / time^2)")


def unit_system(spec: str, where: str = "units") -> UnitSystem:
    """The declared unit system, checked for consistency. ``where`` names the parameter in the error."""
    if not isinstance(spec, str) or not spec.strip():
        raise FEImportError(f"{where}: missing; accepted: {accepted_text()}")
    key = spec.strip()
    named = {k.lower(): k for k in NAMED}
    if key.lower() in named:
        name = named[key.lower()]
        f, ln, m, t = NAMED[name]
    else:
        parts = key.split("-")
        if len(parts) != 4:
            raise FEImportError(f"{where}: unknown unit system {spec!r}; accepted: {accepted_text()}")
        f, ln, m, t = parts
        for val, table, what in ((f, FORCES, "force"), (ln, LENGTHS, "length"), (m, MASSES, "mass"),
                                 (t, TIMES, "time")):
            if val not in table:
                raise FEImportError(f"{where}: unknown {what} unit {val!r} in {spec!r}; accepted: {accepted_text()}")
        name = key
    F, L, Ms, T = FORCES[f], LENGTHS[ln], MASSES[m], TIMES[t]
    derived = Ms * L / T**2
    if abs(derived / F - 1.0) > 1e-6:
        raise FEImportError(
            f"{where}: {spec!r} is not a consistent unit system: 1 {m} x 1 {ln} / (1 {t})^2 = {derived:g} N, not "
            f"1 {f} = {F:g} N (an FE code's matrices and prestress come out of one consistent system); "
            f"accepted: {accepted_text()}")
    return UnitSystem(name=name, force=F, length=L, mass=Ms, time=T)
