#!/usr/bin/env python3
"""scripts/regress.py catches a changed figure: a copy of a configuration (spec_narrow.json) with
one expected figure altered must exit 1 with the line naming that figure and both values.
With --target ice40 (how ctest checks the span modes synthesised for iCE40 alone), a changed
ice40 figure is still named, a changed xc7 figure is not compared, and --update rewrites the
ice40 figures while leaving the xc7 ones as recorded.

  regress_detects_change.py --shadesim BIN --synth-dir DIR CONFIG.json
"""
import argparse
import json
import os
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def regress(a, synth, copy, *args):
    cmd = [sys.executable, os.path.join(ROOT, "scripts", "regress.py"), *args,
           "--shadesim", a.shadesim, "--synth-dir", synth, copy]
    r = subprocess.run(cmd, capture_output=True, text=True)
    print(r.stdout, end="")
    print(r.stderr, end="", file=sys.stderr)
    return r


def changed_lines(r):
    return [l for l in r.stdout.splitlines() if "expected" in l and ", got " in l]


def write_altered(copy, text, alter):
    j = json.loads(text)
    alter(j["expected"])
    with open(copy, "w", encoding="utf-8") as f:
        json.dump(j, f, indent=2)


def check(ok, what):
    if not ok:
        print(f"FAIL: {what}", file=sys.stderr)
    return ok


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--shadesim", required=True)
    p.add_argument("--synth-dir", required=True)
    p.add_argument("config")
    a = p.parse_args()
    base = os.path.basename(a.config)
    unit_name = base[:-len(".json")]
    with tempfile.TemporaryDirectory(prefix="regress_detects_") as tmp:
        copy = os.path.join(tmp, base)
        # The synthesis summary is looked up by <unit>_<name> and must name the config file it
        # synthesised: give the copy a summary of its own that points at it.
        synth = os.path.join(tmp, "synth")
        os.makedirs(os.path.join(synth, unit_name))
        with open(os.path.join(a.synth_dir, unit_name, "summary.json"), encoding="utf-8") as f:
            summary = json.load(f)
        summary["config_file"] = copy
        with open(os.path.join(synth, unit_name, "summary.json"), "w", encoding="utf-8") as f:
            json.dump(summary, f)
        with open(a.config, encoding="utf-8") as f:
            text = f.read()
        exp = json.loads(text)["expected"]

        # Both targets compared: the changed scene figure named, nothing else.
        was = exp["sphere"]["spec_cycles"]
        write_altered(copy, text, lambda e: e["sphere"].update(spec_cycles=was + 1))
        r = regress(a, synth, copy, "--check")
        want = f"regress: {unit_name}: sphere.spec_cycles: expected {was + 1}, got {was}"
        if not (check(r.returncode == 1, f"regress.py exited {r.returncode}, expected 1")
                and check(want in r.stdout.splitlines(), f"no line {want!r}")
                and check(len(changed_lines(r)) == 1, "other figures reported as changed")):
            return 1

        # --target ice40: the ice40 change named, the xc7 change not compared.
        luts = {t: exp[t]["luts"] for t in ("ice40", "xc7")}
        write_altered(copy, text, lambda e: [e[t].update(luts=luts[t] + 1) for t in luts])
        r = regress(a, synth, copy, "--check", "--target", "ice40")
        want = f"regress: {unit_name}: ice40.luts: expected {luts['ice40'] + 1}, got {luts['ice40']}"
        if not (check(r.returncode == 1, f"regress.py --target ice40 exited {r.returncode}, expected 1")
                and check(changed_lines(r) == [want], f"not exactly the line {want!r}")):
            return 1
        # --update --target ice40: ice40 as synthesised, xc7 as recorded (altered), the rest as is.
        r = regress(a, synth, copy, "--update", "--target", "ice40")
        with open(copy, encoding="utf-8") as f:
            got = json.load(f)["expected"]
        want_exp = dict(exp, xc7=dict(exp["xc7"], luts=luts["xc7"] + 1))
        if not (check(r.returncode == 0, f"regress.py --update --target ice40 exited {r.returncode}")
                and check(got == want_exp and list(got) == list(exp),
                          f"--update --target ice40 wrote {got}, expected {want_exp}")):
            return 1
    print("regress_detects_change: the changed figures were named, the left-out target's kept")
    return 0


if __name__ == "__main__":
    sys.exit(main())
