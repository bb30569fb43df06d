#!/usr/bin/env bash
# Build and install tools/tf2_msgs (TFMessage only; same type hash as Jazzy's tf2_msgs) into a venv
# made of the ROS 2 wheels, which ship no tf2_msgs. Does nothing when tf2_msgs already imports.
# Usage: tools/build_tf2_msgs.sh VENV. Needs cmake and g++ (Debian: apt-get install cmake g++).
# tools/tf2_msgs/COLCON_IGNORE keeps colcon (full ROS installs, which have tf2_msgs) from building it.
# Installing into the venv prefix puts the Python package in site-packages and the libraries in
# VENV/lib, which the wheels' bootstrapper already puts on LD_LIBRARY_PATH: no env vars at run time.
set -euo pipefail
cd "$(dirname "$0")/.."
VENV=$1
PY="$VENV/bin/python"
if "$PY" -c "import tf2_msgs.msg" 2>/dev/null; then
  exit 0
fi
for tool in cmake g++; do
  command -v "$tool" >/dev/null || { echo "ravh setup: $tool is needed to build tf2_msgs (apt-get install cmake g++)" >&2; exit 1; }
done
# The wheels' metadata lacks these build-time packages.
"$PY" -m pip install -q --disable-pip-version-check -r tools/requirements-build.txt
# The message wheels' CMake exports name the wheel builder's Python and numpy include paths.
py_include=$("$PY" -c "import sysconfig; print(sysconfig.get_paths()['include'])")
np_include=$("$PY" -c "import numpy; print(numpy.get_include())")
sed -i -E -e "s#/opt/python/[^;\"]*/numpy/_core/include#${np_include}#g" \
          -e "s#/opt/python/[^;\"]*/include/python3\.[0-9]+#${py_include}#g" \
    "$VENV"/share/*/cmake/export_*__rosidl_generator_pyExport.cmake
build=$(mktemp -d)
trap 'rm -rf "$build"' EXIT
export CMAKE_PREFIX_PATH="$VENV" AMENT_PREFIX_PATH="$VENV"
cmake -S tools/tf2_msgs -B "$build" -DCMAKE_INSTALL_PREFIX="$VENV" -DPython3_EXECUTABLE="$PY" \
      -DBUILD_TESTING=OFF -DCMAKE_BUILD_TYPE=Release >"$build/log" 2>&1 \
  && cmake --build "$build" -j2 >>"$build/log" 2>&1 \
  && cmake --install "$build" >>"$build/log" 2>&1 \
  || { tail -n 30 "$build/log" >&2; echo "ravh setup: building tf2_msgs failed" >&2; exit 1; }
"$PY" -c "import tf2_msgs.msg"
