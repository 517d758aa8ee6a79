# shellcheck shell=bash
# Sourced by test.sh and demo.sh:  shd_install_and_build BUILD_DIR [cmake -D options...]
# Installs the packages the build needs (scripts/install_deps.sh build), then installs the others
# (group tools: yosys, nextpnr, Icarus, the provers, matplotlib, ...) in the background while
# scripts/build.sh compiles into BUILD_DIR, and waits for that install before returning. A fresh
# machine's install is mostly unpacking files; beside the compile it costs the run little
# (docs/verification.md, "Run time"). The install's output follows the build's. If the build
# fails, or the script is interrupted, the exit still waits for the install to end: dpkg is
# never left halfway.
shd_deps_dir=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)

# Waits for the background install; prints its output; its exit status.
shd_tools_wait() {
  [ -n "${shd_tools_pid:-}" ] || return 0
  local status=0
  wait "$shd_tools_pid" || status=$?
  cat "$shd_tools_log"
  rm -f "$shd_tools_log"
  shd_tools_pid=
  [ "$status" = 0 ] || echo "install_deps: installing the tools group failed (exit $status)" >&2
  return "$status"
}

shd_install_and_build() {
  local dir=$1
  shift
  "$shd_deps_dir/install_deps.sh" build
  # shellcheck source=direct_python.sh
  source "$shd_deps_dir/direct_python.sh"
  shd_tools_log=$(mktemp)
  "$shd_deps_dir/install_deps.sh" tools > "$shd_tools_log" 2>&1 &
  shd_tools_pid=$!
  trap 'shd_tools_wait || true' EXIT
  "$shd_deps_dir/build.sh" "$dir" "$@"
  shd_tools_wait
  trap - EXIT
}
