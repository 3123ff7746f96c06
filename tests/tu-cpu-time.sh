#!/usr/bin/env bash
# A compiler launcher that logs each translation unit's CPU time (user +
# system seconds) and object to $TU_LOG: compares build cost on a machine
# shared with other work, where wall times mean little.
#   cmake -S . -B /tmp/b -DCMAKE_CXX_COMPILER_LAUNCHER=$PWD/tests/tu-cpu-time.sh
#   TU_LOG=/tmp/tu.log cmake --build /tmp/b -j2
#   awk '{s += $1 + $2} END {print NR " units, " s " CPU s"}' /tmp/tu.log
out="" prev=""
for a in "$@"; do
  [[ $prev == -o ]] && out=$a
  prev=$a
done
timing=$(mktemp)
/usr/bin/time -f "%U %S" -o "$timing" "$@"
rc=$?
read -r user sys < "$timing" && echo "$user $sys $PWD/$out" >> "${TU_LOG:?set TU_LOG to a log file}"
rm -f "$timing"
exit $rc
