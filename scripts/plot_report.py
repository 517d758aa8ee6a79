#!/usr/bin/env python3
"""plot_report.py REPORT_JSON [-o DIR]: the plots of a `shadesim report` (docs/report.md).

Writes into DIR (default: the directory of REPORT_JSON), each PNG with the CSV of exactly the
data it plots beside it (the same text is also stored in the PNG, in a tEXt chunk with the key
"shadesim-plot-data", so that a PNG can be checked against its CSV):

  error_vs_cycles.png/.csv  every row with hardware time: its error (left: max abs LSB, right:
                            RMSE LSB) against span + specular-unit cycles per frame; the Pareto
                            front of each panel (least cycles, least error) ringed and joined;
                            each point labelled method/lobe, coloured by lane mode, a triangle
                            where the specular unit evaluates the lobe (quadratic, cubic).
  error_vs_time.png/.csv    when the report has place and route: max abs LSB against the time
                            per frame in microseconds at the units' fmax, one panel per iCE40
                            device where some row has a time, the front of each marked; a row
                            whose units do not fit a device has an empty cell there.
  error_vs_area.png/.csv    when the report has area (shadesim report without --no-hardware): max abs
                            LSB against the LUTs of the row's units (span + specular) per target,
                            one panel per target, the front of each marked.

Draws with gnuplot (Debian: gnuplot-nox; its pngcairo terminal), run once on a script written
into a temporary directory; the tEXt chunk is added here. `shadesim report` runs this script
itself when a python3 and gnuplot are found. Exit 0, or 2 with one "plot_report: error:" line.
"""
import argparse
import csv
import io
import json
import math
import os
import shutil
import struct
import subprocess
import sys
import tempfile
import zlib

DATA_KEY = "shadesim-plot-data"


def fail(msg):
    print(f"plot_report: error: {msg}", file=sys.stderr)
    sys.exit(2)


def pareto(points):
    """Indices of the points no other point dominates (<= in both coordinates, < in one)."""
    front = []
    for i, (x, y) in enumerate(points):
        dominated = any(x2 <= x and y2 <= y and (x2 < x or y2 < y) for j, (x2, y2) in enumerate(points) if j != i)
        if not dominated:
            front.append(i)
    return front


def label(row):
    return f"{row['method']}/{row['lobe']}"


def uses_spec(row):
    """1 when the row's lobe is evaluated by the specular unit (a device lobe), else 0."""
    return int(bool(row["spec_configs"]))


def csv_text(header, rows):
    out = io.StringIO()
    w = csv.writer(out, lineterminator="\n")
    w.writerow(header)
    w.writerows(rows)
    return out.getvalue()


def cycles_data(report):
    """The rows with hardware time, their errors and their front membership per panel."""
    rows = [r for r in report["rows"] if r.get("total_cycles") is not None]
    fronts = {}
    for key in ("max_abs_lsb", "rmse_lsb"):
        fronts[key] = set(pareto([(r["total_cycles"], r["metrics"][key]) for r in rows]))
    table = [[label(r), r["method"], r["lobe"], r["mode"], uses_spec(r), r["total_cycles"],
              repr(r["metrics"]["max_abs_lsb"]), repr(r["metrics"]["rmse_lsb"]), int(i in fronts["max_abs_lsb"]),
              int(i in fronts["rmse_lsb"])]
             for i, r in enumerate(rows)]
    header = ["label", "method", "lobe", "mode", "spec_unit", "total_cycles", "max_abs_lsb", "rmse_lsb",
              "front_max_abs_lsb", "front_rmse_lsb"]
    return header, table


def area_data(report, targets):
    rows = [r for r in report["rows"] if r.get("area") is not None]
    fronts = {t: set(pareto([(r["area"][t]["luts"], r["metrics"]["max_abs_lsb"]) for r in rows])) for t in targets}
    table = [[label(r), r["method"], r["lobe"], r["mode"], uses_spec(r), *[r["area"][t]["luts"] for t in targets],
              repr(r["metrics"]["max_abs_lsb"]), *[int(i in fronts[t]) for t in targets]]
             for i, r in enumerate(rows)]
    header = ["label", "method", "lobe", "mode", "spec_unit", *[f"{t}_luts" for t in targets], "max_abs_lsb",
              *[f"front_{t}" for t in targets]]
    return header, table


