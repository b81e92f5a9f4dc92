"""The linear structure in the rotating frame: parameters, Ritz bases, shaft, blades, casing, assembly.

Each component builds its own M, D, G1, C1, N2, S2 (``frames.Matrices``); ``model.build_model``
places them.
"""
