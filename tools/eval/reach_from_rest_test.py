#!/usr/bin/env python3
"""Tests of reach_from_rest.py on recordings written here, whose answers
are known: a wrist at rest that then accelerates uniformly, and one that
moves at constant velocity all along (no excess), and bad input."""

import math
import os
import subprocess
import sys
import tempfile
import unittest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import reach_from_rest as r  # noqa: E402

RATE = 30.0


def write_csv(path, rows_of_joint):
    """One sequence; rows_of_joint: list of (t, (x, y, z)) for wrist_r."""
    with open(path, "w") as f:
        f.write("sequence,subject,action,frame,time,wrist_r.x,wrist_r.y,wrist_r.z\n")
        for k, (t, p) in enumerate(rows_of_joint):
            f.write(f"s1,h1,reach,{k},{t:.6f},{p[0]:.9f},{p[1]:.9f},{p[2]:.9f}\n")


class ReachFromRestTest(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.TemporaryDirectory()

    def tearDown(self):
        self.dir.cleanup()

    def test_uniform_acceleration_from_rest_gives_half_a_t_squared(self):
        # At rest for 1 s, then a = 2 m/s^2 along x: from the last frame at
        # rest the hand gets a T^2 / 2 = 0.16 m in T = 0.4 s.
        a, start = 2.0, 1.0
        rows = []
        for k in range(int(2.0 * RATE) + 1):
            t = k / RATE
            x = 0.5 * a * max(0.0, t - start) ** 2
            rows.append((t, (0.3 + x, 0.1, 0.8)))
        seqs = {"s1": ([t for t, _ in rows], {"wrist_r": [p for _, p in rows]})}
        times, points = seqs["s1"]
        # At rest below 1 mm/s: the frames before the start only (the
        # velocity window lags, so at 0.1 m/s the first 0.17 s of the
        # motion would count as rest too).
        out = r.excesses(times, points["wrist_r"], 0.4, 0.3, 1e-3)
        at_rest = [e for e, rest, _ in out if rest]
        self.assertEqual(len(at_rest), 23)  # frames 8 to 30: from the first with 80 % of a window (0.27 s) to the start
        self.assertAlmostEqual(max(at_rest), 0.5 * a * 0.4 ** 2, delta=1e-6)
        # With the default 0.1 m/s the lagging window lets the hand be
        # already moving: more than a T^2 / 2.
        lagging = [e for e, rest, _ in r.excesses(times, points["wrist_r"], 0.4, 0.3, 0.1) if rest]
        self.assertGreater(max(lagging), 0.2)

    def test_constant_velocity_has_no_excess_and_is_not_at_rest(self):
        v = 0.5  # m/s along y
        rows = [(k / RATE, (0.3, 0.1 + v * k / RATE, 0.8)) for k in range(61)]
        path = os.path.join(self.dir.name, "cv.csv")
        write_csv(path, rows)
        seqs, joints = r.load(path, ["wrist_r", "hand_r"])
        self.assertEqual(joints, ["wrist_r"])
        times, points = seqs["s1"]
        out = r.excesses(times, points["wrist_r"], 0.4, 0.3, 0.1)
        self.assertGreater(len(out), 20)
        self.assertLess(max(e for e, _, _ in out), 1e-6)
        self.assertFalse(any(rest for _, rest, _ in out))
        self.assertAlmostEqual(max(d for _, _, d in out), v * 0.4, delta=1e-6)

    def test_the_command_prints_percentiles_and_refuses_bad_input(self):
        rows = [(k / RATE, (0.3, 0.1, 0.8)) for k in range(61)]
        path = os.path.join(self.dir.name, "still.csv")
        write_csv(path, rows)
        script = os.path.join(os.path.dirname(os.path.abspath(__file__)), "reach_from_rest.py")
        ok = subprocess.run([sys.executable, script, path], capture_output=True, text=True)
        self.assertEqual(ok.returncode, 0, ok.stderr)
        self.assertIn("excess, at rest:        0.000 0.000 0.000 0.000 0.000", ok.stdout)
        missing = subprocess.run([sys.executable, script, path, "--joints", "knee_l"], capture_output=True, text=True)
        self.assertEqual(missing.returncode, 2)
        self.assertIn("none of the joints", missing.stderr)
        bad = subprocess.run([sys.executable, script, path, "--horizon", "0"], capture_output=True, text=True)
        self.assertEqual(bad.returncode, 2)
        self.assertIn("must be > 0", bad.stderr)


if __name__ == "__main__":
    unittest.main()
