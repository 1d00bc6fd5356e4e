"""Dampers: geometry (frames, patches, G_D, G_P; Eq. 6-9) and kinetics (preload Eq. 26, seating)."""
from .geometry import ContactProperties, CylinderDamper, DamperGeometry, WedgeDamper
from .kinetics import centrifugal_force, retention_stiffness, seat

__all__ = ["ContactProperties", "CylinderDamper", "WedgeDamper", "DamperGeometry", "centrifugal_force", "retention_stiffness", "seat"]
