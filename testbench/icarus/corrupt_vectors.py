#!/usr/bin/env python3
"""corrupt_vectors.py IN OUT: a copy of a shadesim vector file (sim/vectors/vector_file.h) with exactly one
expected output value wrong, to prove that a replay fails when it should.

The value changed is the least significant bit of
  spec: exp_spec of the first cycle line, from the middle of the file on, whose exp_valid is 1;
  span: attribute 0 of the lowest expected-valid lane of the first C record, from the middle of
        the file on, whose exp_out_valid is 1.
A relative "# prom" path is made absolute, since the copy lives elsewhere. Prints the cycle
(1-based, as the testbenches count) and the port name the replays report, e.g. "1517 spec_o".
"""
import os
import sys


def main():
    if len(sys.argv) != 3:
        sys.exit("usage: corrupt_vectors.py IN OUT")
    src, dst = sys.argv[1], sys.argv[2]
    with open(src) as f:
        lines = f.read().split("\n")
    unit = next((l.split()[2] for l in lines if l.startswith("# unit ")), None)
    if unit not in ("spec", "span"):
        sys.exit(f"corrupt_vectors.py: {src}: no '# unit spec|span' line")
    cycle_lines = [i for i, l in enumerate(lines)
                   if l and not l.startswith("#") and (unit == "spec" or l.startswith("C "))]
    if not cycle_lines:
        sys.exit(f"corrupt_vectors.py: {src}: no cycles")
    done = None
    for cycle, i in enumerate(cycle_lines, start=1):
        if cycle <= len(cycle_lines) // 2:
            continue
        t = lines[i].split()
        if unit == "spec" and t[6] == "1":
            t[7] = format(int(t[7], 16) ^ 1, "x")
            done = (cycle, "spec_o")
        elif unit == "span" and t[4] == "1":
            mask = int(t[6], 16)
            lane = (mask & -mask).bit_length() - 1
            t[9] = format(int(t[9], 16) ^ 1, "x")  # x y attr0 of the first valid lane follow the mask
            done = (cycle, f"out_attr_o[lane {lane} attr 0]")
        if done:
            lines[i] = " ".join(t)
            break
    if not done:
        sys.exit(f"corrupt_vectors.py: {src}: no cycle with a valid output in its second half")
    for i, l in enumerate(lines):
        if l.startswith("# prom ") and not os.path.isabs(l[7:]):
            lines[i] = "# prom " + os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(src)), l[7:]))
    with open(dst, "w") as f:
        f.write("\n".join(lines))
    print(done[0], done[1])


if __name__ == "__main__":
    main()
