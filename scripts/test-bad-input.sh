#!/usr/bin/env bash
# Builds the bad-input corpus runner (tests/bad_input) alone under the asan-corpus
# preset (asan at -O0), AddressSanitizer + UndefinedBehaviorSanitizer with float-cast-overflow
# and every finding fatal, and runs it: each corpus file must be refused
# cleanly, each good file must load. Only that target and the libraries it
# links are built. Extra arguments go to the build (e.g. -j2).
# Usage: scripts/test-bad-input.sh [-jN]
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
cmake --preset asan-corpus >/dev/null
cmake --build --preset asan-corpus --target bad_input_tests "$@"
ctest --preset asan-corpus
