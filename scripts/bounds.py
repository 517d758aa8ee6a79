#!/usr/bin/env python3
"""bounds.py: proved error bounds beside the measured worst cases (docs/proved-bounds.md).

Usage: scripts/bounds.py --shadesim build/sim/shadesim [--measure FILE] [--only WHAT ...]
                         [--jobs N] [--work DIR] [--json-out FILE] [--fault KIND] [--quiet]

For every configuration of the shadesim build (`shadesim configs --json`: the registry, one
list for every tool; of the specular unit's kinds the paper's poly only) and for phong-fixed's datapath, this proves a bound with Sollya or Gappa,
measures the same quantity on the model (testbench/test_bounds, built beside shadesim), and
prints a table: configuration, quantity, proved bound, measured worst, gap.

  spec:<name>  approximation  sup over c in [0, 1] of |f - c^n|, f the ideal device on the
               coefficients AS STORED in the PROM (`shadesim prom --config <name> --format
               csv`), clamp and cut code included: Sollya's supnorm per n (spec_approx.sollya)
               on pieces of [0, 1] split at the cut and at the roots of p and p - 1, which this
               script encloses exactly (rational arithmetic). Measured: at every cos code.
               datapath       the unit against that ideal device, before the clamp
               (spec_datapath2.g: every coefficient of the table's range at once; degree 3:
               spec_datapath3.g per entry) and at the colour outputs (spec_output.g), signed, in
               LSBs of f (spec_o) and of the output. Measured exactly at every cos code.
               total          the unit against cos^n at every cos code, output LSBs: L times
               the approximation bound plus the output datapath bound, per n.
  span:<name>  plane          the attribute codes against the exact plane (span_plane.g) for
               the measured viewport and for the largest the configuration allows. Measured on
               generated triangles through the unit, exactly.
  nh           rsqrt          rsqrtCore<10>'s relative error (rsqrt_newton.g, from the seed
               table's exact error range); N.H (nh_scale.g) and the blinn lobe c^n of its lobe
               table (composed here: see the doc). Measured on random normals.

Options:
  --shadesim   the shadesim program (default build/sim/shadesim of the repository)
  --measure    the test_bounds program (default: <shadesim's build>/testbench/test_bounds)
  --only       spec:<name>, span:<name> or nh; repeatable (default: everything)
  --jobs       processes at a time (default 2)
  --work       keep the generated Sollya and Gappa scripts and their outputs in DIR
  --json-out   write every bound and measurement as JSON to FILE
  --fault      make the check fail on purpose, to show that it can:
                 rounding  the datapath proofs model MUL2 and MUL3..5 as truncation, not
                           round-half-up (a wrong model of the hardware)
                 shrink    every proved bound is taken 10 % smaller (a wrong bound)
  --lobe-n     the blinn exponents of the lobe bound (default 8,32,128; 32 is the default scene's)
  --quiet      no progress on stderr

Exit status: 0 when every proof succeeds and every measurement lies within its proved bound;
1 when a measurement EXCEEDS its proved bound (each one is printed); 2 when a proof fails, a
tool or program is missing or fails, or the arguments are wrong. sollya and gappa come from
scripts/install_deps.sh.
"""
import argparse
import concurrent.futures
import csv
import io
import json
import math
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
from fractions import Fraction

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BOUNDS_DIR = os.path.join(ROOT, "scripts", "bounds")

# Root enclosures are rounded outwards to this many fraction bits: the piece ends passed to
# Sollya are then short dyadic numbers, exact at its precision (spec_approx.sollya: prec 200).
ENCLOSURE_BITS = 64
TRIANGLES = 10000   # per span configuration
RENDER_VIEWPORT = 512  # test_bounds measures the span unit in the renderer's 512 x 512 viewport
NH_SAMPLES = 300000
SEED = 20261124


class ProofError(Exception):
    """A proof or a program failed: exit status 2."""


# ------------------------------------------------------------------------------ small helpers

def log(args, msg):
    if not args.quiet:
        print(f"bounds.py: {msg}", file=sys.stderr, flush=True)


def run(cmd, what, stdin=None):
    """stdout and stderr of a command; ProofError naming `what` when it fails."""
    try:
        p = subprocess.run(cmd, input=stdin, text=True, capture_output=True)
    except OSError as e:
        raise ProofError(f"{what}: cannot run {cmd[0]}: {e.strerror}")
    if p.returncode != 0:
        tail = (p.stderr or p.stdout).strip().splitlines()[-5:]
        raise ProofError(f"{what}: {os.path.basename(cmd[0])} exited with {p.returncode}: " + " | ".join(tail))
    return p.stdout, p.stderr


def dyadic_text(x):
    """A Fraction with a power-of-two denominator as Gappa/Sollya text: '<num>b-<k>'."""
    x = Fraction(x)
    k = x.denominator.bit_length() - 1
    if x.denominator != 1 << k:
        raise ValueError(f"{x} is not dyadic")
    return f"{x.numerator}b-{k}" if k else str(x.numerator)


