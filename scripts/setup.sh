#!/usr/bin/env bash
# Installs every Debian 12 package the build, tests, benchmarks and demo need.
# Idempotent: skips the install when every package is already present.
# --demo adds what only the MuJoCo demo needs (ffmpeg for the MP4); --fuzz adds clang-14 and
# its libFuzzer/sanitizer runtimes for tests/fuzz (scripts/fuzz.sh; scripts/test.sh runs them).
# --rt adds cyclictest (rt-tests) and stress-ng for the jitter measurements of docs/realtime.md.
set -euo pipefail

PACKAGES=(
  build-essential cmake git pkg-config
  libeigen3-dev liburdfdom-dev
  libmujoco-dev libgl-dev libegl-dev libqhull-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libyaml-cpp-dev libcli11-dev nlohmann-json3-dev libnlopt-cxx-dev
  liblodepng-dev
  python3 python3-numpy python3-scipy python3-matplotlib
)
for arg in "$@"; do
  case "$arg" in
    --demo) PACKAGES+=(ffmpeg) ;;
    --fuzz) PACKAGES+=(clang-14 libclang-rt-14-dev llvm-14) ;;
    --rt) PACKAGES+=(rt-tests stress-ng) ;;
    *) echo "setup: unknown option $arg" >&2; exit 2 ;;
  esac
done

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#PACKAGES[@]} Debian packages already installed"
  exit 0
fi

SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
echo "setup: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update
$SUDO apt-get install -y --no-install-recommends "${missing[@]}"
echo "setup: done"
