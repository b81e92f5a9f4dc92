"""rotorub: blade-tip / casing contact model of a turbofan fan module.

Model of Parent, Thouverez & Chevillot, *3D interaction in bladed rotor-to-stator
contact* (EURODYN 2014): a flexible bladed rotor and a flexible suspended casing
written in the rotating frame, 2D and 3D contact formulations, and the paper's
analyses. SI units throughout; see docs/THEORY.md for the conventions.
"""

from .errors import ConvergenceError, DivergenceError, ParameterError, RotorubError
from .structure.model import Model, build_model
from .structure.params import Parameters, load_parameters, reference_parameters

__all__ = [
    "ConvergenceError",
    "DivergenceError",
    "Model",
    "ParameterError",
    "Parameters",
    "RotorubError",
    "build_model",
    "load_parameters",
    "reference_parameters",
]
__version__ = "0.1.0"
