"""The linearised stiffness of a mooring at its coupled points and on a vessel that carries
them (``MooringStatics.stiffness``, ``vessel_stiffness``), against a published matrix and
against finite differences of re-solved equilibria."""

import dataclasses
from pathlib import Path

import numpy as np
import pytest

import vinculo.mooring as mooring
from vinculo.errors import InvalidInputError
from vinculo.mooring.moordyn_file import parse_moordyn

DATA = Path(__file__).resolve().parent.parent / "data" / "moordyn"
OC3 = DATA / "oc3_hywind.txt"


def test_the_oc3_hywind_mooring_has_its_published_stiffness():
    # Reference: the linearised restoring matrix of the OC3-Hywind mooring about the spar's
    # reference point at the still water level (J. Jonkman, "Definition of the Floating System
    # for Phase IV of OC3", NREL/TP-500-47535, 2010, eq. 5-3; docs/theory/references.md),
    # computed there from the quasi-static elastic catenary of the same three lines (the
    # crowfoot's extra yaw stiffness apart). vinculo's 20 lumped-mass segments a line differ
    # from the continuous line by the discretisation: measured, 0.05 to 0.15 % on every
    # entry; 0.5 % holds it, where the moment of the fairlead forces as the fairleads turn
    # (the last term of vessel_stiffness) makes 38 % of roll and pitch and 99 % of yaw.
    statics = mooring.statics(OC3)
    assert statics.coupled_points() == [4, 5, 6]
    k = statics.vessel_stiffness()
    published = {
        (0, 0): 41_180.0, (1, 1): 41_180.0, (2, 2): 11_940.0,  # N/m
        (3, 3): 311_100_000.0, (4, 4): 311_100_000.0, (5, 5): 11_560_000.0,  # N m/rad
        (0, 4): -2_821_000.0, (4, 0): -2_821_000.0,  # N/rad, N m/m
        (1, 3): 2_821_000.0, (3, 1): 2_821_000.0,
    }
    for (i, j), value in published.items():
        assert k[i, j] == pytest.approx(value, rel=5e-3), (i, j, k[i, j])
    # The other entries vanish by the mooring's symmetry (1e-6 of the largest, round-off).
    others = [abs(k[i, j]) for i in range(6) for j in range(6) if (i, j) not in published]
    assert max(others) < 1e-6 * np.abs(k).max()


def _moved(model, particles_ids, displacement):
    """The file with its coupled points moved by ``displacement(position)``."""
    points = tuple(
        dataclasses.replace(p, position=tuple(np.asarray(p.position) + displacement(
            np.asarray(p.position)))) if p.id in particles_ids else p
        for p in model.points)
    return dataclasses.replace(model, points=points)


def _load(model, ids, reference):
    """The mooring's force and moment about ``reference`` on the points ``ids``, re-solved."""
    statics = mooring.statics(model)
    forces = statics.point_forces(ids)
    positions = np.array([model.points[k - 1].position for k in ids])
    return np.concatenate([forces.sum(axis=0),
                           np.cross(positions - reference, forces).sum(axis=0)])


def _rotation(axis, angle):
    """The rotation matrix of ``angle`` (rad) about the unit vector ``axis`` (Rodrigues)."""
    k = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]],
                  [-axis[1], axis[0], 0.0]])
    return np.eye(3) + np.sin(angle) * k + (1.0 - np.cos(angle)) * k @ k


