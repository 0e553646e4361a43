#!/usr/bin/env bash
# Installs the packages, builds the release preset and runs every test, then
# the bad-input corpus under ASan + UBSan (its target alone) and the threaded
# suites under ThreadSanitizer (scripts/test-tsan.sh).
# Usage: scripts/test.sh   (as root on a fresh Debian machine, or any user once
# the packages are installed)
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
cmake --preset release >/dev/null
cmake --build --preset release
ctest --preset release
scripts/test-bad-input.sh
scripts/test-tsan.sh
