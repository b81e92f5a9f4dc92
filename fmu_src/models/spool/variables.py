"""LPSpool's variables, one list for both spool FMUs (native C and pythonfmu): the native build turns it into
the C tables and variables.h, the pythonfmu build into the slave's manifest (the slave imports nothing of
fmu_src); both write their model description from it (fmu_src/fmi/description.py).

Model (model.c, slave.py next to this file): one rigid spool of polar inertia J,

    J dOmega/dt = tau_drive(t) - c_w Omega^2 + friction_torque,

with the drive torque a schedule in time, tau_drive = J dOmega_s/dt + c_w Omega_s^2, that makes the
rub-free spool follow the half-cosine run-up Omega_s(t) exactly:

    Omega_s(t) = Omega0 + (Omega1 - Omega0) (1 - cos(pi x)) / 2,  x = clip((t - t_ramp_start) / t_ramp, 0, 1).

Integration: RK4 on e = Omega - Omega_s(t) in n = ceil(h / dt_max) equal substeps per communication
step, friction_torque held (zero-order hold). A step at whose end Omega would be negative or not
finite is refused (fmi2Discard, status 1: the spool stops; the run ends).
"""

from __future__ import annotations

from ...fmi.description import ModelInfo
from ...fmi.variables import TIME, Var, numbered, ranged

MODEL_IDENTIFIER = "LPSpool"
DESCRIPTION = (
    "Speed of the low-pressure spool of a turbofan: J dOmega/dt = tau_drive(t) - c_w Omega^2 + friction_torque. "
    "The drive torque schedule makes the rub-free spool follow a run-up speed schedule exactly; the friction "
    "torque of the blade-tip/casing contact (RotorCasingContact.fmu) slows it down."
)
STATUS_OK, STATUS_STOPPED, STATUS_ERROR = 0, 1, 2
MAX_SUBSTEPS = 10_000_000  # per communication step, as the contact FMU's (fmu_model.h MODEL_MAX_SUBSTEPS)

# reference low-pressure spool of the rotorub fan (reference.toml): polar inertia of the fan hub
# (15.7) + LP turbine (9.2) + ten 5.8 kg blades from r = 0.4 to 1.0 m (10 x 3.02) + hollow shaft (0.44)
DEFAULTS = {
    "J": 55.5,  # kg m^2
    "c_w": 0.05,  # N m s^2/rad^2: 2.5 kN m of windage at 224 rad/s
    "Omega0": 149.52,  # rad/s: 2.8 x omega_ref (53.4 rad/s), below the first critical speed (3.49 x omega_ref)
    "Omega1": 224.28,  # rad/s: 4.2 x omega_ref, above it
    "t_ramp_start": 0.5,  # s
    "t_ramp": 4.0,  # s
    "dt_max": 1.0e-3,  # s
}

# unit -> (SI base-unit exponents, display units)
UNITS = {
    "rad/s": ({"rad": 1, "s": -1}, {}),
    "N.m": ({"kg": 1, "m": 2, "s": -2}, {}),
    "kg.m2": ({"kg": 1, "m": 2}, {}),
    "N.m.s2/rad2": ({"kg": 1, "m": 2, "rad": -2}, {}),
    "s": ({"s": 1}, {}),
}

DEFAULT_EXPERIMENT = {"startTime": 0.0, "stopTime": 5.0, "stepSize": 1e-3}

MODEL = ModelInfo(identifier=MODEL_IDENTIFIER, description=DESCRIPTION, units=UNITS,
                  default_experiment=DEFAULT_EXPERIMENT, initial_from_parameters=True)


def variables(values: dict | None = None) -> list[Var]:
    """The spool's variables in value-reference order, numbered; the start values DEFAULTS overridden by
    ``values``. The ranges are the ones an engine spool can have (a few grams to a hundred tonnes metre squared,
    ...): declared so that a tool checks them, and refused outside. New variables go at the end."""
    x = {**DEFAULTS, **(values or {})}

    def par(name: str, unit: str, rng: tuple[float, float], text: str, *kind: str) -> Var:
        return ranged(name, unit, rng, text, x.get(name, 0.0), *kind)

    def out(name: str, unit: str, text: str) -> Var:
        return Var(name, "Real", "output", "continuous", text, unit=unit)

    return numbered([
        par("friction_torque", "N.m", (-1e8, 1e8),
            "External axial torque on the spool, held over each communication step: the friction torque of the "
            "blade-tip contact (negative brakes the spin)", "input", "continuous"),
        par("J", "kg.m2", (1e-3, 1e5),
            "Polar moment of inertia of the whole LP spool (fan hub and blades, shaft, LP turbine)"),
        par("c_w", "N.m.s2/rad2", (0.0, 1e3), "Windage coefficient: windage torque c_w Omega^2 opposing the spin"),
        par("Omega0", "rad/s", (0.0, 1e4), "Initial spin speed, held until t_ramp_start (start of the speed schedule)"),
        par("Omega1", "rad/s", (0.0, 1e4), "Final spin speed of the schedule, reached at t_ramp_start + t_ramp"),
        par("t_ramp_start", "s", (-1e6, 1e6), "Time the run-up (or run-down) starts"),
        par("t_ramp", "s", (1e-6, 1e6),
            "Duration of the speed change Omega0 -> Omega1 (half-cosine: zero acceleration at both ends)"),
        par("dt_max", "s", (1e-7, 1.0),
            "Largest internal RK4 step: each communication step h is split into ceil(h / dt_max) equal substeps"),
        out("Omega", "rad/s", "Spin speed of the LP spool"),
        out("Omega_schedule", "rad/s",
            "Speed the drive schedule was designed for: the speed of the spool without external torque"),
        out("drive_torque", "N.m",
            "Drive torque of the schedule, J dOmega_schedule/dt + c_w Omega_schedule^2 (open loop)"),
        out("windage_torque", "N.m", "Windage torque c_w Omega^2 (brakes the spin)"),
        Var("status", "Integer", "output", "discrete",
            "0 = ok, 1 = the spool stopped (Omega would fall below 0 or stop being finite; step refused, the run "
            "ends), 2 = bad parameter or input (message in the log; call refused)"),
        Var("message", "String", "output", "discrete",
            "Cause of the last refused call (the text also sent to the FMI logger); empty after a step that "
            "succeeded"),
        TIME,  # the FMI 3.0 build's independent variable (FMI 2.0: none, a gap)
    ])


# what the pythonfmu slave reads from its manifest (it imports nothing of fmu_src)
SLAVE_CONSTANTS = {"DESCRIPTION": DESCRIPTION, "DEFAULTS": DEFAULTS, "MAX_SUBSTEPS": MAX_SUBSTEPS,
                   "STATUS_OK": STATUS_OK, "STATUS_STOPPED": STATUS_STOPPED, "STATUS_ERROR": STATUS_ERROR}