NUMBER_RE = r"[-+]?\d+(?:b[-+]?\d+)?"


def parse_dyadic(text):
    m = re.fullmatch(r"([-+]?\d+)(?:b([-+]?\d+))?", text.strip())
    if not m:
        raise ValueError(text)
    e = int(m.group(2) or 0)
    return Fraction(int(m.group(1))) * (Fraction(2) ** e)


def round_up(x, bits=ENCLOSURE_BITS):
    return Fraction(math.ceil(Fraction(x) * (1 << bits)), 1 << bits)


def round_down(x, bits=ENCLOSURE_BITS):
    return Fraction(math.floor(Fraction(x) * (1 << bits)), 1 << bits)


def sqrt_bounds(x, bits=80):
    """Dyadic (lo, hi) with lo <= sqrt(x) <= hi for a Fraction x >= 0 (integer square roots)."""
    x = Fraction(x)
    lo_n = math.isqrt(math.floor(x * (1 << (2 * bits))))
    hi_n = math.isqrt(math.ceil(x * (1 << (2 * bits))))
    if hi_n * hi_n < x * (1 << (2 * bits)):
        hi_n += 1
    return Fraction(lo_n, 1 << bits), Fraction(hi_n, 1 << bits)


def fnum(x, digits=6):
    """A Fraction or float for people."""
    return f"{float(x):.{digits}g}"


def gappa(args, script, what, workdir, name):
    """Run one Gappa script; the enclosures of its `in ?` goals, in order, as (lo, hi) Fractions."""
    path = os.path.join(workdir, name)
    with open(path, "w", encoding="utf-8") as f:
        f.write(script)
    _, err = run(["gappa", path], what)
    with open(path + ".out", "w", encoding="utf-8") as f:
        f.write(err)
    found = re.findall(rf" in \[({NUMBER_RE})(?: {{[^}}]*}})?, ({NUMBER_RE})(?: {{[^}}]*}})?\]", err)
    if "Results:" not in err or not found or re.search(r"^Error", err, re.M):
        raise ProofError(f"{what}: Gappa proved no enclosure: {err.strip()[:300]}")
    # A rewriting hint Gappa cannot verify as an identity is only warned about, and what it then
    # proves rests on the hint: refuse it.
    if "not trivially equal" in err or "pointless" in err:
        raise ProofError(f"{what}: Gappa could not verify a rewriting hint: {err.strip()[:300]}")
    return [(parse_dyadic(a), parse_dyadic(b)) for a, b in found]


def template(name):
    with open(os.path.join(BOUNDS_DIR, name), encoding="utf-8") as f:
        return f.read()


# ------------------------------------------------------------------------ specular unit: approx

def quad_roots(A, B, C):
    """Enclosures [lo, hi] (dyadic, ENCLOSURE_BITS) of the real roots of A x^2 + B x + C."""
    if A == 0:
        if B == 0:
            return []
        r = -C / B
        return [(round_down(r), round_up(r))]
    D = B * B - 4 * A * C
    if D < 0:
        return []
    s_lo, s_hi = sqrt_bounds(D)
    out = []
    for sign in (-1, 1):
        ends = [(-B + sign * s) / (2 * A) for s in (s_lo, s_hi)]
        out.append((round_down(min(ends)), round_up(max(ends))))
    return out


def approx_pieces(u, v, kappa):
    """Cover [kappa, 1] for p(c) = c q(c), q = u c^2 + (v - u) c + 1 - v, p - 1 = (c - 1) w(c),
    w = u c^2 + v c + 1. Returns pieces (kind, lo, hi): 'zero' where p < 0 (f = 0: error c^n),
    'one' where p > 1 (f = 1: error 1 - c^n), 'poly' elsewhere (error <= |p - c^n|: Sollya).
    Every root of q and w lies inside an enclosure, and enclosures become 'poly' pieces, so q and
    w keep one sign between them: the sign at the midpoint classifies the gap."""
    q = (u, v - u, 1 - v)
    w = (u, v, Fraction(1))
    enc = sorted(e for coeffs in (q, w) for e in quad_roots(*coeffs) if e[1] > kappa and e[0] < 1)
    merged = []
    for lo, hi in enc:
        lo, hi = max(lo, kappa), min(hi, Fraction(1))
        if merged and lo <= merged[-1][1]:
            merged[-1] = (merged[-1][0], max(merged[-1][1], hi))
        else:
            merged.append((lo, hi))
    pieces, x = [], Fraction(kappa)
    for lo, hi in merged + [(Fraction(1), Fraction(1))]:
        if lo > x:
            mid = (x + lo) / 2
            qm = (q[0] * mid + q[1]) * mid + q[2]
            wm = (w[0] * mid + w[1]) * mid + w[2]
            pieces.append(("zero" if qm < 0 else "one" if wm < 0 else "poly", x, lo))
        if hi > lo:
            pieces.append(("poly", lo, hi))
        x = max(x, hi)
    out = []
    for kind, lo, hi in pieces:  # merge neighbouring poly pieces
        if out and kind == "poly" and out[-1][0] == "poly" and out[-1][2] == lo:
            out[-1] = ("poly", out[-1][1], hi)
        else:
            out.append((kind, lo, hi))
    return out


