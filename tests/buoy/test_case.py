"""The buoy case: derived quantities against the study's table, validation, TOML input."""

import dataclasses
import math
from decimal import Decimal

import numpy as np
import pytest

from vinculo.buoy.case import (
    ASSUMPTIONS,
    PAPER_VALUES,
    BuoyCase,
    SweepSettings,
    load_case,
    load_study,
    load_sweep,
)
from vinculo.errors import InvalidInputError


def test_derived_quantities_match_the_study_table():
    # Reference: the parameter table of the study (docs/guide/buoy-study.md), which quotes
    # m_s = 0.1920 kg, m_f = 0.5236 kg and m_a = 0.2723 kg to four digits for D = 0.1 m.
    case = BuoyCase()
    assert case.radius == 0.05
    assert case.sphere_mass == pytest.approx(0.1920, abs=5e-5)
    assert case.displaced_mass == pytest.approx(0.5236, abs=5e-5)
    assert case.added_mass == pytest.approx(0.2723, abs=5e-5)
    # Closed forms of a sphere: V = pi D^3 / 6, A = pi R^2, I = 2/5 m R^2.
    assert case.volume == pytest.approx(math.pi * 0.1**3 / 6, rel=1e-15)
    assert case.frontal_area == pytest.approx(math.pi * 0.05**2, rel=1e-15)
    assert case.centre_inertia == pytest.approx(0.4 * case.sphere_mass * 0.05**2, rel=1e-15)


def test_pendulum_length_follows_the_attachment():
    # Reference: the study's note that the centre rests 0.21 m above the anchor when the 0.16 m
    # string is tied to the sphere's lowest point, and 0.16 m when it reaches the centre.
    assert BuoyCase().pendulum_length == pytest.approx(0.21, rel=1e-15)
    assert BuoyCase(attachment="centre").pendulum_length == 0.16


def test_assumptions_name_existing_fields_with_reasons():
    # Reference: the study does not give X0, the attachment point or a ramp
    # (docs/guide/buoy-study.md), nor a heavy string or a viscous force; everything else is the
    # paper's table (docs/guide/buoy-study.md, its parameter table), so each field is one or the
    # other, except the tank: its size is the paper's, its being closed (no sloshing) an
    # assumption.
    assert {"amplitude", "attachment", "ramp_periods"} <= set(ASSUMPTIONS)
    names = {field.name for field in dataclasses.fields(BuoyCase)}
    assert set(ASSUMPTIONS) | set(PAPER_VALUES) == names
    assert not set(ASSUMPTIONS) & (set(PAPER_VALUES) - {"tank_size"})
    assert all(len(reason) > 20 for reason in ASSUMPTIONS.values())
    assert BuoyCase.ASSUMPTIONS is ASSUMPTIONS
    paper = {"diameter": 0.1, "sphere_density": 366.69, "fluid_density": 1000.0,
             "string_length": 0.16, "drag_coefficient": 0.22, "added_mass_coefficient": 0.52,
             "gravity": 9.81, "tank_size": (0.38, 0.38, 0.40)}
    assert PAPER_VALUES == paper
    assert all(getattr(BuoyCase(), name) == value for name, value in paper.items())


@pytest.mark.parametrize(
    ("field", "value"),
    [
        ("diameter", 0.0),
        ("diameter", -0.1),
        ("diameter", math.nan),
        ("sphere_density", 0.0),
        ("fluid_density", -1.0),
        ("string_length", 0.0),
        ("amplitude", 0.0),
        ("gravity", -9.81),
        ("drag_coefficient", -0.1),
        ("added_mass_coefficient", -0.5),
        ("ramp_periods", -1.0),
        ("string_mass", -0.01),
        ("attachment", "top"),
        ("string_beads", -1),
        ("string_beads", 2.5),
        ("tank_size", (0.38, 0.38)),
        ("tank_size", (0.38, 0.0, 0.4)),
    ],
)
def test_out_of_domain_field_is_named_with_its_value(field, value):
    with pytest.raises(InvalidInputError) as caught:
        BuoyCase(**{field: value})
    assert caught.value.name == field
    assert field in str(caught.value)
    assert repr(value) in str(caught.value) or str(value) in str(caught.value)


def test_beads_need_mass_and_mass_needs_beads():
    with pytest.raises(InvalidInputError, match="string_mass is 0 but string_beads is 3"):
        BuoyCase(string_beads=3)
    with pytest.raises(InvalidInputError, match="string_beads is 0"):
        BuoyCase(string_mass=0.01)
    # Both together are valid.
    assert BuoyCase(string_beads=3, string_mass=0.01).string_beads == 3


def test_dict_round_trip_reproduces_the_case():
    case = BuoyCase(amplitude=0.004, attachment="centre", string_beads=2, string_mass=0.003)
    data = case.to_dict()
    assert data["tank_size"] == [0.38, 0.38, 0.40]
    assert BuoyCase.from_mapping(data) == case


def test_mapping_with_unknown_key_lists_the_valid_ones():
    with pytest.raises(InvalidInputError) as caught:
        BuoyCase.from_mapping({"amplitud": 0.004}, source="study.toml")
    message = str(caught.value)
    assert "'amplitud'" in message and "study.toml" in message
    assert "amplitude" in message and "string_length" in message
    assert caught.value.name == "amplitud"


