"""Blades from FE exports (bladedamp.fe_formats, ModalBlade.from_file): Nastran OUTPUT4 and punch
DMIG, Abaqus matrix output, MATLAB. Real files of the exporting programs are in tests/data/fe
(README there: sources and licences); the reference blade's own matrices are written in every
format by the small writers below."""
import struct
from pathlib import Path

import numpy as np
import pytest
import scipy.io
import scipy.linalg
import scipy.sparse

from bladedamp.blade import ModalBlade, beam_modes
from bladedamp.fe_formats import read_fe_matrices, read_matlab, read_op4
from bladedamp.reference import reference_blade_geometry

DATA = Path(__file__).parent / "data" / "fe"


# ---------------------------------------------------------------------------------------
# files written by the real programs
# ---------------------------------------------------------------------------------------
def test_nastran_binary_and_text_output4_of_the_same_matrices_agree_exactly():
    """Nastran wrote the same test matrices (identity, lower triangular, random real and complex,
    null, strings) as binary and as text OUTPUT4, both in the sparse 'bigmat' layout: the two
    independent code paths of the reader give the same numbers (the text has 16 digits, enough
    to carry the single- and double-precision values exactly)."""
    text, binary = read_op4(DATA / "mat_t_s2.op4"), read_op4(DATA / "mat_b_s2.op4")
    assert sorted(text) == sorted(binary) == ["EYE10", "EYE5CD", "LOW", "NULL", "RND1CD", "RND1CS",
                                              "RND1RD", "RND1RS", "STRINGS"]
    for name in text:
        (a, nra, nca, _), (b, nrb, ncb, _) = text[name], binary[name]
        assert (nra, nca) == (nrb, ncb)
        A, B = np.zeros((nra, nca), complex), np.zeros((nrb, ncb), complex)
        A[a.rows, a.cols] = a.vals
        B[b.rows, b.cols] = b.vals
        if name == "RND1RS" or name == "RND1CS":          # single precision: text rounds to 16 digits
            np.testing.assert_allclose(A, B, rtol=1e-15)
        else:
            np.testing.assert_array_equal(A, B)
    e = text["EYE10"][0]
    assert sorted(zip(e.rows, e.cols)) == [(k, k) for k in range(10)] and set(e.vals) == {1.0}
    s = text["STRINGS"][0]                                 # 30 x 20: column j holds j in strings of 3 rows
    assert text["STRINGS"][1:3] == (30, 20) and set(s.vals) <= set(range(1, 21))


def raw_dmig_large_field(path, name):
    """Independent reading of a large-field DMIG matrix: the '*' lines after 'DMIG* name'."""
    entries, column = {}, None
    for line in Path(path).read_text().splitlines():
        if line.startswith("DMIG*"):
            column = (int(line[24:40]), int(line[40:56])) if line[8:24].strip() == name else None
        elif line.startswith("*") and column is not None:
            row = (int(line[8:24]), int(line[24:40]))
            entries[(row, column)] = float(line[40:56].replace("D", "E"))
        elif not line.startswith("*"):
            column = None
    labels = sorted({k for pair in entries for k in pair})
    A = np.zeros((len(labels), len(labels)))
    for (r, c), v in entries.items():
        A[labels.index(r), labels.index(c)] = A[labels.index(c), labels.index(r)] = v
    return A, labels


def test_nastran_punch_dmig_matrices_and_their_eigenvalues():
    """KAAX, MAAX of a Nastran EXTOUT,DMIGPCH punch (one triangle, large field, D exponents):
    the reader gives the file's values (read here line by line) and the generalized
    eigenvalues of the spring chain, node 101 clamped, equal scipy's on those values."""
    fe = read_fe_matrices(DATA / "dmig.pch")
    assert fe.names == ("MAAX", "KAAX")
    K, k_labels = raw_dmig_large_field(DATA / "dmig.pch", "KAAX")
    M, m_labels = raw_dmig_large_field(DATA / "dmig.pch", "MAAX")
    assert k_labels == m_labels == [tuple(lab) for lab in fe.labels.tolist()]
    np.testing.assert_array_equal(fe.stiffness.toarray(), K)
    np.testing.assert_array_equal(fe.mass.toarray(), M)
    free = fe.row_indices("free", [(n, (1,)) for n in (102, 105, 106, 107, 108, 109, 201, 301, 302, 305,
                                                     306, 307, 308, 309)])
    lam_file = scipy.linalg.eigh(K[np.ix_(free, free)], M[np.ix_(free, free)], eigvals_only=True)
    lam = scipy.linalg.eigh(fe.stiffness.toarray()[np.ix_(free, free)], fe.mass.toarray()[np.ix_(free, free)],
                            eigvals_only=True)
    np.testing.assert_array_equal(lam, lam_file)
    assert lam.min() > 0                                   # clamping node 101 removes the rigid mode


def test_nastran_craig_bampton_output4_blade():
    """External superelement KAA, MAA (Nastran EXTSEOUT, text OUTPUT4, 12 boundary grids x 6 DOF,
    then 33 fixed-interface modal coordinates). With every boundary grid clamped the modal block
    is M = I, K = diag(omega_j^2): the fixed-interface frequencies. Freeing grid 1 (rows 1-6) and
    reading it as OL, OR, tip and excitation gives a blade whose frequencies are scipy's on the
    same rows and, by Rayleigh's interlacing theorem, lie below the fixed-interface ones."""
    fe = read_fe_matrices(DATA / "se_test_n11.op4")
    assert fe.names == ("MAA", "KAA") and fe.labels is None and fe.n == 105
    M, K = fe.mass.toarray(), fe.stiffness.toarray()
    np.testing.assert_allclose(M[72:, 72:], np.eye(33), atol=1e-12)
    k_mm = K[72:, 72:]
    off = k_mm - np.diag(np.diag(k_mm))
    assert np.abs(off).max() <= 1e-11 * np.diag(k_mm).max()      # diagonal to Nastran's rounding
    fixed_interface_hz = np.sqrt(np.diag(k_mm)) / (2 * np.pi)
    lam_mm = scipy.linalg.eigh(k_mm, M[72:, 72:], eigvals_only=True)
    # Weyl: the rounding-level off-diagonal part E moves each eigenvalue by at most ||E||_2 (plus M - I)
    bound = np.linalg.norm(off, 2) + np.abs(M[72:, 72:] - np.eye(33)).sum() * np.diag(k_mm).max()
    assert np.abs(lam_mm - np.sort(np.diag(k_mm))).max() <= bound

    points = {p: (0.0, 0.0, 0.0) for p in ("OL", "OR", "tip", "excitation")}
    blade = ModalBlade.from_file(DATA / "se_test_n11.op4", dof_map={p: range(1, 7) for p in points}, points=points,
                                 n_modes=8, damping_ratios=0.01, fixed_dofs=range(7, 73))
    free = np.r_[0:6, 72:105]
    lam = scipy.linalg.eigh(K[np.ix_(free, free)], M[np.ix_(free, free)], eigvals_only=True)
    np.testing.assert_allclose(blade.natural_frequencies_hz, np.sqrt(lam[:8]) / (2 * np.pi), rtol=1e-9)
    # Cauchy interlacing, 6 DOF added to the 33 modal ones: f_k <= f_k(clamped) <= f_(k+6)
    clamped = np.sqrt(lam_mm) / (2 * np.pi)
    assert np.all(blade.natural_frequencies_hz <= clamped[:8] * (1 + 1e-12))
    assert np.all(blade.natural_frequencies_hz[6:] >= clamped[:2] * (1 - 1e-12))


