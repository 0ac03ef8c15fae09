"""Unit tests of the peer benchmark's deck writer, output readers and Hertz
fit: `python3 -m unittest discover -s scripts/peers` (no gmsh or ccx
needed; `make bench-peers` runs them first)."""
import math
import os
import tempfile
import unittest

import ccx
import hertz


def two_cubes(flip_top=False):
    """Unit cube `block` at z in [0, 1] under unit cube `ball` at z in [1, 2]
    (sharing no nodes); the upper one numbered upside down if flip_top."""
    nodes = {}
    for layer in range(4):
        z = [0.0, 1.0, 1.0, 2.0][layer]
        for k, (x, y) in enumerate([(0, 0), (1, 0), (1, 1), (0, 1)]):
            nodes[1 + 4 * layer + k] = (float(x), float(y), z)
    lower = [1, 2, 3, 4, 5, 6, 7, 8]
    upper = [9, 10, 11, 12, 13, 14, 15, 16]
    if flip_top:
        upper = upper[4:] + upper[:4]
    return nodes, [(1, "block", lower), (2, "ball", upper)]


def deck(pair=True, flip_top=False):
    nodes, hexes = two_cubes(flip_top)
    surfaces = {"SSLAVE": [[9, 10, 11, 12]], "SMASTER": [[5, 6, 7, 8]]}
    nsets = {"NBOTTOM": [1, 2, 3, 4], "NTOP": list(range(13, 17))}
    return ccx.deck_lines("two cubes", nodes, hexes, ["block", "ball"], nsets, surfaces,
                          ["NBOTTOM, 1, 3, 0.0"], ["NTOP, 3, 3, -0.01"], "NTOP",
                          (1000.0, 0.3), pair=("SSLAVE", "SMASTER", 5e4) if pair else None)


def after(lines, head):
    """The data lines after keyword line `head`, up to the next keyword."""
    i = lines.index(head) + 1
    out = []
    while i < len(lines) and not lines[i].startswith("*"):
        out.append(lines[i])
        i += 1
    return out


class DeckWriter(unittest.TestCase):
    def test_surfaces_are_the_faces_they_name(self):
        lines = deck()
        # Lower cube's top face (nodes 5..8) is C3D8 face S2; the upper
        # cube's bottom (9..12) is S1.
        self.assertEqual(after(lines, "*SURFACE, NAME=SMASTER, TYPE=ELEMENT"), ["1, S2"])
        self.assertEqual(after(lines, "*SURFACE, NAME=SSLAVE, TYPE=ELEMENT"), ["2, S1"])
        self.assertEqual(after(lines, "*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=LINEAR"),
                         ["50000"])
        self.assertEqual(after(lines, "*CONTACT PAIR, INTERACTION=HERTZ, TYPE=SURFACE TO SURFACE"),
                         ["SSLAVE, SMASTER"])

    def test_an_inverted_hex_is_renumbered_and_its_faces_follow(self):
        lines = deck(flip_top=True)
        self.assertEqual(after(lines, "*ELEMENT, TYPE=C3D8, ELSET=EBALL"),
                         ["2, 9, 10, 11, 12, 13, 14, 15, 16"])
        self.assertEqual(after(lines, "*SURFACE, NAME=SSLAVE, TYPE=ELEMENT"), ["2, S1"])

    def test_conditions_sets_and_sections(self):
        lines = deck()
        self.assertEqual(len(after(lines, "*NODE, NSET=NALL")), 16)
        self.assertEqual(after(lines, "*NSET, NSET=NTOP"), ["13, 14, 15, 16"])
        self.assertEqual(after(lines, "*ELASTIC"), ["1000.0, 0.3"])
        self.assertIn("*SOLID SECTION, ELSET=EBLOCK, MATERIAL=STEEL", lines)
        self.assertIn("*SOLID SECTION, ELSET=EBALL, MATERIAL=STEEL", lines)
        self.assertEqual(after(lines, "*BOUNDARY"), ["NBOTTOM, 1, 3, 0.0"])
        step = lines[lines.index("*STEP"):]
        self.assertEqual(after(step, "*BOUNDARY"), ["NTOP, 3, 3, -0.01"])
        self.assertEqual(lines[-1], "*END STEP")

    def test_the_plain_deck_has_no_contact(self):
        lines = deck(pair=False)
        self.assertFalse([ln for ln in lines if "SURFACE" in ln or "CONTACT" in ln])
        self.assertEqual(after(lines, "*NODE PRINT, NSET=NTOP, TOTALS=ONLY"), ["RF"])

    def test_a_facet_that_is_no_face_is_an_error(self):
        nodes, hexes = two_cubes()
        with self.assertRaises(ValueError):
            ccx.deck_lines("bad", nodes, hexes, ["block", "ball"], {}, {"S": [[1, 2, 7, 8]]},
                           [], [], "NALL", pair=("S", "S", 1.0))


