#!/usr/bin/env bash
# scripts/lcm-spy starts LCM's spy under a virtual X display and finds at
# least as many LCM types as lcmtypes/ defines. Runs in a private network
# namespace (through ctest), so the spy listens on loopback only.
set -euo pipefail
root="$1"
expected=$(ls "$root"/lcmtypes/*.lcm | wc -l)
out=$(mktemp)
trap 'kill -- -$pid 2>/dev/null || true; rm -f "$out"' EXIT
setsid xvfb-run -a "$root/scripts/lcm-spy" >"$out" 2>&1 &
pid=$!
# Wait (deadline 60 s) for the spy to report the types it found.
for _ in $(seq 600); do
  if grep -q "Found [0-9]* LCM types" "$out"; then break; fi
  if ! kill -0 "$pid" 2>/dev/null; then break; fi
  sleep 0.1
done
line=$(grep -o "Found [0-9]* LCM types" "$out" || true)
if [ -z "$line" ]; then
  echo "lcm-spy never printed 'Found N LCM types'; its output:"; cat "$out"; exit 1
fi
found=$(echo "$line" | awk '{print $2}')
echo "lcm-spy: $line (lcmtypes/ has $expected)"
if [ "$found" -lt "$expected" ]; then
  echo "FAIL: found $found types, expected at least $expected"; exit 1
fi
echo "PASS"
