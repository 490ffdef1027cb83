#!/usr/bin/env python3
"""Write a copy of a configuration folder whose synthetic person works
nearer the robot.

The person of `perception.yaml` (section perception.synthetic) steps
DISTANCE metres the way they face (`facing_yaw`; the shipped person faces
-x, the robot): their torso and every action's `target` move by
DISTANCE x (cos yaw, sin yaw, 0) in the world frame. Nothing else
changes; the copy leaves out `models/`, so the commands that need the
cell's intent model (`iplan eval cell`, `iplan demo`) train it for the
moved person.

    tools/eval/person_nearer.py --by 0.10 --out /tmp/cell10
    build/bin/iplan eval cell --config-dir /tmp/cell10 ...

How far into the shared space the person works decides whether foresight
can pay at all (docs/benchmarks.md, "How near the person works").

Exit code 2 on bad input (a DISTANCE that is not finite, an OUT that
exists, a perception.yaml without the synthetic person, or with
`more_people`), with the reason on stderr.
"""

import argparse
import math
import os
import re
import shutil
import sys

# A flow sequence of three numbers: "[x, y, z]".
_VEC = r"\[\s*([-+0-9.eE]+)\s*,\s*([-+0-9.eE]+)\s*,\s*([-+0-9.eE]+)\s*\]"


def _fmt(v):
    """A coordinate as the file writes them (m, no trailing noise)."""
    s = f"{round(v, 4) + 0.0:.4f}".rstrip("0")  # + 0.0: no "-0.0"
    return s + "0" if s.endswith(".") else s


def _synthetic_lines(lines):
    """(first, end) line indices of the perception.synthetic block."""
    start = None
    indent = None
    for i, line in enumerate(lines):
        m = re.match(r"^(\s*)synthetic:\s*(#.*)?$", line)
        if start is None and m:
            start, indent = i + 1, len(m.group(1))
            continue
        if start is not None and line.strip() and not line.lstrip().startswith("#"):
            if len(line) - len(line.lstrip()) <= indent:
                return start, i
    if start is None:
        raise ValueError("no 'synthetic:' section")
    return start, len(lines)


def move_person(text, distance):
    """perception.yaml's text with the synthetic person moved; returns
    (text, number of positions moved). Raises ValueError."""
    lines = text.split("\n")
    first, end = _synthetic_lines(lines)
    yaw = None
    for line in lines[first:end]:
        m = re.match(r"^\s*facing_yaw:\s*([-+0-9.eE]+)", line)
        if m:
            yaw = float(m.group(1))
            break
    if yaw is None:
        raise ValueError("the synthetic person has no facing_yaw")
    for line in lines[first:end]:
        m = re.match(r"^\s*more_people:\s*(.*)$", line.partition("#")[0])
        if m and m.group(1).strip() != "[]":
            raise ValueError("more_people is not empty: which way each of them steps is not defined")
    dx, dy = distance * math.cos(yaw), distance * math.sin(yaw)

    def shift(m):
        x, y, z = (float(m.group(k)) for k in (3, 4, 5))
        return f"{m.group(1)}[{_fmt(x + dx)}, {_fmt(y + dy)}, {_fmt(z)}]"

    moved = 0
    torso = 0
    for i in range(first, end):
        code, hash_, comment = lines[i].partition("#")
        code, n = re.subn(r"(\b(torso|target):\s*)" + _VEC, shift, code)
        torso += len(re.findall(r"^\s*torso:", code))
        moved += n
        lines[i] = code + hash_ + comment
    if torso != 1:
        raise ValueError(f"expected one torso position in the synthetic section, found {torso}")
    return "\n".join(lines), moved


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter,
                                 epilog="\n\n".join(__doc__.split("\n\n")[1:]))
    ap.add_argument("--by", type=float, required=True, metavar="DISTANCE",
                    help="m the person steps towards where they face (negative: away)")
    ap.add_argument("--out", required=True, help="the new configuration folder (must not exist)")
    ap.add_argument("--config-dir", default=os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "config"),
                    help="the configuration folder to copy (default: the source tree's config/)")
    a = ap.parse_args(argv)
    try:
        if not math.isfinite(a.by):
            raise ValueError(f"--by must be a finite distance, got {a.by}")
        if os.path.exists(a.out):
            raise ValueError(f"{a.out} exists; give a new folder")
        src = os.path.join(a.config_dir, "perception.yaml")
        with open(src) as f:
            text, moved = move_person(f.read(), a.by)
    except (OSError, ValueError) as e:
        print(f"person_nearer: {e}", file=sys.stderr)
        return 2
    shutil.copytree(a.config_dir, a.out, ignore=shutil.ignore_patterns("models"))
    tmp = os.path.join(a.out, "perception.yaml.tmp")
    with open(tmp, "w") as f:
        f.write(text)
    os.replace(tmp, os.path.join(a.out, "perception.yaml"))
    print(f"{a.out}: the synthetic person {a.by:+.3f} m nearer, {moved} positions moved")
    return 0


if __name__ == "__main__":
    sys.exit(main())
