"""MoorDyn v2 input files: reading (tests/data/moordyn, files MoorDyn itself runs), writing
back (a round trip, and MoorDyn reading the written file to the same result), and bad files
rejected with an error naming the file, the line and the field."""

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest

import vinculo
from vinculo.errors import InvalidInputError, MooringFileError
from vinculo.mooring import format_moordyn, parse_moordyn, read_moordyn, write_moordyn

DATA = Path(__file__).resolve().parent.parent / "data" / "moordyn"
FILES = sorted(DATA.glob("*.txt"))


def test_the_example_files_are_there():
    names = {p.stem for p in FILES}
    assert {"chain_on_seabed", "hanging_line", "bending_line", "taut_line"} <= names


def test_reading_a_file_gives_its_values():
    # The values as written in tests/data/moordyn/chain_on_seabed.txt.
    model = read_moordyn(DATA / "chain_on_seabed.txt")
    chain = model.line_types["chain"]
    assert (chain.diameter, chain.mass_per_length, chain.ea, chain.ba) == (0.137, 126.0, 5e8, -1)
    assert (chain.ei, chain.cd, chain.ca, chain.cdax, chain.caax) == (0, 2.4, 1.0, 1.15, 0.5)
    anchor, fairlead = model.points
    assert anchor.attachment == "fixed" and anchor.position == (-300.0, 0.0, -50.0)
    assert fairlead.attachment == "coupled" and fairlead.position == (0.0, 0.0, -10.0)
    (line,) = model.lines
    assert (line.line_type, line.attach_a, line.attach_b) == ("chain", 1, 2)
    assert (line.unstretched_length, line.segments) == (315.0, 63)
    o = model.options
    assert (o.depth, o.density, o.gravity, o.kbot, o.cbot) == (50.0, 1025.0, 9.80665, 3e6, 3e5)
    assert o.time_step == 5e-4 and o.friction == 0.0
    assert ("TmaxIC", "100.0") in o.settings
    assert model.coupled_points() == [fairlead]
    assert "studless chain" in model.title


def test_defaults_are_moordyns_for_omitted_options():
    # MoorDyn-C's defaults (moordyn.readthedocs.io, "Input Files", Options): g = 9.80665,
    # rho = 1025, kBot = 3e6, cBot = 3e5, FrictionCoefficient 0, FricDamp 200,
    # StatDynFricScale 1.
    o = read_moordyn(DATA / "hanging_line.txt").options
    assert (o.gravity, o.density, o.kbot, o.cbot) == (9.80665, 1025.0, 3e6, 3e5)
    assert (o.friction, o.friction_damping, o.static_dynamic_scale) == (0.0, 200.0, 1.0)


@pytest.mark.parametrize("path", FILES, ids=lambda p: p.stem)
def test_round_trip(path, tmp_path):
    model = read_moordyn(path)
    written = write_moordyn(model, tmp_path / path.name)
    again = read_moordyn(written)
    assert dataclasses.replace(again, path=None) == dataclasses.replace(model, path=None)
    assert format_moordyn(again) == format_moordyn(model)


def test_round_trip_keeps_friction_options_and_outputs():
    text = (DATA / "chain_on_seabed.txt").read_text().replace(
        "------------------------- need this line",
        "0.5  FrictionCoefficient\n150  FricDamp\n1.2  StatDynFricScale\n"
        "---------------------- OUTPUTS ---------\nFAIRTEN1\nANCHTEN1\nEND\n"
        "------------------------- need this line",
    )
    model = parse_moordyn(text)
    assert model.options.friction == 0.5
    assert model.options.friction_damping == 150.0
    assert model.options.static_dynamic_scale == 1.2
    assert model.outputs == ("FAIRTEN1", "ANCHTEN1")
    assert parse_moordyn(format_moordyn(model)) == model


