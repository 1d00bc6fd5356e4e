"""bladedamp: forced response of turbine bladed disks with underplatform friction dampers.

Data flows one way: geometry and parameters -> model -> harmonic balance residual ->
continuation solver -> result objects -> plots, reports and 3D views.

Layers. A module imports only from the layers below its own (``a | b``: independent
siblings), never from one above; import-linter checks it against the contracts in
pyproject.toml (``[tool.importlinter]``, run by the test suite, which also finds no
import cycle). From the top:

    front ends       cli > app > viz | compare | reproduce (the paper's pipeline) > report | design (files)
                     | compilation
    studies          studies (mass, engine orders, platform angles, Monte Carlo, backbone)
    reference        reference (the paper's disk: reference_disk) | fit (contact parameters from measurements)
    disk models      disk (the tuned sector) | oscillator > mistuned (the full ring) > diskmodel (what
                     both disks share: damper position, contact element, DiskModel, checks)
    FRF driver       frf (one frequency-response driver of every model)
    analyses         hbm.stability > hbm.monodromy > timedomain | hbm.accuracy | hbm.nonlinear_modes
                     > response (the FRF result)
    blade            geometry (3D) > blade: the package blade.solid > blade.reference > blade.modal
                     (the modal blade and its files) > blade.beam > fe_formats | measurement (readers)
    contact, damper  damper > contact
    results on disk  io (save / load of results and blades by class name; old blade files by tag)
    engine           hbm.peaks > hbm.continuation | start | system | elements > hbm.newton (the one
                     Newton) > hbm.fourier | linsolve
    utilities        plotting | progress > palette | validation | lazy | _numba_cache

The engine and its analyses (``bladedamp.hbm``) import no model: stability and the monodromy
reach a model through the protocols it implements
(:class:`bladedamp.hbm.monodromy.PeriodMapModel`, :class:`~bladedamp.hbm.monodromy.AssemblyModel`),
and the engine core (Fourier, residual, elements, Newton, continuation, linear solvers) imports
nothing outside hbm but validation. This package (its public names below) sits above every
layer. No back arrow is left.
"""
from .lazy import lazy_attributes

from . import _numba_cache

NUMBA_CACHE_DIR = _numba_cache.configure()   # compiled kernels go to a per-user cache, never site-packages

__version__ = "0.1.0"

# The public names, imported on first use (PEP 562): ``import bladedamp`` stays fast (the CLI's
# --help, worker start-up) and loads numpy, scipy and numba only with the first model.
_LAZY = {
    "BeamBladeGeometry": "blade", "ModalBlade": "blade", "reference_blade": "blade",
    "solid": "blade",            # the module bladedamp.blade.solid (``from bladedamp import solid``)
    "ContactPatch": "contact", "LinearNormalLaw": "contact", "RoughnessNormalLaw": "contact",
    "ContactProperties": "damper", "CylinderDamper": "damper", "WedgeDamper": "damper",
    "TunedDisk": "disk", "DiskResponse": "disk",
    "MistunedDisk": "mistuned", "MistunedResponse": "mistuned",
    "HarmonicBasis": "hbm", "HarmonicBalanceSystem": "hbm", "Coupling": "hbm",
    "TimeDomainElement": "hbm", "CubicSpring": "hbm", "GapSpring": "hbm", "with_element": "hbm",
    "FrictionOscillator": "oscillator",
    "reference_disk": "reference",
    "FrequencyResponse": "response", "Status": "response", "Note": "response", "NoteKind": "response",
    "load": "io", "save": "io",
    "load_measurement": "measurement", "load_modes": "measurement", "MeasuredResponse": "measurement",
    "MeasuredModes": "measurement",
    "load_design": "design",
    "nonlinear_mode": "hbm.nonlinear_modes",
    "precompile": "compilation",
    "fit_contact": "fit", "ContactFit": "fit",
    "Sensitivities": "response", "PeakSensitivities": "response",
}
__all__ = sorted(_LAZY) + ["frequency_response", "peak_sensitivities"]


