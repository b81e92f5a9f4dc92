"""Former home of the figure and JSON helpers, now :mod:`rotorub_model.plotting` and :mod:`rotorub_model.writing`
(named for what they hold). Kept only while ``analyses/harmonic/interaction.py`` still imports from here; nothing
else does, and nothing new should."""

from .plotting import blade_colour, legend_outside, plot_blade_forces, pyplot, save_figure  # noqa: F401
from .writing import dumps, plain, save_result, write_json  # noqa: F401
