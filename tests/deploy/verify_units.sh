#!/usr/bin/env bash
# Installs the build into a temporary prefix and checks the deployment:
# every systemd unit passes `systemd-analyze verify` without a complaint
# (it exits 0 on parse warnings, so its output must be empty too), and every
# installed service accepts its installed configuration (--check-config),
# except the intent service, which must refuse clearly until a model is trained.
set -euo pipefail
build="$1"
prefix="$(mktemp -d)"
trap 'rm -rf "$prefix"' EXIT
cmake --install "$build" --prefix "$prefix" > "$prefix/install.log"
units="$prefix/lib/systemd/system"
failures=0
for unit in "$units"/*.service "$units"/iplan.target; do
  out="$(SYSTEMD_UNIT_PATH="$units:" systemd-analyze verify "$unit" 2>&1)" || { echo "FAIL verify $unit: $out"; failures=$((failures+1)); continue; }
  if [ -n "$out" ]; then echo "FAIL verify $unit: $out"; failures=$((failures+1)); else echo "ok   verify $(basename "$unit")"; fi
done
grep -q '^Type=notify$' "$units/iplan-trajopt.service" || { echo "FAIL units are not Type=notify"; failures=$((failures+1)); }
grep -q '^WatchdogSec=' "$units/iplan-trajopt.service" || { echo "FAIL units have no watchdog"; failures=$((failures+1)); }
# shellcheck disable=SC1091
set -a; . "$prefix/etc/iplan/iplan.env"; set +a
for svc in perception collision_risk trajopt robot_sim supervisor; do
  exe="$prefix/bin/iplan-${svc//_/-}"
  if out="$("$exe" --config "$IPLAN_CONFIG_DIR/$svc.yaml" --check-config 2>&1)"; then
    echo "ok   $svc accepts its installed configuration"
  else
    echo "FAIL $svc refuses its installed configuration: $out"; failures=$((failures+1))
  fi
done
# Secure by default: every unit starts its service with --require-security,
# which refuses to run without a keystore (exit 2, the reason said) unless
# IPLAN_INSECURE=1 says it is meant.
for unit in "$units"/iplan-*.service; do
  grep -q '^ExecStart=.* --require-security ' "$unit" || { echo "FAIL $(basename "$unit") does not require DDS Security"; failures=$((failures+1)); }
done
# expect_refusal WHAT PATTERN CMD...: CMD exits 2 and its output matches PATTERN.
expect_refusal() {
  local what="$1" pattern="$2" out rc
  shift 2
  set +e
  out="$("$@" 2>&1)"; rc=$?
  set -e
  if [ "$rc" -eq 2 ] && grep -q "$pattern" <<<"$out"; then
    echo "ok   $what"
  else
    echo "FAIL $what: exit $rc: $out"; failures=$((failures+1))
  fi
}
expect_refusal "a unit's service without a keystore refuses to start (exit 2, says why)" \
  "refusing to start without DDS Security" \
  "$prefix/bin/iplan-trajopt" --require-security --config "$IPLAN_CONFIG_DIR/trajopt.yaml" --check-config
if out="$(IPLAN_INSECURE=1 "$prefix/bin/iplan-trajopt" --require-security --config "$IPLAN_CONFIG_DIR/trajopt.yaml" --check-config 2>&1)" \
    && grep -q "DDS Security is off on purpose" <<<"$out"; then
  echo "ok   IPLAN_INSECURE=1 runs it unsecured on purpose, and says so"
else
  echo "FAIL IPLAN_INSECURE=1: $out"; failures=$((failures+1))
fi
expect_refusal "intent refuses to start without a trained model (exit 2, names the model)" "model" \
  "$prefix/bin/iplan-intent" --config "$IPLAN_CONFIG_DIR/intent.yaml" --check-config
echo "$failures failures"
[ "$failures" -eq 0 ]
