# shellcheck shell=bash
# Sourced by test.sh and demo.sh, after install_deps.sh: when `python3` on PATH is a version
# manager's shim, puts the directory of the interpreter it runs first on PATH. pyenv's shim is a
# shell script that starts a dozen processes to choose the interpreter on every call: `python3 -c
# pass` takes 0.52 CPU-s through it against 0.11 for the interpreter itself (10 calls each, 3
# interleaved rounds, one of this project's 2-core machines), and the tests call python3 hundreds
# of times (scripts/lint.sh alone twice per configuration). The interpreter is the one the shim
# runs, chosen once here the way the shim chooses it.
shd_direct_python() {
  local exe
  exe=$(python3 -c 'import sys; print(sys.executable)' 2>/dev/null) || return 0
  [ -x "$exe" ] || return 0
  [ "$(dirname "$exe")" != "$(dirname "$(command -v python3)")" ] || return 0
  echo "direct_python: python3 is $(command -v python3), which runs $exe: $(dirname "$exe") first on PATH"
  PATH="$(dirname "$exe"):$PATH"
  export PATH
}
shd_direct_python
