"""Will it rub? Uncertainty studies: rub probability, sensitivity indices, small probabilities, mistuning.

A study file (TOML, :mod:`.study`) names the uncertain inputs with their distributions, the blades' mistuning,
the quantities asked and the method; :func:`run_uq` samples (scipy.stats.qmc, SALib, OpenTURNS), evaluates
each sample with the cheapest analysis that answers (:mod:`.quantities`) through the project's executor,
resumably (:mod:`.runner`), and returns a :class:`UQResult` (figures, JSON, verdict, report section).
docs/THEORY.md section 10 holds the definitions and the decisions.

>>> from rotorub_model.uncertainty import load_study, EXAMPLE_STUDY
>>> load_study(EXAMPLE_STUDY).method
'montecarlo'
"""

from pathlib import Path

from .quick import run_uq_quick
from .results import UQResult
from .runner import run_uq
from .study import Study, load_study, study_from_dict

EXAMPLE_STUDY = Path(__file__).resolve().parents[1] / "data" / "study_example.toml"

__all__ = ["EXAMPLE_STUDY", "Study", "UQResult", "load_study", "run_uq", "run_uq_quick", "study_from_dict"]
