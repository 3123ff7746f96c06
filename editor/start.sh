#!/usr/bin/env bash
# The main job from a fresh clone: install what is missing, configure, build,
# then open the editor on levels/default.json. With no display (or before the
# editor exists) it runs the level headlessly and prints what it did.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
bash tests/setup-debian.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release
cmake --build build -j "$(nproc)"
level=${1:-levels/default.json}
if [[ -n "${DISPLAY:-}" ]] && ./build/stepwise edit --help >/dev/null 2>&1; then
  exec ./build/stepwise edit "$level"
fi
echo "start: no display or no editor in this build; running $level headlessly"
./build/stepwise validate "$level"
exec ./build/stepwise run "$level" --steps 600 --out build/default-after-600-steps.json --trace build/default-trace.csv
