"""The one palette of bladedamp: the same colour for the same thing in every figure and view.

Colours are the Okabe-Ito set (distinguishable with the common colour-vision deficiencies) as
hex strings for matplotlib; :func:`rgb` gives the (3,) floats in [0, 1] that meshcat's vertex
colours take. Contact states are indexed as :mod:`bladedamp.contact.point` numbers them
(STICK = 0, SLIP = 1, SEPARATED = 2).
"""
from __future__ import annotations

STICK = "#0072B2"          # blue
SLIP = "#D55E00"           # vermillion
SEPARATED = "#999999"      # grey
CONTACT_STATES = (STICK, SLIP, SEPARATED)             # indexed by the contact state code
CONTACT_STATE_NAMES = ("stick", "slip", "separated")

DAMPER = {"cylinder": "#009E73", "wedge": "#CC79A7"}    # bluish green, reddish purple
UNDAMPED = "#000000"       # the damper-free reference, drawn dashed
MEASURED = "#E69F00"       # orange
# engine orders, nodal diameters and other series of one kind, in order
SERIES = ("#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#56B4E9", "#F0E442", "#000000")


def series(k: int) -> str:
    """The colour of the k-th series of one kind (engine order k, the k-th design, ...)."""
    return SERIES[k % len(SERIES)]


def rgb(colour: str) -> tuple[float, float, float]:
    """'#rrggbb' as (r, g, b) floats in [0, 1]."""
    c = colour.lstrip("#")
    return tuple(int(c[i:i + 2], 16) / 255.0 for i in (0, 2, 4))
