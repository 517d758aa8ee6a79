#!/usr/bin/env bash
# Installs the Debian packages shadesim builds and runs with, skipping the ones present.
# Every package the build, the tests or the demo use is listed here, including those a fresh
# machine may already have, so that nothing depends on a hand-installed tool.
set -euo pipefail
packages=(
  build-essential cmake ninja-build pkg-config python3 python3-matplotlib
  verilator iverilog yosys nextpnr-ice40 libjemalloc2
  sollya gappa clang parallel
  libsystemc-dev libfmt-dev libcli11-dev nlohmann-json3-dev
  libgtest-dev libgmock-dev libbenchmark-dev libpng-dev
  libassimp-dev assimp-testmodels
)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install_deps: all ${#packages[@]} packages present"
  exit 0
fi
echo "install_deps: installing ${missing[*]}"
sudo=""
[ "$(id -u)" = 0 ] || sudo="sudo"
export DEBIAN_FRONTEND=noninteractive
$sudo apt-get update -qq
$sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
echo "install_deps: done"