def nastran_eigenvalue_table(path, title="(AFTER AUGMENTATION OF RESIDUAL VECTORS)"):
    """The rows (mode, eigenvalue, cycles) of the REAL EIGENVALUES table under ``title`` of a
    Nastran listing (.f06/.out), as printed: the numbers and their strings. A table continued on
    the next pages (the title repeated) is one table; a row of mode 1 starts a new one."""
    rows, inside = [], False
    for line in Path(path).read_text(errors="replace").splitlines():
        if "R E A L   E I G E N V A L U E S" in line:
            inside = False
        if title in line:
            inside = True
            continue
        fields = line.split()
        if inside and len(fields) == 7 and fields[0].isdigit() and fields[1].isdigit():
            if fields[0] == "1":
                rows = []
            rows.append((int(fields[0]), fields[2], fields[4]))
        elif inside and rows and line.startswith("1"):     # the next page ends the table
            inside = False
    return rows


def half_unit(printed: str) -> float:
    """Half a unit of the last printed digit of a number printed as d.ddddddE+xx."""
    mantissa, exponent = printed.upper().split("E")
    return 0.5 * 10.0 ** (int(exponent) - len(mantissa.split(".")[1]))


def test_nastran_extseout_output4_gives_the_frequencies_nastran_printed():
    """NX Nastran 9.1 EXTSEOUT(MATOP4=...) of a Craig-Bampton component (binary OUTPUT4, KXX and
    MXX: 4 boundary grids x 6 DOF, rows 1-24, then 22 modal coordinates) beside the listing of
    the same run. With the boundary clamped, the blade read from the file has the fixed-interface
    eigenvalues that run printed (16 modes and 6 residual vectors, the table after augmentation).

    Bounds: the eigenvalues lambda agree with the printed EIGENVALUE column to half a unit of its
    7th digit. Nastran keeps eigenvalues in single precision (every modal stiffness in the file is
    a float32 number) and prints CYCLES computed in single precision from them: the blade's
    frequencies sqrt(lambda)/2 pi (double precision) agree with the CYCLES column to half a unit
    of its last digit plus three float32 roundings (2 pi, the square root, the division: 3 x 2^-24
    relative), and the same sums in float32 print exactly Nastran's digits."""
    table = nastran_eigenvalue_table(DATA / "outboard.out")
    assert [r[0] for r in table] == list(range(1, 23))
    fe = read_fe_matrices(DATA / "outboard.op4")
    assert fe.names == ("MXX", "KXX") and fe.n == 46 and fe.labels is None
    K, M = fe.stiffness.toarray(), fe.mass.toarray()
    lam = scipy.linalg.eigh(K[24:, 24:], M[24:, 24:], eigvals_only=True)
    printed_lam = np.array([float(r[1]) for r in table])
    assert np.all(np.abs(lam - printed_lam) <= [half_unit(r[1]) for r in table])
    q = np.diag(K)[24:]
    assert np.array_equal(q.astype(np.float32).astype(float), q)         # the file holds float32 eigenvalues

    points = {p: (0.0, 0.0, 0.0) for p in ("OL", "OR", "tip", "excitation")}
    blade = ModalBlade.from_file(DATA / "outboard.op4", dof_map={p: range(25, 31) for p in points}, points=points,
                                 n_modes=22, damping_ratios=0.01, fixed_dofs=range(1, 25))
    cycles = np.array([float(r[2]) for r in table])
    bound = np.array([half_unit(r[2]) for r in table]) + 3 * 2.0**-24 * cycles
    assert np.all(np.abs(blade.natural_frequencies_hz - cycles) <= bound)
    single = np.sqrt(q.astype(np.float32)) / np.float32(2 * np.pi)
    assert [f"{float(f):.6E}" for f in single] == [r[2] for r in table]


def test_nastran_punch_dmig_gives_the_frequencies_nastran_printed():
    """MSC Nastran 2013 SOL 103 of a free-free beam (4 CBAR, a CONM2, coupled mass; GRDSET
    leaves T3 and R1 of grids 1-5, SUPORT on grid 3): the deck's PARAM,EXTOUT (matrixpch in
    test_case.bdf) punched KAAX and MAAX (test_case.pch, 10 x 10, 10 significant digits) and a
    run of the same deck without it printed the REAL EIGENVALUES table (test_case.f06, Givens,
    7 digits; ExportNastranKM's README: comment out PARAM,EXTOUT for the modes run). The eigenvalues of the file's
    (K, M), with no further boundary condition, are the printed ones.

    Bounds: each eigenvalue agrees with its print to half a unit of the 7th digit (the two
    rigid-body modes of the SUPORT Nastran prints as exactly 0.0) plus what the punch's rounding
    to 10 digits (|dK_ij| <= 5e-10 |K_ij|, the same for M) can move it, to first order
    5e-10 (|phi|'|K||phi| + lambda |phi|'|M||phi|) for the mass-normalised mode phi (up to
    5.7e-8 relative for mode 3, twice its half unit; 4e-9 for mode 7), plus eigh's n eps lambda_max.
    The CYCLES column: the same relative bound plus half a unit of its last digit and three
    float32 roundings, as in the EXTSEOUT test."""
    table = nastran_eigenvalue_table(DATA / "test_case.f06", title="R E A L   E I G E N V A L U E S")
    assert [r[0] for r in table] == list(range(1, 11))
    fe = read_fe_matrices(DATA / "test_case.pch")
    assert fe.names == ("MAAX", "KAAX") and fe.n == 10
    assert fe.labels.tolist() == [[g, c] for g in range(1, 6) for c in (3, 4)]
    K, M = fe.stiffness.toarray(), fe.mass.toarray()
    lam, phi = scipy.linalg.eigh(K, M)
    assert [r[1] for r in table[:2]] == ["0.0", "0.0"]
    printed = np.array([float(r[1]) for r in table])
    rounding = 5e-10 * (np.einsum("ik,ij,jk->k", abs(phi), abs(K), abs(phi))
                        + lam * np.einsum("ik,ij,jk->k", abs(phi), abs(M), abs(phi)))
    half = np.array([half_unit(r[1]) if "E" in r[1] else 0.0 for r in table])
    assert np.all(np.abs(lam - printed) <= half + rounding + 10 * np.finfo(float).eps * lam[-1])
    cycles = np.array([float(r[2]) for r in table[2:]])
    bound = (np.array([half_unit(r[2]) for r in table[2:]])
             + (3 * 2.0**-24 + rounding[2:] / lam[2:]) * cycles)
    assert np.all(np.abs(np.sqrt(lam[2:]) / (2 * np.pi) - cycles) <= bound)


