#!/usr/bin/env bash
# Set up .venv (see tools/setup.sh) and run the whole test suite. Extra arguments go to pytest (test files
# given there narrow the run to them; without any, pytest.ini's testpaths is the whole suite).
set -euo pipefail
cd "$(dirname "$0")/.."
VENV=$(tools/setup.sh)
export ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST
export RAVH_CACHE=${RAVH_CACHE:-$PWD/.cache/ravh}
exec "$VENV/bin/python" -m pytest -q "$@"
