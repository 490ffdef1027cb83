#!/usr/bin/env bash
# What DDS Security costs the cell (docs/benchmarks.md, "DDS Security"):
#  1. start-up to the first skeleton: the time from starting
#     `iplan topic echo /iplan/human/skeleton -n 1` (process start,
#     participant, discovery, the handshake when secured, the first sample of
#     a 30 Hz stream) to its exit, with iplan-perception running; RUNS times
#     per vendor, secured and not, alternating;
#  2. end-to-end latency: `iplan demo --episodes 1` secured (its default) and
#     --insecure, DEMO_RUNS times each, alternating: the demo's skeleton-stamp
#     to trajectory latency (p50, p99) and its run time.
# Prints medians and ranges, and the machine's load before and after.
#   scripts/bench-security.sh [RUNS] [DEMO_RUNS]        (defaults: 7, 3)
# Environment: BUILD (default: build), VENDORS (default: "cyclonedds fastdds").
set -euo pipefail
ROOT="$(cd "$(dirname "$0")/.." && pwd)"
BUILD="${BUILD:-$ROOT/build}"
RUNS="${1:-7}"
DEMO_RUNS="${2:-3}"
VENDORS="${VENDORS:-cyclonedds fastdds}"
BIN="$BUILD/bin"
[ -x "$BIN/iplan" ] || { echo "missing $BIN/iplan: build first (scripts/setup.sh)" >&2; exit 1; }
OUT="$(mktemp -d /tmp/iplan-bench-security-XXXXXX)"
trap 'kill $(jobs -p) 2>/dev/null || true; rm -rf "$OUT"' EXIT
"$BIN/iplan" security create-keystore "$OUT/keystore" > /dev/null
echo "load before: $(cut -d' ' -f1-3 /proc/loadavg)"

for vendor in $VENDORS; do
  domain=$((150 + RANDOM % 50))
  "$BIN/iplan-perception" --dds "$vendor" --domain "$domain" --security "$OUT/keystore" > "$OUT/perception.log" 2>&1 &
  secured_pid=$!
  "$BIN/iplan-perception" --dds "$vendor" --domain $((domain + 1)) --insecure > "$OUT/perception-insecure.log" 2>&1 &
  insecure_pid=$!
  sleep 3
  for run in $(seq 1 "$RUNS"); do
    for mode in secured insecure; do
      if [ "$mode" = secured ]; then args=(--domain "$domain" --security "$OUT/keystore"); else args=(--domain $((domain + 1))); fi
      start=$(date +%s%N)
      "$BIN/iplan" topic echo /iplan/human/skeleton -n 1 --timeout 20 --dds "$vendor" "${args[@]}" > /dev/null 2>&1 \
        || echo "$vendor $mode run $run: no skeleton" >&2
      echo "$vendor $mode $(( $(date +%s%N) - start ))" >> "$OUT/startup.txt"
    done
  done
  kill "$secured_pid" "$insecure_pid"
  wait "$secured_pid" "$insecure_pid" 2>/dev/null || true
done

for run in $(seq 1 "$DEMO_RUNS"); do
  for mode in secured insecure; do
    flags=(--security "$OUT/keystore")
    [ "$mode" = insecure ] && flags=(--insecure)
    "$BIN/iplan" demo --episodes 1 --dds cyclonedds "${flags[@]}" --state-dir "$OUT/state-$mode-$run" \
      --summary "$OUT/demo-$mode-$run.json" > "$OUT/demo-$mode-$run.txt" 2>&1 || echo "demo $mode run $run failed" >&2
  done
done
echo "load after: $(cut -d' ' -f1-3 /proc/loadavg)"

python3 - "$OUT" "$DEMO_RUNS" <<'PY'
import json, statistics, sys
out, demo_runs = sys.argv[1], int(sys.argv[2])
def fmt(v, unit, digits):
    return f"{statistics.median(v):.{digits}f} {unit} [{min(v):.{digits}f}, {max(v):.{digits}f}] (n={len(v)})"
times = {}
for line in open(f"{out}/startup.txt"):
    vendor, mode, t = line.split()
    times.setdefault((vendor, mode), []).append(int(t) * 1e-9)
print("\nstart-up to the first skeleton (iplan topic echo -n 1), median [min, max]:")
for (vendor, mode), v in sorted(times.items()):
    print(f"  {vendor:10s} {mode:8s} {fmt(v, 's', 2)}")
print("\niplan demo --episodes 1 (Cyclone DDS), median [min, max] over runs:")
for mode in ("secured", "insecure"):
    p50, p99, dur, contacts = [], [], [], []
    for r in range(1, demo_runs + 1):
        try:
            j = json.load(open(f"{out}/demo-{mode}-{r}.json"))
        except (OSError, ValueError):
            continue
        p50.append(j["latency_ms"]["p50"]); p99.append(j["latency_ms"]["p99"])
        dur.append(j["duration_s"]); contacts.append(j["true_contacts"])
        assert j["security"]["secured"] == (mode == "secured"), j["security"]
    if p50:
        print(f"  {mode:8s} latency p50 {fmt(p50, 'ms', 1)}, p99 {fmt(p99, 'ms', 1)}, run {fmt(dur, 's', 1)}, "
              f"true contacts {sum(contacts):.0f}")
PY
