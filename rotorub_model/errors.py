"""Exceptions raised by rotorub for bad input and failed analyses."""


class RotorubError(Exception):
    """Base class for every error rotorub raises on purpose."""


class ParameterError(RotorubError, ValueError):
    """A parameter is missing, unknown, out of range or inconsistent.

    The message always names the field (``section.name``) and the accepted range.
    """


class ConvergenceError(RotorubError):
    """An iterative solver did not converge; the message gives the residual."""


class DivergenceError(RotorubError):
    """A transient run diverged; the message gives the time and the quantity."""


class FEImportError(RotorubError, ValueError):
    """A finite-element export cannot be imported as it is (units, dof map, matrices, tip nodes, speeds,
    coordinates); the message names the file or the field and what is accepted. Nothing is written."""