def test_matlab_file_of_nastran_system_matrices_gives_the_frequencies_nastran_printed():
    """pyyeti's nas2cam.mat: MAT-file v5 written by Yeti (db('save'), pyyeti's
    mk_nas2cam_mat.y) from what NX Nastran 9's NAS2CAM DMAP wrote in the SEMFREQ run
    assemble.dat (inboard and outboard external superelements on residual SE 0); struct nas with
    kaa.k0, maa.k0 the residual's a-set (54 DOF). assemble.out is that run's listing: its REAL
    EIGENVALUES table of SE 0 holds all 54 modes, the first six rigid-body modes (AUTOSUP).

    Bounds: NX keeps eigenvalues in single precision (the file's own nas.lambda.k0 holds float32
    numbers), so an elastic eigenvalue of the file's (K, M) agrees with the printed one to half
    a unit of its 7th digit plus one float32 rounding (2^-24 relative) plus eigh's n eps
    lambda_max; the CYCLES column to half a unit plus 3.5 float32 roundings relative (the
    rounding of lambda halved by the square root, and 2 pi, the square root, the division). The
    rigid-body eigenvalues, printed and computed, are rounding noise below n eps lambda_max."""
    table = nastran_eigenvalue_table(DATA / "assemble.out", title="(BEFORE AUGMENTATION OF RESIDUAL VECTORS)")
    assert [r[0] for r in table] == list(range(1, 55))
    fe = read_fe_matrices(DATA / "nas2cam.mat", mass="nas.maa.k0", stiffness="nas.kaa.k0")
    assert fe.names == ("nas.maa.k0", "nas.kaa.k0") and fe.n == 54 and fe.labels is None
    K, M = fe.stiffness.toarray(), fe.mass.toarray()
    lam = scipy.linalg.eigh(K, M, eigvals_only=True)
    noise = 54 * np.finfo(float).eps * lam[-1]
    printed = np.array([float(r[1]) for r in table])
    assert np.all(np.abs(lam[:6]) <= noise) and np.all(np.abs(printed[:6]) <= noise)
    half = np.array([half_unit(r[1]) for r in table[6:]])
    assert np.all(np.abs(lam[6:] - printed[6:]) <= half + 2.0**-24 * lam[6:] + noise)
    cycles = np.array([float(r[2]) for r in table[6:]])
    bound = np.array([half_unit(r[2]) for r in table[6:]]) + 3.5 * 2.0**-24 * cycles
    assert np.all(np.abs(np.sqrt(lam[6:]) / (2 * np.pi) - cycles) <= bound)
    own = read_matlab(DATA / "nas2cam.mat")["nas.lambda.k0"].ravel()
    assert np.array_equal(own.astype(np.float32).astype(float), own)     # single precision


def test_matlab_file_craig_bampton_blade_gives_the_frequencies_nastran_printed():
    """The same nas2cam.mat holds the outboard superelement's KAA, MAA (nas.kaa.k101,
    nas.maa.k101): the Craig-Bampton component of outboard.op4, rows ordered as nas.uset.k101
    says, the 22 modal coordinates (SPOINTs 1995001-1995022) first, then grids 3, 11, 19, 27 x 6.
    A blade read from the MAT-file with those grids clamped has the fixed-interface frequencies
    the outboard run printed (outboard.out), with the bounds of the EXTSEOUT OUTPUT4 test: the
    eigenvalues to half a unit of the 7th digit, the CYCLES column plus three float32 roundings."""
    table = nastran_eigenvalue_table(DATA / "outboard.out")
    uset = read_matlab(DATA / "nas2cam.mat")["nas.uset.k101"]
    assert list(uset[:22, 0]) == list(range(1995001, 1995023)) and not uset[:22, 1].any()
    assert uset[22:, :2].tolist() == [[g, c] for g in (3, 11, 19, 27) for c in range(1, 7)]
    fe = read_fe_matrices(DATA / "nas2cam.mat", mass="nas.maa.k101", stiffness="nas.kaa.k101")
    K, M = fe.stiffness.toarray(), fe.mass.toarray()
    lam = scipy.linalg.eigh(K[:22, :22], M[:22, :22], eigvals_only=True)
    assert np.all(np.abs(lam - [float(r[1]) for r in table]) <= [half_unit(r[1]) for r in table])
    points = {p: (0.0, 0.0, 0.0) for p in ("OL", "OR", "tip", "excitation")}
    blade = ModalBlade.from_file(DATA / "nas2cam.mat", mass="nas.maa.k101", stiffness="nas.kaa.k101",
                                 dof_map={p: range(1, 7) for p in points}, points=points, n_modes=22,
                                 damping_ratios=0.01, fixed_dofs=range(23, 47))
    cycles = np.array([float(r[2]) for r in table])
    bound = np.array([half_unit(r[2]) for r in table]) + 3 * 2.0**-24 * cycles
    assert np.all(np.abs(blade.natural_frequencies_hz - cycles) <= bound)


def test_matlab_struct_fields_are_named_as_matlab_writes_them(tmp_path):
    """A scalar struct's fields (at any depth) are variables "struct.field", in v5 files
    (scipy.io.savemat writes a dict as a struct) and in v7.3 (a struct is an HDF5 group)."""
    M, K, _, _ = reference_matrices()
    path = tmp_path / "v5.mat"
    scipy.io.savemat(path, {"FEM": {"K": K, "M": M, "info": {"n": 3.0}}})
    assert sorted(read_matlab(path)) == ["FEM.K", "FEM.M", "FEM.info.n"]
    fe = read_fe_matrices(path, mass="FEM.M", stiffness="FEM.K")
    np.testing.assert_array_equal(fe.stiffness.toarray(), K)
    with pytest.raises(ValueError, match=r"no matrix named 'FEM\.X' \(mass\); the file holds \['FEM\.K'"):
        read_fe_matrices(path, mass="FEM.X", stiffness="FEM.K")
    h5py = pytest.importorskip("h5py")
    path = tmp_path / "v73.mat"
    with h5py.File(path, "w", userblock_size=512) as f:
        g = f.create_group("FEM")
        g.attrs["MATLAB_class"] = np.bytes_("struct")
        g["K"], g["M"] = K.T, M.T                       # MATLAB stores column-major
    fe = read_fe_matrices(path, mass="FEM.M", stiffness="FEM.K")
    np.testing.assert_array_equal(fe.mass.toarray(), M)


def test_nastran_64bit_binary_output4_equals_its_text_twin():
    """MSC Nastran 2007 run with 8-byte integers (mode=i8) wrote the same four matrices (one of
    10 000 001 columns) as text (header NCOL, NROW in 16 characters: format ...|I16) and as
    binary in the 64-bit layout (48-byte headers, 8-byte integers and reals), dense, sparse and
    sparse 'bigmat': the binary files give the text file's numbers exactly (16 digits carry a
    double exactly)."""
    text = read_op4(DATA / "nas_large_dim_bigmat_ascii.op4")
    assert sorted(text) == ["MATD", "MATD21", "MATD22A", "MATDT"]
    assert text["MATD"][1:3] == (19, 10000001) and text["MATDT"][1:3] == (10000001, 19)
    for layout in ("bigmat", "nonbigmat", "dense"):
        binary = read_op4(DATA / f"nas_large_dim_{layout}_binary.op4")
        assert (DATA / f"nas_large_dim_{layout}_binary.op4").read_bytes()[:4] == struct.pack("<i", 48)
        assert sorted(binary) == sorted(text)
        for name, (a, nra, nca, _) in text.items():
            b, nrb, ncb, _ = binary[name]
            assert (nra, nca) == (nrb, ncb)
            ka = sorted(zip(a.cols, a.rows, a.vals))
            kb = sorted(zip(b.cols, b.rows, b.vals))
            assert ka == kb and len(ka) > 0