def test_moordyn_reads_the_written_file_to_the_same_state(tmp_path):
    # MoorDyn itself (the peer) runs the original and the rewritten file: the same initial
    # fairlead and anchor forces, to the last digits MoorDyn's initial-condition solve keeps.
    pytest.importorskip("moordyn")
    from vinculo.mooring.peer import run_moordyn

    # A short initial-condition solve (TmaxIC 2 s) keeps the test quick.
    source = tmp_path / "taut.txt"
    source.write_text((DATA / "taut_line.txt").read_text().replace("100.0         TmaxIC",
                                                                   "2.0           TmaxIC"))
    model = read_moordyn(source)
    original = run_moordyn(source, None, 0.1)
    rewritten = run_moordyn(model, None, 0.1)
    np.testing.assert_allclose(rewritten.end_forces, original.end_forces, rtol=1e-12, atol=1e-9)


GOOD = (DATA / "taut_line.txt").read_text()


def _line_of(text: str, needle: str) -> int:
    return next(k for k, line in enumerate(text.splitlines(), start=1) if needle in line)


@pytest.mark.parametrize(
    ("old", "new", "field", "words"),
    [
        ("rope      0.08   8.0", "rope      0.08x  8.0", "Diam", "not a number"),
        ("rope      0.08   8.0     1.0e7  -1.0      0   1.2  1.0  0.01  0.0",
         "rope      0.08   8.0     1.0e7  -1.0      0   1.2  1.0  0.01", "CaAx", "needs 10"),
        ("1.0e7  -1.0", "1.0e7|2.0e7  -1.0", "EA", "not supported"),
        ("1.0e7  -1.0", "ea_table.txt  -1.0", "EA", "no such strain-tension file"),
        ("1.0e7  -1.0      0   1.2  1.0  0.01  0.0",
         "1.0e7  -1.0      0   1.2  1.0  0.01  0.0  0.8", "Cl", "vortex"),
        ("1   rope      1        2", "1   chain     1        2", "LineType", "not a line type"),
        ("1   rope      1        2", "1   rope      1        3", "AttachB", "not in the POINTS"),
        ("1   rope      1        2", "1   rope      R1A      2", "AttachA", "rod ends"),
        ("95.0      20", "95.0      0 ", "NumSegs", "at least 1"),
        ("95.0      20", "-95.0     20", "UnstrLen", "must be > 0"),
        ("2   Coupled", "2   Body1  ", "Attachment", "there is no body 1"),
        ("2   Coupled", "2   Sliding", "Attachment", "not a point attachment"),
        ("2   Coupled", "3   Coupled", "ID", "numbered"),
        ("80.0          WtrDpth", "bathy.txt     WtrDpth", "WtrDpth", "no such seafloor file"),
        ("0             writeLog", "1             WaveKin ", "WaveKin", "only waves summed"),
        ("0             writeLog", "2             Currents", "Currents", "only steady currents"),
        ("0             writeLog", "0.3           fooBar  ", "fooBar", "unknown option"),
        ("1.0e-4        dtM", "-1.0e-4       dtM", "dtM", "must be > 0"),
        # MoorDyn v1's layouts (MoorDyn's docs/inputs.rst), whose columns read as v2's would go
        # to the wrong fields (MoorDyn-C v2 rejects them too).
        ("TypeName  Diam   Mass/m  EA     BA/-zeta  EI  Cd   Ca   CdAx  CaAx",
         "Name Diam MassDen EA BA/-zeta Can Cat Cdn Cdt", "LINE TYPES", "Cd = Cdn"),
        ("ID  Attachment  X       Y    Z      Mass  Volume  CdA  Ca",
         "Node Type X Y Z M V FX FY FZ CdA CA", "POINTS", "without FX FY FZ"),
        ("ID  LineType  AttachA  AttachB  UnstrLen  NumSegs  LineOutputs",
         "Line LineType UnstrLen NumSegs NodeAnch NodeFair Outputs", "LINES",
         "the ends before the length"),
        ("TypeName  Diam   Mass/m  EA     BA/-zeta  EI  Cd   Ca   CdAx  CaAx",
         "1 NTypes", "NTypes", "count line"),
    ],
)
def test_a_bad_file_names_the_file_line_and_field(tmp_path, old, new, field, words):
    assert old in GOOD
    text = GOOD.replace(old, new, 1)
    path = tmp_path / "bad.txt"
    path.write_text(text)
    with pytest.raises(MooringFileError) as info:
        read_moordyn(path)
    error = info.value
    line = _line_of(text, new)
    assert error.file == str(path)
    assert error.line == line
    assert error.field == field
    assert str(error).startswith(f"{path}, line {line}: {field}: ")
    assert words in str(error)
    # Every such error is an InvalidInputError (exit code 2 of the command line).
    assert isinstance(error, InvalidInputError) and isinstance(error, vinculo.VinculoError)


