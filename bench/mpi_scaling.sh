#!/usr/bin/env bash
# Scaling across MPI ranks on this machine: an evaluation (the spastic
# flipper on fresh balls) and the imitation method's teacher (its first
# round), each played by one process on one thread (the baseline), one
# process on 2 threads, 2 ranks of one thread, and 4 ranks oversubscribed on
# the 2 cores; and, as the machine's own ceiling, two independent one-thread
# processes at once (their speeds added). Every run must give the same
# figures as the baseline (checked: the script fails otherwise). Each layout
# runs --repeats times (this machine's speed wanders by ~10 % from run to
# run): the table gives the median speed with the slowest and fastest, the
# median's speed-up over the baseline's median, and what gathering the
# results cost (mpi_comm_s: moving them once every rank was there;
# mpi_wait_s: waiting for the slowest rank), medians too.
#
# Usage: bench/mpi_scaling.sh [--eval-balls N] [--teacher-balls N] [--seed S] [--repeats R] [--json]
#   from the repository root after `cmake --build --preset release`, with
#   mpirun (openmpi-bin) installed. Balls are cut at 60 s of game time.
set -euo pipefail
cd "$(dirname "$0")/.."

eval_balls=6000
teacher_balls=40
seed=11
repeats=3
json=false
while [ $# -gt 0 ]; do
  case "$1" in
    --eval-balls) eval_balls="$2"; shift 2 ;;
    --teacher-balls) teacher_balls="$2"; shift 2 ;;
    --seed) seed="$2"; shift 2 ;;
    --repeats) repeats="$2"; shift 2 ;;
    --json) json=true; shift ;;
    -h|--help) sed -n '2,19p' "$0"; exit 0 ;;
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
# label | ranks | threads per rank ("independent": two separate processes at once)
layouts=("1 process, 1 thread (baseline)|1|1" "1 process, 2 threads|1|2" "2 ranks x 1 thread|2|1"
         "4 ranks x 1 thread (oversubscribed)|4|1" "2 independent processes (the machine's ceiling)|independent|1")

