#!/usr/bin/env bash
# Installs the packages, builds, and plays 100 balls of the reconstructed thesis
# table with the spastic flipper on the embedded simulator.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
cmake --preset release >/dev/null
cmake --build --preset release --target pinball
build/release/pinball sim boards/mit1993.board --policy spastic --balls 100 "$@"
