"""The paper's pipeline (bladedamp.reproduce): its handling of the warnings it expects. The run
itself (minutes) is checked by tests/test_cli.py (slow) and benchmarks/bench_reproduce.py."""
import warnings

import numpy as np

from bladedamp.reference import reference_disk
from bladedamp.reproduce import STUCK_LIMIT_MASS, stuck_limit_expected
from bladedamp.studies.mass import with_mass
from bladedamp.validation import PlausibilityWarning


def test_only_the_stuck_limit_mass_passes_without_a_plausibility_warning():
    """The 1 kg damper of the mass sweep (an array element) and of Fig. 5 (a float) warns nothing
    in the block; another implausible mass, another warning and the 1 kg outside the block do."""
    disk = reference_disk("cylinder")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        with stuck_limit_expected():
            with_mass(disk, (np.array([1000.0]) * 1e-3)[0])        # the sweep's last mass: np.float64(1.0)
            reference_disk("cylinder", STUCK_LIMIT_MASS)            # Fig. 5's
            with_mass(disk, 2.0)
            with_mass(disk, 1e-7)
            warnings.warn("another warning", UserWarning)
        with_mass(disk, STUCK_LIMIT_MASS)
    messages = [(w.category, str(w.message).split(" is outside")[0]) for w in caught]
    assert messages == [(PlausibilityWarning, "damper mass = 2.0 kg"), (PlausibilityWarning, "damper mass = 1e-07 kg"),
                        (UserWarning, "another warning"), (PlausibilityWarning, "damper mass = 1.0 kg")], messages
