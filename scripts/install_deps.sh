#!/usr/bin/env bash
# Installs the Debian packages shadesim builds and runs with, skipping the ones present.
#   scripts/install_deps.sh [GROUP...]     groups: build tools fuzz (default: build tools)
# Every package the build, the tests, the demo or a script uses is listed here, including those
# a fresh machine may already have, so that nothing depends on a hand-installed tool.
#   build  what the build compiles and links with (scripts/build.sh)
#   tools  what the tests and the demo run beside shadesim: simulators, synthesis, place and
#          route, the provers, plots, the mesh corpus
#   fuzz   clang for the libFuzzer build (scripts/fuzz.sh)
# On a fresh 2-core machine the install is mostly CPU (unpacking, byte-compiling): installing
# the tools while the build compiled gained nothing measurable (docs/verification.md).
set -euo pipefail
group_packages() {
  case "$1" in
    build) echo build-essential cmake ninja-build pkg-config python3 verilator \
                libsystemc-dev libfmt-dev libcli11-dev nlohmann-json3-dev \
                libgtest-dev libgmock-dev libbenchmark-dev libpng-dev libassimp-dev ;;
    tools) echo iverilog yosys nextpnr-ice40 libjemalloc2 sollya gappa parallel \
                gnuplot-nox assimp-testmodels ;;
    fuzz) echo clang ;;
    *) echo "install_deps: unknown group '$1' (build, tools, fuzz)" >&2; return 2 ;;
  esac
}
groups=("$@")
[ ${#groups[@]} -gt 0 ] || groups=(build tools)
packages=()
for g in "${groups[@]}"; do
  list=$(group_packages "$g") || exit 2
  read -r -a more <<< "$list"
  packages+=("${more[@]}")
done
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install_deps: all ${#packages[@]} packages of ${groups[*]} present"
  exit 0
fi
echo "install_deps: installing ${missing[*]}"
sudo=""
[ "$(id -u)" = 0 ] || sudo="sudo"
export DEBIAN_FRONTEND=noninteractive
install() { $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null; }
# The package lists are read again only when they do not know every missing package (a fresh
# machine), or when an install from them fails (lists older than the mirror's files).
if ! apt-cache show "${missing[@]}" >/dev/null 2>&1; then
  $sudo apt-get update -qq
  install
elif ! install; then
  echo "install_deps: the install failed; reading the package lists again and retrying"
  $sudo apt-get update -qq
  install
fi
echo "install_deps: done"
