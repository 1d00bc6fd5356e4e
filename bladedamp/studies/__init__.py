"""Damper design studies built on the tuned disk: peak search and damper-mass optimisation."""
from .mass import MassOptimum, MassSweep, mass_sweep, optimal_mass, peak_response

__all__ = ["peak_response", "optimal_mass", "mass_sweep", "MassOptimum", "MassSweep"]
