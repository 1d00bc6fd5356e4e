"""Write the two stand-in rig files of the README's worked example (run from the repository root):

* reference_blade_tip_frf.uff: UFF 58 (ASCII), the reference blade's computed linear receptance
  u_x,tip / F_x,excitation [m/N] over 80-120 Hz (161 points), units labelled "m" over "N";
* reference_blade_modes.uff: UFF 164 (SI), 15 (the OL, OR, tip and excitation points as nodes
  11-14) and 55 (its four mass-normalised modes, modal mass 1 kg, with their damping ratios).

They are computed, not measured: they let the examples run and are checked by
tests/test_measurement.py (reading them gives the reference blade to the files' digits).
"""
from pathlib import Path

import numpy as np
import pyuff

import bladedamp as bd

HERE = Path(__file__).parent
NODES = {"OL": 11, "OR": 12, "tip": 13, "excitation": 14}


def write_frf(path: Path) -> None:
    blade = bd.reference_blade()
    f = np.linspace(80.0, 120.0, 161)
    h = blade.linear_frf(f, np.array([1.0, 0, 0, 0, 0, 0]))[:, 0]
    path.unlink(missing_ok=True)
    pyuff.UFF(str(path)).write_sets(pyuff.prepare_58(
        binary=0, func_type=4, id1="reference blade: computed receptance, tip x over excitation x",
        rsp_ent_name="blade", rsp_node=NODES["tip"], rsp_dir=1, ref_ent_name="blade", ref_node=NODES["excitation"],
        ref_dir=1, abscissa_spacing=1, abscissa_spec_data_type=18, abscissa_axis_units_lab="Hz",
        ordinate_spec_data_type=8, ordinate_axis_units_lab="m", orddenom_spec_data_type=13,
        orddenom_axis_units_lab="N", data=h, x=f), mode="add")


def write_modes(path: Path) -> None:
    blade = bd.reference_blade()
    names = list(NODES)
    path.unlink(missing_ok=True)
    uff = pyuff.UFF(str(path))
    uff.write_sets(pyuff.prepare_164(units_code=1, units_description="SI", temp_mode=1, length=1.0, force=1.0,
                                     temp=1.0, temp_offset=273.15), mode="add")
    xyz = np.array([blade.points[n] for n in names])
    uff.write_sets(pyuff.prepare_15(node_nums=[NODES[n] for n in names], def_cs=[0] * 4, disp_cs=[0] * 4,
                                    color=[0] * 4, x=xyz[:, 0], y=xyz[:, 1], z=xyz[:, 2]), mode="add")
    for j in range(blade.n_modes):
        shape = np.array([blade.mode_shapes[n][:, j] for n in names])
        uff.write_sets(pyuff.prepare_55(
            id1=f"reference blade mode {blade.mode_names[j]}", model_type=1, analysis_type=2, data_ch=3,
            spec_data_type=8, data_type=2, n_data_per_node=6, load_case=1, mode_n=j + 1,
            freq=float(blade.natural_frequencies_hz[j]), modal_m=1.0, modal_damp_vis=float(blade.damping_ratios[j]),
            modal_damp_his=0.0, node_nums=[NODES[n] for n in names], **{f"r{i + 1}": shape[:, i] for i in range(6)}),
            mode="add")


if __name__ == "__main__":
    write_frf(HERE / "reference_blade_tip_frf.uff")
    write_modes(HERE / "reference_blade_modes.uff")