def time_data(report, devices):
    rows = [r for r in report["rows"] if any((r.get("time_us") or {}).get(d) is not None for d in devices)]
    fronts = {}
    for d in devices:
        idx = [i for i, r in enumerate(rows) if r["time_us"][d] is not None]
        fronts[d] = {idx[k] for k in pareto([(rows[i]["time_us"][d], rows[i]["metrics"]["max_abs_lsb"]) for i in idx])}
    cell = lambda v: "" if v is None else repr(v)
    table = [[label(r), r["method"], r["lobe"], r["mode"], uses_spec(r), *[cell(r["time_us"][d]) for d in devices],
              repr(r["metrics"]["max_abs_lsb"]), *[int(i in fronts[d]) for d in devices]]
             for i, r in enumerate(rows)]
    header = ["label", "method", "lobe", "mode", "spec_unit", *[f"{d}_us" for d in devices], "max_abs_lsb",
              *[f"front_{d}" for d in devices]]
    return header, table


# gnuplot's point types: a filled square for a lane mode's colour in the legend, a filled circle
# for an exact lobe, a filled triangle for a device lobe, an open circle for the front's rings.
SQUARE, RING = 5, 6
MARKERS = {0: (7, "exact lobe (no specular unit)"), 1: (9, "device lobe (specular unit)")}
COLOURS = ["#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22",
           "#17becf"]  # one per lane mode, in the report's order (the tab10 cycle)
PANEL_PX = 1200  # a panel is 8 x 8 in at 150 dpi
TERMINAL = "pngcairo noenhanced font 'DejaVu Sans,10' fontscale 1.6 linewidth 1.5"
POINT_SIZE, RING_SIZE = 1.4, 3.0
PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def gp(text):
    """text as a gnuplot string: single-quoted, where nothing is an escape but '' for ' (and no
    macro is expanded); a control character becomes a space, as a string cannot span lines."""
    text = "".join(" " if ord(c) < 32 or ord(c) == 127 else c for c in str(text))
    return "'" + text.replace("'", "''") + "'"


def axis_range(vs, log):
    """A gnuplot range [lo:hi] holding vs with a margin of 5 % of their span on each side (of
    the span of their logarithms on a log axis)."""
    lo, hi = min(vs), max(vs)
    if log:
        lo, hi = math.log10(lo), math.log10(hi)
    pad = (hi - lo) * 0.05 or abs(lo) * 0.05 or 1
    lo, hi = lo - pad, hi + pad
    if log:
        lo, hi = 10 ** lo, 10 ** hi
    return f"[{lo!r}:{hi!r}]"


def panel(name, xs, ys, table, front, xlabel, ylabel, modes):
    """One scatter as gnuplot lines, (its data blocks and labels, its settings and plot): points
    coloured by lane mode, shaped by lobe kind, labelled method/lobe, the front ringed and joined
    by a step line (horizontal first: steps-post)."""
    blocks = [f"array L{name}[{len(table)}]"] + [f"L{name}[{k + 1}] = {gp(r[0])}" for k, r in enumerate(table)]

    def block(suffix, points):
        b = f"${name}_{suffix}"
        blocks.extend([f"{b} << EOD", *(" ".join(repr(v) for v in p) for p in points), "EOD"])
        return b

    log = min(ys) > 0
    plots = [f"keyentry with points pt {SQUARE} ps {POINT_SIZE} lc rgb '{COLOURS[m % len(COLOURS)]}' title {gp(mode)}"
             for m, mode in enumerate(modes)]
    plots += [f"keyentry with points pt {pt} ps {POINT_SIZE} lc rgb '#808080' title {gp(text)}"
              for pt, text in MARKERS.values()]
    f = block("front", sorted((xs[i], ys[i]) for i in front))
    plots.append(f"{f} using 1:2 with steps lw 0.8 lc rgb 'black' notitle")
    for m, mode in enumerate(modes):
        for kind, (pt, _) in MARKERS.items():
            idx = [i for i, r in enumerate(table) if r[3] == mode and r[4] == kind]
            if idx:
                b = block(f"m{m}k{kind}", [(xs[i], ys[i]) for i in idx])
                plots.append(f"{b} using 1:2 with points pt {pt} ps {POINT_SIZE} "
                             f"lc rgb '{COLOURS[m % len(COLOURS)]}' notitle")
    b = block("labels", [(x, y, k + 1) for k, (x, y) in enumerate(zip(xs, ys))])
    plots.append(f"{b} using 1:2:(L{name}[int($3)]) with labels left offset char 0.25,0.3 font ',4.5' "
                 "textcolor rgb '#404040' notitle")
    plots.append(f"{f} using 1:2 with points pt {RING} ps {RING_SIZE} lw 1 lc rgb 'black' title 'Pareto front'")
    settings = [f"set xlabel {gp(xlabel)}", f"set ylabel {gp(ylabel)}", f"set xrange {axis_range(xs, False)}",
                f"set yrange {axis_range(ys, log)}", "set logscale y" if log else "unset logscale y",
                "unset grid", f"set grid xtics ytics {'mytics ' if log else ''}lt 1 lw 0.6 lc rgb '#d8d8d8'",
                "set key top right reverse Left opaque box font ',7' samplen 1", "set tics out nomirror",
                "plot " + ", \\\n     ".join(plots)]
    return blocks, settings


