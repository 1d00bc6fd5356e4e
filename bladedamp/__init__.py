"""bladedamp: forced response of turbine bladed disks with underplatform friction dampers.

Data flows one way: geometry and parameters -> model -> harmonic balance residual ->
continuation solver -> result objects -> plots, reports and 3D views.
"""
from . import _numba_cache

NUMBA_CACHE_DIR = _numba_cache.configure()   # compiled kernels go to a per-user cache, never site-packages

from .blade import BeamBladeGeometry, ModalBlade, reference_blade  # noqa: E402 (after the cache set-up)
from .contact import ContactPatch, LinearNormalLaw, RoughnessNormalLaw
from .damper import ContactProperties, CylinderDamper, WedgeDamper
from .disk import DiskResponse, TunedDisk
from .hbm import HarmonicBasis
from .oscillator import FrictionOscillator
from .reference import reference_disk
from .response import FrequencyResponse

__version__ = "0.1.0"
__all__ = ["BeamBladeGeometry", "ModalBlade", "reference_blade", "ContactPatch", "LinearNormalLaw",
           "RoughnessNormalLaw", "ContactProperties", "CylinderDamper", "WedgeDamper", "TunedDisk", "DiskResponse",
           "HarmonicBasis", "FrictionOscillator", "FrequencyResponse", "reference_disk", "frequency_response"]


def frequency_response(model, f_range_hz, harmonics="auto", **options):
    """Forced response of ``model`` (a TunedDisk or MistunedDisk) over ``f_range_hz = (start, end)``
    [Hz] by harmonic balance and arc-length continuation. ``harmonics="auto"`` (default) chooses
    them to the tolerance ``harmonic_tolerance`` (see :mod:`bladedamp.hbm.accuracy`); ``(1,)`` is
    the paper's setting. Returns the model's response (:class:`DiskResponse`, ...)."""
    start, end = f_range_hz
    return model.frequency_response(start, end, harmonics=harmonics, **options)
