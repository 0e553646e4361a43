#!/usr/bin/env bash
# Static analysis of the whole tree (docs/results.md, "Static analysis"):
#   - clang-tidy with the checks of .clang-tidy over every C++ object of the
#     release build: the product, the benchmarks and the test suites;
#   - clang-tidy over the driver-board firmware as cross-compiled for the
#     STM32F446 (its portable core and its MCU layer);
#   - cppcheck over the same firmware.
# Any report fails the run: a place that is right as it stands says so where
# it stands (NOLINT or cppcheck-suppress, with the reason).
# Prints its progress with the time left on stderr, then every report
# (file:line:col: message [check]) and a summary; --json prints the summary
# and the reports as one JSON object instead.
# Exit 0: nothing reported; 1: reports, or a tool that failed; 2: bad usage.
# Installs clang-tidy and cppcheck itself (scripts/install-deps.sh), builds
# the release preset (its objects include headers the build generates) and the
# firmware (scripts/build-firmware.sh).
# Usage: scripts/static-analysis.sh [-j N] [--json]    (5 to 7 min on 2 cores once built)
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD

usage="usage: scripts/static-analysis.sh [-j N] [--json]"
parallel=$(nproc)
json=0
while [ $# -gt 0 ]; do
  case "$1" in
    -j) [ $# -ge 2 ] || { echo "static-analysis: -j needs a number ($usage)" >&2; exit 2; }
        parallel=$2; shift 2 ;;
    -j*) parallel=${1#-j}; shift ;;
    --json) json=1; shift ;;
    -h|--help) sed -n '2,17p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "static-analysis: unknown argument '$1' ($usage)" >&2; exit 2 ;;
  esac
done
if ! [[ $parallel =~ ^[1-9][0-9]*$ ]]; then
  echo "static-analysis: -j takes a whole number from 1, not '$parallel'" >&2
  exit 2
fi

say() { echo "static-analysis: $*" >&2; }
start_s=$(date +%s)

scripts/install-deps.sh clang-tidy cppcheck
say "building the release preset (its compile database and generated headers)"
cmake --preset release >/dev/null
cmake --build --preset release >/dev/null
# The firmware as scripts/build-firmware.sh builds it: its compile database.
firmware_build=build/firmware-stm32f446
scripts/build-firmware.sh "$firmware_build" >/dev/null

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# One line an object: the compile database it is read with, then its file.
python3 - "$firmware_build" >"$work/units" <<'EOF'
import json, sys
for e in json.load(open('build/release/compile_commands.json')):
    if e['file'].endswith(('.cpp', '.cxx')):
        print('build/release\t' + e['file'])
for f in sorted({e['file'] for e in json.load(open(sys.argv[1] + '/compile_commands.json'))}):
    print(sys.argv[1] + '\t' + f)
EOF
units=$(wc -l <"$work/units")

# Reports only in the tree's own files, not in generated or system headers.
header_filter="^$root/(include|src|bench|calibration|firmware_interface|tests)/"
# The firmware's database is arm-none-eabi-gcc's: clang needs the target, its
# newlib headers, and short enums to lay structs out as that GCC does.
firmware_args=(--extra-arg=--target=arm-none-eabi --extra-arg=-fshort-enums
               --extra-arg=-isystem/usr/lib/arm-none-eabi/include)

tidy_one() {  # index, compile database, file: writes index.log and index.rc
  local args=()
  [ "$2" = "$firmware_build" ] && args=("${firmware_args[@]}")
  local rc=0
  clang-tidy -p "$2" --quiet --header-filter="$header_filter" "${args[@]}" "$3" \
    >"$work/$1.log" 2>&1 </dev/null || rc=$?
  echo "$rc" >"$work/$1.rc"
}

progress() {  # finished of units, with the time left at the pace so far
  local finished elapsed
  finished=$(find "$work" -name '*.rc' | wc -l)
  elapsed=$(($(date +%s) - start_tidy_s))
  if [ "$finished" -gt 0 ]; then
    local left=$((elapsed * (units - finished) / finished))
    say "clang-tidy: $finished of $units objects, $elapsed s, about $left s left"
  fi
}

say "clang-tidy over $units objects on $parallel jobs"
start_tidy_s=$(date +%s)
i=0
while IFS=$'\t' read -r database file; do
  i=$((i + 1))
  while [ "$(jobs -rp | wc -l)" -ge "$parallel" ]; do
    wait -n || true
    progress
  done
  tidy_one "$i" "$database" "$file" &
done <"$work/units"
wait
progress

say "cppcheck over the firmware"
cppcheck_rc=0
cppcheck --quiet --enable=all --inline-suppr --suppress=missingIncludeSystem --suppress=unusedFunction \
  --std=c11 --platform=arm32-wchar_t4 -DPINBALL_FW_MAJOR=1 -DPINBALL_FW_MINOR=0 \
  -I include -I firmware_interface/stm32f446 \
  --template='{file}:{line}:{column}: {severity}: {message} [{id}]' \
  firmware_interface/core firmware_interface/stm32f446 2>"$work/cppcheck.log" || cppcheck_rc=$?

# The reports, each once (a header's appear in every object that includes it),
# paths from the repository root; and each tool run that failed without one.
report_line='^[^ :]+:[0-9]+:[0-9]+: [a-z ]+: .* \[[^]]+\]$'
{
  cat "$work"/*.log | sed "s|^$root/||" | grep -E "$report_line" || true
} | sort -u >"$work/reports"
: >"$work/failures"
i=0
while IFS=$'\t' read -r database file; do
  i=$((i + 1))
  rc=$(cat "$work/$i.rc")
  if [ "$rc" != 0 ] && ! sed "s|^$root/||" "$work/$i.log" | grep -qE "$report_line"; then
    echo "clang-tidy exited $rc on ${file#"$root"/} without a report: $(tail -n 1 "$work/$i.log")" >>"$work/failures"
  fi
done <"$work/units"
[ "$cppcheck_rc" = 0 ] || echo "cppcheck exited $cppcheck_rc" >>"$work/failures"

reports=$(wc -l <"$work/reports")
failures=$(wc -l <"$work/failures")
wall_s=$(($(date +%s) - start_s))
if [ "$json" = 1 ]; then
  python3 - "$work" "$units" "$wall_s" <<'EOF'
import json, sys
work, units, wall_s = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
lines = lambda name: [l for l in open(f'{work}/{name}').read().splitlines() if l]
reports, failures = lines('reports'), lines('failures')
print(json.dumps({'objects': units, 'reports': reports, 'report_count': len(reports),
                  'tool_failures': failures, 'wall_s': wall_s, 'clean': not reports and not failures}))
EOF
else
  cat "$work/reports" "$work/failures"
  echo "static analysis: $units objects (clang-tidy) and the firmware (cppcheck): $reports reports," \
       "$failures tool failures, $wall_s s"
fi
[ "$reports" = 0 ] && [ "$failures" = 0 ]
