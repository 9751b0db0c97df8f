#!/usr/bin/env bash
# The test suite: serial pytest, with the MPI cases run under mpiexec -n 2 in subprocesses.
#
#   bash tools/test.sh [PYTEST ARGS]               one run; the summary names every failure and error
#   bash tools/test.sh --repeat N [PYTEST ARGS]    N runs in a row, each logged to .test-runs/; a table of
#                                                  every failure by test name at the end; exit 1 if any run failed
#   bash tools/test.sh --repeat N --loaded ...     the same with a niced CPU hog on every core beside the suite
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/bootstrap.sh
bash tools/surfacetopography.sh >/dev/null  # the optional extra of instrument files, so that its reader is tested too
source tools/env.sh

run_once() {
  # -rfE: the short summary names every failed and erroring test with its message.
  .venv/bin/python -m pytest -q -rfE tests "$@"
}

if [ "${1:-}" != "--repeat" ]; then
  run_once "$@"
  exit
fi

repeats="${2:?--repeat needs a count}"
[[ "$repeats" =~ ^[1-9][0-9]*$ ]] || { echo "tools/test.sh: --repeat needs a positive count, got '$repeats'" >&2; exit 2; }
shift 2
loaded=0
if [ "${1:-}" = "--loaded" ]; then loaded=1; shift; fi

logs=".test-runs/$(date +%Y%m%d-%H%M%S)"
mkdir -p "$logs"
hogs=()
stop_hogs() { for pid in "${hogs[@]:-}"; do [ -n "$pid" ] && kill "$pid" 2>/dev/null || true; done; }
trap stop_hogs EXIT
if ((loaded)); then
  for _ in $(seq "$(nproc)"); do nice -n 19 bash -c 'while :; do :; done' & hogs+=($!); done
fi

failed_runs=0
for k in $(seq "$repeats"); do
  log="$logs/run-$k.log"
  if run_once "$@" >"$log" 2>&1; then status=0; else status=$?; failed_runs=$((failed_runs + 1)); fi
  echo "run $k/$repeats: exit $status, $(grep -E '^(=+ )?[0-9]+ (passed|failed)|^[0-9]+ (passed|failed)' "$log" | tail -1)"
done

echo "--- ${ROUGHPETSC_FFT_EFFORT:-default effort}, $repeats runs$( ((loaded)) && echo ', loaded'), logs in $logs"
if grep -h -E '^(FAILED|ERROR) ' "$logs"/run-*.log | sed 's/ - .*//' | sort | uniq -c | sort -rn | grep .; then
  echo "$failed_runs of $repeats runs failed; messages: grep -h -E '^(FAILED|ERROR) ' $logs/run-*.log"
  exit 1
fi
((failed_runs == 0)) || { echo "$failed_runs of $repeats runs failed without a named test; see $logs"; exit 1; }
echo "all $repeats runs passed"
