"""Figures of the result objects: a headless matplotlib, the one saving rule, the blades' colours and the
legends every figure shares. (The JSON side of a result's ``save`` is :mod:`rotorub_model.writing`.)"""

from __future__ import annotations

from pathlib import Path

import numpy as np


def pyplot():
    """matplotlib.pyplot on the non-interactive Agg backend (no display needed)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def save_figure(fig, path: str | Path, dpi: int = 120, layout: bool = True) -> Path:
    """Lay out (unless the caller did: ``layout=False``), write the PNG and release the figure (figures
    are many in a sweep: never leak one). The saved area grows to take in what lies outside the axes,
    so a legend placed beside the data, where it hides none, is never cut off."""
    if layout and fig.get_layout_engine() is None:  # a constrained-layout figure lays itself out
        fig.tight_layout()
    fig.savefig(path, dpi=dpi, bbox_inches="tight", pad_inches=0.1)
    pyplot().close(fig)
    return Path(path)


def blade_colour(j: int) -> tuple[float, float, float, float]:
    """Colour of blade j (0-based), the same in every figure, so that a blade is followed from one
    panel to the next (tab10; past ten blades tab20's pale partners). The blades that touch together
    are neighbours, the last one next to the first: tab10's cyan, next to its blue, goes to blade 8."""
    plt = pyplot()
    order = (0, 1, 2, 3, 4, 5, 6, 9, 7, 8)
    if j < 10:
        return plt.get_cmap("tab10")(order[j])
    return plt.get_cmap("tab20")((2 * order[j % 10] + 1) % 20)


def plot_blade_forces(ax, t: np.ndarray, F_N: np.ndarray, lw: float = 1.0) -> int:
    """Normal force of every blade that touches, in its own colour; says so on the axes when none does
    (an empty panel with an empty legend read as a failed plot). Returns the number of blades drawn."""
    drawn = 0
    for j in range(F_N.shape[1] if F_N.ndim == 2 else 0):
        if F_N[:, j].max() > 0:
            ax.plot(t, F_N[:, j], lw=lw, color=blade_colour(j), label=f"blade {j + 1}")
            drawn += 1
    if not drawn:
        ax.text(0.5, 0.5, "no blade touches the casing", transform=ax.transAxes, ha="center", va="center",
                color="0.35")
    if len(t) > 1:
        ax.set_xlim(float(t[0]), float(t[-1]))
    return drawn


def legend_outside(ax, fontsize: float = 8, **kw):
    """The axes' legend to their right, outside the data (the saved figure grows to take it in);
    None when nothing is labelled."""
    handles, labels = ax.get_legend_handles_labels()
    if not handles:
        return None
    ncol = 1 if len(handles) <= 12 else 2
    return ax.legend(handles, labels, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0,
                     fontsize=fontsize, ncol=ncol, **kw)
