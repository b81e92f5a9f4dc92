"""The paper's analyses: linear response and modes, detection maps, static solutions and their
stability, central-difference transients, and the maps/sweeps that run them over (Omega, g0)."""
