#!/usr/bin/env bash
# Runs `iplan demo` several times, each with its own task-planner seed and a
# fresh Q-table, and reports the learning curve (completion time per episode:
# median and range over the runs) and the safety and latency figures of
# docs/demo.md. Run it on an otherwise idle machine: the figures are times.
#   scripts/eval-demo.sh [RUNS] [EPISODES]        (defaults: 3 runs, 6 episodes)
# Environment: BUILD (default: build), OUT (default: $BUILD/demo-eval),
# DDS (cyclonedds or fastdds, default: cyclonedds), DEMO_ARGS (more
# arguments of iplan demo, split at spaces, e.g.
# DEMO_ARGS="--robot ../shared/robots/ur5e/ur5e.urdf").
set -euo pipefail
ROOT="$(cd "$(dirname "$0")/.." && pwd)"
BUILD="${BUILD:-$ROOT/build}"
OUT="${OUT:-$BUILD/demo-eval}"
DDS="${DDS:-cyclonedds}"
RUNS="${1:-3}"
EPISODES="${2:-6}"
IPLAN="$BUILD/bin/iplan"
[ -x "$IPLAN" ] || { echo "missing $IPLAN: build first (scripts/setup.sh)" >&2; exit 1; }
[[ $RUNS =~ ^[1-9][0-9]*$ && $EPISODES =~ ^[1-9][0-9]*$ ]] || { echo "usage: $0 [RUNS] [EPISODES]" >&2; exit 2; }
mkdir -p "$OUT"

for run in $(seq 1 "$RUNS"); do
  cfg="$OUT/config-$run"
  rm -rf "$cfg" "$OUT/state-$run"
  cp -r "$ROOT/config" "$cfg"
  # The shipped cell with this run's task-planner seed; the model cache is
  # shared with the source folder's so that only the first run trains.
  sed -i -E "s/^(  seed: )[0-9]+/\1$run/" "$cfg/supervisor.yaml"
  grep -q "^  seed: $run\b" "$cfg/supervisor.yaml" || { echo "could not set the seed in $cfg/supervisor.yaml" >&2; exit 1; }
  echo "=== run $run of $RUNS: supervisor seed $run, $EPISODES episodes, $DDS"
  "$IPLAN" demo --dds "$DDS" --episodes "$EPISODES" --config-dir "$cfg" --state-dir "$OUT/state-$run" \
    --summary "$OUT/run-$run.json" ${DEMO_ARGS:-} > "$OUT/run-$run.txt" 2>&1 || echo "run $run exited $? (see $OUT/run-$run.txt)"
  sed -n '/^Summary/,$p' "$OUT/run-$run.txt"
done

python3 - "$OUT" "$RUNS" <<'PY'
import json, statistics, sys
out, runs = sys.argv[1], int(sys.argv[2])
docs = []
for r in range(1, runs + 1):
    try:
        docs.append(json.load(open(f"{out}/run-{r}.json")))
    except (OSError, ValueError) as e:
        print(f"run {r}: no summary ({e})")
if not docs:
    sys.exit(1)

def spread(values, fmt="{:.1f}"):
    if not values:
        return "-"
    return (fmt + " [" + fmt + ", " + fmt + "]").format(statistics.median(values), min(values), max(values))

print(f"\n=== {len(docs)} runs")
n = max(len(d["learning_curve"]) for d in docs)
print("completion time per episode, s: median [min, max] over runs")
for e in range(n):
    times = [d["learning_curve"][e]["completion_time_s"] for d in docs if len(d["learning_curve"]) > e]
    waits = [d["learning_curve"][e]["waiting_time_s"] for d in docs if len(d["learning_curve"]) > e]
    print(f"  episode {e + 1:2d}: {spread(times)}   waiting {spread(waits)}")
for i, d in enumerate(docs, 1):
    curve = [ep["completion_time_s"] for ep in d["learning_curve"]]
    print(f"  run {i}: " + ", ".join(f"{t:.1f}" for t in curve) + "  last order: " +
          (" ".join(d["learning_curve"][-1]["order"]) if d["learning_curve"] else "-"))
first = [d["learning_curve"][0]["completion_time_s"] for d in docs if d["learning_curve"]]
tail = [statistics.mean(ep["completion_time_s"] for ep in d["learning_curve"][-3:]) for d in docs if d["learning_curve"]]
print(f"first episode {spread(first)} s; mean of the last three {spread(tail)} s")
print(f"episodes completed {[d['episodes_completed'] for d in docs]} of {docs[0]['episodes_requested']}")
print(f"true contacts {[d['true_contacts'] for d in docs]}")
print(f"minimum true separation, m {spread([d['min_separation_m'] for d in docs], '{:.3f}')}")
print(f"maximum bound (executing) {spread([d['max_collision_bound'] for d in docs], '{:.3f}')}")
print(f"protective stops {spread([float(len(d['protective_stops'])) if isinstance(d['protective_stops'], list) else float(d['protective_stops']) for d in docs], '{:.0f}')}")
print(f"latency p50, ms {spread([d['latency_ms']['p50'] for d in docs])}")
print(f"latency p99, ms {spread([d['latency_ms']['p99'] for d in docs])}")
print(f"wall time, s {spread([d['duration_s'] for d in docs], '{:.0f}')}")
PY
