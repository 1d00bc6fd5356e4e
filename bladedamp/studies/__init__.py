"""Damper design studies on the tuned disk: peak search, mass optimisation, engine orders,
platform angles, contact states (Eq. 27) and wedge lift-off (Fig. 9)."""
from .design import (ContactState, DesignMap, EngineOrderSweep, LiftoffMap, PlatformAngleStudy, contact_state,
                     design_map, engine_order_sweep, engine_order_sweeps, liftoff_onset, platform_angle_study,
                     wedge_liftoff_map)
from .backbone import BackboneDesign, optimal_mass_by_backbone
from .mass import MassOptimum, MassSweep, mass_sweep, optimal_mass, peak_response

__all__ = ["peak_response", "optimal_mass", "mass_sweep", "MassOptimum", "MassSweep", "engine_order_sweep",
           "engine_order_sweeps", "EngineOrderSweep", "platform_angle_study", "PlatformAngleStudy", "contact_state", "ContactState",
           "wedge_liftoff_map", "LiftoffMap", "design_map", "DesignMap", "liftoff_onset", "optimal_mass_by_backbone", "BackboneDesign"]
