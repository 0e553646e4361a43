#!/usr/bin/env bash
# Builds the threaded suites (daemon, bus, firmware, faults) under the tsan
# preset, ThreadSanitizer, and runs them: threads share data only through
# the documented hand-offs, and a race anywhere fails the run. The tsan-ci
# test preset leaves out four long full-game daemon runs (about ten minutes
# under TSan); `ctest --preset tsan` runs every one. Extra arguments go to
# the build (e.g. -j2).
# Usage: scripts/test-tsan.sh [-jN]
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
cmake --preset tsan >/dev/null
cmake --build --preset tsan "$@" --target daemon_tests daemon_allocation_tests daemon_bench_tests bus_tests \
  firmware_tests firmware_sim_tests firmware_bench_tests coil_fault_tests daemon_fault_tests
ctest --preset tsan-ci