class Readers(unittest.TestCase):
    def test_dat_totals_and_sta_iterations(self):
        with tempfile.TemporaryDirectory() as d:
            dat = os.path.join(d, "job.dat")
            with open(dat, "w") as f:
                f.write("\n total force (fx,fy,fz) for set NTOP and time  0.5000000E+00\n\n"
                        "       1.0E+00  2.0E+00 -3.0E+00\n"
                        "\n total force (fx,fy,fz) for set NTOP and time  0.1000000E+01\n\n"
                        "       4.0E+00  5.0E+00 -6.5E+01\n")
            self.assertEqual(ccx.read_dat_total(dat, "NTOP"), [4.0, 5.0, -65.0])
            self.assertIsNone(ccx.read_dat_total(dat, "NBOTTOM"))
            sta = os.path.join(d, "job.sta")
            with open(sta, "w") as f:
                f.write("SUMMARY OF JOB INFORMATION\n"
                        "  STEP      INC     ATT  ITRS     TOT TIME     STEP TIME      INC TIME\n"
                        "     1          1     1     8  0.500000E+00  0.500000E+00  0.500000E+00\n"
                        "     1          2     1     5  0.100000E+01  0.100000E+01  0.500000E+00\n")
            self.assertEqual(ccx.ccx_newton(sta), (13, 2))


class Fit(unittest.TestCase):
    def test_the_fit_recovers_exact_profiles(self):
        p0, w = 27.3, 1.04
        xs = [0.05 * k for k in range(30)]
        line = [(x, 0.0, 0.0) for x in xs]
        ps = [p0 * math.sqrt(max(0.0, 1 - x * x / (w * w))) for x in xs]
        got = hertz.fit_profile(line, ps)
        self.assertAlmostEqual(got[0], p0, places=9)
        self.assertAlmostEqual(got[1], w, places=9)
        # The same radii on a diagonal: only a point contact sees them.
        disc = [(x / math.sqrt(2), x / math.sqrt(2), 0.0) for x in xs]
        got = hertz.fit_profile(disc, ps, point=True)
        self.assertAlmostEqual(got[1], w, places=9)
        self.assertNotAlmostEqual(hertz.fit_profile(disc, ps)[1], w, places=3)

    def test_point_formulas_integrate_to_the_force(self):
        a, p0 = hertz.point(100.0, 10.0, hertz.effective_modulus(1000.0, 0.3))
        self.assertAlmostEqual(2.0 / 3.0 * math.pi * a * a * p0, 100.0, places=10)
        b, p0 = hertz.line(43.0, 10.0, 549.45)
        self.assertAlmostEqual(math.pi * b * p0 / 2.0, 43.0, places=10)


class TetDeck(unittest.TestCase):
    def test_tet10_cells_are_c3d10_and_faces_found_by_corners(self):
        # One tet10 (corners 1..4, mid-edge nodes 5..10 in C3D10 order) and a
        # mirrored copy (corners 1 and 2 swapped) that the writer reverses.
        corners = {1: (0.0, 0.0, 0.0), 2: (1.0, 0.0, 0.0), 3: (0.0, 1.0, 0.0), 4: (0.0, 0.0, 1.0)}
        edges = [(1, 2), (2, 3), (3, 1), (1, 4), (2, 4), (3, 4)]
        nodes = dict(corners)
        for k, (a, b) in enumerate(edges):
            nodes[5 + k] = tuple((corners[a][c] + corners[b][c]) / 2 for c in range(3))
        good = list(range(1, 11))
        bad = [good[k] for k in [0, 2, 1, 3, 6, 5, 4, 7, 9, 8]]
        cells = [(1, "block", good), (2, "ball", bad)]
        bottom = [1, 2, 3, 5, 6, 7]  # the z = 0 face: S1, tri6
        lines = ccx.deck_lines("tets", nodes, cells, ["block", "ball"], {"N": [1]},
                               {"S": [bottom], "M": [bottom]}, [], [], "N",
                               pair=("S", "M", 1.0))
        self.assertEqual(after(lines, "*ELEMENT, TYPE=C3D10, ELSET=EBLOCK"),
                         ["1, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10"])
        self.assertEqual(after(lines, "*ELEMENT, TYPE=C3D10, ELSET=EBALL"),
                         ["2, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10"])
        self.assertEqual(after(lines, "*SURFACE, NAME=S, TYPE=ELEMENT"), ["2, S1"])
        with self.assertRaises(ValueError):
            ccx.deck_lines("tets", nodes, cells, ["block", "ball"], {"N": [1]},
                           {"S": [[1, 2, 5, 6, 7, 8]], "M": [[2, 3, 4]]}, [], [], "N",
                           pair=("S", "M", 1.0))


if __name__ == "__main__":
    unittest.main()