def test_vessel_stiffness_matches_finite_differences_of_rigid_motions():
    # A bridle: two coupled fairleads hold a free point, which a chain holds to an anchor on
    # the seabed, and a third fairlead its own line. The vessel carrying the three fairleads
    # is moved rigidly by +-1 mm and +-1e-5 rad about each axis (rotations about a reference
    # away from the points, which moves with the vessel), the equilibrium re-solved each time,
    # and central differences of the mooring's force and moment on it give each column of the
    # 6 x 6 (K = -d(F, M)/d(u, theta)). Central differences are O(h^2): agreement to 1e-6 of
    # the largest entry (measured 1.1e-9; with the moments about a reference fixed in space
    # under the translations, 3.5e-2). Its blocks on the points are the joint stiffness of the
    # points.
    text = """--------------------- MoorDyn Input File ----------------------
a bridle and a single line
---------------------- LINE TYPES ------------------------------
TypeName Diam Mass/m EA BA/-zeta EI Cd Ca CdAx CaAx
(name) (m) (kg/m) (N) (N-s/-) (N-m^2) (-) (-) (-) (-)
chain 0.08 40.0 2.0e8 -1.0 0 1.2 1.0 0.4 0.5
rope 0.05 5.0 2.0e7 -1.0 0 1.2 1.0 0.4 0.5
---------------------- POINTS ----------------------------------
ID Attachment X Y Z Mass Volume CdA Ca
(#) (-) (m) (m) (m) (kg) (m^3) (m^2) (-)
1 Fixed 180.0 0.0 -60.0 0 0 0 0
2 Free 20.0 0.0 -25.0 0 0 0 0
3 Coupled 4.0 3.0 -8.0 0 0 0 0
4 Coupled 4.0 -3.0 -8.0 0 0 0 0
5 Fixed -150.0 20.0 -60.0 0 0 0 0
6 Coupled -3.0 1.0 -8.0 0 0 0 0
---------------------- LINES -----------------------------------
ID LineType AttachA AttachB UnstrLen NumSegs LineOutputs
(#) (name) (#) (#) (m) (-) (-)
1 chain 1 2 175.0 20 -
2 rope 2 3 22.0 4 -
3 rope 2 4 22.0 4 -
4 chain 5 6 165.0 20 -
---------------------- OPTIONS ---------------------------------
60.0 WtrDpth water depth (m)
------------------------- need this line -----------------------
"""
    model = parse_moordyn(text)
    statics = mooring.statics(model)
    ids = statics.coupled_points()
    assert ids == [3, 4, 6]
    reference = np.array([1.0, -2.0, 5.0])
    k = statics.vessel_stiffness(reference)
    fd = np.zeros((6, 6))
    h_u, h_t = 1e-3, 1e-5
    for j in range(6):
        axis = np.eye(3)[j % 3]
        if j < 3:
            # A translation carries the reference point along: the moments are about the
            # vessel's own point.
            def load(sign, axis=axis):
                shift = sign * h_u * axis
                return _load(_moved(model, ids, lambda x: shift), ids, reference + shift)
            step = h_u
        else:
            def load(sign, axis=axis):
                rotation = _rotation(axis, sign * h_t)
                moved = _moved(model, ids, lambda x: rotation @ (x - reference) + reference - x)
                return _load(moved, ids, reference)
            step = h_t
        fd[:, j] = -(load(1.0) - load(-1.0)) / (2.0 * step)
    scale = np.abs(k).max()
    worst = np.abs(fd - k).max() / scale
    assert worst < 1e-6, (worst, k, fd)
    # The translation block is the sum of the joint stiffness's blocks; the fairleads of the
    # bridle are coupled through it (an off-diagonal block not small), the third is not.
    joint = statics.stiffness()
    blocks = joint.reshape(3, 3, 3, 3).transpose(0, 2, 1, 3)
    np.testing.assert_allclose(k[:3, :3], blocks.sum(axis=(0, 1)), atol=1e-9 * scale)
    assert np.abs(blocks[0, 1]).max() > 0.1 * np.abs(blocks[0, 0]).max()
    assert np.abs(blocks[0, 2]).max() < 1e-9 * np.abs(joint).max()


def test_bad_stiffness_requests_are_refused_naming_the_value():
    statics = mooring.statics(OC3)
    with pytest.raises(InvalidInputError, match="point 7"):
        statics.stiffness([4, 7])
    with pytest.raises(InvalidInputError, match="each point once"):
        statics.stiffness([4, 4])
    with pytest.raises(InvalidInputError, match="reference"):
        statics.vessel_stiffness(reference=(0.0, np.nan, 0.0))
    anchored = mooring.statics(DATA / "hanging_line.txt")
    assert anchored.coupled_points() == [2]
    file = anchored.model.file
    fixed = tuple(dataclasses.replace(p, attachment="fixed") for p in file.points)
    no_coupled = dataclasses.replace(file, points=fixed)
    with pytest.raises(InvalidInputError, match="no coupled"):
        mooring.statics(no_coupled).stiffness()


