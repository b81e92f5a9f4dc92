"""analyses/wear.py, what a user reads (issue 25.4, 25.5): the lobe count by the kernel's stated rule in the titles,
the JSON and the console; the wear map's time axis where the wear happens; the polar plot's magnification stated."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from rotorub_model import kernel
from rotorub_model.analyses.wear import LOBE_DOMINANCE, LOBE_UNIFORM, lobe_verdict, run_wear
from rotorub_model.contact import make_contact
from rotorub_model.contact.liner import Liner
from rotorub_model.plotting import pyplot


def test_the_rule_is_the_kernels():
    header = (Path(kernel.__file__).parent / "rotorub_kernel.h").read_text()
    assert float(re.search(r"#define RR_LOBE_DOMINANCE ([0-9.]+)", header).group(1)) == LOBE_DOMINANCE
    assert float(re.search(r"#define RR_LOBE_UNIFORM ([0-9.]+)", header).group(1)) == LOBE_UNIFORM


@pytest.fixture(scope="module")
def liner(ref_model):
    return Liner.for_model(ref_model, make_contact(ref_model, "2D", g0=0.5e-3), wears=True)


def _profile(liner, mean: float, harmonics: dict[int, float]) -> dict:
    th = (np.arange(liner.n_sectors) + 0.5) * 2 * np.pi / liner.n_sectors
    d = mean + sum(a * np.cos(h * th + 0.3 * h) for h, a in harmonics.items())
    liner.depth[:] = d[None, :]
    return liner.summary()


@pytest.mark.parametrize("mean, harmonics, lobes, words", [
    # the 14-blade run: uniform to +-2 %, h1 0.0223 um, h2 0.0217 um, titled "1 lobes dominate"
    (1.1e-6, {1: 0.0223e-6, 2: 0.0217e-6}, 0, "worn evenly"),
    # the reference 3D spectrum: harmonic 2 four times every other, titled "no lobe dominates"; here above 5 %
    (10e-6, {1: 0.5e-6, 2: 2.0e-6, 3: 0.4e-6}, 2, "2 lobes: harmonic 2 is 4 ×"),
    # an offset casing: harmonic 1 and its multiples
    (10e-6, {1: 5e-6, 2: 1e-6}, 1, "1 lobe:"),
    # a 3-lobed profile that is not a sinusoid carries harmonic 6 (the lead's 3-lobe test: 0.8 x harmonic 3)
    (10e-6, {3: 2e-6, 6: 1.6e-6, 1: 0.3e-6}, 3, "3 lobes"),
    # two harmonics of a like size, neither a multiple of the other: none dominates (harmonic 1 the largest would be
    # 1 lobe: every harmonic is its multiple)
    (10e-6, {2: 1.5e-6, 3: 1.0e-6}, 0, "no lobe dominates: harmonic 2 is only 1.5 × harmonic 3"),
])
def test_the_verdict_is_the_kernels_count_in_words(liner, mean, harmonics, lobes, words):
    s = _profile(liner, mean, harmonics)
    n, text = lobe_verdict(s)
    assert s["lobes"] == n == lobes, (s["lobes"], n, text)
    assert words in text, text
    assert "lobes dominate" not in text and not text.startswith("1 lobes")


@pytest.fixture(scope="module")
def rub(ref_model):
    return run_wear(ref_model, "3D", 3.3, 0.3347658066492161e-3, t_end=4.0)


def test_the_figures_say_the_verdict_and_show_where_the_wear_is(rub):
    s = rub.summary()
    assert s["lobes_verdict"] == lobe_verdict(rub.wear["summary"])[1]
    assert f"< {LOBE_UNIFORM:g} x the mean depth" in s["lobes_rule"] and f">= {LOBE_DOMINANCE:g} x" in s["lobes_rule"]
    plt = pyplot()
    fig = rub.figure("wear_profile")
    try:
        spectrum = fig.axes[-1]
        assert s["lobes_verdict"].split(":")[0] in spectrum.get_title().replace("\n", " ")
        polar = next(a for a in fig.axes if a.name == "polar")
        assert "magnified" in polar.get_title() and "µm" in polar.get_title()
    finally:
        plt.close(fig)
    # the section-6 rub wears between about 0.5 and 1.3 s: the map's time axis shows that, not 4 s of black
    win = rub.wear_window()
    assert win is not None and 0.3 < win[0] < win[1] < 2.0
    fig = rub.figure("wear_map")
    try:
        lo, hi = fig.axes[0].get_ylim()
        assert lo <= win[0] and hi >= win[1] and hi - lo < 0.6 * 4.0
        assert "all the wear between" in fig.axes[0].get_title()
    finally:
        plt.close(fig)
