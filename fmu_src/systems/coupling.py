"""Engine coupling: the LP spool's speed as a second FMU, the coupled system as an SSP, an fmpy master.

    python -m fmu_src.systems.coupling OUT_DIR [--full] [--contact-fmu F] [--spool-fmu F]

This module is the master loop and the scenario; the spool FMU is fmu_src/models/spool/'s, the SSP
package fmu_src/systems/ssp.py's, what they share fmu_src/systems/system.py's. Pieces:

* :func:`build_native_spool_fmu` builds ``LPSpool.fmu`` in C (the engine system's spool, no Python on
  the host); :func:`build_spool_fmu` the same FMU with pythonfmu (the example of a slave in Python).
  The spool: J dOmega/dt = tau_drive(t) - c_w Omega^2 + friction_torque, with a drive torque schedule
  that makes the rub-free spool follow a half-cosine run-up Omega0 -> Omega1 exactly
  (fmu_src/models/spool/variables.py).
* :func:`write_ssp` writes an SSP 1.0 package (a zip): ``SystemStructure.ssd`` naming
  the two FMUs (``resources/RotorCasingContact.fmu`` as component ``contact``,
  ``resources/LPSpool.fmu`` as ``spool``), their connections (spool.Omega ->
  contact.Omega, contact.friction_torque -> spool.friction_torque), units, a default
  experiment, and one SSV parameter set per component (``resources/contact.ssv``,
  ``resources/spool.ssv``). :func:`validate_ssp` checks it against the SSP 1.0 XML
  schemas (vendored in fmu_src/systems/schemas/ssp1, BSD-2-Clause, see the README there) and
  checks that every connector, connection and parameter exists in the FMUs.
* :func:`run_coupled` is a fixed-step co-simulation master on fmpy's FMU2Slave.
  Exchange order (Jacobi): at each communication point t_k the inputs of both FMUs
  are set from the outputs of both at t_k (contact.Omega <- spool.Omega(t_k),
  spool.friction_torque <- contact.friction_torque(t_k)), then both step over
  [t_k, t_k + h] with their inputs held (zero-order hold), then the outputs at
  t_{k+1} are read. Each FMU thus sees the other one's output delayed by at most one
  step; the friction torque recorded at t_k is exactly what the spool integrated over
  [t_k, t_k + h], which is what the angular-momentum balance below uses.
* :func:`run_coupled_scenario`: the run-up through the first critical speed with the
  reference imbalance, without rub (g0 = 50 mm: no contact) and with rub (g0 = 1 mm),
  saved as NPZ, a PNG and summary.json next to the SSP.

Balance (CoupledResult.momentum_balance): the drive torque is a schedule in time, the
same in both runs, so the rub run and the rub-free run differ by

    J (Omega_rub(T) - Omega_ref(T)) = sum_k tau_f,rub(t_k) h - sum_k tau_f,ref(t_k) h
                                      - int (tau_w,rub - tau_w,ref) dt.

The friction sums are exact (the torques were held over each step); the windage
integral is a trapezoid rule on the recorded outputs (error O(h^2) of a small term);
the spool's RK4 error is O(dt^4). The residual is therefore tiny next to the friction
impulse (tests/fmu/test_coupling.py states the tolerance).
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from rotorub_model.plotting import pyplot, save_figure
from rotorub_model.writing import write_json

from ..masters.fmi2 import FMUError, Slave
from ..models.contact.builder import build_native_fmu
from ..models.spool.builder import (  # noqa: F401 - the engine system's API
    build_native_spool_fmu,
    build_spool_fmu,
    spool_defaults,
)
from .ssp import ssp_contents, validate_ssp, write_ssp  # noqa: F401
from .system import (  # noqa: F401
    CONNECTIONS,
    CONTACT_ID,
    FIRST_CRITICAL,
    G0_NO_RUB,
    G0_RUB,
    ME_REF,
    OMEGA_REF,
    SPOOL_ID,
    EngineError,
)


# ---------------------------------------------------------------------------------------------- master
def _trapezoid(y: np.ndarray, x: np.ndarray) -> float:
    """Trapezoid rule (np.trapezoid is numpy >= 2 only)."""
    return float(np.sum(0.5 * (y[1:] + y[:-1]) * np.diff(x)))


class FmuInstance(Slave):
    """A :class:`~fmu_src.masters.fmi2.Slave` created uninitialised (logging on, variables by name);
    :meth:`initialize` raises :class:`EngineError` when the FMU logs an fmi2Error while
    initializing (pythonfmu reports a refused configuration that way, with fmi2OK)."""

    def __init__(self, fmu: str | Path, instance_name: str):
        try:
            super().__init__(fmu, instance_name, initialize=False)
        except FMUError as exc:
            raise EngineError(f"{instance_name}: {fmu} could not be instantiated ({exc})", exc.messages) from exc

    def _vr(self, name: str):
        if name not in self.variables:
            raise EngineError(f"{self.instance_name}: no variable '{name}'")
        return self.variables[name]

    def vr(self, name: str) -> int:
        return self._vr(name).valueReference

    def initialize(self, t0: float = 0.0, t_end: float | None = None, **start) -> None:
        n0 = len(self.log.records)
        super().initialize(t0, t_end, **start)
        errs = self.log.problems(n0, level=3)
        if errs:
            raise EngineError(f"{self.instance_name}: initialization refused", errs)


@dataclass
class CoupledResult:
    """Records of a coupled run at the communication points t_0 .. t_N (N + 1 rows).

    ``friction_torque[k]`` is the contact's output at t_k, which the spool held over
    [t_k, t_k + h] (so the last row was not applied). ``F_N`` is (N + 1, blades).
    """

    t: np.ndarray
    omega: np.ndarray
    omega_schedule: np.ndarray
    drive_torque: np.ndarray
    windage_torque: np.ndarray
    friction_torque: np.ndarray
    F_N: np.ndarray
    n_contact: np.ndarray
    gap_min: np.ndarray
    contact_status: np.ndarray
    spool_status: np.ndarray
    meta: dict = field(default_factory=dict)

    @property
    def h(self) -> float:
        return float(self.meta["h"])

    @property
    def J(self) -> float:
        return float(self.meta["J"])

    def friction_impulse(self) -> float:
        """Angular impulse the spool received from the contact [N m s]: sum of held torques x h."""
        return float(np.sum(self.friction_torque[:-1]) * self.h)

    def friction_energy(self) -> float:
        """Energy dissipated by the contact friction [J] (positive), trapezoid over each held step."""
        w = 0.5 * (self.omega[:-1] + self.omega[1:])
        return float(-np.sum(self.friction_torque[:-1] * w) * self.h)

    def momentum_balance(self, reference: CoupledResult) -> dict:
        """J (Omega(T) - Omega_ref(T)) against the torque impulses (see the module docstring)."""
        if self.t.shape != reference.t.shape or not np.array_equal(self.t, reference.t):
            raise ValueError("momentum_balance: the two runs must share their communication points")
        lhs = self.J * (self.omega[-1] - reference.omega[-1])
        friction = self.friction_impulse() - reference.friction_impulse()
        windage = float(_trapezoid(self.windage_torque - reference.windage_torque, self.t))
        drive = float(_trapezoid(self.drive_torque - reference.drive_torque, self.t))
        rhs = friction - windage + drive
        return {"J_delta_omega_N_m_s": float(lhs), "friction_impulse_N_m_s": friction,
                "windage_impulse_difference_N_m_s": windage, "drive_impulse_difference_N_m_s": drive,
                "residual_N_m_s": float(lhs - rhs),
                "relative_residual": float(abs(lhs - rhs) / max(abs(friction), 1e-300))}

    def energy_balance(self, reference: CoupledResult) -> dict:
        """J/2 (Omega(T)^2 - Omega_ref(T)^2) against the work of drive, windage and friction (trapezoid)."""
        lhs = 0.5 * self.J * (self.omega[-1] ** 2 - reference.omega[-1] ** 2)

        def work(r):
            w_mid = 0.5 * (r.omega[:-1] + r.omega[1:])
            drive = float(_trapezoid(r.drive_torque * r.omega, r.t))
            windage = float(_trapezoid(r.windage_torque * r.omega, r.t))
            friction = float(np.sum(r.friction_torque[:-1] * w_mid) * r.h)
            return drive, windage, friction

        d1, w1, f1 = work(self)
        d0, w0, f0 = work(reference)
        rhs = (d1 - d0) - (w1 - w0) + (f1 - f0)
        return {"J_half_delta_omega2_J": float(lhs), "friction_work_J": f1 - f0, "drive_work_difference_J": d1 - d0,
                "windage_work_difference_J": w1 - w0, "residual_J": float(lhs - rhs),
                "relative_residual": float(abs(lhs - rhs) / max(abs(f1 - f0), 1e-300))}

    def summary(self, reference: CoupledResult | None = None) -> dict:
        """Key numbers; with the rub-free ``reference`` run, the speed dip and the balances too."""
        s = {
            "t_end_s": float(self.t[-1]), "h_s": self.h, "steps": int(len(self.t) - 1),
            "g0_m": self.meta.get("g0"), "imbalance_kg_m": self.meta.get("imbalance"),
            "formulation": self.meta.get("formulation"), "exchange": self.meta.get("exchange"),
            "max_contact_force_N": float(np.max(self.F_N)) if self.F_N.size else 0.0,
            "max_n_contact": int(np.max(self.n_contact)) if self.n_contact.size else 0,
            "min_friction_torque_N_m": float(np.min(self.friction_torque)),
            "friction_impulse_N_m_s": self.friction_impulse(),
            "friction_energy_J": self.friction_energy(),
            "contact_time_s": float(np.count_nonzero(self.n_contact[:-1] > 0) * self.h),
            "omega_end_rad_s": float(self.omega[-1]), "wall_time_s": self.meta.get("wall_time_s"),
            "first_step_s": self.meta.get("first_step_s"),
        }
        if np.any(self.n_contact > 0):
            k = int(np.argmax(np.max(self.F_N, axis=1)))
            s["t_max_contact_force_s"] = float(self.t[k])
            s["omega_at_max_contact_force_rad_s"] = float(self.omega[k])
        if reference is not None:
            if not np.array_equal(self.t, reference.t):
                raise ValueError("summary: the reference run must share the communication points")
            short = reference.omega - self.omega
            k = int(np.argmax(short))
            s["min_spool_speed_dip_rad_s"] = float(short[k])  # largest shortfall against the rub-free run
            s["t_speed_dip_s"] = float(self.t[k])
            s["omega_end_shortfall_rad_s"] = float(short[-1])
            s["momentum_balance"] = self.momentum_balance(reference)
            s["energy_balance"] = self.energy_balance(reference)
        return s

    def save_npz(self, path: str | Path) -> Path:
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        np.savez_compressed(path, t=self.t, omega=self.omega, omega_schedule=self.omega_schedule,
                            drive_torque=self.drive_torque, windage_torque=self.windage_torque,
                            friction_torque=self.friction_torque, F_N=self.F_N, n_contact=self.n_contact,
                            gap_min=self.gap_min, contact_status=self.contact_status,
                            spool_status=self.spool_status, meta=json.dumps(self.meta))
        return path

    @classmethod
    def load_npz(cls, path: str | Path) -> CoupledResult:
        with np.load(path) as d:
            arrays = {k: d[k] for k in d.files if k != "meta"}
            meta = json.loads(str(d["meta"]))
        return cls(meta=meta, **arrays)

    def figure(self, reference: CoupledResult | None = None):
        """Spin speed (with the rub-free run), speed shortfall, friction torque, contact forces per blade (each
        blade in its colour, named in the legend beside the panel, with the largest over the blades)."""
        from rotorub_model.plotting import legend_outside, plot_blade_forces

        plt = pyplot()
        fig, ax = plt.subplots(4, 1, figsize=(9, 11), sharex=True)
        t = self.t
        if reference is not None:
            ax[0].plot(reference.t, reference.omega, "k--", lw=1.2, label="no rub (follows the drive schedule)")
        ax[0].plot(t, self.omega, "C3", lw=1.2, label=f"with rub (g0 = {self.meta.get('g0', float('nan')) * 1e3:g} mm)")
        ax[0].axhline(FIRST_CRITICAL, color="0.5", lw=0.8, ls=":")
        ax[0].text(t[0], FIRST_CRITICAL, " first critical speed", va="bottom", fontsize=8, color="0.4")
        ax[0].set_ylabel("spool speed Omega [rad/s]")
        ax[0].legend(loc="lower right", fontsize=8)
        ax[0].set_title(f"LP spool run-up through the first critical speed, imbalance "
                        f"{self.meta.get('imbalance', float('nan')) * 1e3:g} kg mm, "
                        f"{self.meta.get('formulation', '')} contact, h = {self.h * 1e3:g} ms "
                        f"({self.meta.get('exchange')} exchange)",
                        fontsize=9)
        if reference is not None:
            ax[1].plot(t, reference.omega - self.omega, "C3", lw=1.2)
            ax[1].set_ylabel("shortfall Omega_no rub - Omega [rad/s]")
        else:
            ax[1].plot(t, self.omega_schedule - self.omega, "C3", lw=1.2)
            ax[1].set_ylabel("Omega_schedule - Omega [rad/s]")
        ax[2].plot(t, self.friction_torque, "C0", lw=0.8)
        ax[2].set_ylabel("friction torque [N m]")
        if self.F_N.size:
            plot_blade_forces(ax[3], t, self.F_N, lw=0.7)
            ax[3].plot(t, self.F_N.max(axis=1), "k", lw=0.8, ls=":", label="largest over the blades")
            legend_outside(ax[3])
        ax[3].set_ylabel("normal contact force per blade [N]")
        ax[3].set_xlabel("time [s]")
        for a in ax:
            a.grid(alpha=0.3)
        return fig

    def save(self, out: str | Path, reference: CoupledResult | None = None, stem: str = "coupled_runup") -> dict:
        """``<stem>.png``, ``<stem>.json`` (the summary against ``reference``) and ``<stem>.npz`` in ``out``."""
        out = Path(out)
        out.mkdir(parents=True, exist_ok=True)
        save_figure(self.figure(reference), out / f"{stem}.png", dpi=110)
        self.save_npz(out / f"{stem}.npz")
        s = self.summary(reference)
        write_json(out / f"{stem}.json", s)
        return s


def run_coupled(contact_fmu: str | Path, spool_fmu: str | Path, t_end: float, h: float = 1e-3,
                g0: float = G0_RUB, imbalance: float = ME_REF, formulation: str = "3D", progress: bool = False,
                spool_params: dict | None = None, contact_params: dict | None = None,
                t_start: float = 0.0) -> CoupledResult:
    """Fixed-step co-simulation of the contact FMU and the spool FMU (fmpy FMU2Slave, Jacobi exchange).

    ``contact_fmu``/``spool_fmu``: .fmu files or extracted folders. ``g0`` [m] the
    clearance (G0_NO_RUB = 50 mm disables the rub), ``imbalance`` [kg m] held constant, ``formulation``
    '2D' or '3D' (contact mode 'transient'), ``spool_params`` the spool's parameters
    (J, c_w, Omega0, Omega1, t_ramp_start, t_ramp, dt_max), ``contact_params`` further
    contact parameters (k_r, mu, dt_max, ...). A refused step raises :class:`EngineError`
    with the FMUs' messages and the records so far (``exc.result``).

    Exchange (Jacobi), for k = 0 .. N-1: contact.Omega <- spool.Omega(t_k),
    spool.friction_torque <- contact.friction_torque(t_k); fmi2DoStep(t_k, h) on the contact,
    then on the spool (independent: either order gives the same result); read both FMUs'
    outputs at t_{k+1}. Initialization: the spool first, its Omega(t_0) is the contact's
    initial Omega.

    Note: the contact FMU's first step in a process compiles its numba kernels (seconds);
    ``meta["first_step_s"]`` reports it.
    """
    if not (math.isfinite(h) and h > 0 and math.isfinite(t_end) and t_end > t_start):
        raise EngineError(f"run_coupled: need h > 0 and t_end > t_start (h = {h!r}, t_end = {t_end!r})")
    n = int(round((t_end - t_start) / h))
    if n < 1 or abs(n * h - (t_end - t_start)) > 1e-9 * max(1.0, t_end - t_start):
        raise EngineError(f"run_coupled: t_end - t_start = {t_end - t_start!r} s is not a whole number of steps "
                          f"h = {h!r} s")
    from fmpy.fmi1 import FMICallException
    from fmpy.fmi2 import fmi2Integer, fmi2Real, fmi2True, fmi2ValueReference

    wall0 = time.perf_counter()
    spool = FmuInstance(spool_fmu, "spool")
    contact = None
    try:
        contact = FmuInstance(contact_fmu, "contact")
        try:
            spool.initialize(t_start, t_end, **(spool_params or {}))
            omega0 = spool.get("Omega")
            cstart = {"formulation": formulation, "mode": "transient", "g0": g0, "imbalance": imbalance,
                      "Omega": omega0, **(contact_params or {})}
            contact.initialize(t_start, t_end, **cstart)
        except FMUError as exc:  # a value refused at its set (the native FMUs): the same error as a refused step
            raise EngineError(f"run_coupled: initialisation refused ({exc})", exc.messages) from None
        J = spool.get("J")
        nb = sum(1 for name in contact.variables if name.startswith("blade[") and name.endswith("].F_N"))

        def arr(ctype, values):
            return (ctype * len(values))(*values)

        s_out_names = ["Omega", "Omega_schedule", "drive_torque", "windage_torque"]
        c_out_names = ["friction_torque", "gap_min"] + [f"blade[{j}].F_N" for j in range(1, nb + 1)]
        s_vr_out = arr(fmi2ValueReference, [spool.vr(k) for k in s_out_names])
        c_vr_out = arr(fmi2ValueReference, [contact.vr(k) for k in c_out_names])
        s_vr_int = arr(fmi2ValueReference, [spool.vr("status")])
        c_vr_int = arr(fmi2ValueReference, [contact.vr("n_contact"), contact.vr("status")])
        s_vals, c_vals = (fmi2Real * len(s_out_names))(), (fmi2Real * len(c_out_names))()
        s_ints, c_ints = (fmi2Integer * 1)(), (fmi2Integer * 2)()
        c_vr_in = arr(fmi2ValueReference, [contact.vr("Omega"), contact.vr("imbalance")])
        s_vr_in = arr(fmi2ValueReference, [spool.vr("friction_torque")])
        c_in, s_in = (fmi2Real * 2)(), (fmi2Real * 1)()
        sf, cf = spool.fmu, contact.fmu
        sc, cc = sf.component, cf.component

        t = t_start + np.arange(n + 1) * h
        S = np.full((n + 1, len(s_out_names)), np.nan)
        C = np.full((n + 1, len(c_out_names)), np.nan)
        I_s = np.zeros((n + 1, 1), dtype=np.int64)
        I_c = np.zeros((n + 1, 2), dtype=np.int64)

        def read(k):
            sf.fmi2GetReal(sc, s_vr_out, len(s_out_names), s_vals)
            cf.fmi2GetReal(cc, c_vr_out, len(c_out_names), c_vals)
            sf.fmi2GetInteger(sc, s_vr_int, 1, s_ints)
            cf.fmi2GetInteger(cc, c_vr_int, 2, c_ints)
            S[k] = s_vals
            C[k] = c_vals
            I_s[k] = s_ints
            I_c[k] = c_ints

        read(0)
        meta = {"h": h, "g0": g0, "imbalance": imbalance, "formulation": formulation, "J": J,
                "exchange": "Jacobi", "t_start": t_start, "t_end": t_end,
                "spool": {k: spool.get(k) for k in ("J", "c_w", "Omega0", "Omega1", "t_ramp_start", "t_ramp",
                                                    "dt_max")},
                "contact_fmu": str(contact_fmu), "spool_fmu": str(spool_fmu)}
        bar = None
        if progress:
            from tqdm import tqdm

            bar = tqdm(total=n, desc=f"coupled g0={g0:g} m", unit="step", mininterval=1.0)
        first = None
        done = 0
        failure = None
        loop0 = time.perf_counter()
        for k in range(n):
            tk = float(t[k])
            # Jacobi: both inputs from the outputs at t_k, held over [t_k, t_k + h]
            c_in[0] = S[k, 0]
            c_in[1] = imbalance
            s_in[0] = C[k, 0]
            cf.fmi2SetReal(cc, c_vr_in, 2, c_in)
            sf.fmi2SetReal(sc, s_vr_in, 1, s_in)
            n_c, n_s = len(contact.log.records), len(spool.log.records)
            t0 = time.perf_counter()
            try:
                cf.fmi2DoStep(cc, tk, h, fmi2True)
                sf.fmi2DoStep(sc, tk, h, fmi2True)
            except FMICallException as exc:
                msgs = [f"contact: {m}" for m in contact.log.problems(n_c)] + \
                       [f"spool: {m}" for m in spool.log.problems(n_s)]
                failure = (f"run_coupled: step at t = {tk:g} s refused ({exc})", msgs)
                break
            if first is None:
                first = time.perf_counter() - t0
            read(k + 1)
            done = k + 1
            if bar is not None:
                bar.update(1)
        if bar is not None:
            bar.close()
        meta["loop_time_s"] = time.perf_counter() - loop0
        meta["first_step_s"] = first
        meta["wall_time_s"] = time.perf_counter() - wall0
        meta["steps_done"] = done
        m = done + 1
        result = CoupledResult(
            t=t[:m], omega=S[:m, 0], omega_schedule=S[:m, 1], drive_torque=S[:m, 2], windage_torque=S[:m, 3],
            friction_torque=C[:m, 0], gap_min=C[:m, 1], F_N=C[:m, 2:], n_contact=I_c[:m, 0],
            contact_status=I_c[:m, 1], spool_status=I_s[:m, 0], meta=meta)
        if failure is not None:
            raise EngineError(failure[0], failure[1], result=result)
        return result
    finally:
        if contact is not None:
            contact.close()
        spool.close()


# ---------------------------------------------------------------------------------------------- scenario
def scenario_settings(quick: bool = True) -> dict:
    """The run-up scenario: 2.8 -> 4.2 x omega_ref (the first critical speed, about 3.49 x omega_ref, halfway),
    reference imbalance 22 kg mm held from t = 0, 3D contact, h = 1 ms. quick: 4 s run-up; full: 6 s."""
    ramp = 4.0 if quick else 6.0
    return {"h": 1e-3, "t_end": 0.5 + ramp + 0.5, "formulation": "3D", "imbalance": ME_REF, "g0_rub": G0_RUB,
            "g0_no_rub": G0_NO_RUB,
            "spool_params": {"Omega0": 149.52, "Omega1": 224.28, "t_ramp_start": 0.5,
                             "t_ramp": ramp}}


def run_coupled_scenario(out_dir: str | Path, quick: bool = True, contact_fmu: str | Path | None = None,
                         spool_fmu: str | Path | None = None, progress: bool = False,
                         fmu_dir: str | Path | None = None, platforms: tuple[str, ...] | None = None) -> dict:
    """Build the FMUs (unless given: the native contact and spool FMUs, no Python on a host), write and
    validate the SSP, run the rub-free and the rub cases in the fmpy master loop, the rub case's SSP in libcosim
    and in the C master (no Python in the process), and save ``no_rub.npz``, ``rub.npz``, ``coupled_runup.png``,
    ``summary.json`` in ``out_dir``. ``platforms``: the binaries of the FMUs it builds (None: every platform;
    the main job: this machine's, the one it runs)."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    cfg = scenario_settings(quick)
    t0 = time.perf_counter()
    fmu_dir = Path(fmu_dir) if fmu_dir else out / "fmus"
    built_here = not (contact_fmu and spool_fmu)
    contact_fmu = Path(contact_fmu) if contact_fmu else Path(build_native_fmu(fmu_dir / "native",
                                                                              platforms=platforms)["fmu"])
    spool_fmu = Path(spool_fmu) if spool_fmu else build_native_spool_fmu(fmu_dir / "native", platforms=platforms)
    # None (the report's "–") where both FMUs were given: a build time of 1.7e-05 s read as a measurement
    build_s = time.perf_counter() - t0 if built_here else None
    ssp = write_ssp(out / "RotorRubEngine.ssp", contact_fmu, spool_fmu, g0=cfg["g0_rub"], imbalance=cfg["imbalance"],
                    formulation=cfg["formulation"], spool_params=cfg["spool_params"], t_end=cfg["t_end"], h=cfg["h"])
    problems = validate_ssp(ssp)
    if problems:
        raise EngineError(f"{ssp}: the SSP does not validate", problems)
    common = {"t_end": cfg["t_end"], "h": cfg["h"], "imbalance": cfg["imbalance"], "formulation": cfg["formulation"],
              "spool_params": cfg["spool_params"], "progress": progress}
    ref = run_coupled(contact_fmu, spool_fmu, g0=cfg["g0_no_rub"], **common)
    rub = run_coupled(contact_fmu, spool_fmu, g0=cfg["g0_rub"], **common)
    ref.save_npz(out / "no_rub.npz")
    rub.save_npz(out / "rub.npz")
    save_figure(rub.figure(reference=ref), out / "coupled_runup.png", dpi=110)
    summary = rub.summary(reference=ref)
    summary.update({"no_rub_max_deviation_from_schedule_rad_s": float(np.max(np.abs(ref.omega - ref.omega_schedule))),
                    "no_rub_max_friction_torque_N_m": float(np.max(np.abs(ref.friction_torque))),
                    "no_rub_wall_time_s": ref.meta["wall_time_s"], "build_time_s": build_s, "ssp": str(ssp),
                    "ssp_valid": True, "contact_fmu": str(contact_fmu), "spool_fmu": str(spool_fmu),
                    "quick": quick})
    try:  # the same package in a second co-simulation engine, when it is installed
        from .ssp import run_ssp_libcosim

        lc = run_ssp_libcosim(ssp, cfg["t_end"], cfg["h"])
        scale = float(np.abs(rub.omega).max())
        summary["libcosim_ssp_spool_speed_max_rel_diff"] = float(np.abs(lc["spool.Omega"] - rub.omega[1:]).max()
                                                                 / scale)
    except EngineError as exc:
        summary["libcosim_ssp_spool_speed_max_rel_diff"] = None
        summary["libcosim_note"] = str(exc)
    try:  # and in a native process: the C master, no Python anywhere (needs the native FMUs and a C compiler)
        from .ssp import run_ssp_native

        nat = run_ssp_native(ssp, cfg["t_end"], cfg["h"])
        summary["native_host_ssp_spool_speed_max_rel_diff"] = float(np.abs(nat["spool.Omega"] - rub.omega[1:]).max()
                                                                    / float(np.abs(rub.omega).max()))
    except (EngineError, RuntimeError, OSError) as exc:
        summary["native_host_ssp_spool_speed_max_rel_diff"] = None
        summary["native_host_note"] = str(exc)
    write_json(out / "summary.json", summary)
    summary["figures"] = [("Coupled run-up: spool speed with and without rub, friction torque, contact forces",
                           "coupled_runup.png")]
    return summary


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out_dir")
    ap.add_argument("--full", action="store_true", help="6 s run-up instead of 4 s")
    ap.add_argument("--contact-fmu", default=None, help="use this RotorCasingContact.fmu instead of building one")
    ap.add_argument("--spool-fmu", default=None, help="use this LPSpool.fmu instead of building one")
    ap.add_argument("--progress", action="store_true")
    ns = ap.parse_args(argv)
    try:
        s = run_coupled_scenario(ns.out_dir, quick=not ns.full, contact_fmu=ns.contact_fmu, spool_fmu=ns.spool_fmu,
                                 progress=ns.progress)
    except EngineError as exc:
        print(f"engine: error: {exc}", file=sys.stderr)
        return 2
    print(json.dumps(s, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
