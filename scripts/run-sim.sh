#!/usr/bin/env bash
# Installs the packages, builds, and runs the main job: pinballd with no
# arguments, i.e. the embedded simulation of the reconstructed thesis table
# (rendered camera frames, the detector, the tracker, the shipped controller,
# CAN frames to the virtual driver board) for 10 balls. It prints the mean
# score per ball and the latency table. Extra arguments go to pinballd
# (e.g. --balls 100, --json, --realtime).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
cmake --preset release >/dev/null
cmake --build --preset release --target pinballd
build/release/pinballd "$@"
