#!/usr/bin/env bash
# The long generated-input campaign: every target of
# host-tests/tests/generated.rs (dataset manifest and series, params file,
# the core's constructors, the estimator in f64/f32/Fx, period and
# decrement extraction), rerun with fresh random seeds until the time is
# up, each round with TRACKBELT_PROPTEST_SCALE times the CI case counts.
#
#   host-tests/long-campaign.sh [MINUTES] [SCALE]     (defaults: 10, 10)
#
# Prints the cases run and the failures. A failing input is saved by
# proptest in host-tests/tests/generated.proptest-regressions (commit it:
# it is replayed first on every run) and the campaign exits non-zero.
set -euo pipefail
cd "$(dirname "$0")/.."
minutes=${1:-10}
scale=${2:-10}
cargo test --release -p trackbelt-host-tests --test generated --no-run
base=$(awk '/^pub const BASE_CASES_TOTAL/,/;/' host-tests/tests/generated.rs \
  | grep -o '[0-9_]\{3,\}' | tr -d _ | paste -sd+ | bc)
end=$(( $(date +%s) + minutes * 60 ))
rounds=0
failed=0
start=$(date +%s)
while [ "$(date +%s)" -lt "$end" ]; do
  if ! TRACKBELT_PROPTEST_SCALE=$scale cargo test -q --release -p trackbelt-host-tests \
      --test generated -- --test-threads 2 >/tmp/trackbelt-campaign-round.log 2>&1; then
    failed=$((failed + 1))
    grep -E "^---- |minimal failing input" /tmp/trackbelt-campaign-round.log || true
    break
  fi
  rounds=$((rounds + 1))
done
secs=$(( $(date +%s) - start ))
cases=$(echo "$rounds * $base * $scale" | bc)
echo "long campaign: $rounds rounds x $base x $scale cases = $cases generated cases in ${secs} s, failing rounds: $failed"
[ "$failed" -eq 0 ]
