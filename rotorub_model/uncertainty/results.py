"""The result of a study: its numbers (``summary``), its figures, its verdict and its report section.

``save(out)`` is the only writer: ``uq_summary.json``, ``uq_samples.npz`` (inputs, deviations, quantities)
and one PNG per figure the study has (``uq_distributions.png``, ``uq_rub_vs_clearance.png``, ``uq_sobol.png``,
``uq_morris.png``, ``uq_mistuning.png``, ``uq_small_probability.png``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import ParameterError
from ..plotting import pyplot, save_figure
from ..writing import write_json
from .quantities import QUANTITIES, event_display
from .study import Study

UNITS = {"m": (1e3, "mm"), "N": (1.0, "N"), "1/s": (1.0, "1/s"), "-": (1.0, "")}
TARGET_P = 0.01  # the rub probability the verdict sizes the build clearance for


def _scale(q: str) -> tuple[float, str]:
    return UNITS[QUANTITIES[q].unit]


def _json_safe(x):
    """Arrays to lists and NaN / inf to None: strict JSON (a Morris group's sigma is NaN in SALib)."""
    if isinstance(x, dict):
        return {k: _json_safe(v) for k, v in x.items()}
    if isinstance(x, list | tuple):
        return [_json_safe(v) for v in x]
    if isinstance(x, np.ndarray):
        return _json_safe(x.tolist())
    if isinstance(x, float | np.floating):
        return float(x) if math.isfinite(x) else None
    return x


def _pct(p: float | None) -> str:
    if p is None or not math.isfinite(p):
        return "n/a"
    return f"{100 * p:.3g} %" if p >= 1e-3 else f"{p:.2e}"


@dataclass
class UQResult:
    study: Study
    speeds: list[float]
    X: np.ndarray | None
    D: np.ndarray | None
    replicate: np.ndarray | None
    values: dict[str, np.ndarray]
    estimates: dict
    cost: dict
    wall_s: float

    # ------------------------------------------------------------------ numbers
    @property
    def figures(self) -> list[str]:
        e = self.estimates
        out = []
        if "values" in e or "probabilities" in e:
            out.append("distributions")
        if "clearance_curve" in e:
            out.append("rub_vs_clearance")
        if "sobol" in e:
            out.append("sobol")
        if "morris" in e:
            out.append("morris")
        if "mistuning" in e:
            out.append("mistuning")
        if "small_probability" in e:
            out.append("small_probability")
        return out

    def operating_text(self) -> str:
        s = self.study
        if s.model != "rotorub":
            return "the test function"
        if s.speeds is not None:
            return f"a run-up over speeds {s.speeds[0]:g}-{s.speeds[1]:g} Ω_ref ({s.formulation})"
        first = ", the first critical" if s.speed == "first_critical" else ""
        # the speed is normalised: the unit says so (a bare "speed 3.455" read as a number of what?)
        return f"speed {self.speeds[0]:.4g} Ω_ref ({s.formulation}{first})"

    def clearance_for(self, p_target: float = TARGET_P) -> float | None:
        """The smallest build clearance whose rub probability's upper bound is at most p_target (None when the
        curve never gets there)."""
        c = self.estimates.get("clearance_curve")
        if not c:
            return None
        ok = np.flatnonzero(np.asarray(c["high"]) <= p_target)
        if not ok.size:
            return None
        g = np.asarray(c["build_clearance_m"])
        # the curve falls with the clearance: the first point from which it stays below
        bad = np.flatnonzero(np.asarray(c["high"]) > p_target)
        first = bad[-1] + 1 if bad.size else 0
        return float(g[first]) if first < g.size else None

    def verdict(self) -> str:
        s, e = self.study, self.estimates
        lines = []
        conf = f"{100 * s.confidence:g} %"
        for text, p in e.get("probabilities", {}).items():
            lines.append(f"P({event_display(text)}) at {self.operating_text()} = {_pct(p['probability'])} "
                         f"[{_pct(p['low'])}, {_pct(p['high'])}] ({conf}; {p['points']} points)")
        g = self.clearance_for()
        if "clearance_curve" in e:
            lines.append(f"build clearance for P(rub) <= {100 * TARGET_P:g} % (upper bound): "
                         + (f"{g * 1e3:.3g} mm or more" if g is not None else "not reached on the curve"))
        for q, si in e.get("sobol", {}).items():
            if "undefined" in si:
                lines.append(f"Sobol' indices of {q}: {si['undefined']}")
                continue
            order = np.argsort(si["ST"])[::-1]
            top = ", ".join(f"{si['names'][k]} (ST {si['ST'][k]:.2f} ± {si['ST_conf'][k]:.2f})" for k in order[:3])
            lines.append(f"{q}: most influential {top}")
        for q, mo in e.get("morris", {}).items():
            if "undefined" in mo:
                lines.append(f"Morris screening of {q}: {mo['undefined']}")
                continue
            order = np.argsort(mo["mu_star"])[::-1]
            lines.append(f"{q}: screening ranks " + " > ".join(mo["names"][k] for k in order))
        for k, c in e.get("mistuning", {}).items():
            if not c.get("pearson"):
                lines.append(f"{k} against amp_linear: {c.get('note')}")
                continue
            r = c["pearson"]
            sig = r["low"] > 0 or r["high"] < 0
            if sig and abs(r["r"]) >= 0.5:
                what = "correlated: the linear amplification does predict this one here"
            elif sig:
                what = f"weakly correlated: the linear factor explains {100 * r['r'] ** 2:.0f} % of its variance"
            else:
                what = "no correlation found (as the 2021 finding)"
            lines.append(f"{k} against amp_linear over {c['points']} mistuned disks: Pearson r = {r['r']:.2f} "
                         f"[{r['low']:.2f}, {r['high']:.2f}] ({conf}): {what}")
        sp = e.get("small_probability")
        if sp:
            iv = f" [{_pct(sp['low'])}, {_pct(sp['high'])}]" if sp.get("low") is not None else ""
            lines.append(f"P({event_display(sp['event'])}) at {self.operating_text()} = {_pct(sp['probability'])}{iv} "
                         f"({s.method}, {sp['evaluations']} evaluations)")
        return "; ".join(lines) if lines else "no estimate"

    def summary(self) -> dict:
        s = self.study
        out = {"study": s.summary(), "operating_speeds": self.speeds if len(self.speeds) <= 5 else
               {"from": self.speeds[0], "to": self.speeds[-1], "points": len(self.speeds)},
               "estimates": self.estimates, "cost": self.cost, "wall_s": self.wall_s,
               "build_clearance_for_p_rub_1pct_m": self.clearance_for(), "verdict": self.verdict()}
        return _json_safe(out)

    # ------------------------------------------------------------------ figures
    def figure(self, kind: str = "distributions"):
        """One figure (open: the caller saves or closes it): any of :attr:`figures`."""
        if kind not in self.figures:
            raise ParameterError(f"figure: '{kind}' unknown for this study; accepted: {', '.join(self.figures)}")
        return getattr(self, f"_fig_{kind}")()

    def _title(self) -> str:
        return f"{self.study.name}: {self.operating_text()}"

    def _fig_distributions(self):
        plt = pyplot()
        vals = [q for q in self.estimates.get("values", {}) if self.estimates["values"][q].get("points")]
        probs = self.estimates.get("probabilities", {})
        n = len(vals) + (1 if probs else 0)
        cols = min(n, 3)
        rows = math.ceil(n / cols)
        fig, axes = plt.subplots(rows, cols, figsize=(4.6 * cols, 3.6 * rows), squeeze=False)
        axes = axes.ravel()
        rep = self.replicate
        for ax, q in zip(axes, vals):
            k, unit = _scale(q)
            y = self.values[q]
            ok = np.isfinite(y)
            if rep is not None and self.study.sampler == "qmc":
                for r in range(self.study.replicates):
                    yr = np.sort(y[ok & (rep == r)]) * k
                    ax.step(yr, np.arange(1, yr.size + 1) / yr.size, color="0.75", lw=0.6,
                            label="one replicate" if r == 0 else None)
            ys = np.sort(y[ok]) * k
            ax.step(ys, np.arange(1, ys.size + 1) / ys.size, color="C0", lw=1.6, label="all points")
            est = self.estimates["values"][q]
            for lev, qq in est["quantiles"].items():
                ax.errorbar(qq["value"] * k, float(lev), xerr=[[max(qq["value"] - qq["low"], 0) * k],
                                                               [max(qq["high"] - qq["value"], 0) * k]],
                            fmt="o", color="C3", ms=4, capsize=3)
            if q == "margin":
                ax.axvline(0.0, color="k", lw=0.8, ls="--")
                ax.text(0.0, 0.02, " rub ←", ha="right", va="bottom", fontsize=8)
            ax.set_xlabel(f"{q} [{unit}]" if unit else q)
            ax.set_ylabel("cumulative probability")
            u = f" {unit}" if unit else ""
            ax.set_title(f"{q}: mean {est['mean'] * k:.4g}{u}, sd {est['sd'] * k:.3g}{u}", fontsize=9)
            ax.grid(alpha=0.3)
            ax.legend(fontsize=7, loc="upper left")
        if probs:
            ax = axes[len(vals)]
            names = list(probs)
            p = np.array([probs[k]["probability"] for k in names])
            lo = np.array([probs[k]["low"] for k in names])
            hi = np.array([probs[k]["high"] for k in names])
            ax.bar(range(len(names)), p, color="C1")
            ax.errorbar(range(len(names)), p, yerr=[np.maximum(p - lo, 0), np.maximum(hi - p, 0)], fmt="none",
                        color="k", capsize=5)
            ax.set_xticks(range(len(names)), names, rotation=20, fontsize=8)
            ax.set_ylabel("probability")
            ax.set_ylim(0, max(1e-3, float(np.nanmax(hi)) * 1.15))
            ax.set_title(f"event probabilities ({100 * self.study.confidence:g} % intervals)", fontsize=9)
            for i, v in enumerate(p):
                ax.annotate(_pct(v), (i, v), textcoords="offset points", xytext=(4, 4), fontsize=8)
            ax.grid(alpha=0.3, axis="y")
        for ax in axes[n:]:
            ax.set_visible(False)
        fig.suptitle(self._title(), fontsize=10)
        return fig

    def _fig_rub_vs_clearance(self):
        plt = pyplot()
        c = self.estimates["clearance_curve"]
        g = np.asarray(c["build_clearance_m"]) * 1e3
        p, lo, hi = (np.asarray(c[k]) for k in ("probability", "low", "high"))
        fig, axes = plt.subplots(1, 2, figsize=(12, 4.4))
        gt = self.clearance_for()
        for ax, log in zip(axes, (False, True)):
            k = 1.0 if log else 100.0
            ax.fill_between(g, lo * k, hi * k, color="C0", alpha=0.3, lw=0,
                            label=f"{100 * self.study.confidence:g} % interval")
            ax.plot(g, p * k, color="C0", lw=1.6, label="P(rub)")
            ax.axvline(c["nominal_build_clearance_m"] * 1e3, color="0.3", ls=":", lw=1,
                       label=f"this study's build clearance {c['nominal_build_clearance_m'] * 1e3:.3g} mm")
            ax.axhline(TARGET_P * k, color="C3", lw=0.8, ls="--")
            if gt is not None:
                ax.axvline(gt * 1e3, color="C3", lw=1, ls="--",
                           label=f"P(rub) ≤ {100 * TARGET_P:g} % (upper bound) from {gt * 1e3:.3g} mm")
            ax.set_xlabel("build clearance (mean of the clearance g0) [mm]")
            ax.grid(alpha=0.3, which="both")
        axes[0].set_ylabel("probability of a rub [%]")
        axes[0].set_ylim(-2, 102)
        axes[0].legend(fontsize=8, loc="upper right")
        axes[0].set_title("rub probability against the build clearance", fontsize=9)
        n = int(self.estimates["probabilities"].get("rub", {}).get("points", 0)) if "probabilities" in \
            self.estimates else 0
        floor = 0.5 / max(n, 1)
        axes[1].set_yscale("log")
        axes[1].set_ylim(max(floor, float(np.nanmin(hi[hi > 0])) * 0.5 if (hi > 0).any() else floor), 1.5)
        axes[1].set_ylabel("probability of a rub (log scale)")
        axes[1].set_title("the tail: where the interval is the answer (upper bound)", fontsize=9)
        fig.suptitle(self._title() + " (the clearance's scatter shifted with its mean: the same evaluations)",
                     fontsize=9.5)
        return fig

    def _fig_sobol(self):
        plt = pyplot()
        items = list(self.estimates["sobol"].items())
        fig, axes = plt.subplots(1, len(items), figsize=(max(5.0, 1.2 * 8) * min(len(items), 2) / 1.6, 4.0),
                                 squeeze=False)
        for ax, (q, si) in zip(axes[0], items):
            if "undefined" in si:
                ax.text(0.5, 0.5, si["undefined"], ha="center", va="center", wrap=True, fontsize=8,
                        transform=ax.transAxes)
                ax.set_title(q)
                continue
            x = np.arange(len(si["names"]))
            ax.bar(x - 0.2, si["S1"], 0.4, yerr=si["S1_conf"], capsize=3, label="first order S1", color="C0")
            ax.bar(x + 0.2, si["ST"], 0.4, yerr=si["ST_conf"], capsize=3, label="total order ST", color="C1")
            ax.set_xticks(x, si["names"], rotation=25, fontsize=8)
            ax.axhline(0, color="k", lw=0.6)
            ax.set_ylabel("Sobol' index")
            ax.set_title(f"{q} (SALib, N = {self.study.n}, {100 * self.study.confidence:g} % bootstrap)", fontsize=9)
            ax.grid(alpha=0.3, axis="y")
            ax.legend(fontsize=8)
        fig.suptitle(self._title(), fontsize=10)
        return fig

    def _fig_morris(self):
        plt = pyplot()
        items = list(self.estimates["morris"].items())
        fig, axes = plt.subplots(1, len(items), figsize=(5.2 * min(len(items), 3), 4.2), squeeze=False)
        for ax, (q, mo) in zip(axes[0], items):
            if "undefined" in mo:
                ax.text(0.5, 0.5, mo["undefined"], ha="center", va="center", fontsize=8, transform=ax.transAxes)
                continue
            k, unit = _scale(q)
            ms, conf, sg = (np.asarray(mo[x], dtype=float) * k for x in ("mu_star", "mu_star_conf", "sigma"))
            grp = ~np.isfinite(sg)  # a group (the mistuning pattern): SALib gives no sigma, drawn on the axis
            sg = np.where(grp, 0.0, sg)
            ax.errorbar(ms[~grp], sg[~grp], xerr=conf[~grp], fmt="o", capsize=3)
            if grp.any():
                ax.errorbar(ms[grp], sg[grp], xerr=conf[grp], fmt="s", mfc="none", capsize=3, color="C1",
                            label="a group (σ not defined)")
            for i, nm in enumerate(mo["names"]):
                ax.annotate(nm, (ms[i], sg[i]), textcoords="offset points", xytext=(4, 4), fontsize=8)
            top = max(float(np.max(ms + conf)), float(np.max(sg)), 1e-12)
            ax.plot([0, top], [0, top], color="0.6", ls=":", lw=0.8, label="σ = μ* (non-linear or interacting)")
            ax.set_xlabel(f"μ* [{unit}]" if unit else "μ*")
            ax.set_ylabel(f"σ [{unit}]" if unit else "σ")
            ax.set_title(f"{q}: Morris ({self.study.n} trajectories)", fontsize=9)
            ax.grid(alpha=0.3)
            ax.legend(fontsize=7)
        fig.suptitle(self._title(), fontsize=10)
        return fig

    def _fig_mistuning(self):
        plt = pyplot()
        items = list(self.estimates["mistuning"].items())
        fig, axes = plt.subplots(1, len(items), figsize=(5.4 * len(items), 4.6), squeeze=False)
        a = self.values["amp_linear"]
        for ax, (k, c) in zip(axes[0], items):
            b = self.values[k]
            ok = np.isfinite(a) & np.isfinite(b)
            ax.scatter(a[ok], b[ok], s=9, alpha=0.6, color="C0", linewidths=0)
            ax.axhline(1.0, color="0.5", lw=0.7, ls=":")
            ax.axvline(1.0, color="0.5", lw=0.7, ls=":")
            lo = min(float(a[ok].min()), float(b[ok].min()), 1.0)
            hi = max(float(a[ok].max()), float(b[ok].max()), 1.0)
            ax.plot([lo, hi], [lo, hi], color="C3", lw=0.8, ls="--", label="contact = linear")
            ax.set_xlabel("linear amplification factor (no contact)")
            ax.set_ylabel({"amp_contact": "contact amplification factor (static solution)",
                           "amp_force": "largest-force amplification (static solution)",
                           "amp_contact_transient": "contact amplification factor (transient)"}[k])
            r = c.get("pearson")
            sp = c.get("spearman")
            ttl = (f"Pearson r = {r['r']:.2f} [{r['low']:.2f}, {r['high']:.2f}], Spearman ρ = {sp['rho']:.2f} "
                   f"[{sp['low']:.2f}, {sp['high']:.2f}]" if r else c.get("note", ""))
            ax.set_title(f"{c['points']} mistuned disks\n{ttl}", fontsize=8.5)
            ax.grid(alpha=0.3)
            ax.legend(fontsize=8, loc="upper left")
        m = self.study.mistuning
        fig.suptitle(f"{self._title()}; {m.kind} scatter sd {100 * m.sd:g} %, neighbour correlation {m.correlation:g}",
                     fontsize=9.5)
        return fig

    def _fig_small_probability(self):
        plt = pyplot()
        sp = self.estimates["small_probability"]
        fig, ax = plt.subplots(figsize=(7, 4))
        names = [i.name for i in self.study.inputs]
        if self.study.mistuning is not None:
            names += [f"blade{j + 1}" for j in range(self.study.mistuning.n_blades)]
        if "importance_factors" in sp:
            ax.bar(range(len(names)), sp["importance_factors"], color="C2")
            ax.set_xticks(range(len(names)), names, rotation=25, fontsize=8)
            ax.set_ylabel("FORM importance factor α_i²")
            ax.set_title(f"P({sp['event']}) = {sp['probability']:.3e} (FORM, β = {sp['beta']:.3f}, "
                         f"{sp['evaluations']} evaluations)", fontsize=9)
        else:
            per = sp["probability_per_step"]
            ax.semilogy(range(1, len(per) + 1), per, "o-")
            ax.set_xticks(range(1, len(per) + 1))
            ax.set_xlabel("subset step (each a conditional probability of about 0.1)")
            ax.set_ylabel("probability estimate after the step")
            ax.set_title(f"P({sp['event']}) = {sp['probability']:.3e} [{sp['low']:.2e}, {sp['high']:.2e}] (subset "
                         f"sampling, {sp['evaluations']} evaluations)", fontsize=9)
        ax.grid(alpha=0.3)
        fig.suptitle(self._title(), fontsize=10)
        return fig

    # ------------------------------------------------------------------ writing
    def save(self, out: str | Path) -> dict:
        """uq_summary.json, uq_samples.npz and the study's figures into ``out``; returns the summary."""
        out = Path(out)
        out.mkdir(parents=True, exist_ok=True)
        for k in self.figures:
            save_figure(self.figure(k), out / f"uq_{k}.png")
        arrays = {f"q_{k}": v for k, v in self.values.items()}
        if self.X is not None:
            arrays["inputs"] = self.X
            arrays["input_names"] = np.array([i.name for i in self.study.inputs])
        if self.D is not None:
            arrays["mistuning_delta"] = self.D
        if self.replicate is not None:
            arrays["replicate"] = self.replicate
        np.savez_compressed(out / "uq_samples.npz", **arrays)
        s = self.summary()
        write_json(out / "uq_summary.json", s)
        return s

    def markdown(self, title: str = "Will it rub? Uncertainty study", level: int = 2) -> str:
        """A report section (markdown, a heading of ``level``): the study, its estimates, the cost table, the
        verdict."""
        s, e = self.study, self.estimates
        lines = [f"{'#' * level} {title}", "",
                 f"{s.name}: {s.method}" + (f" ({s.sampler}, {s.replicates} × {s.n} points)" if s.method == "montecarlo"
                                          and s.sampler == "qmc" else f", n = {s.n}") + f" at {self.operating_text()}.",
                 "", "| input | parameter | distribution |", "|---|---|---|"]
        lines += [f"| {i.name} | {i.target.name} | {i.distribution.describe()} |" for i in s.inputs]
        if s.mistuning is not None:
            m = s.mistuning
            lines.append(f"| mistuning | per-blade {m.kind} | {m.marginal.describe()}, neighbour correlation "
                         f"{m.correlation:g} |")
        if e.get("probabilities"):
            lines += ["", f"| event | probability | {100 * s.confidence:g} % interval | interval |",
                      "|---|---|---|---|"]
            lines += [f"| {k} | {_pct(p['probability'])} | {_pct(p['low'])} – {_pct(p['high'])} | {p['interval']} |"
                      for k, p in e["probabilities"].items()]
        if e.get("values"):
            lines += ["", "| quantity | mean | sd | quantiles |", "|---|---|---|---|"]
            for q, v in e["values"].items():
                if not v.get("points"):
                    continue
                k, unit = _scale(q)
                qs = ", ".join(f"{lev}: {qq['value'] * k:.4g}" for lev, qq in v["quantiles"].items())
                lines.append(f"| {q} [{unit or '-'}] | {v['mean'] * k:.4g} | {v['sd'] * k:.3g} | {qs} |")
        for q, si in e.get("sobol", {}).items():
            if "undefined" in si:
                lines += ["", f"Sobol' indices of {q}: {si['undefined']}."]
                continue
            lines += ["", f"| Sobol' ({q}) | S1 | ST |", "|---|---|---|"]
            lines += [f"| {nm} | {a:.3f} ± {ca:.3f} | {b:.3f} ± {cb:.3f} |" for nm, a, ca, b, cb in
                      zip(si["names"], si["S1"], si["S1_conf"], si["ST"], si["ST_conf"])]
        for k, c in e.get("mistuning", {}).items():
            if c.get("pearson"):
                r, sp = c["pearson"], c["spearman"]
                lines += ["", f"{k} vs amp_linear ({c['points']} disks): Pearson r = {r['r']:.3f} [{r['low']:.3f}, "
                              f"{r['high']:.3f}], Spearman ρ = {sp['rho']:.3f} [{sp['low']:.3f}, {sp['high']:.3f}]."]
        if e.get("small_probability"):
            sp = e["small_probability"]
            lines += ["", f"{s.method}: P({sp['event']}) = {sp['probability']:.3e}, {sp['evaluations']} evaluations."]
        c = self.cost
        lines += ["", "| analysis | evaluations | ms per evaluation (mean / median) | seconds |", "|---|---|---|---|"]
        lines += [f"| {lv} | {v['evaluations']} | {v['ms_per_evaluation_mean']:.3g} / "
                  f"{v['ms_per_evaluation_median']:.3g} | {v['seconds_total']:.3g} |" for lv, v in c["levels"].items()]
        lines += ["", f"{c['evaluations']} evaluations in {c['tasks']} tasks on {c['executor']}: {c['wall_s']:.3g} s "
                      f"wall ({c['tasks_reused_from_store']} tasks reused).", "", f"**Verdict:** {self.verdict()}", ""]
        return "\n".join(lines)