@pytest.mark.parametrize(
    ("key", "value"),
    [("amplitude", "5 mm"), ("attachment", 1), ("string_beads", 2.0), ("diameter", True)],
)
def test_mapping_with_wrong_type_is_rejected(key, value):
    with pytest.raises(InvalidInputError) as caught:
        BuoyCase.from_mapping({key: value})
    assert caught.value.name == key
    assert key in str(caught.value)


def test_mapping_accepts_integers_for_lengths():
    # TOML writes 1 for 1.0; the field is stored as a float.
    case = BuoyCase.from_mapping({"gravity": 10})
    assert case.gravity == 10.0 and isinstance(case.gravity, float)


def test_sweep_defaults_and_frequencies():
    sweep = SweepSettings()
    # The grid is linspace's, to round-off, and every point is the decimal number it stands
    # for (reference: exact decimal arithmetic), so sweep.csv shows 0.85, not 0.8500000000000001.
    assert np.allclose(sweep.frequencies, np.linspace(0.5, 1.5, 21), rtol=1e-12, atol=0)
    decimal = [float(Decimal("0.5") + Decimal("0.05") * k) for k in range(21)]
    assert sweep.frequencies.tolist() == decimal
    assert [repr(f) for f in SweepSettings(f_min=0.1, f_max=0.7, count=7).frequencies.tolist()] == [
        "0.1", "0.2", "0.3", "0.4", "0.5", "0.6", "0.7"
    ]
    assert sweep.frequencies[1] - sweep.frequencies[0] == pytest.approx(0.05, rel=1e-12)
    # A run lasts settle + fit periods.
    assert sweep.t_end(0.5) == pytest.approx((30 + 10) / 0.5, rel=1e-15)
    assert SweepSettings(f_min=0.9, f_max=0.9, count=1).frequencies.tolist() == [0.9]


@pytest.mark.parametrize(
    ("changes", "name"),
    [
        ({"count": 0}, "count"),
        ({"f_min": 0.0}, "f_min"),
        ({"f_min": 1.0, "f_max": 0.5}, "f_max"),
        ({"count": 1}, "count"),
        ({"f_min": 1.0, "f_max": 1.0}, "count"),
        ({"dt": 0.0}, "dt"),
        ({"dt": 0.05}, "dt"),
        ({"fit_periods": 0}, "fit_periods"),
        ({"settle_periods": -1.0}, "settle_periods"),
    ],
)
def test_bad_sweep_is_named(changes, name):
    with pytest.raises(InvalidInputError) as caught:
        SweepSettings(**changes)
    assert caught.value.name == name
    assert name in str(caught.value)


def test_empty_frequency_range_says_so():
    with pytest.raises(InvalidInputError, match="a frequency range with no points"):
        SweepSettings(count=0)


def test_toml_file_with_case_and_sweep(tmp_path):
    path = tmp_path / "study.toml"
    path.write_text(
        '[case]\namplitude = 0.004\nattachment = "centre"\ntank_size = [0.4, 0.4, 0.5]\n'
        "\n[sweep]\nf_min = 0.6\nf_max = 1.4\ncount = 17\n",
        encoding="utf-8",
    )
    case, sweep = load_study(path)
    assert case == BuoyCase(amplitude=0.004, attachment="centre", tank_size=(0.4, 0.4, 0.5))
    assert sweep == SweepSettings(f_min=0.6, f_max=1.4, count=17)
    assert load_case(path) == case
    assert load_sweep(path) == sweep


def test_toml_file_without_tables_gives_defaults(tmp_path):
    path = tmp_path / "empty.toml"
    path.write_text("# nothing to change\n", encoding="utf-8")
    assert load_study(path) == (BuoyCase(), SweepSettings())


def test_toml_top_level_case_key_points_to_the_case_table(tmp_path):
    path = tmp_path / "flat.toml"
    path.write_text("amplitude = 0.004\n", encoding="utf-8")
    with pytest.raises(InvalidInputError) as caught:
        load_case(path)
    message = str(caught.value)
    assert "'amplitude'" in message and str(path) in message and "[case]" in message


def test_toml_bad_value_names_the_file(tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text("[case]\ndiameter = -0.1\n", encoding="utf-8")
    with pytest.raises(InvalidInputError) as caught:
        load_case(path)
    assert "diameter" in str(caught.value) and str(path) in str(caught.value)
    assert caught.value.source == str(path)


def test_toml_unknown_sweep_key_names_the_file(tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text("[sweep]\nfmin = 0.4\n", encoding="utf-8")
    with pytest.raises(InvalidInputError) as caught:
        load_sweep(path)
    assert "'fmin'" in str(caught.value) and str(path) in str(caught.value)
    assert "f_min" in str(caught.value)


def test_missing_and_malformed_toml_files(tmp_path):
    missing = tmp_path / "absent.toml"
    with pytest.raises(InvalidInputError, match="does not exist") as caught:
        load_case(missing)
    assert str(missing) in str(caught.value)
    broken = tmp_path / "broken.toml"
    broken.write_text("[case\namplitude = \n", encoding="utf-8")
    with pytest.raises(InvalidInputError, match="not valid TOML") as caught:
        load_case(broken)
    assert str(broken) in str(caught.value)