median() { sort -g | awk '{ v[NR] = $1 } END { print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }

# One run of a layout: prints "balls_per_s phase_s wall_s comm_s wait_s bytes" and checks the figures.
run_once() {
  local name=$1 args=$2 ranks=$3 threads=$4 out=$5 figures_file=$6
  local start end rate phase_s
  start=$(date +%s.%N)
  if [ "$ranks" = independent ]; then
    # shellcheck disable=SC2086
    "$exe" $args --threads "$threads" >"$out.b" &
    # shellcheck disable=SC2086
    "$exe" $args --threads "$threads" >"$out"
    wait
  elif [ "$ranks" = 1 ]; then
    # shellcheck disable=SC2086
    "$exe" $args --threads "$threads" >"$out"
  else
    # shellcheck disable=SC2086
    mpirun --oversubscribe -n "$ranks" "$exe" $args --threads "$threads" >"$out"
  fi
  end=$(date +%s.%N)
  if [ "$name" = evaluation ]; then
    rate=$(field balls_per_s "$out")
    [ "$ranks" = independent ] && rate=$(awk -v a="$rate" -v b="$(field balls_per_s "$out.b")" 'BEGIN { print a + b }')
    phase_s=$(awk -v n="$eval_balls" -v r="$rate" -v k="$([ "$ranks" = independent ] && echo 2 || echo 1)" 'BEGIN { printf "%.3f", k * n / r }')
  else
    phase_s=$(field wall_s "$out")
    rate=$(awk -v n="$teacher_balls" -v s="$phase_s" 'BEGIN { printf "%.4f", n / s }')
    [ "$ranks" = independent ] && rate=$(awk -v a="$rate" -v n="$teacher_balls" -v s="$(field wall_s "$out.b")" 'BEGIN { print a + n / s }')
  fi
  if [ ! -s "$figures_file" ]; then
    figures "$out" >"$figures_file"
  elif ! figures "$out" | cmp -s - "$figures_file"; then
    echo "mpi_scaling: $name with $ranks ranks x $threads threads gave other figures than the baseline" >&2
    exit 1
  fi
  echo "$rate $phase_s $(awk -v a="$start" -v b="$end" 'BEGIN { printf "%.2f", b - a }') $(field mpi_comm_s "$out") $(field mpi_wait_s "$out") $(field mpi_bytes_received "$out")"
}

rows=()
total=$((${#workloads[@]} * ${#layouts[@]} * repeats))
done_runs=0
t0=$(date +%s)
for w in "${workloads[@]}"; do
  IFS='|' read -r name args <<<"$w"
  base_rate=""
  figures_file="$work/$name.figures"
  for l in "${layouts[@]}"; do
    IFS='|' read -r label ranks threads <<<"$l"
    : >"$work/runs"
    for ((k = 0; k < repeats; k++)); do
      run_once "$name" "$args" "$ranks" "$threads" "$work/out.json" "$figures_file" >>"$work/runs"
      done_runs=$((done_runs + 1))
      elapsed=$(($(date +%s) - t0))
      echo "mpi_scaling: $done_runs/$total runs, ${elapsed} s elapsed, ETA $((elapsed * (total - done_runs) / done_runs)) s" >&2
    done
    rate=$(cut -d' ' -f1 "$work/runs" | median)
    lo=$(cut -d' ' -f1 "$work/runs" | sort -g | head -1)
    hi=$(cut -d' ' -f1 "$work/runs" | sort -g | tail -1)
    [ -z "$base_rate" ] && base_rate=$rate
    rows+=("$name|$label|$ranks|$threads|$rate|$lo|$hi|$(awk -v r="$rate" -v b="$base_rate" 'BEGIN { printf "%.2f", r / b }')|$(cut -d' ' -f2 "$work/runs" | median)|$(cut -d' ' -f3 "$work/runs" | median)|$(cut -d' ' -f4 "$work/runs" | median)|$(cut -d' ' -f5 "$work/runs" | median)|$(cut -d' ' -f6 "$work/runs" | median)")
  done
done

if $json; then
  printf '{\n  "eval_balls": %s,\n  "teacher_balls": %s,\n  "seed": %s,\n  "repeats": %s,\n  "runs": [\n' "$eval_balls" "$teacher_balls" "$seed" "$repeats"
  for i in "${!rows[@]}"; do
    IFS='|' read -r name label ranks threads rate lo hi speedup phase wall comm wait bytes <<<"${rows[$i]}"
    sep=","
    [ "$i" = $((${#rows[@]} - 1)) ] && sep=""
    [ "$ranks" = independent ] && ranks='"independent"'
    printf '    {"workload": "%s", "layout": "%s", "ranks": %s, "threads_per_rank": %s, "balls_per_s_median": %s, "balls_per_s_min": %s, "balls_per_s_max": %s, "speedup": %s, "phase_s": %s, "command_wall_s": %s, "mpi_comm_s": %s, "mpi_wait_s": %s, "mpi_bytes_received": %s, "mpi_comm_share": %s}%s\n' \
      "$name" "$label" "$ranks" "$threads" "$rate" "$lo" "$hi" "$speedup" "$phase" "$wall" "$comm" "$wait" "$bytes" \
      "$(awk -v c="$comm" -v p="$phase" 'BEGIN { printf "%.5f", c / p }')" "$sep"
  done
  printf '  ]\n}\n'
else
  printf '%-10s %-48s %18s %8s %9s %9s %10s %10s %10s\n' workload layout "balls/s (min-max)" speed-up phase_s wall_s comm_s wait_s bytes_in
  for r in "${rows[@]}"; do
    IFS='|' read -r name label ranks threads rate lo hi speedup phase wall comm wait bytes <<<"$r"
    printf '%-10s %-48s %7.2f (%.2f-%.2f) %8s %9.2f %9s %10.4f %10.4f %10s\n' "$name" "$label" "$rate" "$lo" "$hi" "$speedup" "$phase" "$wall" "$comm" "$wait" "$bytes"
  done
fi
