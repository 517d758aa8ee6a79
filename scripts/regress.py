#!/usr/bin/env python3
"""Named baselines: each configuration's "expected" figures, recomputed and compared.

A configuration file (vectors/config/<unit>_<name>.json) ends with a member "expected" that
records what the configuration reaches (the figure names: EXPECTED in scripts/shd_config.py):

  spec  error.{total_max_lsb, total_peak_max_lsb, datapath_max_lsb, datapath_max_f_lsb}
            the summary of `shadesim spec-error --config FILE --json`
        latency   cycles valid_i -> valid_o: 2 + PipeStages (model/device/spec_params.h)
        <scene>.{spec_cycles, spec_evaluations, max_abs_lsb}
            `shadesim render --scene vectors/scenes/<scene>.json --method phong-fixed
             --brdf quadratic --quadratic-config FILE` (Degree 3: --brdf cubic --cubic-config)
  span  <scene>.{cycles, fragments}
            `shadesim render --scene vectors/scenes/<scene>.json --method gouraud --mode FILE`
  both  <target>.{luts, ffs, carries, dsps, brams}  for ice40 and xc7, from
            <synth-dir>/<unit>_<name>/summary.json (ctest -R synth_ writes it); --target ice40
            or xc7 compares (or updates) that target's alone and leaves the other's as recorded

The scenes are sphere and still_life. Figures are compared exactly: the model is deterministic.

  regress.py --check  [--shadesim BIN] [--synth-dir DIR] [--target T] [CONFIG.json ...]
        prints "regress: <unit>_<name>: <group>.<figure>: expected X, got Y" for every figure
        that differs (or is missing); exit 1 when one does
  regress.py --update [...]   rewrites only the "expected" member of each file (atomically, in
        the files' own style: one line per group); commit the diff
No CONFIG: the whole registry (scripts/shd_config.py list). Exit 0, 1 (a figure changed) or 2
with "regress.py: error: ..." when the figures cannot be computed.
"""
import argparse
import concurrent.futures
import json
import os
import re
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
import shd_config  # noqa: E402

ERROR_FIGURES = shd_config.EXPECTED["spec"]["error"]


class RegressError(Exception):
    pass


def run_json(cmd, out_json):
    """Runs shadesim; the JSON it wrote to out_json."""
    try:
        p = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, timeout=1800)
    except OSError as e:
        raise RegressError(f"cannot run {cmd[0]}: {e.strerror}")
    except subprocess.TimeoutExpired:
        raise RegressError(f"timed out: {' '.join(cmd)}")
    if p.returncode != 0:
        raise RegressError(f"{' '.join(cmd)} exited {p.returncode}: {p.stderr.strip()[-2000:]}")
    try:
        with open(out_json, encoding="utf-8") as f:
            return json.load(f)
    except (OSError, ValueError) as e:
        raise RegressError(f"{' '.join(cmd)}: no JSON in {out_json}: {e}")


def area(c, synth_dir, targets):
    path = os.path.join(synth_dir, f"{c.unit}_{c.name}", "summary.json")
    try:
        with open(path, encoding="utf-8") as f:
            s = json.load(f)
    except (OSError, ValueError) as e:
        raise RegressError(f"{path}: cannot read the synthesis summary ({e}); run "
                           f"ctest -R synth_{c.unit}_{c.name} first")
    if s.get("config_file") and os.path.abspath(s["config_file"]) != os.path.abspath(c.path):
        raise RegressError(f"{path}: synthesised {s['config_file']}, not {c.path}")
    out = {}
    for tgt in targets:
        t = s.get("targets", {}).get(tgt)
        if t is None:
            raise RegressError(f"{path}: no target {tgt} (synth.py --target {tgt}, or --target both)")
        out[tgt] = {f: t[f] for f in shd_config.EXPECTED[c.unit][tgt]}
    return out


def figures(c, shadesim, synth_dir, targets):
    """Every figure of EXPECTED[c.unit] for configuration c, computed now: the area of `targets`."""
    fig = {}
    cfg = os.path.abspath(c.path)
    with tempfile.TemporaryDirectory(prefix=f"regress_{c.unit}_{c.name}_") as tmp:
        if c.unit == "spec":
            js = os.path.join(tmp, "spec_error.json")
            j = run_json([shadesim, "spec-error", "--config", cfg, "--compare", "none", "--json-out", js,
                          "--quiet"], js)
            fig["error"] = {f: j["summary"][f]["value"] for f in ERROR_FIGURES}
            fig["latency"] = 2 + c.rtl.get("PipeStages", 1)  # SpecUnitParams::latency()
            lobe = "cubic" if c.rtl.get("Degree", 2) == 3 else "quadratic"
            method = ["--method", "phong-fixed", "--brdf", lobe, f"--{lobe}-config", cfg]
        else:
            method = ["--method", "gouraud", "--mode", cfg]
        for scene in shd_config.SCENES:
            js = os.path.join(tmp, f"{scene}.json")
            j = run_json([shadesim, "render", "--scene", os.path.join(ROOT, "vectors", "scenes", f"{scene}.json")]
                         + method + ["-o", os.path.join(tmp, f"{scene}.png"), "--json", js, "--quiet"], js)
            fig[scene] = {f: j[f] for f in shd_config.EXPECTED[c.unit][scene]}
    fig.update(area(c, synth_dir, targets))
    return fig