def prove_approx(args, cfg, entries, workdir):
    """Per entry: the exact pieces and Sollya's bounds; returns {address: Fraction bound}."""
    rtl = cfg["rtl"]
    cf, wc = rtl["CoefFracBits"], rtl["CosFracBits"]
    calls, partial, detail = [], {}, {}
    for e in entries:
        n = e["n"]
        if n != int(n):
            raise ProofError(f"spec:{cfg['name']}: shininess {n} is not an integer: the proof "
                             "(spec_approx.sollya) takes x^n with integer n only")
        n = int(n)
        u, v = Fraction(e["U"], 1 << cf), Fraction(e["V"], 1 << cf)
        kappa = Fraction(e["cut"], 1 << wc)
        exact = (n, u, v) in ((1, 0, 0), (2, 0, 1), (3, 1, 1))  # p = c^n identically
        bound = kappa ** n  # below the cut f = 0: the error c^n < kappa^n
        pieces = approx_pieces(u, v, kappa)
        for kind, lo, hi in pieces:
            if kind == "zero":
                bound = max(bound, hi ** n)
            elif kind == "one":
                bound = max(bound, 1 - lo ** n)
            elif not exact:
                calls.append((len(calls), e["address"], e["U"], e["V"], cf, n, lo, hi))
        partial[e["address"]] = bound
        detail[e["address"]] = [(k, dyadic_text(lo), dyadic_text(hi)) for k, lo, hi in pieces]
    lines = [f'execute("{os.path.join(BOUNDS_DIR, "spec_approx.sollya")}");']
    for cid, _, U, V, cf_, n, lo, hi in calls:
        lines.append(f"piece({cid}, {U}, {V}, {cf_}, {n}, {dyadic_text(lo)}, {dyadic_text(hi)});")
    lines.append("quit;")
    path = os.path.join(workdir, "approx.sollya")
    with open(path, "w", encoding="utf-8") as f:
        f.write("\n".join(lines) + "\n")
    out, _ = run(["sollya", "--warnonstderr", path], f"spec:{cfg['name']} approximation (Sollya)", stdin="")
    with open(path + ".out", "w", encoding="utf-8") as f:
        f.write(out)
    got = {}
    for m in re.finditer(rf"^piece (\d+) (\S+)$", out, re.M):
        try:
            got[int(m.group(1))] = parse_dyadic(m.group(2))
        except ValueError:
            raise ProofError(f"spec:{cfg['name']}: Sollya gave no bound for piece {m.group(1)}: {m.group(2)}")
    for cid, addr, *_ in calls:
        if cid not in got:
            raise ProofError(f"spec:{cfg['name']}: Sollya proved no bound for piece {cid} (address {addr}); "
                             f"see {path}")
        partial[addr] = max(partial[addr], got[cid])
    return partial, detail, len(calls)


# ---------------------------------------------------------------------- specular unit: datapath

def prove_datapath(args, cfg, entries, workdir):
    """Gappa: the error of f before the clamp, per address (degree 2: one proof for all), and
    the output error. Returns ({address: (lo, hi) of f - f*}, (lo, hi) of out - L f*)."""
    rtl = cfg["rtl"]
    rnd = "dn" if args.fault == "rounding" else "nu"
    common = dict(config=cfg["name"], Wc=rtl["CosFracBits"], Ci=rtl["CoefIntBits"], Cf=rtl["CoefFracBits"],
                  Df=rtl["DiffFracBits"], Hf=rtl["HornerFracBits"], Wf=rtl["SpecFracBits"], rnd=rnd)
    depth = 1 << rtl["ShinBits"]
    per = {}
    if rtl["Degree"] == 2:
        codes = [e["V"] for e in entries] + ([0] if len(entries) < depth else [])  # unused words: a = 0
        cf = rtl["CoefFracBits"]
        script = template("spec_datapath2.g") % dict(common, amin=dyadic_text(Fraction(min(codes), 1 << cf)),
                                                     amax=dyadic_text(Fraction(max(codes), 1 << cf)))
        (enc,) = gappa(args, script, f"spec:{cfg['name']} datapath (Gappa)", workdir, "datapath2.g")
        for e in entries:
            per[e["address"]] = enc
    else:
        jobs = [(e["address"], e["n"], e["U"], e["V"], e["cut"]) for e in entries]
        if len(entries) < depth:
            jobs.append(("unused", "-", 0, 0, 0))  # unused words: u = v = 0, no cut
        def one(job):
            addr, n, U, V, cut = job
            script = template("spec_datapath3.g") % dict(common, n=n, U=U, V=V, cut=cut)
            (enc,) = gappa(args, script, f"spec:{cfg['name']} datapath at address {addr} (Gappa)", workdir,
                           f"datapath3_{addr}.g")
            return addr, enc
        for addr, enc in map(one, jobs):  # one task: the other workers measure meanwhile
            per[addr] = enc
    # The clamp to [0, 1] is monotone and moves no two values apart, so f - f* lies between 0
    # and the error before the clamp: the interval widened to contain 0.
    f_all = (min(min(lo for lo, _ in per.values()), 0), max(max(hi for _, hi in per.values()), 0))
    script = template("spec_output.g") % dict(config=cfg["name"], Wf=rtl["SpecFracBits"], Lbits=rtl["LightBits"],
                                              Lmax=(1 << rtl["LightBits"]) - 1, rnd=rnd,
                                              flo=dyadic_text(f_all[0]), fhi=dyadic_text(f_all[1]))
    (out,) = gappa(args, script, f"spec:{cfg['name']} output (Gappa)", workdir, "output.g")
    return {a: (min(lo, 0), max(hi, 0)) for a, (lo, hi) in per.items()}, out


