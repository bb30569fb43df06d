#!/usr/bin/env bash
# Set up .venv (tools/setup.sh) and run the main job: the sim node on a house (default 15), headless,
# with a behaviour driving the robot (default: the wanderer, logging every capture to out/). The
# arguments are checked before anything starts; when any process exits, the others are stopped too.
# Ctrl-C stops them all cleanly (SIGINT, so Fast DDS removes its shared-memory files).
# Usage: bash tools/run.sh [--house N] [--seed S] [--behaviour wanderer|grid|none] [--rtf F]
set -euo pipefail
cd "$(dirname "$0")/.."
usage="usage: $0 [--house N] [--seed S] [--behaviour wanderer|grid|none] [--rtf F]"
house=15 seed=0 behaviour=wanderer rtf=1
while [ $# -gt 0 ]; do
  case "$1" in
    --house) house=${2:?$usage}; shift 2 ;;
    --seed) seed=${2:?$usage}; shift 2 ;;
    --behaviour) behaviour=${2:?$usage}; shift 2 ;;
    --rtf) rtf=${2:?$usage}; shift 2 ;;
    *) echo "$usage" >&2; exit 2 ;;
  esac
done
case "$behaviour" in
  wanderer|grid|none) ;;
  *) echo "run.sh: error: unknown behaviour '$behaviour'; valid: wanderer, grid, none" >&2; exit 2 ;;
esac
VENV=$(tools/setup.sh)
RAVH="$VENV/bin/ravh"
# house and seed are checked the way the sim will read them (one-line error, nothing started)
"$RAVH" query "$house" --seed "$seed" '{"query": "counts"}' > /dev/null
"$VENV/bin/python" -c 'import math, sys; v = float(sys.argv[1]); sys.exit(not (math.isfinite(v) and v >= 0))' \
  "$rtf" 2>/dev/null || { echo "run.sh: error: --rtf must be a number >= 0, got '$rtf'" >&2; exit 2; }
export ROS_AUTOMATIC_DISCOVERY_RANGE=${ROS_AUTOMATIC_DISCOVERY_RANGE:-LOCALHOST}
echo "ravh_sim: ROS_DOMAIN_ID ${ROS_DOMAIN_ID:-0}$([ -n "${ROS_DOMAIN_ID:-}" ] || echo ' (the default; set ROS_DOMAIN_ID to choose)')" >&2
pids=()
stop() { for p in "${pids[@]}"; do kill -INT "$p" 2>/dev/null || true; done; wait || true; }
trap 'stop; exit 130' INT TERM
"$RAVH" sim --house "$house" --seed "$seed" --rtf "$rtf" & pids+=($!)
if [ "$behaviour" != none ]; then
  mkdir -p out
  "$RAVH" "$behaviour" --log "out/captures_house${house}.jsonl" & pids+=($!)
fi
echo "ravh_sim: house $house running (behaviour: $behaviour); Ctrl-C to stop" >&2
status=0
wait -n "${pids[@]}" || status=$?
stop
exit "$status"
