"""The allow-list scan of gmsh ``.geo`` scripts (beamfx.geometry.geo_scan): plain geometry
passes, anything that runs, writes, reads, waits or loops is refused by line and word."""

from pathlib import Path

import pytest

from beamfx.geometry.geo_scan import check_geo

MESHES = Path(__file__).parents[2] / "meshes"

PLAIN = """// a spline centre line with variables, options and names
lc = 0.1; r = 2.5e-1; n_pts = 3;
Mesh.CharacteristicLengthMax = lc;
Geometry.Tolerance = 1e-9;
SetFactory("Built-in");
Point(1) = {0, 0, 0, lc};
Point(2) = {r * Cos(Pi / 4), r * Sin(Pi / 4), .5};
p = newp; Point(p) = {1, 1, Sqrt(2) / 2};
pts[] = {1, 2, p};
Spline(1) = {pts[]};
Physical Curve("centre line") = {1}; /* a block
comment with SystemCall in it */
"""


def test_plain_geometry_passes():
    check_geo(PLAIN)
    check_geo((MESHES / "quarter_circle.geo").read_text())


@pytest.mark.parametrize(
    "text, word",
    [
        ('SystemCall "touch x";', "SystemCall"),
        ('NonBlockingSystemCall "x";', "NonBlockingSystemCall"),
        ('SystemCall = 1;\nSystemCall "x";', "SystemCall"),  # gmsh goes on after the error
        ('Include "other.geo";', "Include"),
        ('Merge "/etc/passwd";', "Merge"),
        ('Save "x.msh";', "Save"),
        ('Printf("%g", 1) > "x.txt";', "Printf"),
        ('CreateDir "x";', "CreateDir"),
        ("Sleep 10;", "Sleep"),
        ("Exit;", "Exit"),
        ("For i In {1:10}\nEndFor", "For"),
        ("If (1)\nEndIf", "If"),
        ("Macro m\nReturn\nCall m;", "Macro"),
        ('General.FileName = "x";', "General.FileName"),
        ('Solver.Executable0 = "sh";', "Solver.Executable0"),
        ("Plugin(Integrate).Run;", "Plugin"),
        ('x = GetValue("ask", 1);', "GetValue"),
        ("R = 1;", "R"),  # a variable starts with a lower-case letter
        ("x = y + 1;", "y"),  # assigned before use
    ],
)
def test_actions_are_refused_by_line_and_word(text, word):
    with pytest.raises(ValueError) as e:
        check_geo("Point(1) = {0, 0, 0};\n" + text)
    assert f"line 2: {word!r} is not allowed" in str(e.value)


@pytest.mark.parametrize("text", ['s = "open', "Point(1) = {0, 0, 0}; $", "x = 1; é = 2;"])
def test_unknown_characters_are_refused(text):
    with pytest.raises(ValueError, match="is not allowed"):
        check_geo(text)