def prom_entries(args, cfg):
    """The PROM as shadesim writes it: per entry n, address and the stored codes."""
    out, _ = run([args.shadesim, "prom", "--config", cfg["name"], "--format", "csv"],
                 f"spec:{cfg['name']}: shadesim prom")
    rows = list(csv.DictReader(io.StringIO(out)))
    entries = []
    for r in rows:
        if cfg["rtl"]["Degree"] == 2:
            U, V, cut = 0, int(r["a_code"]), 0
        else:
            U, V, cut = int(r["a1_code"]), int(r["v_code"]), int(r["cut_code"])
        entries.append(dict(n=float(r["n"]), address=int(r["address"]), U=U, V=V, cut=cut))
    if not entries:
        raise ProofError(f"spec:{cfg['name']}: shadesim prom wrote no entry")
    return entries


# ------------------------------------------------------------------------------- the checks

class Report:
    def __init__(self, shrink):
        self.rows, self.excesses, self.shrink = [], [], shrink

    def bound(self, b):
        """A proved bound as compared: 10 % smaller with --fault shrink."""
        return b * Fraction(9, 10) if self.shrink else b

    def check_max(self, where, what, proved, measured):
        """measured (a float, >= 0) <= proved (a Fraction)."""
        proved = self.bound(proved)
        if Fraction(measured) > proved:
            self.excesses.append(f"{where}: {what}: measured {measured!r} EXCEEDS its proved bound "
                                 f"{float(proved)!r}")

    def check_interval(self, where, what, proved, lo, hi):
        """[lo, hi] (Fractions) inside proved (lo, hi)."""
        plo, phi = self.bound(proved[0]), self.bound(proved[1])
        if lo < plo or hi > phi:
            self.excesses.append(f"{where}: {what}: measured [{float(lo)!r}, {float(hi)!r}] EXCEEDS its proved "
                                 f"bound [{float(plo)!r}, {float(phi)!r}]")

    def row(self, config, quantity, proved, measured, gap, note=""):
        self.rows.append(dict(config=config, quantity=quantity, proved=proved, measured=measured, gap=gap,
                              note=note))


def exact_value(d):
    return Fraction(int(d["num"])) / (Fraction(2) ** d["exp"])


def prove_spec(args, cfg, workdir):
    """Every proof of one specular configuration (no measurement needed)."""
    entries = prom_entries(args, cfg)
    t0 = time.time()
    approx, pieces, calls = prove_approx(args, cfg, entries, workdir)
    t1 = time.time()
    dp_f, dp_out = prove_datapath(args, cfg, entries, workdir)
    t2 = time.time()
    return dict(entries=entries, approx=approx, pieces=pieces, calls=calls, dp_f=dp_f, dp_out=dp_out,
                seconds_sollya=round(t1 - t0, 2), seconds_gappa=round(t2 - t1, 2))


