"""bladedamp: forced response of turbine bladed disks with underplatform friction dampers.

Data flows one way: geometry and parameters -> model -> harmonic balance residual ->
continuation solver -> result objects -> plots, reports and 3D views.
"""
from .contact import ContactPatch, LinearNormalLaw, RoughnessNormalLaw
from .hbm import HarmonicBasis
from .oscillator import FrictionOscillator
from .response import FrequencyResponse

__version__ = "0.1.0"
__all__ = ["ContactPatch", "LinearNormalLaw", "RoughnessNormalLaw", "HarmonicBasis", "FrictionOscillator",
           "FrequencyResponse"]
