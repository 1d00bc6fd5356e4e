"""Views of bladed disks with underplatform dampers.

* :mod:`bladedamp.viz.meshcat_view` (needs the "viz" extra: meshcat, trimesh): ``show(result)``
  builds the operating deflection shape of a :class:`~bladedamp.disk.DiskResponse` at a frequency
  of its FRF, with the contact state (stick / slip / separated over the cycle) or the normal
  pressure painted at every point contact on the damper's and the platforms' faces, the damper
  solid, transparent or exploded, and an HTML overlay (design, frequency, legend, play / pause,
  phase scrubber, camera and damper buttons) (a solid FE blade is drawn as its deformed FE
  surface, the exact mode superposition; ``MorphMeshGeometry``); ``Scene.save_html`` writes a
  standalone HTML file that opens in a browser without a server; ``Scene.serve`` starts a
  meshcat server bound to localhost (close it).
* :mod:`bladedamp.viz.notebook3d`: notebook helpers; ``contact_view`` puts a picked point's
  hysteresis loop beside the 3D view.
* :mod:`bladedamp.viz.widgets`: slider callbacks of the notebooks (no meshcat needed).

Nothing here imports meshcat until a 3D name is used, so ``bladedamp.viz.widgets`` works
without the "viz" extra.
"""
_MESHCAT_NAMES = ("Scene", "LiveView", "show", "ods_scene", "contact_map_scene", "cycle_data",
                  "blade_deflection", "screenshot", "MorphMeshGeometry", "project", "point_pressure")

__all__ = list(_MESHCAT_NAMES)


#: the one-line hint when the 3D view's packages are missing
INSTALL_HINT = "the 3D view needs meshcat and trimesh: pip install 'bladedamp[viz]'"


def __getattr__(name):
    if name in _MESHCAT_NAMES:
        try:
            from . import meshcat_view
        except ModuleNotFoundError as exc:
            if exc.name and exc.name.split(".")[0] in ("meshcat", "trimesh", "umsgpack", "zmq"):
                raise ModuleNotFoundError(f"bladedamp.viz.{name}: {INSTALL_HINT} (missing: {exc.name})",
                                          name=exc.name) from None
            raise
        return getattr(meshcat_view, name)
    raise AttributeError(f"module 'bladedamp.viz' has no attribute {name!r}")
