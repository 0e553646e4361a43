#!/usr/bin/env bash
# What a flipper calibration error costs: the simulated lab's machine is
# mounted off its board file by a known error, `pinball calibrate --sim`
# measures that machine (the camera first, then the flippers), and pinballd's
# embedded simulation, whose table is the board file's machine, plays with
# the calibration file. The calibration is then wrong by the mounting error,
# as a real calibration would be wrong by its own error. The baseline, in the
# same run: pinballd without a calibration file (it believes the board file).
#
# Usage: bench/flipper_calibration_cost.sh [--balls N] [--seed S] [--json]
#   from the repository root after `cmake --build --preset release`.
# Prints one line per case (mean score per ball, its 95 % interval, mean ball
# time), or one JSON object with --json. Each ball is cut at pinballd's
# sim.max_ball_time_s (60 s by default).
set -euo pipefail
cd "$(dirname "$0")/.."

balls=50
seed=101
json=false
while [ $# -gt 0 ]; do
  case "$1" in
    --balls) balls="$2"; shift 2 ;;
    --seed) seed="$2"; shift 2 ;;
    --json) json=true; shift ;;
    -h|--help) sed -n '2,15p' "$0"; exit 0 ;;
    *) echo "flipper_calibration_cost: unknown argument '$1' (try --help)" >&2; exit 2 ;;
  esac
done

bin=build/release
for exe in "$bin/pinball" "$bin/pinballd"; do
  [ -x "$exe" ] || { echo "flipper_calibration_cost: $exe missing: cmake --build --preset release" >&2; exit 1; }
done
board=boards/mit1993.board
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# The figure of one pinballd --json report: a top-level number.
field() { sed -n "s/^  \"$1\": \\(.*\\),\$/\\1/p" "$2"; }

# case label | pivot x y (mm) | length (mm) | stops (deg); "none": no calibration file
cases=(
  "no calibration file (baseline)|none"
  "calibrated, no mounting error|0 0|0|0"
  "pivot 1 mm across|1 0|0|0"
  "pivot 3 mm across, 2 mm down (3.6 mm)|3 -2|0|0"
  "flippers 2 mm longer|0 0|2|0"
  "stops 0.35 degrees higher|0 0|0|0.35"
  "stops 0.7 degrees higher|0 0|0|0.7"
  "all three (the practice lab's old default)|3 -2|2|0.7"
)

"$bin/pinball" calibrate camera --sim "$board" --out "$work/camera.yaml" >/dev/null 2>"$work/calibrate.err" ||
  { cat "$work/calibrate.err" >&2; exit 1; }
rows=()
n=0
start=$(date +%s)
for c in "${cases[@]}"; do
  IFS='|' read -r label pivot length theta <<<"$c"
  config="$work/sim$n.yaml"
  # best.json, which docs/results.md's figures were measured with (pinballd's default until 2026-12-04).
  printf 'version: 1\nmode: sim\nlcm_url: "memq://"\ncontroller: %s\n' "$PWD/controllers/best.json" >"$config"
  if [ "$pivot" != none ]; then
    cal="$work/cal$n.yaml"
    cp "$work/camera.yaml" "$cal"
    # shellcheck disable=SC2086  # pivot is two numbers
    "$bin/pinball" calibrate flippers --sim "$board" --sim-pivot-offset-mm $pivot --sim-length-offset-mm "$length" \
      --sim-theta-offset-deg "$theta" --out "$cal" >/dev/null 2>"$work/calibrate.err" ||
      { cat "$work/calibrate.err" >&2; exit 1; }
    echo "calibration: $cal" >>"$config"
  fi
  "$bin/pinballd" --config "$config" --balls "$balls" --seed "$seed" --json >"$work/report$n.json" 2>"$work/pinballd.err" ||
    { cat "$work/pinballd.err" >&2; exit 1; }
  mean=$(field mean_score_per_ball "$work/report$n.json")
  ci=$(field score_ci95_half_width "$work/report$n.json")
  ball_s=$(field mean_ball_time_s "$work/report$n.json")
  cut=$(field balls_cut_at_time_limit "$work/report$n.json")
  rows+=("$label|$mean|$ci|$ball_s|$cut")
  n=$((n + 1))
  elapsed=$(($(date +%s) - start))
  echo "flipper_calibration_cost: $n of ${#cases[@]} cases ($((100 * n / ${#cases[@]})) %), ETA $((elapsed * (${#cases[@]} - n) / n)) s" >&2
done

if $json; then
  printf '{"balls": %s, "seed": %s, "max_ball_time_s": 60, "cases": [' "$balls" "$seed"
  sep=""
  for r in "${rows[@]}"; do
    IFS='|' read -r label mean ci ball_s cut <<<"$r"
    printf '%s{"case": "%s", "mean_score_per_ball": %s, "score_ci95_half_width": %s, "mean_ball_time_s": %s, "balls_cut_at_time_limit": %s}' \
      "$sep" "$label" "$mean" "$ci" "$ball_s" "$cut"
    sep=", "
  done
  printf ']}\n'
else
  echo "$balls balls a case, seed $seed, each ball cut at 60 s"
  for r in "${rows[@]}"; do
    IFS='|' read -r label mean ci ball_s cut <<<"$r"
    printf '%-45s %9.0f ± %5.0f per ball   mean ball time %5.1f s   cut %s\n' "$label" "$mean" "$ci" "$ball_s" "$cut"
  done
fi