def test_nastran_64bit_big_endian_binary_output4():
    """MSC Nastran (mode=i8) read the text file rd.op4 and wrote its matrices big-endian in the
    64-bit binary layout (rdbin.op4, a dense 5 x 6, an empty 10 x 19 and a 1 x 1): the same numbers."""
    text, binary = read_op4(DATA / "rd.op4"), read_op4(DATA / "rdbin.op4")
    assert (DATA / "rdbin.op4").read_bytes()[:4] == struct.pack(">i", 48)
    assert sorted(text) == sorted(binary) == ["R1", "R2", "R3"]
    for name in text:
        (a, nra, nca, _), (b, nrb, ncb, _) = text[name], binary[name]
        assert (nra, nca) == (nrb, ncb)
        assert sorted(zip(a.cols, a.rows, a.vals)) == sorted(zip(b.cols, b.rows, b.vals))
    assert text["R1"][1:3] == (5, 6) and len(text["R1"][0].vals) == 20 and len(text["R2"][0].vals) == 0


def test_abaqus_matrix_generate_beam_blade():
    """Abaqus *MATRIX GENERATE of one B33 beam element (nodes 1, 2 and internal node -1;
    MATRIX INPUT lines, lower triangle): the file's values land at (node, DOF) and the blade
    clamped at node 1 has scipy's frequencies on the values read here with numpy."""
    fe = read_fe_matrices(DATA / "model_STIF1.mtx")
    assert fe.names == ("model_MASS1.mtx", "model_STIF1.mtx")
    labels = [tuple(lab) for lab in fe.labels.tolist()]
    assert labels == [(-1, 1), (-1, 2)] + [(n, d) for n in (1, 2) for d in range(1, 7)]
    raw = {}
    for which in ("MASS", "STIF"):
        A = np.zeros((14, 14))
        for a, b, c, d, v in np.loadtxt(DATA / f"model_{which}1.mtx", delimiter=","):
            i, j = labels.index((int(a), int(b))), labels.index((int(c), int(d)))
            A[i, j] = A[j, i] = v
        raw[which] = A
    np.testing.assert_array_equal(fe.mass.toarray(), raw["MASS"])
    np.testing.assert_array_equal(fe.stiffness.toarray(), raw["STIF"])

    points = {p: (0.0, 0.0, 3.0) for p in ("OL", "OR", "tip", "excitation")}
    blade = ModalBlade.from_file(DATA / "model_MASS1.mtx", dof_map={p: 2 for p in points}, points=points,
                                 n_modes=6, damping_ratios=0.0, fixed_dofs=[1])
    free = [labels.index(lab) for lab in labels if lab[0] != 1]
    lam = scipy.linalg.eigh(raw["STIF"][np.ix_(free, free)], raw["MASS"][np.ix_(free, free)], eigvals_only=True)
    np.testing.assert_allclose(blade.natural_frequencies_hz, np.sqrt(lam[:6]) / (2 * np.pi), rtol=1e-9)


def test_matlab_v5_file_from_tmdsimpy():
    """tmdsimpy's 3-DOF test system (MATLAB 5.0 MAT-file): M and K as MATLAB wrote them."""
    data = scipy.io.loadmat(DATA / "duffing_3DOF.mat")
    fe = read_fe_matrices(DATA / "duffing_3DOF.mat")
    assert fe.names == ("M", "K") and fe.labels is None
    np.testing.assert_array_equal(fe.mass.toarray(), data["M"])
    np.testing.assert_array_equal(fe.stiffness.toarray(), data["K"])


# ---------------------------------------------------------------------------------------
# the reference blade's matrices written in every format
# ---------------------------------------------------------------------------------------
def reference_matrices():
    g = reference_blade_geometry()
    modes = beam_modes(g)
    n = modes.mass.shape[0]
    assert n == 6 * (modes.n_nodes - 1)                   # node k >= 1 at rows 6k-6 .. 6k-1
    nodes = {"platform": modes.platform_node, "tip": modes.n_nodes - 1, "excitation": modes.n_nodes - 1}
    points = {p: g.points()[p] for p in ("OL", "OR", "platform", "tip", "excitation")}
    return modes.mass, modes.stiffness, nodes, points


LINKS = {"OL": "platform", "OR": "platform"}


def write_op4_text(path, matrices):
    with open(path, "w") as fh:
        for name, A in matrices.items():
            n = A.shape[0]
            fh.write(f"{n:8d}{n:8d}{6:8d}{2:8d}{name:<8s}1P,3E26.17\n")
            for j in range(n):
                col = A[:, j]
                nz = np.flatnonzero(col)
                if nz.size == 0:
                    continue
                lo, hi = nz[0], nz[-1] + 1
                fh.write(f"{j + 1:8d}{lo + 1:8d}{hi - lo:8d}\n")
                values = col[lo:hi]
                for k in range(0, values.size, 3):
                    fh.write("".join(f"{v:26.17E}" for v in values[k:k + 3]) + "\n")
            fh.write(f"{n + 1:8d}{1:8d}{1:8d}\n{1.0:26.17E}\n")