__getattr__, __dir__ = lazy_attributes(__name__, _LAZY, globals())


def frequency_response(model, f_range_hz, harmonics="auto", stability: bool = False, **options):
    """Forced response of ``model`` over ``f_range_hz = (start, end)`` [Hz] by harmonic balance
    and arc-length continuation, the same call for every model: a :class:`FrictionOscillator`,
    a :class:`TunedDisk` or a :class:`~bladedamp.mistuned.MistunedDisk` (each takes Hz).
    ``harmonics="auto"`` (default) chooses them to the tolerance ``harmonic_tolerance`` (see
    :mod:`bladedamp.hbm.accuracy`); ``(1,)`` is the paper's setting; ``options`` go to the
    model's ``frequency_response``. Returns the model's response (:class:`FrequencyResponse`,
    :class:`DiskResponse`, :class:`~bladedamp.mistuned.MistunedResponse`). ``stability=True``
    adds the stability of every point (``stable``, ``floquet_exponents``, ``bifurcations``; see
    :mod:`bladedamp.hbm.stability`: Hill's method, or the sign of det J for friction).

    Raises TypeError for any other model, ValueError for a range that is not (start, end) in Hz.
    """
    from .disk import TunedDisk
    from .mistuned import MistunedDisk
    from .oscillator import FrictionOscillator

    models = (FrictionOscillator, TunedDisk, MistunedDisk)
    if not isinstance(model, models):
        raise TypeError(f"model must be a FrictionOscillator, TunedDisk or MistunedDisk "
                        f"(got {type(model).__module__}.{type(model).__qualname__})")
    try:
        start, end = (float(f) for f in f_range_hz)
    except (TypeError, ValueError):
        raise ValueError(f"f_range_hz must be a pair (f_start_hz, f_end_hz) in Hz (got {f_range_hz!r})") from None
    response = model.frequency_response(start, end, harmonics=harmonics, **options)
    if stability:
        from .hbm.stability import with_stability

        extra = options.get("extra_couplings")
        if extra is not None:
            from .diskmodel import WithCouplings

            model = WithCouplings(model, extra)
        response = with_stability(model, response)
    return response


def peak_sensitivities(model, f_range_hz, parameters, direction: int = 0, **options):
    """The derivatives of ``model``'s resonance peak over ``f_range_hz = (start, end)`` [Hz] in the
    design-file keys ``parameters`` (e.g. ``["damper.mass_g", "damper.friction_coefficient"]``;
    :data:`bladedamp.diskmodel.SENSITIVITY_KEYS`): :func:`frequency_response` with ``options``, then
    the peak (the largest tip amplitude in ``direction``, of any blade) solved by d|u|/dOmega = 0
    and differentiated by the implicit function theorem with the analytic dR/dp
    (:meth:`bladedamp.diskmodel.DiskModelResponse.peak_sensitivities`). Returns a
    :class:`~bladedamp.response.PeakSensitivities`: ``result["damper.mass_g"].peak_amplitude`` [m per
    g], ``.peak_frequency_hz`` [Hz per g]. A TunedDisk or MistunedDisk, or a FrictionOscillator (its
    fields as keys, per SI unit: :attr:`FrictionOscillator.PARAMETERS`; TypeError for anything else);
    ValueError for an unknown key, a range without a solvable peak, or a response that is not a
    success (its status message says why)."""
    from .diskmodel import DiskModel
    from .oscillator import FrictionOscillator

    if not isinstance(model, (DiskModel, FrictionOscillator)):
        raise TypeError(f"model must be a TunedDisk, MistunedDisk or FrictionOscillator (got {type(model).__qualname__})")
    response = frequency_response(model, f_range_hz, **options)
    if not response.success:
        raise ValueError(f"the frequency response is not a success, so its peak is not differentiated: "
                         f"{response.status_message}")
    if isinstance(model, FrictionOscillator):
        return model.peak_sensitivities(response, parameters)
    return response.peak_sensitivities(parameters, direction)