def figure_lines(png, title, panels):
    """The gnuplot lines that draw panels side by side into png under title."""
    head = [line for blocks, _ in panels for line in blocks]
    body = [line for _, settings in panels for line in settings]
    return [*head, f"set terminal {TERMINAL} size {PANEL_PX * len(panels)},{PANEL_PX}", f"set output {gp(png)}",
            f"set multiplot layout 1,{len(panels)} title {gp(title)} font ',12'", *body, "unset multiplot",
            "unset output"]


def plot_cycles(report, modes):
    """The cycles figure: (stem, CSV text, title, panels), or None without rows with cycles."""
    header, table = cycles_data(report)
    if not table:
        return None
    xs = [int(r[5]) for r in table]
    panels = []
    for k, (col, front_col, name) in enumerate(((6, 8, "max abs error (LSB)"), (7, 9, "RMSE (LSB)"))):
        ys = [float(r[col]) for r in table]
        front = [i for i, r in enumerate(table) if r[front_col] == 1]
        panels.append(panel(f"c{k}", xs, ys, table, front, "span + specular-unit cycles per frame", name, modes))
    return ("error_vs_cycles", csv_text(header, table),
            f"{report['scene']['name']}: error against cycles per frame (each point method/lobe)", panels)


def plot_time(report, modes):
    devices = [d["name"] for d in report.get("options", {}).get("pnr_devices") or []]
    header, table = time_data(report, devices)
    devices = [d for k, d in enumerate(devices) if any(r[5 + k] != "" for r in table)]
    if not table:
        return None
    names = [d["name"] for d in report["options"]["pnr_devices"]]
    panels = []
    for k, d in enumerate(devices):
        col = 5 + names.index(d)
        sub = [r for r in table if r[col] != ""]
        xs = [float(r[col]) for r in sub]
        ys = [float(r[5 + len(names)]) for r in sub]
        front = [j for j, r in enumerate(sub) if r[6 + len(names) + names.index(d)] == 1]
        title = next(e["title"] for e in report["options"]["pnr_devices"] if e["name"] == d)
        panels.append(panel(f"t{k}", xs, ys, sub, front, f"time per frame on the {title} (µs, units at their fmax)",
                            "max abs error (LSB)", modes))
    return ("error_vs_time", csv_text(header, table),
            f"{report['scene']['name']}: error against hardware time per frame (each point method/lobe)", panels)


def plot_area(report, modes):
    targets = report.get("options", {}).get("synth_targets") or []
    header, table = area_data(report, targets)
    if not table or not targets:
        return None
    ys = [float(r[5 + len(targets)]) for r in table]
    panels = []
    for k, t in enumerate(targets):
        xs = [int(r[5 + k]) for r in table]
        front = [i for i, r in enumerate(table) if r[6 + len(targets) + k] == 1]
        panels.append(panel(f"a{k}", xs, ys, table, front, f"{t} LUTs (span + specular units)",
                            "max abs error (LSB)", modes))
    return ("error_vs_area", csv_text(header, table),
            f"{report['scene']['name']}: error against area (each point method/lobe)", panels)


