"""The interface of LPSpool, one definition for both spool FMUs (native C and pythonfmu).

Pure data and no imports from the package: the pythonfmu build stages this file next to the slave
script (under a hashed module name, as the contact FMU's interface), and the native build turns it
into the C variable table (fmu_src/build/native_fmu.py). Value references are the positions in SPECS.

Model (fmu_src/native/spool_model.c, fmu_src/pythonfmu/spool_slave.py): one rigid spool of polar
inertia J,

    J dOmega/dt = tau_drive(t) - c_w Omega^2 + friction_torque,

with the drive torque a schedule in time, tau_drive = J dOmega_s/dt + c_w Omega_s^2, that makes the
rub-free spool follow the half-cosine run-up Omega_s(t) exactly:

    Omega_s(t) = Omega0 + (Omega1 - Omega0) (1 - cos(pi x)) / 2,  x = clip((t - t_ramp_start) / t_ramp, 0, 1).

Integration: RK4 on e = Omega - Omega_s(t) in n = ceil(h / dt_max) equal substeps per communication
step, friction_torque held (zero-order hold). A step at whose end Omega would be negative or not
finite is refused (fmi2Discard, status 1: the spool stops; the run ends).
"""

from __future__ import annotations

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

# FMI 2.0 unit definitions: name -> SI base-unit exponents
UNITS = {
    "rad/s": {"rad": 1, "s": -1},
    "N.m": {"kg": 1, "m": 2, "s": -2},
    "kg.m2": {"kg": 1, "m": 2},
    "N.m.s2/rad2": {"kg": 1, "m": 2, "rad": -2},
    "s": {"s": 1},
}

DEFAULT_EXPERIMENT = {"startTime": 0.0, "stopTime": 5.0, "stepSize": 1e-3}

# (name, type, causality, variability, unit, (min, max) or None, description), in value-reference order.
# The ranges are the ones an engine spool can have (a few grams to a hundred tonnes metre squared, ...):
# declared so that a tool checks them, and refused outside.
SPECS = [
    ("friction_torque", "Real", "input", "continuous", "N.m", (-1e8, 1e8),
     "External axial torque on the spool, held over each communication step: the friction torque of the "
     "blade-tip contact (negative brakes the spin)"),
    ("J", "Real", "parameter", "fixed", "kg.m2", (1e-3, 1e5),
     "Polar moment of inertia of the whole LP spool (fan hub and blades, shaft, LP turbine)"),
    ("c_w", "Real", "parameter", "fixed", "N.m.s2/rad2", (0.0, 1e3),
     "Windage coefficient: windage torque c_w Omega^2 opposing the spin"),
    ("Omega0", "Real", "parameter", "fixed", "rad/s", (0.0, 1e4),
     "Initial spin speed, held until t_ramp_start (start of the speed schedule)"),
    ("Omega1", "Real", "parameter", "fixed", "rad/s", (0.0, 1e4),
     "Final spin speed of the schedule, reached at t_ramp_start + t_ramp"),
    ("t_ramp_start", "Real", "parameter", "fixed", "s", (-1e6, 1e6), "Time the run-up (or run-down) starts"),
    ("t_ramp", "Real", "parameter", "fixed", "s", (1e-6, 1e6),
     "Duration of the speed change Omega0 -> Omega1 (half-cosine: zero acceleration at both ends)"),
    ("dt_max", "Real", "parameter", "fixed", "s", (1e-7, 1.0),
     "Largest internal RK4 step: each communication step h is split into ceil(h / dt_max) equal substeps"),
    ("Omega", "Real", "output", "continuous", "rad/s", None, "Spin speed of the LP spool"),
    ("Omega_schedule", "Real", "output", "continuous", "rad/s", None,
     "Speed the drive schedule was designed for: the speed of the spool without external torque"),
    ("drive_torque", "Real", "output", "continuous", "N.m", None,
     "Drive torque of the schedule, J dOmega_schedule/dt + c_w Omega_schedule^2 (open loop)"),
    ("windage_torque", "Real", "output", "continuous", "N.m", None, "Windage torque c_w Omega^2 (brakes the spin)"),
    ("status", "Integer", "output", "discrete", None, None,
     "0 = ok, 1 = the spool stopped (Omega would fall below 0 or stop being finite; step refused, the run ends), "
     "2 = bad parameter or input (message in the log; call refused)"),
    ("message", "String", "output", "discrete", None, None,
     "Cause of the last refused call (the text also sent to the FMI logger); empty after a step that succeeded"),
]
