"""The moored-buoy study: its RAO sweep against the closed-form heave response of a floating
vertical cylinder, its coupled statics against the balance of forces, its case file errors.

Heave of a free-floating vertical cylinder (radius R, draft T, waterplane A = pi R^2) in
deep-water regular waves of amplitude a and frequency omega (k = omega^2 / g), with the loads
of vinculo's floating body (docs/theory/ocean.md): the hydrostatic force of the surface
rho g A eta, and the Froude-Krylov and added-mass share rho (1 + Ca) A of the water's vertical
acceleration -a omega^2 e^{kz} cos(theta) integrated over -T < z < 0, together
rho g A a cos(theta) [e^{-kT} - Ca (1 - e^{-kT})] (omega^2 / k = g). With the restoring
rho g A z and the inertia (m + m_a) z'', m_a = Ca rho A T, the heave RAO is

    |Z / a| = |e^{-kT} - Ca (1 - e^{-kT})| / |1 - (m + m_a) omega^2 / (rho g A)|.
"""

from __future__ import annotations

import dataclasses
import math
import re
from pathlib import Path

import numpy as np
import pytest

from vinculo.errors import InvalidInputError
from vinculo.ocean import Sea, cylinder
from vinculo.ocean import moored_buoy as mb

RHO, G = 1025.0, 9.80665
EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "moored_buoy"


def test_heave_rao_of_a_floating_cylinder_against_the_closed_form():
    radius, draft, ca = 1.0, 2.0, 0.5
    area = math.pi * radius**2
    mass = RHO * area * draft
    # The centre of gravity at half draft, on the still-water equilibrium.
    case = mb.MooredBuoyCase(
        mass=mass, centre=(0.0, 0.0, -draft / 2),
        inertia=np.diag([mass * (3 * radius**2 + 4.0**2) / 12] * 2 + [mass * radius**2 / 2]),
        hull=cylinder(radius, -draft / 2, 3.0 - draft / 2), sea=Sea(depth=math.inf), ca=ca)
    periods = (6.0, 9.0, 14.0)
    table = mb.rao(case, periods=periods, height=0.2, cycles=6)
    for period, heave in zip(periods, table.amplitude[:, 2], strict=True):
        omega = 2 * math.pi / period
        k = omega**2 / G
        decay = math.exp(-k * draft)
        expected = abs(decay - ca * (1 - decay)) / abs(
            1 - (mass + ca * mass) * omega**2 / (RHO * G * area))
        assert heave == pytest.approx(expected, rel=0.01), (period, heave, expected)


def test_moored_statics_balance_buoyancy_weight_and_mooring():
    """At the coupled equilibrium the buoy's buoyancy carries its weight and the vertical pull
    of the lines at its fairleads (the lines' end forces at the fairleads, from the same
    statics): rho g V_submerged = m g + sum F_z (the buoy is a wall-sided cylinder, heeled a
    little by the current: V is pi R^2 times the length of its axis below z = 0)."""
    case = mb.read_case(EXAMPLES / "surface_buoy.toml")
    built = mb.build(case)
    positions = built.statics.positions
    centre = positions[built.body["centre"].index]
    axis = mb._rotation(positions[None], built.body)[0][:, 2]
    keel = centre - 0.8 * axis  # the hull's bottom is 0.8 m below the centre
    buoyancy = RHO * G * math.pi * 1.5**2 * (-keel[2] / axis[2])
    pull = 0.0
    for line, end in zip(built.lines, built.fairleads, strict=True):
        forces = line.end_forces(built.statics)
        pull += -forces[end][0][2]  # the line's force on the fairlead, downwards
    # The current's drag is horizontal; the statics tolerance 1e-9 of the length scale.
    assert buoyancy == pytest.approx(case.mass * G + pull, rel=1e-6)
    assert pull > 0.0


def test_the_moving_mass_is_the_buoys_and_its_lines():
    """The particles that move carry the buoy's mass and the lines' (mass per length times
    unstretched length), less the half segments whose nodes are the fixed anchors: a fairlead,
    a particle that moves with the buoy, carries the half segment at its end, as MoorDyn's
    body takes its points' end-node masses (three_chains.txt: 50 kg/m, 112 m in 20 segments,
    so 140 kg at each fairlead, 420 kg in all, that a fairlead's weight alone would leave out
    of the buoy's inertia)."""
    case = mb.read_case(EXAMPLES / "surface_buoy.toml")
    built = mb.build(case, solve=False)
    system = built.system
    moving = np.asarray(system.masses())[~np.asarray(system.fixed())].sum()
    lines = 3 * 50.0 * 112.0
    anchors = 3 * 0.5 * 50.0 * 112.0 / 20
    # Each point without a mass of its own gets 1e-6 kg (a particle needs one).
    assert moving == pytest.approx(case.mass + lines - anchors, abs=1e-5)