def draw(gnuplot, figures, tmp):
    """Runs gnuplot once on a script drawing every figure into tmp/<stem>.png; their bytes."""
    lines = []
    for stem, _, title, panels in figures:
        lines += figure_lines(os.path.join(tmp, stem + ".png"), title, panels)
    script = os.path.join(tmp, "plots.gp")
    with open(script, "w", encoding="utf-8", errors="replace") as f:
        f.write("\n".join(lines) + "\n")
    try:  # -d: no initialization file (~/.gnuplot) changes the figures
        r = subprocess.run([gnuplot, "-d", script], cwd=tmp, stdin=subprocess.DEVNULL, capture_output=True,
                           text=True, errors="replace")
    except OSError as e:
        fail(f"gnuplot: {e}")
    said = [line.strip()[:160] for line in r.stderr.splitlines() if line.strip()]
    if r.returncode != 0:
        how = f"exit {r.returncode}" if r.returncode > 0 else f"signal {-r.returncode}"
        fail(f"gnuplot failed ({how})" + (": " + " / ".join(said[:3]) if said else ""))
    pngs = []
    for stem, *_ in figures:
        try:
            with open(os.path.join(tmp, stem + ".png"), "rb") as f:
                pngs.append(f.read())
        except OSError as e:
            fail(f"gnuplot wrote no {stem}.png ({e})")
    return pngs


def with_text(png, key, text):
    """png with a tEXt chunk key: text inserted before its IEND chunk (iTXt, UTF-8, where text is
    not Latin-1)."""
    iend = len(png) - 12
    if png[:8] != PNG_SIGNATURE or iend < 8 or png[iend:iend + 8] != b"\0\0\0\0IEND":
        fail("gnuplot wrote no valid PNG (no IEND chunk at its end)")
    try:
        kind, body = b"tEXt", key.encode("latin-1") + b"\0" + text.encode("latin-1")
    except UnicodeEncodeError:
        kind, body = b"iTXt", key.encode("latin-1") + b"\0\0\0\0\0" + text.encode("utf-8")
    chunk = struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body) & 0xFFFFFFFF)
    return png[:iend] + chunk + png[iend:]


def write_replacing(path, data):
    """Writes data (bytes or str) under a temporary name beside path, then renames it to path:
    no half-written file where a reader looks."""
    tmp = os.path.join(os.path.dirname(path), f".{os.path.basename(path)}.{os.getpid()}.tmp")
    try:
        with open(tmp, "xb" if isinstance(data, bytes) else "x") as f:
            f.write(data)
        os.replace(tmp, path)
    except OSError as e:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        fail(f"{path}: {e}")


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("report")
    p.add_argument("-o", "--out", help="the directory the plots are written to (default: the report's)")
    a = p.parse_args()
    try:
        with open(a.report) as f:
            report = json.load(f)
    except (OSError, ValueError) as e:
        fail(f"{a.report}: {e}")
    if report.get("format") != "shadesim report 1":
        fail(f"{a.report}: not a shadesim report (format {report.get('format')!r})")
    outdir = a.out or os.path.dirname(os.path.abspath(a.report))
    if not os.path.isdir(outdir):
        fail(f"{outdir}: no such directory")
    gnuplot = shutil.which("gnuplot")
    if gnuplot is None:
        fail("gnuplot is missing; Debian: apt-get install gnuplot-nox")
    modes = report["options"]["modes"]
    figures = [f for f in (plot_cycles(report, modes), plot_time(report, modes), plot_area(report, modes)) if f]
    if not figures:
        return 0
    with tempfile.TemporaryDirectory(prefix="plot_report.") as tmp:
        pngs = draw(gnuplot, figures, tmp)
    for (stem, data, _, _), png in zip(figures, pngs):
        write_replacing(os.path.join(outdir, stem + ".png"), with_text(png, DATA_KEY, data))
        write_replacing(os.path.join(outdir, stem + ".csv"), data)
        print(os.path.join(outdir, stem + ".png"))
        print(os.path.join(outdir, stem + ".csv"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
