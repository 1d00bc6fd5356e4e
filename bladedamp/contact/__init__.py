"""Contact: normal laws, vectorised point contacts (2D Masing + lift-off), contact patches."""
from .laws import LinearNormalLaw, RoughnessNormalLaw
from .patch import ContactPatch, PatchEvaluation, rigid_point_map
from .point import SEPARATED, SLIP, STICK, PointContactSamples, point_contact_forces

__all__ = ["LinearNormalLaw", "RoughnessNormalLaw", "ContactPatch", "PatchEvaluation", "rigid_point_map",
           "point_contact_forces", "PointContactSamples", "STICK", "SLIP", "SEPARATED"]