@pytest.mark.parametrize(
    ("section", "what"),
    [
        ("---------------------- RODS ----------------------\nID RodType Attachment Xa Ya Za Xb "
         "Yb Zb NumSegs Outputs\n(#) (-) (-) (m) (m) (m) (m) (m) (m) (-) (-)\n1 can Fixed 0 0 "
         "-10 0 0 -5 4 -\n", "rods"),
        ("---------------------- BODIES ----------------------\nID Attachment X0 Y0 Z0 r0 p0 "
         "y0 Mass CG I Volume CdA Ca\n(#) (-) (m) (m) (m) (deg) (deg) (deg) (kg) (m) (kg-m^2) "
         "(m^3) (m^2) (-)\n1 free 0 0 0 0 0 0 0 0 0 0 0 0\n", "free bodies"),
    ],
)
def test_unsupported_sections_are_rejected_on_their_first_row(section, what):
    text = GOOD.replace("---------------------- POINTS", section + "---------------------- POINTS")
    with pytest.raises(MooringFileError, match=f"{what} are not supported yet") as info:
        parse_moordyn(text, "model.dat")
    assert info.value.line == _line_of(text, section.splitlines()[3])


def test_an_empty_unsupported_section_is_accepted():
    # MoorDyn files often carry empty RODS or BODIES tables: nothing to model, nothing to reject.
    text = GOOD.replace("---------------------- POINTS",
                        "---------------------- BODIES -----\nID Attachment\n(#) (-)\n"
                        "---------------------- POINTS")
    assert parse_moordyn(text).lines == read_moordyn(DATA / "taut_line.txt").lines


def test_a_file_without_lines_is_rejected():
    text = GOOD[: GOOD.index("---------------------- LINES")]
    with pytest.raises(MooringFileError, match="at least one line"):
        parse_moordyn(text, "nolines.txt")


def test_a_missing_file_is_a_mooring_file_error(tmp_path):
    with pytest.raises(MooringFileError, match="cannot read"):
        read_moordyn(tmp_path / "missing.txt")


def test_comments_are_ignored():
    text = GOOD.replace("1.0e7  -1.0", "1.0e7  -1.0  ", 1).replace(
        "80.0          WtrDpth", "80.0          WtrDpth  # the depth at the site")
    assert parse_moordyn(text).options.depth == 80.0
    assert math.isclose(parse_moordyn(text).line_types["rope"].ea, 1e7)


def test_moordyn_reads_the_written_options(tmp_path):
    # The options are written under names MoorDyn-C 2.7 knows (it ignores, with a warning, a
    # name it does not, such as rhoW): a density of 900 kg/m^3 written back changes MoorDyn's
    # fairlead force exactly as the original file's does.
    pytest.importorskip("moordyn")
    from vinculo.mooring.peer import run_moordyn

    base = tmp_path / "base.txt"
    base.write_text((DATA / "taut_line.txt").read_text()
                    .replace("100.0         TmaxIC", "2.0           TmaxIC"))
    source = tmp_path / "light.txt"
    source.write_text(base.read_text()
                      .replace("80.0          WtrDpth", "80.0 WtrDpth\n900.0 rho\n9.81 g"))
    model = read_moordyn(source)
    assert (model.options.density, model.options.gravity) == (900.0, 9.81)
    original = run_moordyn(source, None, 0.1)
    rewritten = run_moordyn(model, None, 0.1)
    default = run_moordyn(base, None, 0.1)
    np.testing.assert_allclose(rewritten.end_forces, original.end_forces, rtol=1e-12, atol=1e-9)
    assert abs(original.end_forces[0, 0, 1, 2] - default.end_forces[0, 0, 1, 2]) > 100.0
