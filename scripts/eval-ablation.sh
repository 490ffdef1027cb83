#!/usr/bin/env bash
# Does anticipation pay in the cell? Runs `iplan demo` for each predictor the
# cell can plan with (model, constant-velocity, constant-position, none) over
# the same task-planner seeds, each run with a fresh Q-table, and prints
# completion time, protective stops and waiting side by side (median and
# range over the runs, and the ratio of medians against `none`).
#   scripts/eval-ablation.sh [RUNS] [EPISODES] [PREDICTORS]
#       defaults: 3 runs, 3 episodes, "model constant-velocity constant-position none"
# Run it on an otherwise idle machine: the figures are times. Environment:
# BUILD (default: build), OUT (default: $BUILD/ablation-eval), DDS
# (cyclonedds or fastdds, default: cyclonedds).
set -euo pipefail
ROOT="$(cd "$(dirname "$0")/.." && pwd)"
BUILD="${BUILD:-$ROOT/build}"
OUT="${OUT:-$BUILD/ablation-eval}"
DDS="${DDS:-cyclonedds}"
RUNS="${1:-3}"
EPISODES="${2:-3}"
PREDICTORS="${3:-model constant-velocity constant-position none}"
IPLAN="$BUILD/bin/iplan"
[ -x "$IPLAN" ] || { echo "missing $IPLAN: build first (scripts/setup.sh)" >&2; exit 1; }
[[ $RUNS =~ ^[1-9][0-9]*$ && $EPISODES =~ ^[1-9][0-9]*$ ]] || { echo "usage: $0 [RUNS] [EPISODES] [PREDICTORS]" >&2; exit 2; }
for p in $PREDICTORS; do
  case "$p" in model|constant-velocity|constant-position|none) ;; *) echo "unknown predictor '$p'" >&2; exit 2 ;; esac
done
mkdir -p "$OUT"

for p in $PREDICTORS; do
  for run in $(seq 1 "$RUNS"); do
    cfg="$OUT/config-$p-$run"
    rm -rf "$cfg" "$OUT/state-$p-$run"
    cp -r "$ROOT/config" "$cfg"
    # The same seed for every predictor: paired runs.
    sed -i -E "s/^(  seed: )[0-9]+/\1$run/" "$cfg/supervisor.yaml"
    grep -q "^  seed: $run\b" "$cfg/supervisor.yaml" || { echo "could not set the seed in $cfg/supervisor.yaml" >&2; exit 1; }
    echo "=== $p, run $run of $RUNS: supervisor seed $run, $EPISODES episodes, $DDS"
    "$IPLAN" demo --dds "$DDS" --episodes "$EPISODES" --predictor "$p" --config-dir "$cfg" \
      --state-dir "$OUT/state-$p-$run" --summary "$OUT/$p-$run.json" > "$OUT/$p-$run.txt" 2>&1 ||
      echo "$p run $run exited $? (see $OUT/$p-$run.txt)"
  done
done

python3 - "$OUT" "$RUNS" $PREDICTORS <<'PY'
import json, statistics, sys
out, runs, predictors = sys.argv[1], int(sys.argv[2]), sys.argv[3:]

def load(p, r):
    try:
        return json.load(open(f"{out}/{p}-{r}.json"))
    except (OSError, ValueError):
        return None

def stops(d):
    s = d["protective_stops"]
    return float(len(s)) if isinstance(s, list) else float(s)

def spread(v, fmt="{:.1f}"):
    return "-" if not v else (fmt + " [" + fmt + ", " + fmt + "]").format(statistics.median(v), min(v), max(v))

rows = {}
for p in predictors:
    docs = [d for d in (load(p, r) for r in range(1, runs + 1)) if d]
    mean_time = [statistics.mean(e["completion_time_s"] for e in d["learning_curve"]) for d in docs if d["learning_curve"]]
    waiting = [d["robot_waiting_time_s"] for d in docs]
    rows[p] = {
        "runs": len(docs),
        "completed": [d["episodes_completed"] for d in docs],
        "time": mean_time,
        "stops": [stops(d) for d in docs],
        "waiting": waiting,
        "contacts": [d["true_contacts"] for d in docs],
        "separation": [d["min_separation_m"] for d in docs],
    }

print(f"\n=== ablation: {runs} runs per predictor (paired seeds), median [min, max] over runs")
print(f"{'predictor':<18} {'runs':>4}  {'episode time, s':<22} {'protective stops':<20} {'waiting, s':<20} {'min separation, m':<24} contacts")
for p, r in rows.items():
    print(f"{p:<18} {r['runs']:>4}  {spread(r['time']):<22} {spread(r['stops'], '{:.0f}'):<20} {spread(r['waiting']):<20} "
          f"{spread(r['separation'], '{:.3f}'):<24} {r['contacts']}")
if "none" in rows and rows["none"]["time"]:
    base = rows["none"]
    print("\nratio of medians against none (episode time / stops / waiting):")
    for p, r in rows.items():
        if p == "none" or not r["time"]:
            continue
        def ratio(a, b):
            mb = statistics.median(b) if b else 0
            return "-" if not a or mb == 0 else f"{statistics.median(a) / mb:.2f}"
        print(f"  {p:<18} {ratio(r['time'], base['time'])} / {ratio(r['stops'], base['stops'])} / {ratio(r['waiting'], base['waiting'])}")
PY
