"""``rotorub import-blade``: read an FE export once, reduce it, check it, and write the superelement.

:func:`read_fe` picks the reader from the files (CalculiX jobs, Matrix Market, OP4, DMIG, or a superelement
already made); :func:`run_import_blade` reduces and measures, and returns an :class:`ImportBladeResult`
whose ``save(dir)`` writes ``blade.npz`` (the superelement a parameter file names), ``import_blade.png``
(the mesh and its tip nodes, frequencies against speed, convergence with the number of modes, the step of
each reduction) and ``import_blade.json`` (every number, and a verdict).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import FEImportError
from ..plotting import pyplot, save_figure
from ..writing import write_json
from .blade import ReducedBlade, load_superelement, reduce_blade
from .femodel import FEModel
from .reduction import TWO_PI, compare_reductions, condensed, contact_stiffness, explicit_step, mac

CALCULIX_SUFFIXES = (".sti", ".mas", ".dof", ".inp", "")
VARIANTS_MAX_DOFS = 20000  # above, the comparison of reductions costs more than the import: asked for only


def read_tip_nodes(spec) -> np.ndarray:
    """Tip node ids from a list, a 'comma, or blank separated' string, or a file of ids."""
    if isinstance(spec, str | Path) and Path(str(spec)).is_file():
        text = Path(spec).read_text()
    elif isinstance(spec, list | tuple) and len(spec) == 1 and Path(str(spec[0])).is_file():
        text = Path(str(spec[0])).read_text()
    elif isinstance(spec, list | tuple | np.ndarray):
        text = " ".join(str(x) for x in spec)
    else:
        text = str(spec)
    toks = [t for t in text.replace(",", " ").split() if not t.startswith("#")]
    try:
        return np.array([int(t) for t in toks], dtype=np.int64)
    except ValueError:
        raise FEImportError(f"--tip-nodes: {spec!r}; accepted: node ids (a list, or a file of ids)") from None


def read_fe(files: list[str], units: str, coordinates: str | None = None, speeds: list[float] | None = None,
            dofs: str | None = None, mass_dofs: str | None = None, matrices: list[str] | None = None,
            mass_free: str | None = None) -> FEModel:
    """The FE model of ``files``: CalculiX jobs (``job`` or ``job.sti``...: one job a speed, the first at rest),
    Matrix Market (the mass first, then one stiffness a speed; ``dofs`` and ``coordinates`` needed), an OP4 or a
    DMIG punch file (``matrices``: the mass's name, then one stiffness a speed)."""
    from .calculix import read_calculix
    from .matrix_market import read_matrix_market
    from .nastran import read_dmig, read_op4

    if not files:
        raise FEImportError("--fe: no file given")
    suffixes = {Path(f).suffix.lower() for f in files}
    if suffixes <= {".mtx", ".mm"}:
        if len(files) < 2 or dofs is None or coordinates is None:
            raise FEImportError("--fe: Matrix Market needs the mass then the stiffness files, --dofs and --coordinates")
        return read_matrix_market(files[0], files[1:], dofs, coordinates, units, speeds, mass_dofs=mass_dofs)
    if suffixes <= {".op4"}:
        if not matrices or len(matrices) < 2 or dofs is None or coordinates is None:
            raise FEImportError("--fe: OP4 needs --matrices MASS STIFFNESS..., --dofs and --coordinates")
        return read_op4(files[0], matrices[0], matrices[1:], dofs, coordinates, units, speeds)
    if suffixes <= {".pch", ".bdf", ".dat", ".nas", ".blk"} and matrices:
        if len(matrices) < 2:
            raise FEImportError("--matrices: the DMIG names of the mass, then of one stiffness a speed")
        return read_dmig(files[0], matrices[0], matrices[1:], coordinates, units, speeds)
    if suffixes <= set(CALCULIX_SUFFIXES):
        return read_calculix(files, coordinates, units, speeds, mass_free)
    raise FEImportError(f"--fe: {', '.join(files)}: format not recognised; accepted: CalculiX jobs (.sti/.mas/.dof), "
                        "Matrix Market (.mtx), OP4 (.op4), DMIG punch (.pch with --matrices), a superelement (.npz)")


def calculix_own_frequencies(files: list[str]) -> list[np.ndarray] | None:
    """CalculiX's own eigenfrequencies of each job (its .dat), None when a job has none."""
    from .calculix import _stem, read_dat_frequencies

    out = []
    for f in files:
        dat = _stem(f).with_suffix(".dat")
        try:
            out.append(read_dat_frequencies(dat))
        except FEImportError:
            return None
    return out


@dataclass
class ImportBladeResult:
    blade: ReducedBlade
    speeds: np.ndarray  # [rad/s] of the FE data
    full_hz: list[np.ndarray]  # the full FE model's frequencies at each speed (scipy)
    own_hz: list[np.ndarray] | None  # the FE code's own (CalculiX's .dat), when there
    reduced_hz: list[np.ndarray]
    mac_rest: np.ndarray
    mac_top: np.ndarray
    convergence: dict  # modes kept -> worst error of the first frequencies at the top speed
    variants: list[dict]
    step: dict
    seconds: dict
    k_r: float
    n_compare: int
    notes: list[str] = field(default_factory=list)

    def errors(self, against: str = "own") -> np.ndarray:
        """Worst relative error of the first n_compare frequencies at each speed."""
        ref = self.own_hz if against == "own" and self.own_hz is not None else self.full_hz
        out = []
        for r, f in zip(ref, self.reduced_hz):
            n = min(self.n_compare, len(r), len(f))
            out.append(float(np.max(np.abs(f[:n] / r[:n] - 1.0))))
        return np.array(out)

    def verdict(self) -> str:
        b = self.blade
        err = self.errors()
        who = "CalculiX's own modal analyses" if self.own_hz is not None else "the full FE model"
        good = err.max() <= 1e-3 and min(self.mac_rest.min(), self.mac_top.min()) >= 0.99
        return (f"{'OK' if good else 'CHECK'}: {b.m} dofs a blade (modes below {b.info['cutoff_hz']:g} Hz, basis "
                f"{b.info['basis']}); the first {self.n_compare} frequencies within {100 * err.max():.3g} % of {who} "
                f"at {len(err)} speeds (0 to {self.speeds.max():.4g} rad/s); MAC >= "
                f"{min(self.mac_rest.min(), self.mac_top.min()):.4f}; explicit step {1e3 * self.step['step']:.3g} ms, "
                f"set by the highest kept mode ({self.step['f_max_hz']:.4g} Hz at the top speed; the contact, "
                f"k_r = {self.k_r:.3g} N/m through the tip's massless flexibility, shortens it by "
                f"{100 * (1 - self.step['step'] / self.step['step_free']):.2g} %)" + ("" if good else self._advice()))

    def _advice(self) -> str:
        """What to try when the reduction misses the FE code's frequencies by more than 0.1 %."""
        b = self.blade
        if b.info.get("basis") == "condensed" and len(self.errors()) > 1 and self.errors()[-1] > 1e-3:
            return ("; the error grows with the speed: the prestressed blade's modes leave the rest modes' span "
                    "(what the condensed basis keeps massless); --basis two-speed keeps both speeds' modes with "
                    "their mass (exact at both, a shorter step), or accept the error if it is within your tolerance")
        return "; raise --cutoff-hz (more modes) and compare"

    def summary(self) -> dict:
        b = self.blade
        return {
            "verdict": self.verdict(),
            "dofs_per_blade": b.m, "dofs_full": b.info.get("dofs_full"), "cutoff_hz": b.info.get("cutoff_hz"),
            "basis": b.info.get("basis"), "identification_order": b.info.get("order"),
            "spin_softening_in_fe_K": b.info.get("spin_softening_in_fe_K"),
            "blade_mass_kg": b.mass, "tip_nodes": len(b.tip_nodes),
            "speeds_rad_s": self.speeds, "full_fe_hz": self.full_hz, "fe_code_own_hz": self.own_hz,
            "reduced_hz": self.reduced_hz, "max_error_vs_fe_code": self.errors("own"),
            "max_error_vs_full_fe": self.errors("full"), "mac_rest": self.mac_rest, "mac_top": self.mac_top,
            "convergence_top_speed": self.convergence, "reductions": self.variants, "explicit_step": self.step,
            "tip_radial_growth_at_top_speed_mm": 1e3 * float(np.max(b.tip_centrifugal[:, 0])) * self.speeds.max()**2,
            "seconds": self.seconds, "notes": self.notes,
        }

    def figure(self):
        plt = pyplot()
        b = self.blade
        fig = plt.figure(figsize=(15, 8.5))
        gs = fig.add_gridspec(2, 3)
        x = b.nodes
        step = max(1, x.shape[0] // 20000)
        for k, (i, j) in enumerate(((0, 2), (1, 2))):
            a = fig.add_subplot(gs[0, k])
            a.plot(x[::step, i], x[::step, j], ",", color="0.55")
            a.plot(b.tip_positions[:, i], b.tip_positions[:, j], "o", ms=3.5, color="tab:red",
                   label=f"tip nodes ({len(b.tip_nodes)})")
            a.set_xlabel(("radial x", "tangential y (spin direction)")[i] + " [m]")
            a.set_ylabel("axial z [m]")
            a.set_aspect("equal", adjustable="datalim")
            a.grid(alpha=0.3)
            a.set_title(("mesh, blade frame: side view", "mesh seen down the span (twist)")[k])
            if k == 0:
                a.legend(loc="best", fontsize=8)
        a = fig.add_subplot(gs[0, 2])
        if self.convergence:
            ks = np.array(sorted(int(k) for k in self.convergence))
            a.semilogy(ks, [max(self.convergence[k], 1e-16) for k in ks], "o-", color="tab:blue")
            a.set_xlabel("modes at rest kept (the top speed's additions condensed)")
            a.set_ylabel("worst error, first three frequencies")
            a.set_title(f"convergence at the top speed ({self.speeds.max():.4g} rad/s)")
            a.grid(alpha=0.3, which="both")
        else:
            a.text(0.5, 0.5, "one speed: no convergence at speed to show", ha="center", va="center",
                   transform=a.transAxes, color="0.35")
            a.set_axis_off()
        a = fig.add_subplot(gs[1, :2])
        w = np.linspace(0.0, self.speeds.max(), 60)
        curves = np.array([b.frequencies(float(v))[:self.n_compare] for v in w])
        a.plot(w, curves, color="tab:blue", lw=1.0)
        for k, v in enumerate(self.speeds):
            n = min(self.n_compare, len(self.full_hz[k]))
            a.plot([v] * n, self.full_hz[k][:n], "o", mfc="none", color="k", ms=6,
                   label="full FE model" if k == 0 else None)
            if self.own_hz is not None:
                a.plot([v] * min(n, len(self.own_hz[k])), self.own_hz[k][:n], "x", color="tab:red", ms=6,
                       label="CalculiX's own" if k == 0 else None)
        a.plot([], [], color="tab:blue", label=f"reduced ({b.m} dofs), K(Ω) identified")
        a.set_xlabel("spin speed Ω [rad/s]")
        a.set_ylabel("clamped blade frequency [Hz]")
        a.set_title(f"frequencies against speed (worst error {100 * self.errors().max():.2g} %); explicit step "
                    f"{1e3 * self.step['step']:.3g} ms ({self.step['f_max_hz']:.4g} Hz at the top speed)")
        a.legend(fontsize=8)
        a.grid(alpha=0.3)
        a = fig.add_subplot(gs[1, 2])
        if self.variants:
            names = [v["name"] for v in self.variants]
            steps = [1e3 * v["step"] for v in self.variants]
            colors = ["tab:green" if n == "condensed+massless-boundary" else "tab:gray" for n in names]
            a.barh(names, steps, color=colors)
            a.set_xscale("log")
            for k, v in enumerate(self.variants):
                a.text(steps[k], k, f" {v['dofs']} dofs, {100 * v['freq_error_top']:.2g} %", va="center", fontsize=7)
            a.set_xlabel("explicit step at the top speed [ms] (log); dofs, top-speed error")
            a.set_title("what each reduction allows (green: the one kept)")
            a.grid(alpha=0.3, axis="x")
        else:
            a.text(0.5, 0.5, "the reductions were not compared\n(a large model: --compare-reductions)",
                   ha="center", va="center", transform=a.transAxes, color="0.35")
            a.set_axis_off()
        fig.suptitle(f"Imported blade: {b.info.get('source', '')} ({b.info.get('dofs_full')} dofs -> {b.m})",
                     fontsize=11)
        return fig

    def save(self, out: str | Path) -> dict:
        out = Path(out)
        out.mkdir(parents=True, exist_ok=True)
        self.blade.save(out / "blade.npz")
        save_figure(self.figure(), out / "import_blade.png")
        s = self.summary()
        s["superelement"] = str(out / "blade.npz")
        write_json(out / "import_blade.json", s)
        return s


def run_import_blade(fe: FEModel | ReducedBlade, tip_nodes=None, *, cutoff_hz: float = 1500.0,
                     basis: str = "condensed", k_r: float = 1.5e6, own_hz: list[np.ndarray] | None = None,
                     n_compare: int = 8, variants: bool | None = None, **kw) -> ImportBladeResult:
    """Reduce ``fe`` and measure: frequencies at every speed against the full model (and the FE code's own),
    MAC, convergence with the number of modes, the explicit step of each reduction (contact k_r [N/m] spread
    over the tip nodes, radially; ``variants``: default for models up to VARIANTS_MAX_DOFS dofs: the
    comparison factorizes the blade with its tip fixed and builds Craig-Bampton's hundreds of constraint
    modes). ``kw``: the other arguments of :func:`reduce_blade`."""
    t0 = time.perf_counter()
    if variants is None:
        variants = fe.n_dofs <= VARIANTS_MAX_DOFS
    diag: dict = {"keep_factor": bool(variants)}  # K0's factorization outlives the reduction only for the comparison
    if isinstance(fe, ReducedBlade):
        raise FEImportError("import-blade: a superelement is already reduced; load it with load_superelement")
    blade = reduce_blade(fe, tip_nodes, cutoff_hz=cutoff_hz, basis=basis, diagnostics=diag, **kw)
    t_reduce = time.perf_counter() - t0
    speeds = fe.speeds
    full = [blade.reference["full_rest_hz"]] + [blade.reference[f"full_{k}_hz"] for k in range(1, speeds.size)]
    red = [blade.reference[f"reduced_{k}_hz"] for k in range(speeds.size)]
    M = fe.M_free
    V = diag["V"]
    w0, P0 = diag["rest"]
    n = min(n_compare, blade.m)
    _, z0 = _modes(blade.K0, blade.M)
    mac_rest = np.diag(mac(P0[:, :n], V @ z0[:, :n], M))
    top = diag["top"]
    if top is not None:
        Kt = blade.K_at(float(speeds[-1]))
        _, zt = _modes(Kt, blade.M)
        mac_top = np.diag(mac(top[1][:, :n], V @ zt[:, :n], M))
    else:
        mac_top = mac_rest
    # convergence: the first n modes at rest kept (the top speed's additions condensed as in the basis)
    conv = {}
    if top is not None:
        Ktop = fe.stiffness[-1][1]
        wt = top[0] / TWO_PI
        C = diag["complement"]
        for k in range(1, blade.m + 1):
            Vk = V[:, :k]
            Kk = condensed(Vk, C, Ktop) if C is not None else Vk.T @ (Ktop @ Vk)
            fk = _modes(0.5 * (Kk + Kk.T), Vk.T @ (M @ Vk))[0] / TWO_PI
            j = min(3, k)
            conv[k] = float(np.max(np.abs(fk[:j] / wt[:j] - 1.0)))
    # the step of the kept blade: at the top speed, contact through the tip's massless residual flexibility
    frame = diag["frame"]
    normals = blade.tip_positions * np.array([1.0, 1.0, 0.0])
    normals /= np.linalg.norm(normals, axis=1)[:, None]
    Kt = blade.K_at(float(speeds.max()))
    step_c, fmax_c = explicit_step(Kt + contact_stiffness(blade.tip_recovery, normals, k_r, blade.tip_residual),
                                   blade.M)
    step_f, fmax_f = explicit_step(Kt, blade.M)
    step = {"step": step_c, "f_max_hz": fmax_c, "step_free": step_f, "f_max_free_hz": fmax_f}
    var = []
    t1 = time.perf_counter()
    if variants and top is not None and (diag["tip_rows"] >= 0).all():
        nfile = normals @ frame.axes  # blade frame -> file axes
        vs, _ = compare_reductions(fe.K0, fe.stiffness[-1][1], M, cutoff_hz, diag["tip_rows"], nfile, k_r,
                                   n_compare, factor0=diag["factor0"], rest=diag["rest"], top=top)
        var = [v.as_dict() for v in vs]
    t_var = time.perf_counter() - t1
    notes = []
    if not var:
        notes.append(f"the reductions were not compared ({fe.n_dofs} dofs > {VARIANTS_MAX_DOFS}, or one speed, or "
                     "constrained tip translations): --compare-reductions to force it")
    if speeds.size < 2:
        w_div = [float(v) for v in np.linspace(0.0, 2000.0, 401) if blade.frequencies(float(v))[0] < 1e-6]
        notes.append("one stiffness only: the stress stiffening is neglected (the spin softening from M is in)"
                     + (f"; the first mode softens to zero at {w_div[0]:.4g} rad/s: fit for speeds well below" if w_div
                        else ""))
    return ImportBladeResult(blade=blade, speeds=speeds, full_hz=full, own_hz=own_hz, reduced_hz=red,
                             mac_rest=mac_rest, mac_top=mac_top, convergence=conv, variants=var, step=step,
                             seconds={"reduce": t_reduce, "reductions_compared": t_var}, k_r=float(k_r),
                             n_compare=int(n_compare), notes=notes)


def _modes(K: np.ndarray, M: np.ndarray):
    from scipy.linalg import eigh

    lam, z = eigh(K, M)
    return np.sqrt(np.clip(lam, 0.0, None)), z


def import_blade_command(files: list[str], units: str, tip_nodes, out: str | Path, **kw) -> dict:
    """What ``rotorub import-blade`` runs: read, reduce, measure, write; returns the summary (nothing is
    written when the input is refused)."""
    if len(files) == 1 and Path(files[0]).suffix.lower() == ".npz":
        blade = load_superelement(files[0])
        return {"verdict": f"already a superelement: {blade.m} dofs a blade, {len(blade.tip_nodes)} tip nodes, "
                           f"mass {blade.mass:.4g} kg (nothing written)"}
    read_kw = {k: kw.pop(k) for k in ("coordinates", "speeds", "dofs", "mass_dofs", "matrices", "mass_free")
               if k in kw}
    fe = read_fe(files, units, **read_kw)
    own = calculix_own_frequencies(files) if set(Path(f).suffix.lower() for f in files) <= set(CALCULIX_SUFFIXES) \
        else None
    res = run_import_blade(fe, read_tip_nodes(tip_nodes), own_hz=own, **kw)
    s = res.save(out)
    return {"verdict": s["verdict"], "superelement": s["superelement"], "dofs_per_blade": s["dofs_per_blade"],
            "max_error_vs_fe_code": s["max_error_vs_fe_code"], "written": str(Path(out) / "import_blade.json")}
