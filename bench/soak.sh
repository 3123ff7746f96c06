#!/usr/bin/env bash
# Soak: every shipped level runs STEPS steps headless through
# `stepwise run`, which checks every state for non-finite values (exit 3
# names the step, entity and quantity). Memory must stay flat: the script
# prints the peak resident set (getrusage's ru_maxrss through /usr/bin/time)
# of the level run for 1,000 steps (the start) and of the long run (the
# end); a leak or a growing cache shows as growth between the two.
# Not a timed test and not in CI: it takes hours at 1,000,000 steps.
#
#   bash bench/soak.sh [--steps N] [--max-minutes M] [--binary PATH] [LEVEL...]
#
#   --steps N        steps per level (default 1000000)
#   --max-minutes M  cap each level's run at about M minutes: the level's
#                    speed is measured first and its steps are cut to fit,
#                    and the table says how many it ran (default: no cap)
#   --binary PATH    the stepwise executable (default build/stepwise)
#   LEVEL...         default: every levels/*.json (joints: bridge, car,
#                    chain, ragdoll; polygons: car, polygons) and
#                    tests/data/joints_every_type.json (the slider, distance
#                    and rope joints no shipped level uses)
#
# Output: one Markdown table row per level (steps run, ms/step including
# start-up, peak RSS at the start and at the end in MiB, growth, result).
set -uo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
steps=1000000
max_minutes=0
binary="$root/build/stepwise"
levels=()
while (($#)); do
  case "$1" in
    --steps) steps=$2; shift 2 ;;
    --max-minutes) max_minutes=$2; shift 2 ;;
    --binary) binary=$2; shift 2 ;;
    -h|--help) sed -n '2,23p' "$0"; exit 0 ;;
    *) levels+=("$1"); shift ;;
  esac
done
if ((${#levels[@]} == 0)); then
  for f in "$root"/levels/*.json; do
    [[ $(basename "$f") == scene.schema.json ]] || levels+=("$f")
  done
  levels+=("$root/tests/data/joints_every_type.json")
fi
[[ -x $binary ]] || { echo "soak: $binary is not built (cmake --build build)" >&2; exit 2; }

peak_kib() {  # peak_kib STEPS: runs the level, prints "KIB SECONDS STATUS"; stderr to $err
  /usr/bin/time -f "%M %e" -o "$tm" "$binary" run "$level" --steps "$1" >/dev/null 2>"$err"
  local status=$?
  echo "$(cat "$tm") $status"
}

echo "| level | steps | ms/step | peak RSS after 1,000 steps (MiB) | peak RSS at the end (MiB) | growth | result |"
echo "|---|---:|---:|---:|---:|---:|---|"
failed=0
err=$(mktemp)
tm=$(mktemp)
trap 'rm -f "$err" "$tm"' EXIT
for level in "${levels[@]}"; do
  name=$(basename "$level" .json)
  # Start: the peak resident set of the same level run for 1,000 steps
  # (loaded, world built, caches and contact arrays at their working size).
  read -r early t_early status <<<"$(peak_kib 1000)"
  if ((status != 0)); then
    echo "| $name | 0 | - | - | - | - | does not run: $(head -c 200 "$err" | tr '\n' ' ') |"
    failed=1
    continue
  fi
  n=$steps
  if ((max_minutes > 0)); then
    # Speed from 1,000 vs 3,000 steps, so process start-up does not count.
    read -r _ t_more _ <<<"$(peak_kib 3000)"
    fit=$(awk -v a="$t_early" -v b="$t_more" -v m="$max_minutes" \
      'BEGIN {ms = (b - a) * 1000 / 2000; if (ms <= 0) ms = 0.0005; printf "%d", m * 60000 / ms}')
    ((fit < n)) && n=$fit
  fi
  # End: the peak of the whole long run (VmHWM at exit, from wait4).
  read -r late t_late status <<<"$(peak_kib "$n")"
  case $status in
    0) result="ok" ;;
    3) result="NON-FINITE: $(head -c 200 "$err" | tr '\n' ' ')"; failed=1 ;;
    *) result="exit $status: $(head -c 200 "$err" | tr '\n' ' ')"; failed=1 ;;
  esac
  awk -v l="$name" -v n="$n" -v t="$t_late" -v e="$early" -v f="$late" -v r="$result" 'BEGIN {
    printf "| %s | %d | %.4f | %.1f | %.1f | %+.1f%% | %s |\n", l, n, t * 1000 / n, e / 1024, f / 1024,
           (e > 0 ? (f - e) * 100 / e : 0), r }'
done
exit $failed