def check_spec(cfg, proof, measured, report):
    name, rtl = cfg["name"], cfg["rtl"]
    where = f"spec:{name}"
    entries, meas = proof["entries"], measured["entries"]
    if [(e["n"], e["address"], e["U"], e["V"], e["cut"]) for e in entries] != \
       [(m["n"], m["address"], m["u"], m["v"], m["cut"]) for m in meas]:
        raise ProofError(f"{where}: the PROM test_bounds measured is not the one shadesim writes")
    approx, dp_f, dp_out = proof["approx"], proof["dp_f"], proof["dp_out"]
    L = (1 << rtl["LightBits"]) - 1
    out_max = max(-dp_out[0], dp_out[1])
    f_lo = f_hi = o_lo = o_hi = Fraction(0)
    per_n, totals = [], []
    for e, m in zip(entries, meas):
        a, n = e["address"], m["n"]
        report.check_max(where, f"approximation at n = {n:g}", approx[a], m["approx_disc"])
        flo, fhi = exact_value(m["dp_f_lo"]), exact_value(m["dp_f_hi"])
        olo, ohi = exact_value(m["dp_out_lo"]), exact_value(m["dp_out_hi"])
        report.check_interval(where, f"datapath f at n = {n:g}", dp_f[a], flo, fhi)
        report.check_interval(where, f"datapath output at n = {n:g}", dp_out, olo, ohi)
        total_bound = L * approx[a] + out_max  # |out - L c^n| <= L |f* - c^n| + |out - L f*|
        report.check_max(where, f"total at n = {n:g}", total_bound, m["total"])
        totals.append(total_bound)
        f_lo, f_hi, o_lo, o_hi = min(f_lo, flo), max(f_hi, fhi), min(o_lo, olo), max(o_hi, ohi)
        per_n.append(dict(n=n, address=a, approx_proved=float(approx[a]), approx_pieces=proof["pieces"][a],
                          approx_measured_codes=m["approx_disc"], approx_model_continuous=m["approx_cont"],
                          datapath_f_proved=[float(x) for x in dp_f[a]], datapath_f_measured=[float(flo), float(fhi)],
                          datapath_out_measured=[float(olo), float(ohi)], total_proved=float(total_bound),
                          total_measured=m["total"]))
    max_proved = max(approx.values())
    max_meas = max(m["approx_disc"] for m in meas)
    max_cont = max(m["approx_cont"] for m in meas)
    report.row(where, "approximation |f - c^n|, max over n", fnum(max_proved), fnum(max_meas),
               f"{float(max_proved - Fraction(max_meas)):.2e}",
               f"proved over [0, 1], measured at the {(1 << rtl['CosFracBits']) + 1} cos codes; "
               f"the model's exact maximum over [0, 1] (not gated) is {max_cont:.6g}")
    f_proved = (min(lo for lo, _ in dp_f.values()), max(hi for _, hi in dp_f.values()))
    lsb_f = Fraction(1, 1 << rtl["SpecFracBits"])
    report.row(where, "datapath spec_o - f (f LSB)", interval_text(f_proved, lsb_f),
               interval_text((f_lo, f_hi), lsb_f), gap_text(f_proved, (f_lo, f_hi), lsb_f))
    report.row(where, "datapath out - L f (output LSB)", interval_text(dp_out),
               interval_text((o_lo, o_hi)), gap_text(dp_out, (o_lo, o_hi)))
    max_total = max(m["total"] for m in meas)
    report.row(where, "total |out - L c^n| (output LSB), max over n", fnum(max(totals), 5), fnum(max_total, 5),
               f"{float(max(totals)) - max_total:.3f}")
    return dict(config=name, unit="spec", rtl=rtl, sollya_pieces=proof["calls"],
                seconds_sollya=proof["seconds_sollya"], seconds_gappa=proof["seconds_gappa"],
                datapath_f_proved=[float(x) for x in f_proved], datapath_out_proved=[float(x) for x in dp_out],
                light_max=L, per_n=per_n)


def interval_text(iv, unit=Fraction(1)):
    return f"[{float(iv[0] / unit):.5g}, {float(iv[1] / unit):.5g}]"


def gap_text(proved, measured, unit=Fraction(1)):
    """The room left on each side, in the unit."""
    return f"{float((measured[0] - proved[0]) / unit):.3g} / {float((proved[1] - measured[1]) / unit):.3g}"


# --------------------------------------------------------------------------------- span unit

def prove_span(args, cfg, workdir):
    """Gappa for the renderer's viewport (the one test_bounds measures in) and the largest one
    the configuration allows: {label: (W, H, enclosure)}."""
    name, rtl = cfg["name"], cfg["rtl"]
    # The largest viewport setup accepts (model/raster/setup.cpp RasterConfig::validate):
    # W, H <= 2^PixBits and 2 max(W, H) <= 2^(CoordBits - 3).
    wmax = min(1 << rtl["PixBits"], 1 << (rtl["CoordBits"] - 4))
    out = {}
    for label, W, H in (("measured", RENDER_VIEWPORT, RENDER_VIEWPORT), ("largest", wmax, wmax)):
        script = template("span_plane.g") % dict(config=name, AttrBits=rtl["AttrBits"], W=W, H=H, lim="1b62",
                                                 Xmax=W - 1, Ymax=H - 1)
        (enc,) = gappa(args, script, f"span:{name} plane {W}x{H} (Gappa)", workdir, f"plane_{W}x{H}.g")
        out[label] = (W, H, enc)
    return out