def flatten(exp):
    """{"group.figure": value} (a one-number group: {"group": value})."""
    out = {}
    for g, v in exp.items():
        if isinstance(v, dict):
            out.update({f"{g}.{f}": x for f, x in v.items()})
        else:
            out[g] = v
    return out


def differences(c, expected, got):
    e, g = flatten(expected or {}), flatten(got)
    lines = []
    for k in list(g) + [k for k in e if k not in g]:
        ev = json.dumps(e[k]) if k in e else "(none)"
        gv = json.dumps(g[k]) if k in g else "(none)"
        if k not in e or k not in g or e[k] != g[k]:
            lines.append(f"regress: {c.unit}_{c.name}: {k}: expected {ev}, got {gv}")
    return lines


def expected_text(fig):
    """The "expected" member in the files' style: one line per group, two-space indent."""
    rows = []
    for g, v in fig.items():
        if isinstance(v, dict):
            inner = ", ".join(f"{json.dumps(f)}: {json.dumps(x)}" for f, x in v.items())
            rows.append(f'    "{g}": {{ {inner} }}')
        else:
            rows.append(f'    "{g}": {json.dumps(v)}')
    return '"expected": {\n' + ",\n".join(rows) + "\n  }"


def rewrite(c, fig):
    """The file's text with "expected" (its last member) replaced or appended; the rest as is."""
    text = c.text
    old = json.loads(text)
    body = text.rstrip()
    if not body.endswith("}"):
        raise RegressError(f"{c.path}: does not end with '}}'")
    body = body[:-1].rstrip()
    if "expected" in old:
        if list(old)[-1] != "expected":
            raise RegressError(f"{c.path}: \"expected\" must be the last member to be rewritten")
        m = list(re.finditer(r',\s*"expected"\s*:', body))
        if not m:
            raise RegressError(f"{c.path}: cannot find the \"expected\" member")
        body = body[:m[-1].start()]
    new = body + ",\n  " + expected_text(fig) + "\n}\n"
    j = json.loads(new)  # the other members must be untouched
    if {k: v for k, v in j.items() if k != "expected"} != {k: v for k, v in old.items() if k != "expected"} \
            or j["expected"] != fig:
        raise RegressError(f"{c.path}: rewriting \"expected\" would change other members")
    shd_config.parse(new, c.path, c.unit, c.name)
    return new


def main(argv):
    p = argparse.ArgumentParser(prog="regress.py", description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    mode = p.add_mutually_exclusive_group(required=True)
    mode.add_argument("--check", action="store_true", help="compare; exit 1 on any difference")
    mode.add_argument("--update", action="store_true", help="rewrite the expected figures")
    p.add_argument("--shadesim", default=os.path.join(ROOT, "build", "sim", "shadesim"))
    p.add_argument("--synth-dir", default=os.path.join(ROOT, "build", "synth"))
    p.add_argument("--target", choices=("ice40", "xc7", "both"), default="both",
                   help="the synthesis targets whose area is compared or updated (the other's figures "
                        "are left as recorded)")
    p.add_argument("-j", "--jobs", type=int, default=1, help="configurations computed at once")
    p.add_argument("configs", nargs="*", metavar="CONFIG.json")
    a = p.parse_args(argv)
    targets = shd_config.TARGETS if a.target == "both" else (a.target,)
    left_out = [t for t in shd_config.TARGETS if t not in targets]
    try:
        if not os.access(a.shadesim, os.X_OK):
            raise RegressError(f"{a.shadesim}: no shadesim binary (--shadesim)")
        if a.configs:
            configs = [shd_config.load_file(f) for f in a.configs]
        else:
            configs = shd_config.registry([shd_config.DEFAULT_DIR])
        if not configs:
            raise RegressError("no configuration")
        with concurrent.futures.ThreadPoolExecutor(max(1, a.jobs)) as pool:
            results = list(pool.map(lambda c: figures(c, a.shadesim, a.synth_dir, targets), configs))
        failed = 0
        for c, fig in zip(configs, results):
            old = json.loads(c.text).get("expected") or {}
            if a.check:
                lines = differences(c, {g: v for g, v in old.items() if g not in left_out}, fig)
                for l in lines:
                    print(l)
                failed += bool(lines)
                if not lines:
                    print(f"regress: {c.unit}_{c.name}: {len(flatten(fig))} figures as expected"
                          + "".join(f" ({t} not compared)" for t in left_out))
            else:
                # The left-out target's figures as recorded, in the groups' order.
                fig = {g: fig[g] if g in fig else old[g] for g in shd_config.EXPECTED[c.unit]
                       if g in fig or g in old}
                new = rewrite(c, fig)
                if new != c.text:
                    shd_config.write_if_changed(c.path, new)  # a temporary file, then rename
                    print(f"regress: {c.unit}_{c.name}: updated {c.path}")
                else:
                    print(f"regress: {c.unit}_{c.name}: unchanged")
    except (RegressError, shd_config.ConfigError) as e:
        print(f"regress.py: error: {e}", file=sys.stderr)
        return 2
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
