"""LPSpool: FMI 2.0 co-simulation slave for the speed of the low-pressure spool.

This file is the pythonfmu script of ``LPSpool.fmu`` (built by
:func:`fmu_src.engine.spool.build_spool_fmu`, which stages it under a hashed module name,
``lpspool_<hash>``: every pythonfmu FMU in a process shares one ``sys.modules``).
It is self-contained: numpy is not even needed.

Model: one rigid spool of polar inertia J,

    J dOmega/dt = tau_drive(t) - c_w Omega^2 + tau_ext,

``tau_ext`` the input ``friction_torque`` (the axial torque of the blade-tip contact
forces on the rotor, negative when it brakes), ``c_w Omega^2`` the windage. The drive
torque is a schedule in time, designed so that the rub-free spool follows the speed
schedule

    Omega_s(t) = Omega0 + (Omega1 - Omega0) (1 - cos(pi x)) / 2,   x = clip((t - t_ramp_start) / t_ramp, 0, 1),

exactly: tau_drive(t) = J dOmega_s/dt + c_w Omega_s(t)^2 (feed-forward, open loop: the
drive does not react to the rub). The speed is C1 and the drive torque continuous.

Integration: the state is the deviation e = Omega - Omega_s(t) from the schedule,

    J de/dt = tau_ext - c_w e (2 Omega_s(t) + e),

advanced over each communication step [t, t + h] by classical RK4 in n equal
substeps, n = ceil(h / dt_max), with tau_ext held (zero-order hold, as a master sets
it). With tau_ext = 0 and e(0) = 0 every RK4 stage is exactly 0, so the rub-free
spool reproduces Omega_s(t) to the last bit; with rub the scheme's error is
O(dt^4) on e, a small quantity. Omega = Omega_s(t) + e is the output.

pythonfmu turns an exception escaping a callback into fmi2Fatal and destroys the
Python instance, so no callback lets one out: bad parameters or inputs make
``do_step`` return False (fmi2Discard) after logging a message (status fmi2Error)
that names the variable, and the instance stays usable (corrected inputs,
fmi2SetFMUstate or fmi2Reset).
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from xml.etree.ElementTree import Element, SubElement

from pythonfmu import Fmi2Causality, Fmi2Initial, Fmi2Slave, Fmi2Variability, Integer, Real
from pythonfmu.enums import Fmi2Status

DEFAULTS_FILE = "lpspool_defaults.json"
STATUS_OK, STATUS_STOPPED, STATUS_ERROR = 0, 1, 2
STATE_VERSION = 1

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


class LPSpool(Fmi2Slave):
    author = "rotorub developers"
    description = (
        "Speed of the low-pressure spool of a turbofan: J dOmega/dt = tau_drive(t) - c_w Omega^2 + friction_torque. "
        "The drive torque schedule makes the rub-free spool follow a run-up speed schedule exactly; the friction "
        "torque of the blade-tip/casing contact (RotorCasingContact.fmu) slows it down."
    )
    license = "MIT"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.version = "1.0"
        self.copyright = "rotorub developers"
        here = Path(self.resources) if self.resources else Path(__file__).parent
        defaults = dict(DEFAULTS)
        try:
            defaults.update(json.loads((here / DEFAULTS_FILE).read_text()))
        except (OSError, ValueError):
            pass  # no build-time defaults: the module's own
        self._specs = [
            ("friction_torque", "Real", "input", "continuous", "N.m",
             "External axial torque on the spool, held over each communication step: the friction torque of the "
             "blade-tip contact (negative brakes the spin); must be finite"),
            ("J", "Real", "parameter", "fixed", "kg.m2",
             "Polar moment of inertia of the whole LP spool (fan hub and blades, shaft, LP turbine); > 0"),
            ("c_w", "Real", "parameter", "fixed", "N.m.s2/rad2",
             "Windage coefficient: windage torque c_w Omega^2 opposing the spin; >= 0"),
            ("Omega0", "Real", "parameter", "fixed", "rad/s",
             "Initial spin speed, held until t_ramp_start (start of the speed schedule); >= 0"),
            ("Omega1", "Real", "parameter", "fixed", "rad/s",
             "Final spin speed of the schedule, reached at t_ramp_start + t_ramp; >= 0"),
            ("t_ramp_start", "Real", "parameter", "fixed", "s", "Time the run-up (or run-down) starts"),
            ("t_ramp", "Real", "parameter", "fixed", "s",
             "Duration of the speed change Omega0 -> Omega1 (half-cosine: zero acceleration at both ends); > 0"),
            ("dt_max", "Real", "parameter", "fixed", "s",
             "Largest internal RK4 step: each communication step h is split into ceil(h / dt_max) equal substeps; "
             "> 0"),
            ("Omega", "Real", "output", "continuous", "rad/s", "Spin speed of the LP spool"),
            ("Omega_schedule", "Real", "output", "continuous", "rad/s",
             "Speed the drive schedule was designed for: the speed of the spool without external torque"),
            ("drive_torque", "Real", "output", "continuous", "N.m",
             "Drive torque of the schedule, J dOmega_schedule/dt + c_w Omega_schedule^2 (open loop)"),
            ("windage_torque", "Real", "output", "continuous", "N.m", "Windage torque c_w Omega^2 (brakes the spin)"),
            ("status", "Integer", "output", "discrete", None,
             "0 = ok, 1 = the spool stopped (Omega would fall below 0 or stop being finite; step refused), "
             "2 = bad parameter or input (message in the log; step refused)"),
        ]
        n = len(self._specs)
        self._values = [0.0] * n
        self._slot = {s[0]: i for i, s in enumerate(self._specs)}
        for name, value in defaults.items():
            if name in self._slot:
                self._values[self._slot[name]] = float(value)
        self._values[self._slot["status"]] = STATUS_OK
        for i, spec in enumerate(self._specs):
            self._register(i, spec)
        self._phase = "instantiated"  # -> initialization -> step -> terminated
        self._t = 0.0  # current communication point
        self._e = 0.0  # state: Omega - Omega_schedule
        self._cfg = None  # checked parameters (dict), set at the end of initialization
        self._fatal_msg = None  # configuration error: every step is refused until reset
        self._warned_fixed = set()
        self._update_outputs()

    # ------------------------------------------------------------------ variables
    def _register(self, i: int, spec) -> None:
        name, kind, causality, variability, _unit, desc = spec
        cls, conv = (Real, float) if kind == "Real" else (Integer, int)
        initial = Fmi2Initial.calculated if causality == "output" else None

        def getter(i=i, conv=conv):
            return conv(self._values[i])

        def setter(v, i=i, conv=conv):
            self._set_value(i, conv(v))

        v = cls(name, causality=Fmi2Causality[causality], variability=Fmi2Variability[variability],
                description=desc, initial=initial, getter=getter, setter=setter)
        self.register_variable(v, nested=False)
        assert v.value_reference == i

    def _set_value(self, i: int, value) -> None:
        """Store a value set by the master; never raises (checks happen in initialization and do_step)."""
        name, _kind, causality, variability = self._specs[i][:4]
        if causality == "output":
            self.log(f"{name}: is an output and cannot be set; value ignored", Fmi2Status.error)
            return
        if variability == "fixed" and self._phase in ("step", "terminated"):
            if name not in self._warned_fixed:
                self._warned_fixed.add(name)
                self.log(f"{name}: fixed parameter, cannot change after initialization (reset first); new value "
                         "ignored", Fmi2Status.warning)
            return
        self._values[i] = value

    def _v(self, name: str) -> float:
        return self._values[self._slot[name]]

    def _set_out(self, name: str, value) -> None:
        self._values[self._slot[name]] = value

    # ------------------------------------------------------------------ model description
    def to_xml(self, model_options=None):
        """pythonfmu's description plus units, InitialUnknowns, no direct feedthrough, a default experiment."""
        root = super().to_xml(model_options or {})
        units = Element("UnitDefinitions")
        for name, base in UNITS.items():
            SubElement(SubElement(units, "Unit", name=name), "BaseUnit", {k: str(v) for k, v in base.items()})
        children = list(root)
        cs_pos = next(i for i, el in enumerate(children) if el.tag == "CoSimulation")
        root.insert(cs_pos + 1, units)
        if root.find("DefaultExperiment") is None:
            de = Element("DefaultExperiment", startTime="0", stopTime="5", stepSize="0.001")
            root.insert(list(root).index(root.find("ModelVariables")), de)
        for sv, spec in zip(root.find("ModelVariables"), self._specs):
            real = sv.find("Real")
            if real is not None and real.get("start") is not None:  # pythonfmu writes %.16g: not round-trip
                real.set("start", repr(float(self._values[self._slot[spec[0]]])))
            if spec[4] is not None:
                real.set("unit", spec[4])
        ms = root.find("ModelStructure")
        outs = ms.find("Outputs")
        init = SubElement(ms, "InitialUnknowns")
        for u in outs:
            u.set("dependencies", "")  # the outputs at t depend on the state only, not on the input at t
            SubElement(init, "Unknown", index=u.get("index"))
        return root

    # ------------------------------------------------------------------ FMI life cycle
    def setup_experiment(self, start_time=0.0, stop_time=None, tolerance=None):
        t0 = float(start_time or 0.0)
        self._t = t0 if math.isfinite(t0) else 0.0
        self._update_outputs()

    def enter_initialization_mode(self, *args):
        self._phase = "initialization"

    def exit_initialization_mode(self, *args):
        self._phase = "step"
        try:
            self._cfg = self._check_parameters()
            self._fatal_msg = None
            self._e = 0.0
            self._set_out("status", STATUS_OK)
        except ValueError as exc:
            self._configuration_error(str(exc))
        except Exception as exc:  # noqa: BLE001 - reported, never raised (pythonfmu would go fatal)
            self._configuration_error(f"{type(exc).__name__}: {exc}")
        self._update_outputs()

    def terminate(self):
        self._phase = "terminated"

    def do_step(self, current_time, step_size):
        try:
            return self._do_step(float(current_time), float(step_size))
        except Exception as exc:  # noqa: BLE001 - last resort: report instead of dying
            self._report(STATUS_ERROR, f"internal error at t = {current_time!r} s: {type(exc).__name__}: {exc}; "
                         "step refused")
            return False

    # ------------------------------------------------------------------ messages
    def _report(self, status: int, msg: str) -> None:
        self._set_out("status", status)
        self.log(f"LPSpool: {msg}", Fmi2Status.error if status == STATUS_ERROR else Fmi2Status.discard)

    def _configuration_error(self, msg: str) -> None:
        self._fatal_msg = msg
        self._cfg = None
        self._report(STATUS_ERROR, msg + " (every step is refused until the FMU is reset)")

    # ------------------------------------------------------------------ physics
    def _check_parameters(self) -> dict:
        """The parameters, checked (raises ValueError naming the first bad one)."""
        v = {k: float(self._v(k)) for k in ("J", "c_w", "Omega0", "Omega1", "t_ramp_start", "t_ramp", "dt_max")}
        rules = (
            ("J", "kg.m2", v["J"] > 0, "(0, inf)", "the polar inertia must be finite and > 0"),
            ("c_w", "N.m.s2/rad2", v["c_w"] >= 0, "[0, inf)", "the windage coefficient must be finite and >= 0"),
            ("Omega0", "rad/s", v["Omega0"] >= 0, "[0, inf)", "the initial spin speed must be finite and >= 0"),
            ("Omega1", "rad/s", v["Omega1"] >= 0, "[0, inf)", "the final spin speed must be finite and >= 0"),
            ("t_ramp_start", "s", True, "(-inf, inf)", "the start of the schedule must be finite"),
            ("t_ramp", "s", v["t_ramp"] > 0, "(0, inf)", "the duration of the speed change must be finite and > 0"),
            ("dt_max", "s", v["dt_max"] > 0, "(0, inf)", "the internal step limit must be finite and > 0"),
        )
        for name, unit, ok, rng, why in rules:
            if not (math.isfinite(v[name]) and ok):
                raise ValueError(f"{name}: {v[name]!r} {unit} out of range; {why}; accepted range {rng} {unit}")
        return v

    def _schedule(self, t: float) -> tuple[float, float]:
        """(Omega_s(t), dOmega_s/dt) of the speed schedule."""
        cfg = self._cfg if self._cfg is not None else {k: float(self._v(k)) for k in DEFAULTS}
        x = (t - cfg["t_ramp_start"]) / cfg["t_ramp"]
        if not x > 0.0:  # also NaN: before the start
            return cfg["Omega0"], 0.0
        if x >= 1.0:
            return cfg["Omega1"], 0.0
        d = cfg["Omega1"] - cfg["Omega0"]
        return cfg["Omega0"] + 0.5 * d * (1.0 - math.cos(math.pi * x)), 0.5 * d * math.pi / cfg["t_ramp"] * math.sin(
            math.pi * x)

    def _update_outputs(self) -> None:
        """Outputs at the current communication point from (t, e)."""
        try:
            ws, wsd = self._schedule(self._t)
            cfg = self._cfg if self._cfg is not None else {k: float(self._v(k)) for k in DEFAULTS}
            w = ws + self._e
            self._set_out("Omega", w)
            self._set_out("Omega_schedule", ws)
            self._set_out("drive_torque", cfg["J"] * wsd + cfg["c_w"] * ws * ws)
            self._set_out("windage_torque", cfg["c_w"] * w * w)
        except Exception as exc:  # noqa: BLE001 - e.g. t_ramp = 0 before initialization: outputs stay as they are
            self.log(f"LPSpool: outputs not updated ({type(exc).__name__}: {exc})", Fmi2Status.warning)

    def _rk4(self, t: float, h: float, e: float, tau: float) -> float:
        """e(t + h) by RK4 in n = ceil(h / dt_max) substeps at the held external torque tau."""
        cfg = self._cfg
        J, cw = cfg["J"], cfg["c_w"]
        n = max(1, math.ceil(h / cfg["dt_max"] * (1.0 - 1e-12)))
        ds = h / n

        def f(s, e):
            return (tau - cw * e * (2.0 * self._schedule(s)[0] + e)) / J

        for i in range(n):
            s = t + i * ds
            k1 = f(s, e)
            k2 = f(s + 0.5 * ds, e + 0.5 * ds * k1)
            k3 = f(s + 0.5 * ds, e + 0.5 * ds * k2)
            k4 = f(s + ds, e + ds * k3)
            e = e + ds / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
        return e

    def _do_step(self, t: float, h: float) -> bool:
        if self._fatal_msg is not None:
            self._report(STATUS_ERROR, self._fatal_msg + " (every step is refused until the FMU is reset)")
            return False
        if self._cfg is None:
            self._report(STATUS_ERROR, "do_step called before the end of initialization (fmi2ExitInitializationMode)")
            return False
        if not (math.isfinite(h) and h > 0):
            self._report(STATUS_ERROR, f"communication step size {h!r} s: must be finite and > 0; step refused")
            return False
        if not math.isfinite(t):
            self._report(STATUS_ERROR, f"communication point {t!r} s is not finite; step refused")
            return False
        tau = float(self._v("friction_torque"))
        if not math.isfinite(tau):
            self._report(STATUS_ERROR, f"at t = {t:g} s: friction_torque: {tau!r} N.m is not finite; accepted "
                         "range (-inf, inf) N.m; step refused, state unchanged")
            return False
        e = self._rk4(t, h, self._e, tau)
        w = self._schedule(t + h)[0] + e
        if not (math.isfinite(w) and w >= 0):
            self._report(STATUS_STOPPED, f"at t = {t:g} s: the spool would stop (Omega = {w!r} rad/s at the end of "
                         f"the step, friction_torque = {tau:g} N.m); step refused, state unchanged")
            return False
        self._e = e
        self._t = t + h
        self._set_out("status", STATUS_OK)
        self._update_outputs()
        return True

    # ------------------------------------------------------------------ FMU state (rollback)
    def _get_fmu_state(self):
        return {"version": STATE_VERSION, "values": list(self._values), "phase": self._phase, "t": self._t,
                "e": self._e, "cfg": None if self._cfg is None else dict(self._cfg), "fatal": self._fatal_msg}

    def _set_fmu_state(self, state):
        try:
            if not isinstance(state, dict) or state.get("version") != STATE_VERSION:
                why = state.get("error") if isinstance(state, dict) else None
                raise ValueError(why or "not an LPSpool state of this version")
            values = list(state["values"])
            if len(values) != len(self._values):
                raise ValueError("the state was saved by an FMU with another variable set")
            self._values[:] = values
            self._phase, self._t, self._e = state["phase"], float(state["t"]), float(state["e"])
            self._cfg = None if state["cfg"] is None else dict(state["cfg"])
            self._fatal_msg = state["fatal"]
        except Exception as exc:  # noqa: BLE001
            self._configuration_error(f"fmi2SetFMUstate: the state could not be restored ({type(exc).__name__}: "
                                      f"{exc})")

    @staticmethod
    def _fmu_state_to_bytes(state) -> bytes:
        return json.dumps(state).encode("utf-8")  # floats round-trip exactly (shortest repr)

    @staticmethod
    def _fmu_state_from_bytes(data: bytes):
        try:
            return json.loads(bytes(data).decode("utf-8"))
        except Exception as exc:  # noqa: BLE001 - surfaced by _set_fmu_state
            return {"version": None, "error": f"serialized state is not valid ({exc})"}