def test_case_file_errors_name_the_file_and_entry(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text('[buoy]\nmass = 100.0\ncentre = [0, 0]\n')
    with pytest.raises(InvalidInputError, match=r"bad.toml \[buoy\]: centre"):
        mb.read_case(bad)
    bad.write_text('[buoy]\nmass = 100.0\ncentre = [0, 0, 0]\ninertia = [1, 1, 1]\n'
                   'hull = [{ kind = "box", radius = 1 }]\n[sea]\ndepth = 10.0\n')
    with pytest.raises(InvalidInputError, match="hull section 1: kind = 'box'"):
        mb.read_case(bad)


def test_cli_runs_the_submerged_buoy_and_writes_its_results(tmp_path, capsys):
    """``vinculo moored-buoy`` on the case study's buoy in an open basin: its static string
    tension is the sphere's net buoyancy, (rho V - m) g = (1000 pi 0.1^3 / 6 - 0.19199) 9.81
    = 3.2531 N (the string's own weight, 1.6e-4 kg, and buoyancy change it by 5e-4 N), and
    the files are written."""
    from vinculo import cli

    out = tmp_path / "out"
    code = cli.main(["moored-buoy", str(EXAMPLES / "submerged_buoy.toml"), "--t-end", "2",
                     "--output", str(out), "--no-progress"])
    assert code == 0
    text = capsys.readouterr().out
    match = re.search(r"fairlead tension ([0-9.]+) N", text)
    assert match and float(match.group(1)) == pytest.approx(3.2531, abs=1e-3)
    for name in ("run.nc", "run.csv", "motions.png"):
        assert (out / name).stat().st_size > 0


def test_cli_rejects_a_bad_case_with_code_2(tmp_path, capsys):
    from vinculo import cli

    bad = tmp_path / "bad.toml"
    bad.write_text("[buoy]\nmass = -1\n")
    assert cli.main(["moored-buoy", str(bad), "--output", str(tmp_path / "o")]) == 2
    assert "bad.toml [buoy]" in capsys.readouterr().err
    assert not (tmp_path / "o").exists()


def test_case_with_a_measured_record_reproduces_it_at_the_buoy(tmp_path):
    # A record of regular waves at the buoy's position, read from the case's CSV: the elevation
    # the run sees there is the record (its Fourier components reproduce its samples).
    t = np.arange(0.0, 40.0, 0.25)
    eta = 0.3 * np.cos(2 * np.pi * t / 8.0) + 0.1 * np.sin(2 * np.pi * t / 5.0)
    np.savetxt(tmp_path / "eta.csv", np.column_stack([t, eta]), delimiter=",",
               header="time,elevation", comments="")
    text = (EXAMPLES / "submerged_buoy.toml").read_text()
    text = text.replace('file = "tether.txt"', f'file = "{EXAMPLES / "tether.txt"}"')
    text = text.replace('waves = { kind = "regular", height = 0.02, period = 1.0 }',
                        'waves = { kind = "record", file = "eta.csv" }\ncurrent = { kind = '
                        '"table", z = [-0.4, 0.0], velocity = [[0.0, 0, 0], [0.02, 0, 0]] }')
    text = text.replace("ramp = 5.0", "ramp = 0.0")
    case_file = tmp_path / "case.toml"
    case_file.write_text(text)
    case = mb.read_case(case_file)
    np.testing.assert_allclose(case.sea.elevation(t), eta - eta.mean(), atol=1e-10)
    assert case.sea.current.kind == "table"


def test_a_mooring_file_with_its_own_current_is_refused(tmp_path):
    # The case's sea is the water of the whole run; a MoorDyn file's Currents 1 would be a
    # second current, silently dropped: refused, named.
    case = mb.read_case(EXAMPLES / "single_line.toml")
    text = case.mooring.read_text().replace(
        "------------------------- need this line", "1  Currents\n---------- need this line", 1)
    (tmp_path / "current_profile.txt").write_text("h\nh\nh\n-100 0.5 0 0\n0 0.5 0 0\n")
    mooring = tmp_path / case.mooring.name
    mooring.write_text(text)
    with pytest.raises(InvalidInputError, match="Currents 1"):
        mb.build(dataclasses.replace(case, mooring=mooring))
