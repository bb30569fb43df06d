#!/usr/bin/env bash
# Set up .venv (tools/setup.sh) and run the main job: the sim node on a house (default 15), headless,
# with a behaviour driving the robot (default: the wanderer, logging every capture to out/). Ctrl-C stops
# both cleanly (SIGINT, so Fast DDS removes its shared-memory files).
# Usage: bash tools/run.sh [--house N] [--seed S] [--behaviour wanderer|grid|none] [--rtf F]
set -euo pipefail
cd "$(dirname "$0")/.."
house=15 seed=0 behaviour=wanderer rtf=1
while [ $# -gt 0 ]; do
  case "$1" in
    --house) house=$2; shift 2 ;;
    --seed) seed=$2; shift 2 ;;
    --behaviour) behaviour=$2; shift 2 ;;
    --rtf) rtf=$2; shift 2 ;;
    *) echo "usage: $0 [--house N] [--seed S] [--behaviour wanderer|grid|none] [--rtf F]" >&2; exit 2 ;;
  esac
done
VENV=$(tools/setup.sh)
export ROS_AUTOMATIC_DISCOVERY_RANGE=${ROS_AUTOMATIC_DISCOVERY_RANGE:-LOCALHOST}
RAVH="$VENV/bin/ravh"
pids=()
stop() { for p in "${pids[@]}"; do kill -INT "$p" 2>/dev/null || true; done; wait; }
trap stop INT TERM
"$RAVH" sim --house "$house" --seed "$seed" --rtf "$rtf" & pids+=($!)
if [ "$behaviour" != none ]; then
  mkdir -p out
  "$RAVH" "$behaviour" --log "out/captures_house${house}.jsonl" & pids+=($!)
fi
echo "ravh_sim: house $house running (behaviour: $behaviour); Ctrl-C to stop" >&2
wait -n "${pids[@]}"
stop
