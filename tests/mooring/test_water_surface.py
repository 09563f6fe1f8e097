"""The water of a MoorDyn file ends at its surface, the plane z = 0, as MoorDyn's (which weighs
each segment's submerged fraction): the part of a line above it hangs at its weight in air.

Reference: a vertical line from a point above the water down to a clump, whose top carries the
clump's weight, the dry part's weight in air and the wet part's weight in water (a free body of
the whole line)."""

import math

import pytest

from vinculo.mooring import parse_moordyn, statics

G, RHO = 9.80665, 1025.0
DIAMETER, MASS_PER_LENGTH, LENGTH, CLUMP = 0.1, 20.0, 30.0, 1000.0

FILE = """a line hanging from above the water through its surface
----------------------- LINE TYPES ------------------------------------------
TypeName   Diam    Mass/m     EA         BA/-zeta    EI         Cd     Ca     CdAx    CaAx
(name)     (m)     (kg/m)     (N)        (N-s/-)     (N-m^2)    (-)    (-)    (-)     (-)
rope       0.1     20.0       1.0e12     -1.0        0          1.2    1.0    0.0     0.0
---------------------- POINTS --------------------------------
ID    Type      X       Y       Z       Mass   Volume  CdA    Ca
(#)   (-)       (m)     (m)     (m)     (kg)   (m^3)   (m^2)  (-)
1     Fixed     0       0       {top}   0      0       0      0
2     Free      0       0       -15     1000   0       0      0
---------------------- LINES ----------------------------------------
ID   LineType   AttachA  AttachB  UnstrLen  NumSegs  LineOutputs
(#)   (name)     (#)      (#)       (m)       (-)     (-)
1     rope       1        2         30        30      -
---------------------- OPTIONS -----------------------------------------
100           WtrDpth
1025.0        WtrDnsty
------------------------- END --------------------------------------
"""


@pytest.mark.parametrize("dry", [10.0, 10.5])
def test_the_line_above_the_surface_has_no_buoyancy(dry):
    # The top 10 m above the water (a node on the surface, wet over half its length) or 10.5 m
    # (the surface midway between two nodes): the lumped nodes then split the line at the
    # surface exactly, and the top force is m_c g + w L_dry + (w - rho g A) L_wet to the
    # stretch of EA = 1e12 N (1e-8 relative; measured 7e-9 at 10 m). Water that fills all
    # space (the model before) gave the dry part its buoyancy: 790 N less at 10 m. The file
    # puts the clump 25 m below the top, the 30 m line slack on one vertical: its initial
    # shape sags sideways (sagging along the chord, it folded onto the vertical and the
    # statics stopped without converging).
    result = statics(parse_moordyn(FILE.format(top=dry)))
    top, clump = (e.force for e in result.ends)
    weight = MASS_PER_LENGTH * G
    buoyancy = RHO * G * math.pi * DIAMETER**2 / 4.0
    expected = CLUMP * G + weight * LENGTH - buoyancy * (LENGTH - dry)
    assert top[2] == pytest.approx(-expected, rel=1e-8)
    assert abs(top[0]) < 1e-9 and abs(top[1]) < 1e-9
    # The clump hangs by the line alone (no volume of its own): the line holds m_c g.
    assert clump[2] == pytest.approx(CLUMP * G, rel=1e-12)
