#!/usr/bin/env python3
"""Tests of person_nearer.py: the shipped configuration's person moved by
known distances (positions checked to the millimetre, nothing else in the
folder changed), a person facing another way, and bad input."""

import os
import re
import subprocess
import sys
import tempfile
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import person_nearer as pn  # noqa: E402

CONFIG = os.path.join(HERE, "..", "..", "config")
SCRIPT = os.path.join(HERE, "person_nearer.py")


def positions(text):
    """{'torso' or the action's name: (x, y, z)} of perception.yaml's synthetic person."""
    out = {}
    for line in text.split("\n"):
        code = line.partition("#")[0]
        m = re.match(r"^\s*torso:\s*\[([^\]]*)\]", code)
        if m:
            out["torso"] = tuple(float(v) for v in m.group(1).split(","))
        m = re.match(r"^\s*(\w+):\s*\{.*target:\s*\[([^\]]*)\]", code)
        if m:
            out[m.group(1)] = tuple(float(v) for v in m.group(2).split(","))
    return out


class PersonNearerTest(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.TemporaryDirectory()
        with open(os.path.join(CONFIG, "perception.yaml")) as f:
            self.shipped = f.read()

    def tearDown(self):
        self.dir.cleanup()

    def run_tool(self, *args):
        return subprocess.run([sys.executable, SCRIPT, *args], capture_output=True, text=True)

    def test_the_shipped_person_steps_towards_the_robot(self):
        out = os.path.join(self.dir.name, "cell")
        r = self.run_tool("--by", "0.1", "--out", out, "--config-dir", CONFIG)
        self.assertEqual(r.returncode, 0, r.stderr)
        with open(os.path.join(out, "perception.yaml")) as f:
            moved = f.read()
        before, after = positions(self.shipped), positions(moved)
        # The person, their parts-tray reach and their assembly place; the
        # rest motion has no target.
        self.assertEqual(set(before), {"torso", "reach_parts", "assemble"})
        self.assertEqual(set(after), set(before))
        for name, p in before.items():
            # The shipped person faces -x: 0.1 m nearer is x - 0.1.
            self.assertAlmostEqual(after[name][0], p[0] - 0.1, places=3, msg=name)
            self.assertAlmostEqual(after[name][1], p[1], places=3, msg=name)
            self.assertEqual(after[name][2], p[2], msg=name)
        # Only those lines differ; the comments stay.
        diff = [(a, b) for a, b in zip(self.shipped.split("\n"), moved.split("\n")) if a != b]
        self.assertEqual(len(diff), 3)
        for a, b in diff:
            self.assertEqual(a.partition("#")[2], b.partition("#")[2])
        # Every other file is copied unchanged; the cached models are not.
        with open(os.path.join(CONFIG, "trajopt.yaml")) as f, open(os.path.join(out, "trajopt.yaml")) as g:
            self.assertEqual(f.read(), g.read())
        self.assertFalse(os.path.exists(os.path.join(out, "models")))
        self.assertIn("3 positions moved", r.stdout)

    def test_a_person_facing_plus_y_steps_along_plus_y(self):
        text = ("perception:\n  synthetic:\n    torso: [1.0, -0.5, 0.25]  # m\n"
                "    facing_yaw: 1.5707963268\n    actions:\n"
                "      a: {motion: reach, hand: right, target: [0.8, -0.2, 0.1], period: 3.0}\n"
                "    more_people: []  # none\n"
                "  replay:\n    torso: [9.0, 9.0, 9.0]\n")
        moved, n = pn.move_person(text, 0.25)
        self.assertEqual(n, 2)
        self.assertIn("torso: [1.0, -0.25, 0.25]  # m", moved)
        self.assertIn("target: [0.8, 0.05, 0.1]", moved)
        # Outside the synthetic section nothing moves.
        self.assertIn("torso: [9.0, 9.0, 9.0]", moved)

    def test_bad_input_is_refused_with_exit_code_2(self):
        out = os.path.join(self.dir.name, "cell")
        r = self.run_tool("--by", "nan", "--out", out, "--config-dir", CONFIG)
        self.assertEqual(r.returncode, 2)
        self.assertIn("finite", r.stderr)
        self.assertFalse(os.path.exists(out))
        os.mkdir(out)
        r = self.run_tool("--by", "0.1", "--out", out, "--config-dir", CONFIG)
        self.assertEqual(r.returncode, 2)
        self.assertIn("exists", r.stderr)
        empty = os.path.join(self.dir.name, "empty")
        os.mkdir(empty)
        with open(os.path.join(empty, "perception.yaml"), "w") as f:
            f.write("perception:\n  provider: replay\n")
        r = self.run_tool("--by", "0.1", "--out", os.path.join(self.dir.name, "x"), "--config-dir", empty)
        self.assertEqual(r.returncode, 2)
        self.assertIn("synthetic", r.stderr)
        with self.assertRaises(ValueError):
            pn.move_person("perception:\n  synthetic:\n    torso: [1, 0, 0]\n", 0.1)  # no facing_yaw
        with self.assertRaisesRegex(ValueError, "more_people"):
            pn.move_person("perception:\n  synthetic:\n    torso: [1, 0, 0]\n    facing_yaw: 0\n"
                           "    more_people: [{torso: [2, 0, 0], facing_yaw: 1.0}]\n", 0.1)


if __name__ == "__main__":
    unittest.main()