def test_the_statics_command_prints_and_writes_the_stiffness(tmp_path, capsys):
    # `vinculo mooring statics` writes the API's matrices (the 6 x 6 about --reference, the
    # points' 9 x 9). About a reference d higher the translation block is the same and the
    # coupling blocks follow the rigid-body transformation K_ut(d) = K_ut(0) + K_uu [d] (the
    # points' arms r - d; [d] the matrix of d x): an independent check of the reference's use.
    import csv

    from vinculo import cli

    output = tmp_path / "out"
    code = cli.main(["mooring", "statics", str(OC3), "--output", str(output),
                     "--reference", "0", "0", "-20"])
    assert code == 0
    out = capsys.readouterr().out
    assert "stiffness of the mooring on a vessel carrying points 4, 5, 6, about (0, 0, -20)" in out

    def read(name):
        with (output / name).open() as handle:
            rows = list(csv.reader(handle))
        return rows[0], [row[0] for row in rows[1:]], np.array([r[1:] for r in rows[1:]],
                                                              dtype=float)

    header, names, vessel = read("stiffness.csv")
    assert header == ["row", "x", "y", "z", "rx", "ry", "rz"] and names == header[1:]
    statics = mooring.statics(OC3)
    d = np.array([0.0, 0.0, -20.0])
    np.testing.assert_array_equal(vessel, statics.vessel_stiffness(d))
    at_origin = statics.vessel_stiffness()
    cross = np.array([[0.0, -d[2], d[1]], [d[2], 0.0, -d[0]], [-d[1], d[0], 0.0]])
    scale = np.abs(at_origin[:3, 3:]).max()
    np.testing.assert_allclose(vessel[:3, :3], at_origin[:3, :3], rtol=1e-12)
    np.testing.assert_allclose(vessel[:3, 3:], at_origin[:3, 3:] + at_origin[:3, :3] @ cross,
                               atol=1e-9 * scale)
    header, names, joint = read("point_stiffness.csv")
    assert names == [f"point{p}_{c}" for p in (4, 5, 6) for c in "xyz"]
    np.testing.assert_array_equal(joint, statics.stiffness())


def test_a_bad_reference_is_refused(capsys):
    from vinculo import cli

    with pytest.raises(SystemExit) as info:
        cli.main(["mooring", "statics", str(OC3), "--reference", "0", "nan", "0"])
    assert info.value.code == 2
    assert "argument --reference" in capsys.readouterr().err


def test_a_point_without_a_line_has_no_stiffness_and_the_statics_is_still_written(tmp_path,
                                                                                 capsys):
    # A coupled point that no line holds has no stiffness (its rows of the equilibrium's
    # matrix are empty): the API says so naming the points, and the command still writes the
    # statics, reporting the stiffness as not computed.
    from vinculo import cli
    from vinculo.errors import ConvergenceError

    text = (DATA / "hanging_line.txt").read_text()
    row = "2   Coupled     40.0    0.0  -20.0  0     0       0    0\n"
    assert row in text
    path = tmp_path / "dangling.txt"
    path.write_text(text.replace(row, row + "3   Coupled     10.0    0.0  -5.0  0  0  0  0\n"))
    with pytest.raises(ConvergenceError, match="no finite stiffness at points 2, 3"):
        mooring.statics(path).stiffness()
    output = tmp_path / "out"
    assert cli.main(["mooring", "statics", str(path), "--output", str(output)]) == 0
    out = capsys.readouterr().out
    assert "stiffness at the coupled points not computed: no finite stiffness at points 2, 3" in out
    assert (output / "statics.csv").exists() and not (output / "stiffness.csv").exists()
