# Sourced by the test scripts that take a work directory: fresh_work DIR empties DIR for the
# test, but only if it is missing, empty, or an earlier run's work directory (it holds the
# marker file). Any other directory is refused, never deleted: a mistyped argument (the source
# tree, a home directory) must not be wiped.
fresh_work() {
  local dir=$1
  if [ -e "$dir" ] && [ ! -f "$dir/.shadesim-test-work" ] && [ -n "$(ls -A "$dir" 2>/dev/null)" ]; then
    echo "$(basename "$0"): $dir exists and is not a work directory of these tests; refusing to delete it" >&2
    exit 2
  fi
  rm -rf "$dir"
  mkdir -p "$dir"
  touch "$dir/.shadesim-test-work"
}