def check_span(cfg, out, measured, report):
    name, rtl = cfg["name"], cfg["rtl"]
    where = f"span:{name}"
    if (measured["width"], measured["height"]) != out["measured"][:2]:
        raise ProofError(f"{where}: test_bounds measured in a {measured['width']}x{measured['height']} viewport, "
                         f"the proof is for {out['measured'][0]}x{out['measured'][1]}")
    W, H, enc = out["measured"]
    bound = max(-enc[0], enc[1])
    worst = max(a["worst_codes"] for a in measured["attrs"])
    report.check_max(where, f"attribute error in a {W}x{H} viewport (codes)", bound, worst)
    if measured["over_bound"]:
        report.excesses.append(f"{where}: {measured['over_bound']} fragment values EXCEED the per-pixel bound "
                               "0.5 (1 + |px - xref| + |py - yref|)")
    colour = [a for a in measured["attrs"] if a["out_frac_bits"] == 0]
    lsb = Fraction(1, 1 << colour[0]["frac_bits"]) if colour else None
    note = (f"{measured['fragments']} fragments of {measured['triangles']} triangles; farthest pixel "
            f"{measured['worst_reach']} px from the reference; worst fragment at {measured['worst_ratio']:.3f} "
            f"of its own bound 0.5 (1 + |dx| + |dy|)")
    if lsb is not None:
        note += (f"; colour ({colour[0]['frac_bits']} fraction bits): proved {float(bound * lsb):.4f}, "
                 f"measured {max(a['worst_out_lsb'] for a in colour):.4f} output LSB")
    report.row(where, f"plane, |value - exact| (codes, {W}x{H})", fnum(bound), fnum(worst),
               f"{float(bound) - worst:.1f} codes", note)
    Wl, Hl, encl = out["largest"]
    report.row(where, f"plane, |value - exact| (codes, {Wl}x{Hl}: the largest viewport)",
               fnum(max(-encl[0], encl[1])), "-", "-", "not measured: the renderer's viewport is "
               f"{W}x{H}")
    return dict(config=name, unit="span", rtl=rtl, proved_codes={k: float(max(-v[2][0], v[2][1])) for k, v in out.items()},
                viewport={k: [v[0], v[1]] for k, v in out.items()}, measured_worst_codes=worst,
                measured=measured)


# ------------------------------------------------------------------------ phong-fixed N.H

