"""The linear blade: the modal blade (paper Eq. 1-5) and its files, the beam model, the paper's
reference blade and the solid finite-element blade, one module each, every import pointing down:

    solid       the solid FE blade (gmsh, scikit-fem: the ``fe`` extra): SolidModalBlade, solid_blade
    reference   the paper's reference blade (Table 1), PLATFORM_ANGLE
    modal       ModalBlade, its modal data files (.npz, .csv) and reduced FE matrices
    beam        the beam model: sections, the platform, BeamBladeGeometry, beam_modes

(import-linter checks the order: pyproject.toml). This package gives the public names of the
first three (``from bladedamp.blade import ModalBlade``); the solid blade is ``bladedamp.blade.solid``
(also ``bladedamp.solid`` after ``import bladedamp``). The solid FE blade is built by
:func:`bladedamp.blade.solid.solid_blade` (it was ``ModalBlade.from_solid``, which made the modal
blade import the solid one that derives from it). Files: every blade is saved and read back through
:mod:`bladedamp.io` (``blade.save``, :func:`bladedamp.load`, :meth:`ModalBlade.from_file`), as results are.

Frames and conventions (the rest of bladedamp relies on them)
-------------------------------------------------------------
Blade frame: x = circumferential (flatwise bending direction of 1F, tip excitation F_x),
y = axial, z = radial along the span (root at z = 0, tip at z = L_total).
Every 6-vector is ordered (u_x, u_y, u_z, phi_x, phi_y, phi_z): three translations [m]
then three small rotations [rad].  A point rigidly attached at offset r from a node moves
by u + phi x r and rotates by phi (the rigid-body kinematics used for the platform contact
control points OL, OR, paper section "Contact Kinematics").

Platform contact control points: OL lies at x = -platform_half_width, OR at
x = +platform_half_width (both at y = 0, on the platform underside).  So the damper that
touches OL of one blade touches OR of its neighbour on the -x side.

Units: SI everywhere (m, kg, s, rad, N).  Mass-normalised mode shapes have units
m/sqrt(kg) (translations) and rad/sqrt(kg) (rotations); modal coordinates sqrt(kg)*m.
"""
from .beam import (BENDING_THEORIES, PHIX, PHIY, PHIZ, TORSION_THEORIES, UX, UY, UZ, BeamBladeGeometry, BeamModes,
                   PlatformBlock, RectangularSection, assemble_beam, beam_mesh, beam_modes, n_beam_dofs,
                   platform_section, rigid_offset_motion, torsion_constant_polygon, torsion_constant_rectangle,
                   warping_constant_rectangle)
from .modal import (DENSE_SOLVER_MAX_DOF, MODAL_CSV_COLUMNS, MODAL_NPZ_KEYS, PAPER_MODE_ORDER, REQUIRED_POINTS,
                    RIGID_MODE_TOLERANCE, SHIFT_INVERT_SIGMA, ModalBlade, modal_npz_fields, read_modal_npz)
from .reference import (PLATFORM_ANGLE, TABLE1_DAMPING_RATIOS, TABLE1_FREQUENCIES_HZ, reference_blade,
                        reference_blade_geometry)
from .solid import solid_platform_beam

__all__ = ["BENDING_THEORIES", "DENSE_SOLVER_MAX_DOF", "MODAL_CSV_COLUMNS", "MODAL_NPZ_KEYS", "PAPER_MODE_ORDER",
           "PHIX", "PHIY", "PHIZ", "PLATFORM_ANGLE", "REQUIRED_POINTS", "RIGID_MODE_TOLERANCE", "SHIFT_INVERT_SIGMA",
           "TABLE1_DAMPING_RATIOS", "TABLE1_FREQUENCIES_HZ", "TORSION_THEORIES", "UX", "UY", "UZ",
           "BeamBladeGeometry", "BeamModes", "ModalBlade", "PlatformBlock", "RectangularSection",
           "assemble_beam", "beam_mesh", "beam_modes", "modal_npz_fields", "n_beam_dofs", "platform_section",
           "read_modal_npz", "reference_blade", "reference_blade_geometry", "rigid_offset_motion",
           "solid_platform_beam", "torsion_constant_polygon", "torsion_constant_rectangle",
           "warping_constant_rectangle"]
