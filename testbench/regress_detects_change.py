#!/usr/bin/env python3
"""scripts/regress.py --check catches a changed figure: a copy of a configuration (spec_narrow.json)
with one expected figure altered must exit 1 with the line naming that figure and both values.

  regress_detects_change.py --shadesim BIN --synth-dir DIR CONFIG.json
"""
import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


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
        shutil.copyfile(a.config, copy)
        # The synthesis summary is looked up by <unit>_<name> and must name the config file it
        # synthesised: give the copy a summary of its own that points at it.
        synth = os.path.join(tmp, "synth")
        os.makedirs(os.path.join(synth, unit_name))
        with open(os.path.join(a.synth_dir, unit_name, "summary.json"), encoding="utf-8") as f:
            summary = json.load(f)
        summary["config_file"] = copy
        with open(os.path.join(synth, unit_name, "summary.json"), "w", encoding="utf-8") as f:
            json.dump(summary, f)

        with open(copy, encoding="utf-8") as f:
            text = f.read()
        j = json.loads(text)
        was = j["expected"]["sphere"]["spec_cycles"]
        j["expected"]["sphere"]["spec_cycles"] = was + 1
        with open(copy, "w", encoding="utf-8") as f:
            json.dump(j, f, indent=2)

        cmd = [sys.executable, os.path.join(ROOT, "scripts", "regress.py"), "--check",
               "--shadesim", a.shadesim, "--synth-dir", synth, copy]
        r = subprocess.run(cmd, capture_output=True, text=True)
        want = f"regress: {unit_name}: sphere.spec_cycles: expected {was + 1}, got {was}"
        print(r.stdout, end="")
        print(r.stderr, end="", file=sys.stderr)
        if r.returncode != 1:
            print(f"FAIL: regress.py exited {r.returncode}, expected 1", file=sys.stderr)
            return 1
        lines = r.stdout.splitlines()
        if want not in lines:
            print(f"FAIL: no line {want!r}", file=sys.stderr)
            return 1
        if len([l for l in lines if "expected" in l and ", got " in l]) != 1:
            print("FAIL: other figures reported as changed", file=sys.stderr)
            return 1
    print("regress_detects_change: the changed figure was named")
    return 0


if __name__ == "__main__":
    sys.exit(main())