def write_op4_binary(path, matrices, order="<", word=4):
    """Binary OUTPUT4, sparse strings, per the format's description: 4-byte words (a double is
    two) or, as Nastran's 64-bit integer build writes, 8-byte words (48-byte header with the name
    as two words of 4 characters; integers and doubles one 8-byte word each)."""
    i = "i" if word == 4 else "q"
    per_double = 8 // word

    def record(payload):
        return struct.pack(order + "i", len(payload)) + payload + struct.pack(order + "i", len(payload))
    out = b""
    for name, A in matrices.items():
        n = A.shape[0]
        label = f"{name:<8s}".encode() if word == 4 else f"{name[:4]:<8s}{name[4:8]:<8s}".encode()
        out += record(struct.pack(order + "4" + i, n, n, 6, 2) + label)
        for j in range(n):
            words = b""                                   # sparse strings: IS = IROW + 65536 (L + 1)
            nz = np.flatnonzero(A[:, j])
            if nz.size == 0:
                continue
            runs = np.split(nz, np.flatnonzero(np.diff(nz) > 1) + 1)
            for run in runs:
                words += struct.pack(order + i, int(run[0]) + 1 + 65536 * (per_double * run.size + 1))
                words += A[run, j].astype(order + "f8").tobytes()
            out += record(struct.pack(order + "3" + i, j + 1, 0, len(words) // word) + words)
        out += record(struct.pack(order + "3" + i, n + 1, 1, per_double) + np.float64(1.0).astype(order + "f8").tobytes())
    Path(path).write_bytes(out)


def write_dmig(path, matrices):
    """Free-field DMIG (full 17-digit values), upper triangle (IFO = 6), node k >= 1 with
    components 1-6 at rows 6k-6 .. 6k-1."""
    lines = []
    for name, A in matrices.items():
        n = A.shape[0]
        lines.append(f"DMIG,{name},0,6,2,0,,,{n}")
        for j in range(n):
            rows = np.flatnonzero(A[: j + 1, j])
            if rows.size == 0:
                continue
            lines.append(f"DMIG,{name},{j // 6 + 1},{j % 6 + 1},")
            lines += [f"+,{i // 6 + 1},{i % 6 + 1},{float(A[i, j])!r}," for i in rows]
    Path(path).write_text("\n".join(lines) + "\n")


def write_abaqus(path_stif, path_mass, M, K):
    for path, A in ((path_stif, K), (path_mass, M)):
        rows, cols = np.nonzero(np.tril(A))
        Path(path).write_text("".join(f"{i // 6 + 1},{i % 6 + 1}, {j // 6 + 1},{j % 6 + 1}, {float(A[i, j])!r}\n"
                                      for i, j in zip(rows, cols)))


def write_matlab_v73(path, matrices):
    import h5py
    with h5py.File(path, "w", userblock_size=512) as f:
        for name, A in matrices.items():
            f.create_dataset(name, data=A.T)
            f[name].attrs["MATLAB_class"] = np.bytes_("double")
    with open(path, "r+b") as fh:                          # MATLAB's 128-byte text header
        fh.write(b"MATLAB 7.3 MAT-file, written by the bladedamp tests".ljust(116) + b"\x00" * 8 + b"\x00\x02IM")


@pytest.mark.parametrize("fmt", ["op4-text", "op4-binary-le", "op4-binary-be", "op4-binary-64-le", "op4-binary-64-be",
                                 "dmig", "abaqus", "mat-v5", "mat-v73"])
def test_reference_blade_matrices_in_every_format_give_the_same_frf(tmp_path, fmt):
    M, K, nodes, points = reference_matrices()
    direct = ModalBlade.from_matrices(M, K, {p: range(6 * k - 6, 6 * k) for p, k in nodes.items()}, points=points,
                                      n_modes=4, damping_ratios=0.002, rigid_links=LINKS)
    labelled = fmt in ("dmig", "abaqus")
    dof_map = {p: (k if labelled else range(6 * k - 5, 6 * k + 1)) for p, k in nodes.items()}
    if fmt == "op4-text":
        path = tmp_path / "blade.op4"
        write_op4_text(path, {"KAA": K, "MAA": M})
    elif fmt.startswith("op4-binary"):
        path = tmp_path / "blade.op4"
        write_op4_binary(path, {"KAA": K, "MAA": M}, "<" if fmt.endswith("le") else ">", 8 if "-64-" in fmt else 4)
    elif fmt == "dmig":
        path = tmp_path / "blade.pch"
        write_dmig(path, {"KAAX": K, "MAAX": M})
    elif fmt == "abaqus":
        path = tmp_path / "blade_STIF1.mtx"
        write_abaqus(path, tmp_path / "blade_MASS1.mtx", M, K)
    elif fmt == "mat-v5":
        path = tmp_path / "blade.mat"
        scipy.io.savemat(path, {"M": M, "K": K})
    else:
        pytest.importorskip("h5py")
        path = tmp_path / "blade.mat"
        write_matlab_v73(path, {"M": M, "K": K})
    blade = ModalBlade.from_file(path, dof_map=dof_map, points=points, n_modes=4, damping_ratios=0.002,
                                 rigid_links=LINKS)
    f = np.linspace(50.0, 2000.0, 400)
    force = np.array([1.0, 0.5, 0, 0, 0, 0.01])
    a, b = blade.linear_frf(f, force), direct.linear_frf(f, force)
    assert np.abs(a - b).max() <= 1e-10 * np.abs(b).max()
    for p in ("OL", "OR", "tip"):
        b_frf = direct.linear_frf(f, force, response_at=p)
        assert np.abs(blade.linear_frf(f, force, response_at=p) - b_frf).max() <= 1e-10 * np.abs(b_frf).max()


# ---------------------------------------------------------------------------------------
# bad files: one ValueError naming the file, the place and what was expected
# ---------------------------------------------------------------------------------------
POINTS = {p: (0.0, 0.0, 0.0) for p in ("OL", "OR", "tip", "excitation")}


def blade_args(dof_map):
    return dict(dof_map=dof_map, points=POINTS, n_modes=2, damping_ratios=0.01)


def test_truncated_text_output4(tmp_path):
    lines = (DATA / "se_test_n11.op4").read_text().splitlines()
    path = tmp_path / "cut.op4"
    path.write_text("\n".join(lines[:500]) + "\n")
    with pytest.raises(ValueError, match=r"cut\.op4: line 501: the file ends inside matrix KAA \(header at line 1\); expected \d+ more numbers"):
        read_fe_matrices(path)


def test_truncated_binary_output4(tmp_path):
    data = (DATA / "mat_b_s2.op4").read_bytes()
    path = tmp_path / "cut.op4"
    path.write_bytes(data[:1000])
    with pytest.raises(ValueError, match=r"cut\.op4: record \d+ \(byte \d+\): .*expected a complete Fortran"):
        read_op4(path)


def test_bad_64bit_binary_output4(tmp_path):
    """The 64-bit binary layout's bad files: truncated, a 32-bit header after a 64-bit one, a
    string running past its column, a column whose word count disagrees with NW; and a text
    header with |I16 whose wide fields are not numbers. One ValueError each naming the file, the
    record (or line) and what was expected."""
    data = (DATA / "nas_large_dim_bigmat_binary.op4").read_bytes()
    path = tmp_path / "cut.op4"
    path.write_bytes(data[:3000])
    with pytest.raises(ValueError, match=r"cut\.op4: record \d+ \(byte \d+\): length marker \d+ does not match; "
                                         r"expected a complete Fortran unformatted record"):
        read_op4(path)
    M, K, _, _ = reference_matrices()
    write_op4_binary(tmp_path / "a.op4", {"KAA": K}, word=8)
    write_op4_binary(tmp_path / "b.op4", {"MAA": M}, word=4)
    path = tmp_path / "mixed.op4"
    path.write_bytes((tmp_path / "a.op4").read_bytes() + (tmp_path / "b.op4").read_bytes())
    with pytest.raises(ValueError, match=r"mixed\.op4: record \d+: 24 bytes; expected a 48-byte matrix header "
                                         r"\(NCOL, NROW, FORM, TYPE, NAME in 8-byte words"):
        read_op4(path)
    good = bytearray((tmp_path / "a.op4").read_bytes())
    # the first column record: marker (4 bytes), ICOL, IROW, NW (8 bytes each), IS of its first string
    at = 4 + 48 + 4 + 4 + 24
    irow_l = struct.unpack("<q", good[at:at + 8])[0]
    bad = bytearray(good)
    bad[at:at + 8] = struct.pack("<q", irow_l + 65536 * 100)          # a string 100 words longer
    path.write_bytes(bytes(bad))
    with pytest.raises(ValueError, match=r"mixed\.op4: record 2: a string of \d+ words at word 0; expected a "
                                         r"multiple of 1 inside the column's \d+ words"):
        read_op4(path)
    bad = bytearray(good)
    bad[at - 8:at] = struct.pack("<q", struct.unpack("<q", good[at - 8:at])[0] + 1)   # NW one word too many
    path.write_bytes(bytes(bad))
    with pytest.raises(ValueError, match=r"mixed\.op4: record 2: \d+ data words; expected NW = \d+ \(column 1 of "
                                         r"matrix KAA, 8-byte words\)"):
        read_op4(path)
    lines = (DATA / "nas_large_dim_bigmat_ascii.op4").read_text().splitlines()
    k = next(i for i, line in enumerate(lines) if line.endswith("|I16"))
    lines[k] = "   nineteen     " + lines[k][16:]
    path = tmp_path / "wide.op4"
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(ValueError, match=rf"wide\.op4: line {k + 1}: expected a matrix header NCOL, NROW \(16 "
                                         r"characters each: the format ends in \|I16\)"):
        read_op4(path)


def test_wrong_file_type(tmp_path):
    path = tmp_path / "blade.op4"
    path.write_text("mode,frequency_hz\n1,95\n")
    with pytest.raises(ValueError, match=r"blade\.op4: line 1: expected a matrix header"):
        read_fe_matrices(path)
    path = tmp_path / "blade.pch"
    path.write_text("GRID    1               0.      0.      0.\n")
    with pytest.raises(ValueError, match=r"blade\.pch: no DMIG card found; expected"):
        read_fe_matrices(path)
    path = tmp_path / "blade_STIF1.mtx"
    path.write_text("1, 1, 1.0\n1, 2\n")
    with pytest.raises(ValueError, match=r"blade_STIF1\.mtx: line 2: 2 comma-separated fields; expected 3"):
        read_fe_matrices(path, mass="blade_STIF1.mtx")
    path = tmp_path / "blade.mat"
    path.write_bytes(b"not a mat file at all" * 10)
    with pytest.raises(ValueError, match=r"blade\.mat: not a readable MATLAB \.mat file"):
        read_fe_matrices(path)


def test_dof_map_naming_a_node_or_row_not_in_the_file():
    with pytest.raises(ValueError, match=r"dmig\.pch: dof_map\['tip'\] names node 999 component 1, which is not "
                                         r"in the file .*expected a node"):
        ModalBlade.from_file(DATA / "dmig.pch", **blade_args({"OL": (101, (1,)), "OR": (101, (1,)), "tip": 999,
                                                              "excitation": (101, (1,))}))
    with pytest.raises(ValueError, match=r"dmig\.pch: dof_map\['OL'\] names node 101 component 2, which is not in "
                                         r"the file \(node 101 has components \[1\]\)"):
        ModalBlade.from_file(DATA / "dmig.pch", **blade_args({p: 101 for p in POINTS}))
    with pytest.raises(ValueError, match=r"se_test_n11\.op4: dof_map\['tip'\] must be a sequence of row numbers "
                                         r"in \[1, 105\]"):
        ModalBlade.from_file(DATA / "se_test_n11.op4", **blade_args(dict({p: range(1, 7) for p in POINTS},
                                                                         tip=range(101, 107))))
    with pytest.raises(FileNotFoundError, match=r"absent_MASS1\.mtx: no such Abaqus matrix file \(the mass matrix beside"):
        read_fe_matrices(DATA / "model_STIF1.mtx", mass="absent_MASS1.mtx")


def test_unsymmetric_matrix_names_the_line(tmp_path):
    text = (DATA / "model_STIF1.mtx").read_text()
    path = tmp_path / "model_STIF1.mtx"
    path.write_text(text + "-1,1, -1,2, -2.6e6\n")            # the transpose of line 2 (-2.5e6), disagreeing
    (tmp_path / "model_MASS1.mtx").write_text((DATA / "model_MASS1.mtx").read_text())
    with pytest.raises(ValueError, match=r"model_STIF1\.mtx: matrix model_STIF1\.mtx: line \d+: entry \(\d+, \d+\) = "
                                         r".* but its transpose at line \d+ is .*expected a symmetric matrix"):
        read_fe_matrices(path)


def test_indefinite_matrices_name_the_row_or_the_matrices(tmp_path):
    M, K, nodes, points = reference_matrices()
    bad_m = M.copy()
    bad_m[8, 8] = -1.0
    path = tmp_path / "blade.pch"
    write_dmig(path, {"KAAX": K, "MAAX": bad_m})
    dof_map = dict(nodes)
    with pytest.raises(ValueError, match=r"blade\.pch: mass matrix MAAX: row 9 \(node 2, component 3\) has M = -1; "
                                         r"expected a positive diagonal"):
        ModalBlade.from_file(path, dof_map=dof_map, points=points, n_modes=4, damping_ratios=0.0, rigid_links=LINKS)
    bad_k = K - 2.0 * np.abs(K).max() * np.eye(K.shape[0])
    write_dmig(path, {"KAAX": bad_k, "MAAX": M})
    with pytest.raises(ValueError, match=r"blade\.pch: matrices MAAX \(mass\), KAAX \(stiffness\): stiffness must "
                                         r"be positive semi-definite"):
        ModalBlade.from_file(path, dof_map=dof_map, points=points, n_modes=4, damping_ratios=0.0, rigid_links=LINKS)


def test_fe_options_need_an_fe_file_and_an_fe_file_needs_them(tmp_path):
    with pytest.raises(ValueError, match=r"dmig\.pch: an FE matrix file needs \['points', 'n_modes', 'damping_ratios'\]"):
        ModalBlade.from_file(DATA / "dmig.pch", dof_map={"OL": 101})
    path = tmp_path / "blade.csv"
    path.write_text("x\n")
    with pytest.raises(ValueError, match=r"blade\.csv: \['dof_map'\] apply to FE matrix files only"):
        ModalBlade.from_file(path, dof_map={"OL": 1})


# ---------------------------------------------------------------------------------------
# Ansys (the ansys extra)
# ---------------------------------------------------------------------------------------
def test_ansys_full_file_blade():
    """The .full file of a hexahedral beam shipped with ansys-mapdl-reader (MIT; written by
    Ansys): constrained DOF left out, rows labelled (node, 1-3), and the blade's frequencies are
    the ones ansys-mapdl-reader publishes for this file (its examples.load_km, 8 decimals)."""
    pytest.importorskip("ansys.mapdl.reader")
    from ansys.mapdl.reader import examples
    published_hz = [1283.20036921, 1283.20036921, 5781.97486169, 6919.39887714, 6919.39887714, 10172.61497694]
    fe = read_fe_matrices(examples.fullfile)
    assert fe.n == 900 and set(fe.labels[:, 1]) == {1, 2, 3}       # 321 nodes x 3, 21 nodes clamped
    node = int(fe.labels[-1, 0])
    with pytest.warns(UserWarning, match=r"dof_map\['O[LR]'\] has translations only"):   # OL and OR
        blade = ModalBlade.from_file(examples.fullfile, dof_map={p: (node, (1, 2, 3)) for p in POINTS}, points=POINTS,
                                     n_modes=6, damping_ratios=0.001)
    np.testing.assert_allclose(blade.natural_frequencies_hz, published_hz, rtol=1e-9)
    with pytest.raises(ValueError, match=r"file\.full: dof_map\['OL'\] names node 1 component 1, which is not in "
                                         r"the file"):                 # node 1 is clamped
        ModalBlade.from_file(examples.fullfile, **blade_args({p: (1, (1, 2, 3)) for p in POINTS}))


def test_ansys_bad_file(tmp_path):
    pytest.importorskip("ansys.mapdl.reader")
    path = tmp_path / "blade.full"
    path.write_bytes((DATA / "mat_b_s2.op4").read_bytes())
    with pytest.raises(ValueError, match=r"blade\.full: not a readable Ansys \.full file .*expected the \.full file"):
        read_fe_matrices(path)


def test_matrix_names_and_complex_or_rectangular_matrices(tmp_path):
    with pytest.raises(ValueError, match=r"se_test_n11\.op4: no matrix named 'MHH' \(mass\); the file holds \['KAA'"):
        read_fe_matrices(DATA / "se_test_n11.op4", mass="MHH")
    with pytest.raises(ValueError, match=r"mat_t_s2\.op4: matrix RND1CD is complex; expected a real mass or "
                                         r"stiffness matrix"):
        read_fe_matrices(DATA / "mat_t_s2.op4", mass="RND1CD", stiffness="RND1RD")
    with pytest.raises(ValueError, match=r"mat_t_s2\.op4: matrix STRINGS is 30 x 20; expected a square matrix"):
        read_fe_matrices(DATA / "mat_t_s2.op4", mass="EYE10", stiffness="STRINGS")
    with pytest.raises(ValueError, match=r"dmig\.pch: more than one mass matrix among the default names .*name it "
                                         r"with mass="):
        path = tmp_path / "dmig.pch"
        path.write_text((DATA / "dmig.pch").read_text().replace("BAAX", "MAA "))
        read_fe_matrices(path)


def test_unsymmetric_full_storage_output4_names_the_line(tmp_path):
    M, K, _, _ = reference_matrices()
    bad = K.copy()
    bad[3, 0] += 1e-3 * np.abs(K).max()
    path = tmp_path / "blade.op4"
    write_op4_text(path, {"KAA": bad, "MAA": M})
    with pytest.raises(ValueError, match=r"blade\.op4: matrix KAA: line 2: entry \(4, 1\) = .* has no transposed "
                                         r"entry \(1, 4\); expected a symmetric matrix"):   # K[0, 3] = 0
        read_fe_matrices(path)
    bad = K.copy()
    bad[6, 0] *= 1.001                                         # both entries given, disagreeing
    write_op4_text(path, {"KAA": bad, "MAA": M})
    with pytest.raises(ValueError, match=r"blade\.op4: matrix KAA: line \d+: entry \((7, 1|1, 7)\) = .* but its "
                                         r"transpose at line \d+ is .*expected a symmetric matrix"):
        read_fe_matrices(path)


def test_abaqus_d_exponents_and_a_bad_line(tmp_path):
    """The numpy fast path falls back to the line-by-line reading, which reads Fortran D
    exponents and names a bad line."""
    for which in ("STIF", "MASS"):
        text = (DATA / f"model_{which}1.mtx").read_text().replace("e+", "D+").replace("e-", "D-")
        (tmp_path / f"model_{which}1.mtx").write_text(text)
    fe, ref = read_fe_matrices(tmp_path / "model_STIF1.mtx"), read_fe_matrices(DATA / "model_STIF1.mtx")
    np.testing.assert_array_equal(fe.stiffness.toarray(), ref.stiffness.toarray())
    lines = (DATA / "model_MASS1.mtx").read_text().splitlines()
    lines[6] = "1,1, -1,x, 1.0"
    (tmp_path / "model_MASS1.mtx").write_text("\n".join(lines) + "\n")
    with pytest.raises(ValueError, match=r"model_MASS1\.mtx: line 7: expected node, dof, node, dof, value"):
        read_fe_matrices(tmp_path / "model_STIF1.mtx")


def test_dmig_cards_in_a_punch_file_with_result_sections(tmp_path):
    """A punch file also holding result output (a $ header, then data lines) reads the DMIG
    cards only."""
    results = ("$TITLE   = \n$DISPLACEMENTS\n$REAL OUTPUT\n"
               "         1       G      0.000000E+00      0.000000E+00      0.000000E+00       7\n"
               "-CONT-                  0.000000E+00      0.000000E+00      0.000000E+00       8\n")
    path = tmp_path / "mixed.pch"
    path.write_text(results + (DATA / "dmig.pch").read_text() + results)
    fe, ref = read_fe_matrices(path), read_fe_matrices(DATA / "dmig.pch")
    np.testing.assert_array_equal(fe.stiffness.toarray(), ref.stiffness.toarray())
    np.testing.assert_array_equal(fe.labels, ref.labels)


def test_matlab_v73_sparse_matrices(tmp_path):
    """MATLAB v7.3 stores a sparse matrix as a group (data, ir, jc; attribute MATLAB_sparse =
    number of rows), compressed by columns."""
    h5py = pytest.importorskip("h5py")
    M, K, nodes, points = reference_matrices()
    path = tmp_path / "blade.mat"
    with h5py.File(path, "w", userblock_size=512) as f:
        for name, A in (("MAA", M), ("KAA", K)):
            C = scipy.sparse.csc_matrix(A)
            g = f.create_group(name)
            g.attrs["MATLAB_class"] = np.bytes_("double")
            g.attrs["MATLAB_sparse"] = np.uint64(A.shape[0])
            g["data"], g["ir"], g["jc"] = C.data, C.indices.astype(np.uint64), C.indptr.astype(np.uint64)
    fe = read_fe_matrices(path)
    assert fe.names == ("MAA", "KAA")
    np.testing.assert_array_equal(fe.stiffness.toarray(), K)
    np.testing.assert_array_equal(fe.mass.toarray(), M)


def test_a_matrix_name_written_twice_is_read_as_name_2(tmp_path):
    M, K, _, _ = reference_matrices()
    write_op4_text(tmp_path / "a.op4", {"KAA": K, "MAA": M})
    write_op4_text(tmp_path / "b.op4", {"KAA": 2.0 * K})
    path = tmp_path / "both.op4"
    path.write_text((tmp_path / "a.op4").read_text() + (tmp_path / "b.op4").read_text())
    assert sorted(read_op4(path)) == ["KAA", "KAA#2", "MAA"]
    np.testing.assert_array_equal(read_fe_matrices(path).stiffness.toarray(), K)
    np.testing.assert_array_equal(read_fe_matrices(path, stiffness="KAA#2").stiffness.toarray(), 2.0 * K)


# ---------------------------------------------------------------------------------------
# the design file: [blade] modal_file with [blade.fe]
# ---------------------------------------------------------------------------------------
FE_DESIGN = """[blade]
modal_file = "{file}"
n_modes = 4
damping_ratio = 0.002

[blade.fe]
fixed_rows = {fixed}

[blade.fe.platform]
rows = [1, 2, 3, 4, 5, 6]
position_mm = [0.0, 0.0, 50.0]

[blade.fe.OL]
link = "platform"
position_mm = [-12.0, 0.0, 50.0]

[blade.fe.OR]
link = "platform"
position_mm = [12.0, 0.0, 50.0]

[blade.fe.tip]
rows = [1, 2, 3, 4, 5, 6]
position_mm = [0.0, 0.0, 80.0]

[blade.fe.excitation]
rows = [1, 2, 3, 4, 5, 6]
position_mm = [0.0, 0.0, 80.0]
"""


def write_fe_design(tmp_path, text=None):
    (tmp_path / "se.op4").write_bytes((DATA / "se_test_n11.op4").read_bytes())
    path = tmp_path / "design.toml"
    path.write_text(text if text is not None else FE_DESIGN.format(file="se.op4", fixed=list(range(7, 73))))
    return path


def test_design_file_fe_blade_is_from_file_with_the_same_arguments(tmp_path):
    from bladedamp.design import load_design
    design = load_design(write_fe_design(tmp_path))
    points = {"platform": (0, 0, 0.05), "OL": (-0.012, 0, 0.05), "OR": (0.012, 0, 0.05), "tip": (0, 0, 0.08),
              "excitation": (0, 0, 0.08)}
    blade = ModalBlade.from_file(DATA / "se_test_n11.op4", dof_map={p: range(1, 7) for p in ("platform", "tip",
                                                                                          "excitation")},
                                 points=points, n_modes=4, damping_ratios=0.002, fixed_dofs=range(7, 73),
                                 rigid_links={"OL": "platform", "OR": "platform"})
    got = design.disk.blade
    np.testing.assert_array_equal(got.natural_frequencies_hz, blade.natural_frequencies_hz)
    np.testing.assert_array_equal(got.damping_ratios, blade.damping_ratios)
    for p in points:
        np.testing.assert_array_equal(got.mode_shapes[p], blade.mode_shapes[p])
        np.testing.assert_allclose(got.points[p], blade.points[p], rtol=1e-15)


@pytest.mark.parametrize("edit, expected", [
    (lambda t: t.replace('[blade.fe.tip]\nrows = [1, 2, 3, 4, 5, 6]\n', '[blade.fe.tip]\n'),
     r"\[blade\.fe\.tip\] needs exactly one of node, rows or link \(got none\)"),
    (lambda t: t.replace('link = "platform"\nposition_mm = [-12.0', 'link = "platform"\nrows = [1]\nposition_mm = [-12.0'),
     r"\[blade\.fe\.OL\] needs exactly one of node, rows or link \(got rows, link\)"),
    (lambda t: t.replace('rows = [1, 2, 3, 4, 5, 6]\nposition_mm = [0.0, 0.0, 80.0]\n\n[blade.fe.excitation]',
                         'rows = [101, 102, 103, 104, 105, 106]\nposition_mm = [0.0, 0.0, 80.0]\n\n[blade.fe.excitation]'),
     r"modal_file = \"se\.op4\": .*se\.op4: dof_map\['tip'\] must be a sequence of row numbers in \[1, 105\]"),
    (lambda t: t.replace('modal_file = "se.op4"', 'modal_file = "blade.npz"'),
     r"\[blade\.fe\] fixed_rows applies to an FE matrix file as \[blade\] modal_file"),
])
def test_design_file_fe_blade_errors_are_one_line_naming_the_key(tmp_path, edit, expected):
    from bladedamp.design import DesignError, load_design
    text = edit(FE_DESIGN.format(file="se.op4", fixed=list(range(7, 73))))
    with pytest.raises(DesignError, match=expected) as info:
        load_design(write_fe_design(tmp_path, text))
    assert "\n" not in str(info.value)


def test_cli_fe_blade_error_is_one_line_with_exit_code_2(tmp_path):
    import os
    import subprocess
    import sys
    text = FE_DESIGN.format(file="se.op4", fixed=list(range(7, 73))).replace(
        '[blade.fe.tip]\nrows = [1, 2, 3, 4, 5, 6]', '[blade.fe.tip]\nnode = 5')
    path = write_fe_design(tmp_path, text)
    env = dict(os.environ, PYTHONPATH=str(Path(__file__).parents[1]))
    run = subprocess.run([sys.executable, "-m", "bladedamp.cli", "frf", str(path), "--out", str(tmp_path / "out")],
                         capture_output=True, text=True, env=env, timeout=120)
    assert run.returncode == 2
    lines = run.stderr.strip().splitlines()
    assert len(lines) == 1 and "se.op4" in lines[0] and "row numbers" in lines[0], run.stderr


def test_cli_bad_64bit_output4_blade_is_one_line_with_exit_code_2(tmp_path, capsys):
    """A design file whose modal_file is a truncated 64-bit binary OUTPUT4: bladedamp frf stops with
    one line naming the file, the record and what was expected, exit code 2."""
    from conftest import one_error_line

    from bladedamp.cli import main
    M, K, _, _ = reference_matrices()
    write_op4_binary(tmp_path / "whole.op4", {"KAA": K, "MAA": M}, word=8)
    (tmp_path / "se.op4").write_bytes((tmp_path / "whole.op4").read_bytes()[:5100])
    path = tmp_path / "design.toml"
    path.write_text(FE_DESIGN.format(file="se.op4", fixed=[7]))
    assert main(["frf", str(path), "--out", str(tmp_path / "out")]) == 2
    one_error_line(capsys, "se.op4", "record", "expected a complete Fortran unformatted record")


@pytest.mark.parametrize("suffix", ["op4", "pch", "mtx", "mat"])
def test_missing_empty_or_folder_fe_files_are_one_file_read_error(tmp_path, suffix):
    from bladedamp.io import FileReadError, MissingFileError
    with pytest.raises(MissingFileError, match=rf"none_STIF1\.{suffix}: no such finite-element matrix file"):
        read_fe_matrices(tmp_path / f"none_STIF1.{suffix}")
    (tmp_path / f"empty_STIF1.{suffix}").write_bytes(b"")
    (tmp_path / f"empty_MASS1.{suffix}").write_bytes(b"")
    with pytest.raises(FileReadError, match=rf"empty_STIF1\.{suffix}: .*(empty|no matrix|no DMIG|not a readable)"):
        read_fe_matrices(tmp_path / f"empty_STIF1.{suffix}")
    (tmp_path / f"dir.{suffix}").mkdir()
    with pytest.raises(FileReadError, match=rf"dir\.{suffix}: is a folder, not a finite-element matrix file"):
        read_fe_matrices(tmp_path / f"dir.{suffix}")


def test_readme_fe_examples_run_from_the_files_in_the_repository(tmp_path, monkeypatch):
    """The README's section on FE exports: its Python examples run (from the repository's root,
    the Ansys one with the ansys extra) and its design file builds the blade it describes."""
    import re
    import warnings

    from bladedamp.design import load_design
    root = Path(__file__).parents[1]
    text = (root / "README.md").read_text()
    section = text[text.index("### Blades from Nastran, Abaqus, MATLAB and Ansys exports"):
                   text.index("### A solid FE blade from the geometry")]
    blocks = re.findall(r"```python\n(.*?)```", section, re.S)
    assert len(blocks) == 4
    monkeypatch.chdir(root)
    namespace = {}
    for code in blocks:
        if "ansys" in code and not _has_ansys():
            continue
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            exec(compile(code, "README.md", "exec"), namespace)
        assert namespace["blade"].n_modes >= 1
    (toml,) = re.findall(r"```toml\n(.*?)```", section, re.S)
    path = tmp_path / "design.toml"
    path.write_text(toml.replace('modal_file = "tests/', f'modal_file = "{root.as_posix()}/tests/'))
    blade = load_design(path).disk.blade
    assert blade.n_modes == 4 and set(blade.points) >= {"OL", "OR", "tip", "excitation", "platform"}


def _has_ansys():
    try:
        import ansys.mapdl.reader  # noqa: F401
    except ImportError:
        return False
    return True
