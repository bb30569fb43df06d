#!/usr/bin/env bash
# The test suite under load (issue 23): starts N busy loops (default 8: load 10 on 2 cores), runs the suite
# K times (default 2) with tools/test.sh, stops the loops whatever happens, then checks that the suite left
# nothing behind: no process it started (sims, behaviours, recorders, ravh commands, pytest children: new
# since the start, running in this checkout) and no Fast DDS shared-memory file (/dev/shm/fastrtps_*,
# /dev/shm/sem.fastrtps_*: new since the start and held by no process). Prints a one-line verdict; exits
# non-zero when a run failed or something was left.
#
# Usage: tools/load_suite.sh [--loops N] [--runs K] [--suite CMD] [-- PYTEST ARGS...]
#   --suite CMD   what runs the suite (default tools/test.sh); the pytest arguments are appended to it
#   e.g. tools/load_suite.sh --loops 2 --runs 1 -- test/test_architecture.py
set -uo pipefail
cd "$(dirname "$0")/.."
loops=8 runs=2 suite=tools/test.sh
while [ $# -gt 0 ]; do
  case $1 in
    --loops) loops=$2; shift 2 ;;
    --runs) runs=$2; shift 2 ;;
    --suite) suite=$2; shift 2 ;;
    --) shift; break ;;
    *) echo "usage: $0 [--loops N] [--runs K] [--suite CMD] [-- PYTEST ARGS...]" >&2; exit 2 ;;
  esac
done
root=$PWD

shm_files() { ls -1 /dev/shm 2>/dev/null | grep -E '^(sem\.)?fastrtps_' | sort; }
held_shm() {          # /dev/shm files some process maps (segments, semaphores) or holds open (the _el locks)
  { cat /proc/[0-9]*/maps 2>/dev/null | grep -o '/dev/shm/[^ ]*'; find /proc/[0-9]*/fd -lname '/dev/shm/*' \
      -printf '%l\n' 2>/dev/null; } | sed 's|/dev/shm/||' | sort -u
}
pids() { ps -eo pid= | tr -d ' ' | sort; }
pids_before=$(pids)
shm_before=$(shm_files)

busy=()
stop_loops() {
  for pid in "${busy[@]}"; do kill "$pid" 2>/dev/null; done
  for pid in "${busy[@]}"; do wait "$pid" 2>/dev/null; done
  busy=()
}
suite_pid=
trap stop_loops EXIT
trap 'stop_loops; [ -n "$suite_pid" ] && kill -INT "$suite_pid" && wait "$suite_pid"
      echo "load_suite: INTERRUPTED (leftovers not checked)"; exit 130' INT TERM
for _ in $(seq "$loops"); do
  ( while :; do :; done ) &
  busy+=($!)
done

failed=0
for run in $(seq "$runs"); do
  echo "== run $run/$runs under $loops busy loops: $suite $*"
  env --default-signal=INT $suite "$@" &    # waited for, so that a signal reaches the trap; SIGINT not ignored
  suite_pid=$!
  wait "$suite_pid" || failed=$((failed + 1))
  suite_pid=
done
stop_loops

sleep 2                                                 # let exiting children finish
left_pids=()
for pid in $(comm -13 <(echo "$pids_before") <(pids)); do   # the listing's own pipeline has exited by now
  [ "$(readlink "/proc/$pid/cwd" 2>/dev/null)" = "$root" ] || continue
  args=$(ps -o args= -p "$pid") || continue
  left_pids+=("$pid"); echo "left running: $pid $args"
done
held=$(held_shm)
left_shm=()
for f in $(comm -13 <(echo "$shm_before") <(shm_files)); do
  segment=${f#sem.}; segment=${segment%_mutex}; segment=${segment%_el}   # a lock or mutex goes with its segment
  grep -qxF -e "$f" -e "$segment" <<<"$held" && continue
  left_shm+=("$f"); echo "left in /dev/shm: $f"
done

verdict="$((runs - failed))/$runs runs passed under $loops busy loops, ${#left_pids[@]} processes and ${#left_shm[@]} Fast DDS files left"
if [ "$failed" -eq 0 ] && [ ${#left_pids[@]} -eq 0 ] && [ ${#left_shm[@]} -eq 0 ]; then
  echo "load_suite: PASS: $verdict"
else
  echo "load_suite: FAIL: $verdict"
  exit 1
fi
