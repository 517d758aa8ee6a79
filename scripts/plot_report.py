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

Needs matplotlib (Debian: python3-matplotlib). `shadesim report` runs this script itself when a
python3 with matplotlib is found. Exit 0, or 2 with one "plot_report: error:" line.
"""
import argparse
import csv
import io
import json
import os
import sys

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


MARKERS = {0: ("o", "exact lobe (no specular unit)"), 1: ("^", "device lobe (specular unit)")}


def panel(ax, xs, ys, table, front, xlabel, ylabel, colours):
    """One scatter: points coloured by lane mode, shaped by lobe kind, labelled method/lobe, the
    front ringed and joined."""
    labels = [r[0] for r in table]
    for mode, colour in colours.items():
        for kind, (marker, _) in MARKERS.items():
            idx = [i for i, r in enumerate(table) if r[3] == mode and r[4] == kind]
            ax.scatter([xs[i] for i in idx], [ys[i] for i in idx], s=14, color=colour, marker=marker, zorder=3)
    for mode, colour in colours.items():  # the legend: colours for modes, shapes for lobe kinds
        ax.scatter([], [], s=14, color=colour, marker="s", label=mode)
    for kind, (marker, text) in MARKERS.items():
        ax.scatter([], [], s=14, color="grey", marker=marker, label=text)
    for x, y, text in zip(xs, ys, labels):
        ax.annotate(text, (x, y), fontsize=4.5, xytext=(2, 2), textcoords="offset points", alpha=0.8)
    f = sorted(front, key=lambda i: (xs[i], ys[i]))
    ax.plot([xs[i] for i in f], [ys[i] for i in f], color="black", linewidth=0.8, drawstyle="steps-post", zorder=2)
    ax.scatter([xs[i] for i in f], [ys[i] for i in f], s=70, facecolors="none", edgecolors="black",
               linewidths=1.0, zorder=4, label="Pareto front")
    if ys and min(ys) > 0:
        ax.set_yscale("log")
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.grid(True, which="both", linewidth=0.3, alpha=0.5)
    ax.legend(fontsize=7, loc="upper right")


def finish(plt, fig, outdir, stem, data, title):
    """Titles and writes the figure as <stem>.png (its data in a tEXt chunk) and <stem>.csv."""
    fig.suptitle(title)
    fig.tight_layout()
    fig.savefig(os.path.join(outdir, stem + ".png"), dpi=150, metadata={DATA_KEY: data})
    plt.close(fig)
    with open(os.path.join(outdir, stem + ".csv"), "w") as f:
        f.write(data)
    return [stem + ".png", stem + ".csv"]


def plot_cycles(plt, report, outdir, colours):
    header, table = cycles_data(report)
    if not table:
        return []
    data = csv_text(header, table)
    xs = [int(r[5]) for r in table]
    fig, axes = plt.subplots(1, 2, figsize=(16, 8))
    for ax, col, front_col, name in ((axes[0], 6, 8, "max abs error (LSB)"), (axes[1], 7, 9, "RMSE (LSB)")):
        ys = [float(r[col]) for r in table]
        front = [i for i, r in enumerate(table) if r[front_col] == 1]
        panel(ax, xs, ys, table, front, "span + specular-unit cycles per frame", name, colours)
    return finish(plt, fig, outdir, "error_vs_cycles", data,
                  f"{report['scene']['name']}: error against cycles per frame (each point method/lobe)")


def plot_time(plt, report, outdir, colours):
    devices = [d["name"] for d in report.get("options", {}).get("pnr_devices") or []]
    header, table = time_data(report, devices)
    devices = [d for k, d in enumerate(devices) if any(r[5 + k] != "" for r in table)]
    if not table:
        return []
    data = csv_text(header, table)
    names = [d["name"] for d in report["options"]["pnr_devices"]]
    fig, axes = plt.subplots(1, len(devices), figsize=(8 * len(devices), 8), squeeze=False)
    for k, d in enumerate(devices):
        col = 5 + names.index(d)
        idx = [i for i, r in enumerate(table) if r[col] != ""]
        sub = [table[i] for i in idx]
        xs = [float(r[col]) for r in sub]
        ys = [float(r[5 + len(names)]) for r in sub]
        front = [j for j, r in enumerate(sub) if r[6 + len(names) + names.index(d)] == 1]
        title = next(e["title"] for e in report["options"]["pnr_devices"] if e["name"] == d)
        panel(axes[0][k], xs, ys, sub, front, f"time per frame on the {title} (µs, units at their fmax)",
              "max abs error (LSB)", colours)
    return finish(plt, fig, outdir, "error_vs_time", data,
                  f"{report['scene']['name']}: error against hardware time per frame (each point method/lobe)")


def plot_area(plt, report, outdir, colours):
    targets = report.get("options", {}).get("synth_targets") or []
    header, table = area_data(report, targets)
    if not table or not targets:
        return []
    data = csv_text(header, table)
    ys = [float(r[5 + len(targets)]) for r in table]
    fig, axes = plt.subplots(1, len(targets), figsize=(8 * len(targets), 8), squeeze=False)
    for k, t in enumerate(targets):
        xs = [int(r[5 + k]) for r in table]
        front = [i for i, r in enumerate(table) if r[6 + len(targets) + k] == 1]
        panel(axes[0][k], xs, ys, table, front, f"{t} LUTs (span + specular units)", "max abs error (LSB)",
              colours)
    return finish(plt, fig, outdir, "error_vs_area", data,
                  f"{report['scene']['name']}: error against area (each point method/lobe)")


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
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError as e:
        fail(f"matplotlib is missing ({e}); Debian: apt-get install python3-matplotlib")
    cmap = plt.get_cmap("tab10")
    colours = {m: cmap(i % 10) for i, m in enumerate(report["options"]["modes"])}
    written = (plot_cycles(plt, report, outdir, colours) + plot_time(plt, report, outdir, colours)
               + plot_area(plt, report, outdir, colours))
    for w in written:
        print(os.path.join(outdir, w))
    return 0


if __name__ == "__main__":
    sys.exit(main())
