#!/usr/bin/env bash
# Installs every Debian 12 package Stepwise needs to build, test, benchmark
# and run the editor. Safe to run again: it installs only what is missing.
# Run as root (apt-get).
set -euo pipefail

packages=(
  # toolchain
  cmake g++ make pkg-config python3 git
  # engine and command line
  nlohmann-json3-dev libeigen3-dev libcli11-dev
  # tests and benchmarks (peers: Box2D 2.4.1, Boost.Odeint)
  libgtest-dev libgmock-dev libbenchmark-dev python3-jsonschema libbox2d-dev libboost-dev gnuplot-nox
  # renderer and editor
  libimgui-dev libsdl2-dev libosmesa6-dev libgl-dev libstb-dev libpng-dev
  # the real window under test
  xvfb xdotool xauth
  # fuzzing; lld links the sanitizer and fuzz builds faster
  clang libclang-rt-14-dev lld
)

missing=()
for p in "${packages[@]}"; do
  status=$(dpkg-query -W -f='${db:Status-Status}' "$p" 2>/dev/null || true)
  [[ "$status" == "installed" ]] || missing+=("$p")
done

if ((${#missing[@]} == 0)); then
  echo "setup: all ${#packages[@]} packages present"
  exit 0
fi

if [[ $(id -u) -ne 0 ]]; then
  echo "setup: error: missing packages: ${missing[*]}" >&2
  echo "setup: run this as root (or: sudo apt-get install ${missing[*]})" >&2
  exit 2
fi

echo "setup: installing ${#missing[@]} packages: ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
apt-get update -qq
apt-get install -y -qq --no-install-recommends "${missing[@]}"