def nh_bounds(args, measured, report, workdir):
    where = "nh"
    rnd = "dn" if args.fault == "rounding" else "nu"
    table = measured["seed_table"]
    bits = measured["seed_bits"]
    step = 3 << (30 - bits)  # mq codes per entry: 3 2^30 / 2^bits
    # t0 - 1 = mq r0^2 / 2^64 - 1 over every mq of every entry, exactly (monotone in mq).
    elo = min(Fraction(((1 << 30) + i * step) * r * r, 1 << 64) - 1 for i, r in enumerate(table))
    ehi = max(Fraction(((1 << 30) + (i + 1) * step - 1) * r * r, 1 << 64) - 1 for i, r in enumerate(table))
    script = template("rsqrt_newton.g") % dict(entries=len(table), elo=dyadic_text(elo), ehi=dyadic_text(ehi),
                                               r0min=dyadic_text(Fraction(min(table), 1 << 16)),
                                               r0max=dyadic_text(Fraction(max(table), 1 << 16)))
    (E,) = gappa(args, script, "nh rsqrt (Gappa)", workdir, "rsqrt_newton.g")
    # rho = sqrt(1 + E), increasing in E: rho - 1 in [sqrt(1 + Elo) - 1, sqrt(1 + Ehi) - 1].
    rlo = round_down(sqrt_bounds(1 + E[0])[0] - 1)
    rhi = round_up(sqrt_bounds(1 + E[1])[1] - 1)
    report.check_interval(where, "rsqrt relative error rho - 1", (rlo, rhi),
                          Fraction(measured["rho_minus_1_lo"]), Fraction(measured["rho_minus_1_hi"]))
    report.row("phong-fixed", "rsqrtCore<10> relative error rho - 1", interval_text((rlo, rhi)),
               interval_text((measured["rho_minus_1_lo"], measured["rho_minus_1_hi"])),
               gap_text((rlo, rhi), (Fraction(measured["rho_minus_1_lo"]), Fraction(measured["rho_minus_1_hi"]))),
               f"seed error t0 - 1 in [{float(elo):.3g}, {float(ehi):.3g}] over the {len(table)} entries; "
               "measured at both ends of every seed interval")
    # h: a half vector normalised in double, |h| <= 1 + 2^-40; H its Q1.30 codes, each within
    # 2^-31 of h's component, so |H - h| <= sqrt(3) 2^-31 and |Dn| <= |H| <= 1 + 2^-40 + that.
    hmax = round_up(sqrt_bounds(3)[1] / (1 << 31))
    script = template("nh_scale.g") % dict(rnd=rnd, dmax=dyadic_text(1 + Fraction(1, 1 << 40) + hmax), rlo=dyadic_text(rlo),
                                           rhi=dyadic_text(rhi), hmax=dyadic_text(hmax))
    (C,) = gappa(args, script, "nh N.H (Gappa)", workdir, "nh_scale.g")
    report.check_interval(where, "N.H error", C, Fraction(measured["nh_lo"]), Fraction(measured["nh_hi"]))
    q32 = Fraction(1, 1 << 32)
    report.row("phong-fixed", "N.H - exact cosine (Q2.32 LSB)", interval_text(C, q32),
               interval_text((Fraction(measured["nh_lo"]), Fraction(measured["nh_hi"])), q32),
               gap_text(C, (Fraction(measured["nh_lo"]), Fraction(measured["nh_hi"])), q32),
               f"{measured['samples']} random normals (lengths 2^-8..2^4) and half vectors")
    bnh = max(-C[0], C[1])
    lobes = []
    for lobe in measured["lobes"]:
        n = lobe["n"]
        if n != int(n) or n < 1:
            raise ProofError(f"nh: the lobe bound takes integer exponents >= 1, not {n}")
        n = int(n)
        # |f_table(Cc) - f(x+)| <= n |C - x| (f = c^n is n-Lipschitz on [0, 1]; the clamps are
        # 1-Lipschitz) + n (n - 1) 2^-32 / 8 (linear interpolation at spacing 2^-16, |f''| <=
        # n (n - 1)) + 2^-25 + 2^-52 (a table entry: round(f 2^24) of pow, within 2 ulp)
        # + 2^-25 (the interpolation step rounded half up to 2^-24).
        b = n * bnh + Fraction(n * (n - 1), 8 << 32) + Fraction(1, 1 << 25) + Fraction(1, 1 << 52) \
            + Fraction(1, 1 << 25)
        worst = max(-lobe["lo"], lobe["hi"])
        report.check_max(where, f"blinn lobe c^{n}", b, worst)
        report.row("phong-fixed", f"blinn lobe c^{n}: |f - (N.h)^{n}|", fnum(b), fnum(worst),
                   f"{float(b) / worst:.2f}x" if worst > 0 else "-")
        lobes.append(dict(n=n, proved=float(b), measured=[lobe["lo"], lobe["hi"]]))
    return dict(unit="nh", seed_error=[float(elo), float(ehi)], rsqrt_E=[float(x) for x in E],
                rho_minus_1=[float(rlo), float(rhi)], nh_proved=[float(x) for x in C], lobes=lobes,
                measured={k: v for k, v in measured.items() if k != "seed_table"})


# ----------------------------------------------------------------------------------- driver

