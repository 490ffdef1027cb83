#!/usr/bin/env python3
"""How far a recorded hand travels within the robot's reaction and stopping
time beyond what its measured velocity says (issue 29).

ISO/TS 15066 separation monitoring lets the robot come as close as
S_p = v_h (T_r + T_s) + ...; with a measured v_h (a tracked part of the
person, or a skeleton joint) the question is how far the hand can get in
T = T_r + T_s beyond v_h T, above all when it starts from rest. For every
frame t of every sequence and joint: v0 = (p(t) - p(t - window)) / window,
the speed a tracker would report, and the excess
    e(t) = max over 0 < tau <= T of |p(t + tau) - p(t) - v0 tau|,
the distance the hand got from where constant velocity would have put it.
Prints percentiles of e over all frames and over frames at rest
(|v0| < --rest), and of the plain displacement at rest. Tracking errors of
the recordings (OpenPose jumps, Kinect dropouts) count as motion: the high
percentiles are upper bounds.

Reads the shared CSV layout (../shared/data/README.md); standard library only.
"""

import argparse
import bisect
import csv
import math
import sys
from collections import defaultdict


def load(path, joints):
    """{sequence: (times, {joint: [xyz or None]})} for the joints the file has."""
    with open(path, newline="") as f:
        rows = csv.reader(f)
        header = next(rows)
        cols = {j: header.index(j + ".x") for j in joints if j + ".x" in header}
        if not cols:
            raise ValueError(f"{path}: none of the joints {joints} (columns <joint>.x)")
        seqs = defaultdict(lambda: ([], defaultdict(list)))
        for line, row in enumerate(rows, start=2):
            if len(row) != len(header):
                raise ValueError(f"{path}:{line}: {len(row)} fields, the header has {len(header)}")
            times, points = seqs[row[0]]
            times.append(float(row[4]))
            for j, c in cols.items():
                p = (float(row[c]), float(row[c + 1]), float(row[c + 2]))
                points[j].append(p if any(p) else None)  # (0, 0, 0): not detected
    return seqs, sorted(cols)


def excesses(times, pos, horizon, window, rest):
    """(excess, at rest, displacement) for each usable frame of one joint."""
    out = []
    for k, p in enumerate(pos):
        if p is None:
            continue
        kp = bisect.bisect_left(times, times[k] - window)
        if times[k] - times[kp] < 0.8 * window or pos[kp] is None:
            continue
        dt = times[k] - times[kp]
        v0 = [(p[i] - pos[kp][i]) / dt for i in range(3)]
        kf = bisect.bisect_right(times, times[k] + horizon + 1e-9)
        if kf >= len(times) or times[kf - 1] - times[k] < 0.9 * horizon:
            continue  # the recording ends before the horizon
        e = d = 0.0
        for m in range(k + 1, kf):
            if pos[m] is None:
                continue
            tau = times[m] - times[k]
            dp = [pos[m][i] - p[i] for i in range(3)]
            e = max(e, math.dist(dp, [v0[i] * tau for i in range(3)]))
            d = max(d, math.hypot(*dp))
        out.append((e, math.hypot(*v0) < rest, d))
    return out


def percentiles(values, qs):
    v = sorted(values)
    return [v[min(len(v) - 1, int(len(v) * q / 100))] for q in qs] if v else [float("nan")] * len(qs)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter,
                                 epilog="example: tools/eval/reach_from_rest.py ../shared/data/assembly.csv "
                                        "--joints wrist_l,wrist_r")
    ap.add_argument("csv", nargs="+", help="skeleton CSV files (shared layout)")
    ap.add_argument("--joints", default="wrist_l,wrist_r,hand_l,hand_r",
                    help="comma-separated joints; each file uses those it has (default: %(default)s)")
    ap.add_argument("--horizon", type=float, default=0.4, help="s, T = T_r + T_s (default: %(default)s)")
    ap.add_argument("--window", type=float, default=0.3, help="s, velocity window (default: %(default)s)")
    ap.add_argument("--rest", type=float, default=0.1, help="m/s, at rest below this speed (default: %(default)s)")
    a = ap.parse_args()
    if not (a.horizon > 0 and a.window > 0 and a.rest > 0):
        ap.error("--horizon, --window and --rest must be > 0")
    qs = [50, 90, 99, 99.9, 100]
    print(f"T = {a.horizon} s, velocity window {a.window} s, at rest below {a.rest} m/s; "
          f"percentiles {', '.join(str(q) for q in qs)} (m)")
    for path in a.csv:
        try:
            seqs, joints = load(path, a.joints.split(","))
        except (OSError, ValueError) as e:
            print(f"reach_from_rest: {e}", file=sys.stderr)
            return 2
        rows = []
        for times, points in seqs.values():
            for j in joints:
                rows += excesses(times, points[j], a.horizon, a.window, a.rest)
        fmt = lambda v: " ".join(f"{x:.3f}" for x in v)
        at_rest = [r for r in rows if r[1]]
        print(f"{path} [{','.join(joints)}]: {len(rows)} frames, {len(at_rest)} at rest")
        print(f"  excess, all frames:     {fmt(percentiles([r[0] for r in rows], qs))}")
        print(f"  excess, at rest:        {fmt(percentiles([r[0] for r in at_rest], qs))}")
        print(f"  displacement, at rest:  {fmt(percentiles([r[2] for r in at_rest], qs))}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
