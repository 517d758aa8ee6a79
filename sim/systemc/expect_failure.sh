#!/usr/bin/env bash
# Runs a command that must fail in one particular way: passes only if it exits with <status> and
# a line of its stderr matches <regex> (grep -E). So a fault-injection run (status 1, a MISMATCH
# line) cannot pass by failing for another reason (2 = bad input, a crash), and a bad-input run
# must say what is wrong.
#   expect_failure.sh <status> <regex> <command> [arguments...]
set -uo pipefail
want=$1 regex=$2
shift 2
err=$(mktemp)
trap 'rm -f "$err"' EXIT
"$@" 2>"$err"
rc=$?
cat "$err" >&2
if [ "$rc" -ne "$want" ]; then
  echo "expect_failure: exit status $rc, expected $want" >&2
  exit 1
fi
if ! grep -Eq -- "$regex" "$err"; then
  echo "expect_failure: exit status $rc but no stderr line matches '$regex'" >&2
  exit 1
fi
echo "expect_failure: failed as required (status $rc): $(grep -E -m1 -- "$regex" "$err")"