def main(argv):
    p = argparse.ArgumentParser(prog="bounds.py", description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--shadesim", default=os.path.join(ROOT, "build", "sim", "shadesim"))
    p.add_argument("--measure")
    p.add_argument("--only", action="append", default=[])
    p.add_argument("--jobs", type=int, default=2)
    p.add_argument("--work")
    p.add_argument("--json-out")
    p.add_argument("--fault", choices=["rounding", "shrink"])
    p.add_argument("--lobe-n", default="8,32,128")
    p.add_argument("--quiet", action="store_true")
    args = p.parse_args(argv)
    t_start = time.time()
    work = args.work or tempfile.mkdtemp(prefix="shd_bounds_")
    try:
        for tool in ("sollya", "gappa"):
            if shutil.which(tool) is None:
                raise ProofError(f"{tool} is not installed (scripts/install_deps.sh installs it)")
        args.shadesim = os.path.abspath(args.shadesim)
        if not os.access(args.shadesim, os.X_OK):
            raise ProofError(f"{args.shadesim}: no shadesim program (build it, or pass --shadesim)")
        if args.measure is None:
            args.measure = os.path.join(os.path.dirname(os.path.dirname(args.shadesim)), "testbench", "test_bounds")
        if not os.access(args.measure, os.X_OK):
            raise ProofError(f"{args.measure}: no test_bounds program (build the target test_bounds, or pass --measure)")
        if args.jobs < 1:
            raise ProofError("--jobs must be at least 1")
        out, _ = run([args.shadesim, "configs", "--json"], "shadesim configs")
        configs = [c for c in json.loads(out)]
        known = [f"{c['unit']}:{c['name']}" for c in configs] + ["nh"]
        for o in args.only:
            if o not in known:
                raise ProofError(f"--only {o}: not one of {', '.join(known)}")
        # The proofs model the paper's device (Kind 0). The other kinds have no proof here: their
        # model is checked at every input against the functions they stand for
        # (test_spec_kinds) and the RTL against the model at every input (test_spec_cosim).
        other_kind = [f"spec:{c['name']}" for c in configs if c["unit"] == "spec" and c["rtl"].get("Kind", 0) != 0]
        for o in args.only:
            if o in other_kind:
                raise ProofError(f"--only {o}: the proofs cover the poly kind (Kind 0) only")
        if other_kind:
            log(args, f"not proved (not the poly kind): {', '.join(other_kind)}")
        selected = [c for c in configs if (not args.only or f"{c['unit']}:{c['name']}" in args.only)
                    and f"{c['unit']}:{c['name']}" not in other_kind]
        want_nh = not args.only or "nh" in args.only
        os.makedirs(work, exist_ok=True)

        # Every measurement and every proof is a task; the longest first. The checks follow,
        # in this thread.
        def measure(cmd, what):
            out, _ = run([args.measure] + cmd, what)
            return json.loads(out)

        def workdir(key):
            d = os.path.join(work, key.replace(":", "_"))
            os.makedirs(d, exist_ok=True)
            return d

        pool = concurrent.futures.ThreadPoolExecutor(max_workers=args.jobs)
        meas, proofs = {}, {}
        spec = sorted((c for c in selected if c["unit"] == "spec"),
                      key=lambda c: -(1 << c["rtl"]["CosFracBits"]) * (1 << c["rtl"]["ShinBits"]))
        span = [c for c in selected if c["unit"] == "span"]
        for c in spec:
            key = f"spec:{c['name']}"
            meas[key] = pool.submit(measure, ["spec", c["name"]], f"{key}: test_bounds")
            proofs[key] = pool.submit(prove_spec, args, c, workdir(key))
        for c in span:
            key = f"span:{c['name']}"
            meas[key] = pool.submit(measure, ["span", c["name"], "--triangles", str(TRIANGLES), "--seed", str(SEED)],
                                    f"{key}: test_bounds")
            proofs[key] = pool.submit(prove_span, args, c, workdir(key))
        if want_nh:
            meas["nh"] = pool.submit(measure, ["nh", "--samples", str(NH_SAMPLES), "--seed", str(SEED),
                                               "--lobe-n", args.lobe_n], "nh: test_bounds")
        report = Report(args.fault == "shrink")
        results = []
        try:
            for c in spec + span:
                key = f"{c['unit']}:{c['name']}"
                proof, m = proofs[key].result(), meas[key].result()
                log(args, f"{key}: proved and measured")
                check = check_spec if c["unit"] == "spec" else check_span
                results.append(check(c, proof, m, report))
            if want_nh:
                results.append(nh_bounds(args, meas["nh"].result(), report, workdir("nh")))
                log(args, "nh: proved and measured")
        finally:
            pool.shutdown(cancel_futures=True)
    except ProofError as e:
        print(f"bounds.py: error: {e}", file=sys.stderr)
        if not args.work:
            shutil.rmtree(work, ignore_errors=True)
            print("bounds.py: rerun with --work DIR to keep the Sollya and Gappa scripts", file=sys.stderr)
        return 2

    print_table(report)
    seconds = time.time() - t_start
    if args.json_out:
        tmp = args.json_out + ".tmp"
        with open(tmp, "w", encoding="utf-8") as f:
            json.dump(dict(results=results, table=report.rows, excesses=report.excesses, fault=args.fault,
                           seconds=round(seconds, 1)), f, indent=1)
        os.replace(tmp, args.json_out)
    if args.work:
        print(f"bounds.py: the Sollya and Gappa scripts and their outputs are in {work}")
    else:
        shutil.rmtree(work, ignore_errors=True)
    if report.excesses:
        for x in report.excesses[:20]:
            print(f"bounds.py: {x}")
        if len(report.excesses) > 20:
            print(f"bounds.py: ... and {len(report.excesses) - 20} more")
        print(f"bounds.py: FAIL: {len(report.excesses)} measurements exceed their proved bounds ({seconds:.1f} s)")
        return 1
    print(f"bounds.py: every proof holds and every measurement lies within its bound ({seconds:.1f} s)")
    return 0


def print_table(report):
    cols = ["configuration", "quantity", "proved", "measured worst", "gap"]
    rows = [[r["config"], r["quantity"], r["proved"], r["measured"], r["gap"]] for r in report.rows]
    widths = [max(len(str(x)) for x in [c] + [r[i] for r in rows]) for i, c in enumerate(cols)]
    print(" | ".join(c.ljust(w) for c, w in zip(cols, widths)))
    print("-+-".join("-" * w for w in widths))
    for r in rows:
        print(" | ".join(str(x).ljust(w) for x, w in zip(r, widths)))
    notes = [(r["config"], r["quantity"], r["note"]) for r in report.rows if r["note"]]
    if notes:
        print()
        for cfgname, q, n in notes:
            print(f"  {cfgname}, {q}: {n}")


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
