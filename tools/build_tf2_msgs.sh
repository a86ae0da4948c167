#!/usr/bin/env bash
# Build tf2_msgs (TFMessage only) into a venv made from the ROS 2 Jazzy PyPI wheels.
# PyPI has no tf2_msgs wheel; /tf and /tf_static need it. A sourced ROS 2 install already has it,
# so the build is skipped whenever `import tf2_msgs.msg` works.
# Usage: tools/build_tf2_msgs.sh VENV_DIR
set -euo pipefail

venv=$(cd "${1:?usage: build_tf2_msgs.sh VENV_DIR}" && pwd)
here=$(cd "$(dirname "$0")/.." && pwd)
py="$venv/bin/python"

if "$py" -c "import tf2_msgs.msg" 2>/dev/null; then
  echo "tf2_msgs: already importable, nothing to build"
  exit 0
fi

for tool in cmake make cc c++; do
  command -v "$tool" >/dev/null || { echo "tf2_msgs: '$tool' not found; install cmake and a C/C++ compiler (apt-get install cmake build-essential)" >&2; exit 1; }
done

build=$(mktemp -d "${TMPDIR:-/tmp}/tf2_msgs_build.XXXXXX")
trap 'rm -rf "$build"' EXIT
log="$build/build.log"
echo "tf2_msgs: building into $venv"
if ! (
  cd "$build"
  export AMENT_PREFIX_PATH="$venv${AMENT_PREFIX_PATH:+:$AMENT_PREFIX_PATH}"
  export PATH="$venv/bin:$PATH"
  cmake "$here/interfaces/tf2_msgs" \
    -DCMAKE_PREFIX_PATH="$venv" -DCMAKE_INSTALL_PREFIX="$venv" \
    -DPython3_EXECUTABLE="$py" -DBUILD_TESTING=OFF -DCMAKE_BUILD_TYPE=Release
  make -j"$(nproc)" install
) >"$log" 2>&1; then
  tail -n 40 "$log" >&2
  echo "tf2_msgs: build failed (log above). Check that the ros-jazzy build tools from requirements.lock are installed in $venv." >&2
  exit 1
fi
"$py" -c "import tf2_msgs.msg; tf2_msgs.msg.TFMessage()" || {
  echo "tf2_msgs: built but does not import; remove $venv and run 'make setup' again" >&2; exit 1; }
echo "tf2_msgs: built and importable"
