#!/usr/bin/env bash
# Builds the suites that run threads (the daemon's, the bus's, the firmware
# interface's and the daemon's fault injection) under the tsan preset,
# ThreadSanitizer, and runs them: threads share data only through the
# documented hand-offs, and a race anywhere fails the run. Left out, to keep
# CI's build short, the suites that would make it build the benchmarks or the
# whole `pinball` program: coil faults over lossy links and the protocol and
# latency bench tests (one thread), replay (offline) and the daemon's latency
# bench (the daemon's threads, which daemon_tests runs); and, by the tsan-ci
# test preset, four long full-game daemon runs (about ten minutes under TSan)
# and the Python bindings test (its C++ sample is not built here). `cmake --build
# --preset tsan && ctest --preset tsan` runs everything. Extra arguments go
# to the build (e.g. -j2).
# Usage: scripts/test-tsan.sh [-jN]
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
cmake --preset tsan >/dev/null
cmake --build --preset tsan "$@" --target daemon_tests bus_tests \
  firmware_tests firmware_sim_tests daemon_fault_tests
ctest --preset tsan-ci
