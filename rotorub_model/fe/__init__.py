"""Imported finite-element blades and casings ("bring your own blade", docs/THEORY.md section 9).

Readers return an :class:`FEModel` (SI, checked); :func:`reduce_blade` makes it a :class:`ReducedBlade`
(the project's superelement, saved as .npz); :func:`fe_bladed_disk_matrices` gives the bladed disk of
imported blades as the built-in beams' ``Matrices``; :func:`tip_point_maps` the contact contract.
"""

from .blade import ReducedBlade, load_superelement, reduce_blade
from .bladed_disk import fe_bladed_disk_matrices, tip_point_maps
from .calculix import read_calculix, read_dat_frequencies
from .femodel import FEModel
from .matrix_market import read_matrix_market
from .nastran import read_dmig, read_op4
from .units import unit_system

__all__ = ["FEModel", "ReducedBlade", "fe_bladed_disk_matrices", "load_superelement", "read_calculix",
           "read_dat_frequencies", "read_dmig", "read_matrix_market", "read_op4", "reduce_blade", "tip_point_maps",
           "unit_system"]
