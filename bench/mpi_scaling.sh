#!/usr/bin/env bash
# Scaling across MPI ranks on this machine: an evaluation (the spastic
# flipper on fresh balls) and the imitation method's teacher (its first
# round), each played by one process on one thread (the baseline), one
# process on 2 threads, 2 ranks of one thread, and 4 ranks oversubscribed on
# the 2 cores. Every run must give the same figures (checked: the script
# fails otherwise); the table gives the speed, the speed-up over the
# baseline, and what gathering the results cost (mpi_comm_s: moving them
# once every rank was there; mpi_wait_s: waiting for the slowest rank).
#
# Usage: bench/mpi_scaling.sh [--eval-balls N] [--teacher-balls N] [--seed S] [--json]
#   from the repository root after `cmake --build --preset release`, with
#   mpirun (openmpi-bin) installed. Balls are cut at 60 s of game time.
set -euo pipefail
cd "$(dirname "$0")/.."

eval_balls=6000
teacher_balls=40
seed=11
json=false
while [ $# -gt 0 ]; do
  case "$1" in
    --eval-balls) eval_balls="$2"; shift 2 ;;
    --teacher-balls) teacher_balls="$2"; shift 2 ;;
    --seed) seed="$2"; shift 2 ;;
    --json) json=true; shift ;;
    -h|--help) sed -n '2,15p' "$0"; exit 0 ;;
    *) echo "mpi_scaling: unknown argument '$1' (try --help)" >&2; exit 2 ;;
  esac
done

exe=build/release/pinball
[ -x "$exe" ] || { echo "mpi_scaling: $exe missing: cmake --build --preset release" >&2; exit 1; }
command -v mpirun >/dev/null || { echo "mpi_scaling: no mpirun (apt-get install openmpi-bin)" >&2; exit 1; }
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# A number from pinball's --json (the first key of that name).
field() { sed -n "s/^ *\"$1\": \\([-0-9.e+]*\\),\\{0,1\\}\$/\\1/p" "$2" | head -1; }
# The figures that must not change with the layout: every score, mean and count.
figures() { grep -E '"(mean_score_per_ball|score_ci95_half_width|mean_ball_time_s|flips_per_ball|examples|balls_cut_at_time_limit|fires)"' "$1"; }

workloads=(
  "evaluation|learn boards/mit1993.board --method spastic --eval-balls $eval_balls --seed $seed --json"
  "teacher|learn boards/mit1993.board --method imitate --rounds 1 --budget-balls $teacher_balls --eval-balls 1 --seed $seed --json --out $work/imitation.json"
)
# label | ranks | threads per rank
layouts=("1 process, 1 thread (baseline)|1|1" "1 process, 2 threads|1|2" "2 ranks x 1 thread|2|1" "4 ranks x 1 thread (oversubscribed)|4|1")

rows=()
for w in "${workloads[@]}"; do
  IFS='|' read -r name args <<<"$w"
  base_rate=""
  base_figures="$work/$name.figures"
  for l in "${layouts[@]}"; do
    IFS='|' read -r label ranks threads <<<"$l"
    out="$work/$name.$ranks.$threads.json"
    start=$(date +%s.%N)
    if [ "$ranks" = 1 ]; then
      # shellcheck disable=SC2086
      "$exe" $args --threads "$threads" >"$out"
    else
      # shellcheck disable=SC2086
      mpirun --oversubscribe -n "$ranks" "$exe" $args --threads "$threads" >"$out"
    fi
    end=$(date +%s.%N)
    if [ "$name" = evaluation ]; then
      rate=$(field balls_per_s "$out")                       # the evaluation's own clock
      phase_s=$(awk -v b="$eval_balls" -v r="$rate" 'BEGIN { printf "%.3f", b / r }')
    else
      phase_s=$(field wall_s "$out")                         # the teacher's round
      rate=$(awk -v b="$teacher_balls" -v s="$phase_s" 'BEGIN { printf "%.4f", b / s }')
    fi
    if [ -z "$base_rate" ]; then
      base_rate=$rate
      figures "$out" >"$base_figures"
    elif ! figures "$out" | cmp -s - "$base_figures"; then
      echo "mpi_scaling: $name on '$label' gave other figures than the baseline" >&2
      diff <(figures "$out") "$base_figures" >&2 || true
      exit 1
    fi
    comm=$(field mpi_comm_s "$out")
    wait=$(field mpi_wait_s "$out")
    bytes=$(field mpi_bytes_received "$out")
    rows+=("$name|$label|$ranks|$threads|$rate|$(awk -v r="$rate" -v b="$base_rate" 'BEGIN { printf "%.2f", r / b }')|$phase_s|$(awk -v a="$start" -v b="$end" 'BEGIN { printf "%.2f", b - a }')|$comm|$wait|$bytes")
  done
done

if $json; then
  printf '{\n  "eval_balls": %s,\n  "teacher_balls": %s,\n  "seed": %s,\n  "runs": [\n' "$eval_balls" "$teacher_balls" "$seed"
  for i in "${!rows[@]}"; do
    IFS='|' read -r name label ranks threads rate speedup phase wall comm wait bytes <<<"${rows[$i]}"
    sep=","
    [ "$i" = $((${#rows[@]} - 1)) ] && sep=""
    printf '    {"workload": "%s", "layout": "%s", "ranks": %s, "threads_per_rank": %s, "balls_per_s": %s, "speedup": %s, "phase_s": %s, "command_wall_s": %s, "mpi_comm_s": %s, "mpi_wait_s": %s, "mpi_bytes_received": %s, "mpi_comm_share": %s}%s\n' \
      "$name" "$label" "$ranks" "$threads" "$rate" "$speedup" "$phase" "$wall" "$comm" "$wait" "$bytes" \
      "$(awk -v c="$comm" -v p="$phase" 'BEGIN { printf "%.5f", c / p }')" "$sep"
  done
  printf '  ]\n}\n'
else
  printf '%-10s %-38s %10s %8s %9s %9s %10s %10s %12s\n' workload layout balls/s speed-up phase_s wall_s comm_s wait_s bytes_in
  for r in "${rows[@]}"; do
    IFS='|' read -r name label ranks threads rate speedup phase wall comm wait bytes <<<"$r"
    printf '%-10s %-38s %10.2f %8s %9.2f %9s %10.4f %10.4f %12s\n' "$name" "$label" "$rate" "$speedup" "$phase" "$wall" "$comm" "$wait" "$bytes"
  done
fi
