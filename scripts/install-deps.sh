#!/usr/bin/env bash
# Installs every Debian package the project needs to build, test and run,
# and any named on the command line (tools one script alone needs, e.g.
# scripts/static-analysis.sh: clang-tidy cppcheck).
# Idempotent: when everything is already present it prints nothing and exits 0.
# Usage: scripts/install-deps.sh [PACKAGE ...]
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config git
  libeigen3-dev
  libopencv-core-dev libopencv-imgproc-dev libopencv-imgcodecs-dev libopencv-videoio-dev
  libopencv-calib3d-dev
  libopencv-contrib-dev   # aruco: ChArUco targets for `pinball calibrate intrinsics`
  libopencv-highgui-dev   # the windows of `pinball view` and `pinball play`
  xvfb xauth              # a virtual display: the viewer's and play's tests run headless
  libx11-dev              # pinball play: XQueryKeymap, a flipper key's true up/down state (waitKey sees presses only)
  liblcm-dev liblcm-bin
  libgtest-dev libgmock-dev googletest
  libbenchmark-dev
  libyaml-cpp-dev
  nlohmann-json3-dev libcli11-dev
  can-utils libsocketcan-dev
  python3           # runs the tests of the generated Python LCM bindings and bench/outlane_routes.py (json, statistics)
  # The driver board's firmware (firmware_interface/stm32f446/): the Arm cross compiler
  # and newlib for the image, QEMU to boot it (ctest label firmware).
  gcc-arm-none-eabi libnewlib-arm-none-eabi qemu-system-arm
  # Learning and evaluation across processes and machines (mpirun -n N pinball ...).
  libopenmpi-dev openmpi-bin
  # The MuJoCo lab twin (--world twin, ctest label twin, docs/worlds.md).
  libmujoco-dev
  "$@"
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done
[ ${#missing[@]} -eq 0 ] && exit 0

if [ "$(id -u)" -ne 0 ]; then
  echo "install-deps: missing packages: ${missing[*]}; run this script as root" >&2
  exit 1
fi
echo "install-deps: installing ${missing[*]}" >&2
export DEBIAN_FRONTEND=noninteractive
apt-get update -qq >/dev/null
apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
echo "install-deps: done" >&2
