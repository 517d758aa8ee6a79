#!/usr/bin/env python3
"""report_check.py DIR [METHOD,LOBE,MODE,RENDER_JSON,RENDER_PNG ...]: checks a `shadesim report`
directory against its report.json (testbench/report_test.sh):

  - every cell of every table of report.md is report.json's value formatted as docs/report.md
    states (no figure copied by hand), and no table holds a number it does not account for;
  - report.csv has one line per row of report.json, with its values;
  - the plots are valid PNG files (signature, chunk CRCs, IDAT inflating to the image's size,
    IEND last) whose embedded data (tEXt "shadesim-plot-data") is the CSV beside them, and that
    CSV is the rows of report.json with the Pareto front computed here independently;
  - the images are equal across the lane modes (the report's own check, and every row of one
    method and lobe names one image), contact_sheet.png and every image are valid PNG files;
  - per sample row: `shadesim render --json` gives the same error figures and cycles, and its
    image (rendered in that row's mode) has the same PNG bytes as the report's.
Only the Python standard library. Its PNG decoder (png_pixels) is also testbench/prune_test.sh's.
"""
import csv
import json
import os
import re
import struct
import sys
import zlib

NUMBER = re.compile(r"^-?\d+(\.\d+)?$")
failures = []


def check(cond, msg):
    if not cond:
        failures.append(msg)


# --- PNG -------------------------------------------------------------------------------------

def parse_png(path):
    """(width, height, bytes per pixel, interlace method, the inflated IDAT, {tEXt key: text}) of
    a valid 8-bit PNG; None, a failure recorded, otherwise (an IDAT of another size than a
    non-interlaced image's is recorded too)."""
    data = open(path, "rb").read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        failures.append(f"{path}: not a PNG (signature)")
        return None
    pos, chunks = 8, []
    while pos < len(data):
        if pos + 12 > len(data):
            failures.append(f"{path}: truncated chunk at byte {pos}")
            return None
        n, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + n]
        crc = struct.unpack(">I", data[pos + 8 + n:pos + 12 + n])[0]
        if zlib.crc32(kind + body) & 0xFFFFFFFF != crc:
            failures.append(f"{path}: bad CRC in chunk {kind!r}")
            return None
        chunks.append((kind, body))
        pos += 12 + n
    if not chunks or chunks[0][0] != b"IHDR" or chunks[-1][0] != b"IEND":
        failures.append(f"{path}: IHDR not first or IEND not last")
        return None
    w, h, depth, colour, _, _, interlace = struct.unpack(">IIBBBBB", chunks[0][1][:13])
    channels = {0: 1, 2: 3, 4: 2, 6: 4}.get(colour)
    if depth != 8 or channels is None:
        failures.append(f"{path}: unexpected format depth {depth} colour type {colour}")
        return None
    raw = zlib.decompress(b"".join(b for k, b in chunks if k == b"IDAT"))
    check(len(raw) == h * (1 + w * channels), f"{path}: IDAT inflates to {len(raw)} bytes, not {h}x{w}x{channels}")
    text = {}
    for k, b in chunks:
        if k == b"tEXt":
            key, _, value = b.partition(b"\0")
            text[key.decode("latin-1")] = value.decode("latin-1")
    return w, h, channels, interlace, raw, text


def read_png(path):
    """(width, height, {tEXt key: text}) of a valid PNG; a failure is recorded otherwise."""
    p = parse_png(path)
    return None if p is None else (p[0], p[1], p[5])


def png_pixels(path):
    """(width, height, bytes per pixel, pixels) of a valid 8-bit non-interlaced PNG (parse_png's
    checks): the rows top to bottom, each of the five row filters (None, Sub, Up, Average, Paeth)
    undone; None, a failure recorded, otherwise."""
    p = parse_png(path)
    if p is None:
        return None
    w, h, bpp, interlace, raw, _ = p
    if interlace != 0:
        failures.append(f"{path}: interlaced")
        return None
    stride = w * bpp
    if len(raw) != h * (1 + stride):
        return None  # recorded by parse_png
    out, prev = bytearray(), bytearray(stride)
    for y in range(h):
        ftype, line = raw[y * (1 + stride)], bytearray(raw[y * (1 + stride) + 1:(y + 1) * (1 + stride)])
        if ftype == 1:
            for i in range(bpp, stride):
                line[i] = (line[i] + line[i - bpp]) & 0xFF
        elif ftype == 2:
            for i in range(stride):
                line[i] = (line[i] + prev[i]) & 0xFF
        elif ftype == 3:
            for i in range(stride):
                line[i] = (line[i] + ((line[i - bpp] if i >= bpp else 0) + prev[i]) // 2) & 0xFF
        elif ftype == 4:
            for i in range(stride):
                a, b = (line[i - bpp] if i >= bpp else 0), prev[i]
                c = prev[i - bpp] if i >= bpp else 0
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 0xFF
        elif ftype != 0:
            failures.append(f"{path}: row {y} has filter type {ftype}")
            return None
        out += line
        prev = line
    return w, h, bpp, bytes(out)


# --- report.md -------------------------------------------------------------------------------

def fmt(v, decimals, scale=1):
    if v is None:
        return "—"
    if decimals == 0 and isinstance(v, int):
        return str(v)
    return f"{v * scale:.{decimals}f}"


def get(row, path):
    for k in path:
        if not isinstance(row, dict) or k not in row:
            return None
        row = row[k]
    return row


# header -> (path in the row, decimals, scale, shown on the method's first row only)
LOBE_COLUMNS = {
    "max LSB": (("metrics", "max_abs_lsb"), 2, 1, True),
    "RMSE LSB": (("metrics", "rmse_lsb"), 3, 1, True),
    "PSNR dB": (("metrics", "psnr_db"), 2, 1, True),
    "> 1 LSB %": (("metrics", "share_over_1lsb"), 2, 100, True),
    "hl max LSB": (("highlight", "max_abs_lsb"), 2, 1, True),
    "hl RMSE LSB": (("highlight", "rmse_lsb"), 3, 1, True),
    "hl > 1 LSB %": (("highlight", "share_over_1lsb"), 2, 100, True),
    "model ms": (("ms",), 2, 1, False),
    "span cycles": (("span_cycles",), 0, 1, False),
    "spec cycles": (("spec_cycles",), 0, 1, False),
    "total cycles": (("total_cycles",), 0, 1, False),
    "RTL ms": (("rtl", "ms"), 1, 1, False),
}
for t, name in (("ice40", "iCE40"), ("xc7", "xc7")):
    LOBE_COLUMNS[f"{name} LUT"] = (("area", t, "luts"), 0, 1, False)
    LOBE_COLUMNS[f"{name} DSP"] = (("area", t, "dsps"), 0, 1, False)
for d, name in (("up5k", "UP5K"), ("hx8k", "HX8K")):
    LOBE_COLUMNS[f"{name} µs"] = (("time_us", d), 1, 1, False)


def tables(md):
    """(heading, header cells, body rows) of every Markdown table, with the last ## heading."""
    out, heading, lines = [], None, md.splitlines()
    i = 0
    while i < len(lines):
        if lines[i].startswith("## "):
            heading = lines[i][3:]
        if lines[i].startswith("| ") and i + 1 < len(lines) and lines[i + 1].startswith("| ---"):
            header = [c.strip() for c in lines[i].strip("|").split("|")]
            body, i = [], i + 2
            while i < len(lines) and lines[i].startswith("|"):
                body.append([c.strip() for c in lines[i].strip().strip("|").split("|")])
                i += 1
            out.append((heading, header, body))
            continue
        i += 1
    return out


def expected_lobe_cell(row, header, first):
    path, decimals, scale, first_only = LOBE_COLUMNS[header]
    if first_only and not first:
        return ""
    if path[0] == "highlight" and row["highlight"]["pixels"] == 0:
        return "—"
    v = get(row, path)
    if header == "PSNR dB" and v is None:
        return "∞"
    return fmt(v, decimals, scale)


def check_lobe_table(report, heading, header, body):
    m = re.match(r"Lobe (?:`([^`]+)`|material)", heading)
    lobe = m.group(1) or "material"
    rows = {(r["method"], r["mode"]): r for r in report["rows"] if r["lobe"] == lobe}
    check(len(body) == len(rows), f"report.md lobe {lobe}: {len(body)} lines for {len(rows)} rows")
    last = None
    for cells in body:
        method, mode = cells[0].strip("`"), cells[1]
        row = rows.get((method, mode))
        if row is None:
            failures.append(f"report.md lobe {lobe}: no row {method} {mode} in report.json")
            continue
        first, last = method != last, method
        for h, cell in zip(header[2:], cells[2:]):
            if h == "RTL":
                continue
            if h not in LOBE_COLUMNS:
                failures.append(f"report.md lobe {lobe}: unknown column {h!r}")
                continue
            want = expected_lobe_cell(row, h, first)
            check(cell == want, f"report.md lobe {lobe} {method} {mode} {h}: {cell!r}, report.json gives {want!r}")


def check_units_table(report, header, body):
    for cells in body:
        unit, name = cells[0], cells[1].strip("`")
        u = report["units"][unit][name]
        want = [fmt(u.get("lanes"), 0), fmt(u.get("degree"), 0)]
        for h in header[4:]:
            target, fig = h.split()
            want.append(fmt(get(u, ("area", "ice40" if target == "iCE40" else target,
                                    {"LUT": "luts", "FF": "ffs", "DSP": "dsps", "BRAM": "brams"}[fig])), 0))
        check(cells[2:] == want, f"report.md units {unit} {name}: {cells[2:]} != {want}")


def check_pnr_table(report, body):
    titles = {"UP5K": "up5k", "HX8K": "hx8k"}
    want = 0
    for cells in body:
        unit, name, dev = cells[0], cells[1].strip("`"), titles[cells[2]]
        p = report["units"][unit][name]["pnr"][dev]
        used = [f"{p[f]} / {p[f + '_total']}" for f in ("luts", "dsps", "brams")]
        result = "fmax " + p["fmax_kind"] if p["fits"] else p["why_not"]
        exp = [f"`{p['flow']}`", fmt(p["fmax_mhz"], 2)] + used + [result]
        check(cells[3:] == exp, f"report.md place and route {unit} {name} {dev}: {cells[3:]} != {exp}")
    for unit in ("span", "spec"):
        want += sum(len(u.get("pnr", {})) for u in report["units"][unit].values())
    check(len(body) == want, f"report.md place and route: {len(body)} lines for {want} unit placements")


def prom_bits(rtl):
    """Depth x word width of a specular configuration's PROM, plus the piecewise kind's segment
    ROM, from its parameters (rtl/shd_spec_unit.v, SpecUnitParams::promBits)."""
    kind, kw = rtl.get("Kind", 0), rtl["CoefIntBits"] + rtl["CoefFracBits"]
    if kind == 1:
        return (1 << (rtl["ShinBits"] + rtl["TableBits"])) * (rtl["SpecFracBits"] + 1)
    if kind in (2, 3):  # schlick m, explog n (its fixed log and exp tables are not the PROM)
        return (1 << rtl["ShinBits"]) * kw
    if kind == 4:  # {B_S-1..B_0}; segment ROM {K_d..K_0, e} at {shin, s}, e clog2(Wc+1) bits
        s, wc = rtl.get("Segments", 1), rtl["CosFracBits"]
        seg_word = wc.bit_length() + (rtl["Degree"] + 1) * kw
        return (1 << rtl["ShinBits"]) * s * (wc + 1 + seg_word)
    return (1 << rtl["ShinBits"]) * (kw if rtl["Degree"] == 2 else 2 * kw + rtl["CosFracBits"] + 1)


def fixed_rom_bits(rtl):
    """Bits of the explog kind's log and exp tables (rtl/shd_spec_explog.v: 2^T words of
    {g step, g} and of {e step, e}); 0 for the other kinds."""
    if rtl.get("Kind", 0) != 3:
        return 0
    t, wf = rtl["TableBits"], rtl["SpecFracBits"]
    gf, ef = wf + 6 + max(0, rtl["CoefIntBits"] - rtl["CosFracBits"] - 4), wf + 4
    return (1 << t) * ((gf - t + 1) + (gf + 2) + (ef - t + 1) + (ef + 1))


def check_spec_units_table(report, header, body):
    units = report["units"]["spec"]
    check(len(body) == len(units), f"report.md specular units: {len(body)} lines for {len(units)} units")
    for cells in body:
        name = cells[0].strip("`")
        u = units[name]
        rtl = u["rtl"]
        check(u["latency"] == 2 + rtl["PipeStages"], f"report.json units.spec.{name}.latency = {u['latency']}")
        check(u["prom_bits"] == prom_bits(rtl), f"report.json units.spec.{name}.prom_bits = {u['prom_bits']}, "
              f"the parameters give {prom_bits(rtl)}")
        check(u["fixed_rom_bits"] == fixed_rom_bits(rtl), f"report.json units.spec.{name}.fixed_rom_bits = "
              f"{u['fixed_rom_bits']}, the parameters give {fixed_rom_bits(rtl)}")
        pf = next((r for r in report["rows"] if r["lobe"] == u["lobe"] and r["method"] == "phong-fixed"), {})
        want = [u["kind"], f"`{u['lobe']}`", fmt(u["latency"], 0), fmt(u["prom_bits"], 0),
                fmt(u["fixed_rom_bits"], 0)]
        for h in header[6:]:
            if h.startswith("iCE40 "):
                want.append(fmt(get(u, ("area", "ice40", {"LUT": "luts", "DSP": "dsps", "BRAM": "brams"}[h[6:]])), 0))
            elif h.endswith(" MHz"):
                want.append(fmt(get(u, ("pnr", h[:-4].lower(), "fmax_mhz")), 2))
            elif h == "unit max LSB":
                want.append(fmt(get(u, ("scene_error", "total_max_lsb")), 2))
            elif h == "unit peak LSB":
                want.append(fmt(get(u, ("scene_error", "total_peak_max_lsb")), 2))
            elif h == "phong-fixed max LSB":
                want.append(fmt(get(pf, ("metrics", "max_abs_lsb")), 2))
            elif h == "phong-fixed hl max LSB":
                want.append(fmt(get(pf, ("highlight", "max_abs_lsb")), 2))
            else:
                failures.append(f"report.md specular units: unknown column {h!r}")
        check(cells[1:] == want, f"report.md specular units {name}: {cells[1:]} != {want}")


def check_work_skipped_table(report, body):
    mode = report["options"]["modes"][0]
    want = []
    for r in report["rows"]:
        k = r["counts"]
        if r["mode"] == mode and k["spec_evaluations"] > 0:
            n, z = k["spec_evaluations"], k["spec_at_zero"]
            want.append([r["method"], r["lobe"], f"{z} of {n} ({100 * z / n:.0f} %)"])
    check(body == want, f"report.md work skipped: {body[:3]}... != {want[:3]}... ({len(body)} and {len(want)} lines)")


def check_markdown(d, report):
    md = open(os.path.join(d, "report.md"), encoding="utf-8").read()
    sheet = report["contact_sheet"]
    seen = 0
    for heading, header, body in tables(md):
        if heading.startswith("Lobe "):
            check_lobe_table(report, heading, header, body)
            seen += 1
        elif heading == "Units":
            check_units_table(report, header, body)
        elif heading == "Work skipped":
            check_work_skipped_table(report, body)
        elif heading == "Place and route":
            check_pnr_table(report, body)
        elif heading == "Specular units compared":
            check_spec_units_table(report, header, body)
        elif heading == "Contact sheet":
            key = "rows" if header[1] == "lobe" else "columns"
            prefix = "row" if key == "rows" else "column"
            want = [[f"{prefix} {i + 1}", n if key == "rows" else f"`{n}`"] for i, n in enumerate(sheet[key])]
            check(body == want, f"report.md contact sheet {key}: {body} != {want}")
        else:
            failures.append(f"report.md: a table under '{heading}' that this check does not know")
    lobes = {r["lobe"] for r in report["rows"]}
    check(seen == len(lobes), f"report.md: {seen} lobe tables for {len(lobes)} lobes with rows")


# --- report.csv and the plots ----------------------------------------------------------------

def same_number(text, v):
    if v is None:
        return text == ""
    if isinstance(v, bool):
        return text == ("true" if v else "false")
    if isinstance(v, (int, float)):
        return text != "" and float(text) == v  # every digit: JSON and CSV write the shortest round trip
    if isinstance(v, list):
        return text == "+".join(v)
    return text == str(v)


def check_csv(d, report):
    rows = list(csv.DictReader(open(os.path.join(d, "report.csv"))))
    check(len(rows) == len(report["rows"]), f"report.csv: {len(rows)} lines for {len(report['rows'])} rows")
    for c, r in zip(rows, report["rows"]):
        for k, text in c.items():
            if k.startswith("highlight_"):
                v = r["highlight"][k[len("highlight_"):]]
            elif k in r["metrics"] and k not in ("ms",):
                v = r["metrics"][k]
            elif k.startswith("rtl_"):
                v = r["rtl"][k[4:]]
            elif k.startswith("time_us_"):
                v = get(r, ("time_us", k[len("time_us_"):]))
            elif re.match(r"^(ice40|xc7)_", k):
                t, f = k.split("_", 1)
                v = get(r, ("area", t, f))
            elif k in ("spec_at_zero", "depth_rejected", "fragments"):
                v = r["counts"][k]
            else:
                v = r[k]
            check(same_number(text, v), f"report.csv {r['method']}/{r['lobe']}/{r['mode']} {k}: {text!r} != {v!r}")


def pareto(points):
    return {i for i, (x, y) in enumerate(points)
            if not any(x2 <= x and y2 <= y and (x2 < x or y2 < y) for x2, y2 in points)}


def check_plots(d, report):
    plots = report["plots"]
    check(plots["made"], f"no plots: {plots.get('why')} (install gnuplot-nox)")
    if not plots["made"]:
        return
    check("error_vs_cycles.png" in plots["files"], "error_vs_cycles.png not made")
    for name in plots["files"]:
        if not name.endswith(".png"):
            continue
        png = read_png(os.path.join(d, name))
        text = open(os.path.join(d, name[:-4] + ".csv")).read()
        if png:
            check(png[2].get("shadesim-plot-data") == text, f"{name}: its data is not the CSV beside it")
    # error_vs_cycles.csv from report.json, the front computed here.
    rows = [r for r in report["rows"] if r["total_cycles"] is not None]
    got = list(csv.DictReader(open(os.path.join(d, "error_vs_cycles.csv"))))
    check(len(got) == len(rows), f"error_vs_cycles.csv: {len(got)} points for {len(rows)} rows with cycles")
    fronts = {k: pareto([(r["total_cycles"], r["metrics"][k]) for r in rows]) for k in ("max_abs_lsb", "rmse_lsb")}
    for i, (g, r) in enumerate(zip(got, rows)):
        want = {"label": f"{r['method']}/{r['lobe']}", "method": r["method"], "lobe": r["lobe"], "mode": r["mode"],
                "spec_unit": str(int(bool(r["spec_configs"]))), "total_cycles": str(r["total_cycles"]),
                "front_max_abs_lsb": str(int(i in fronts["max_abs_lsb"])),
                "front_rmse_lsb": str(int(i in fronts["rmse_lsb"]))}
        for k, v in want.items():
            check(g[k] == v, f"error_vs_cycles.csv point {i} {k}: {g[k]!r} != {v!r}")
        for k in ("max_abs_lsb", "rmse_lsb"):
            check(float(g[k]) == r["metrics"][k], f"error_vs_cycles.csv point {i} {k}: {g[k]} != {r['metrics'][k]}")
    check(any(fronts["max_abs_lsb"]), "no Pareto front")
    check_time_plot(d, report)


def check_time_plot(d, report):
    """error_vs_time.csv from report.json: a point per row with a time on some device, its
    fronts computed here; made exactly when some row has a time."""
    devices = [e["name"] for e in report["options"].get("pnr_devices") or []]
    rows = [r for r in report["rows"] if any((r.get("time_us") or {}).get(dv) is not None for dv in devices)]
    made = "error_vs_time.csv" in report["plots"]["files"]
    check(made == bool(rows), f"error_vs_time: made {made}, {len(rows)} rows with a time")
    if not made:
        return
    got = list(csv.DictReader(open(os.path.join(d, "error_vs_time.csv"))))
    check(len(got) == len(rows), f"error_vs_time.csv: {len(got)} points for {len(rows)} rows with a time")
    for dv in devices:
        idx = [i for i, r in enumerate(rows) if r["time_us"][dv] is not None]
        front = {idx[k] for k in pareto([(rows[i]["time_us"][dv], rows[i]["metrics"]["max_abs_lsb"]) for i in idx])}
        for i, (g, r) in enumerate(zip(got, rows)):
            check(same_number(g[f"{dv}_us"], r["time_us"][dv]), f"error_vs_time.csv point {i} {dv}_us: {g[f'{dv}_us']!r}")
            check(g[f"front_{dv}"] == str(int(i in front)), f"error_vs_time.csv point {i} front_{dv}")


# --- images and sample rows ------------------------------------------------------------------

def check_images(d, report):
    check(report["checks"]["images_equal_across_modes"], "report: images differ across modes")
    check(report["checks"]["failures"] == [], f"report: failures {report['checks']['failures']}")
    by_cell = {}
    for r in report["rows"]:
        check(r["image_equals_first_mode"], f"{r['method']}/{r['lobe']} {r['mode']}: image differs from the first mode's")
        by_cell.setdefault((r["method"], r["lobe"]), set()).add((r["image"], r["heat_map"]))
    modes = report["options"]["modes"]
    for cell, files in by_cell.items():
        check(len(files) == 1, f"{cell}: several images {files}")
        n = sum(1 for r in report["rows"] if (r["method"], r["lobe"]) == cell)
        check(n == len(modes), f"{cell}: {n} rows for {len(modes)} modes")
        for f in next(iter(files)):
            read_png(os.path.join(d, f))
    read_png(os.path.join(d, "contact_sheet.png"))


def check_sample(d, report, spec):
    method, lobe, mode, rjson, rpng = spec.split(",")
    r = json.load(open(rjson))
    row = next((x for x in report["rows"] if (x["method"], x["lobe"], x["mode"]) == (method, lobe, mode)), None)
    if row is None:
        failures.append(f"sample {method}/{lobe}/{mode}: no such row")
        return
    check(row["metrics"] == r["metrics"], f"sample {method}/{lobe}: metrics {row['metrics']} != render's {r['metrics']}")
    check(row["highlight"] == r["highlight"], f"sample {method}/{lobe}: highlight differs from render's")
    check(row["span_cycles"] == r["cycles"], f"sample {method}/{lobe}: span cycles {row['span_cycles']} != {r['cycles']}")
    check((row["spec_cycles"] or 0) == r["spec_cycles"], f"sample {method}/{lobe}: spec cycles differ from render's")
    with open(os.path.join(d, row["image"]), "rb") as a, open(rpng, "rb") as b:
        check(a.read() == b.read(), f"sample {method}/{lobe}: render --mode {mode} writes other PNG bytes than the report")


def main():
    d = sys.argv[1]
    report = json.load(open(os.path.join(d, "report.json")))
    check(report["format"] == "shadesim report 1", "report.json: format")
    check(report["command"].startswith("shadesim report "), f"report.json: command {report['command']!r}")
    check(re.fullmatch(r"[0-9a-f]{16}", report["scene"]["hash"]) is not None, "report.json: scene hash")
    check_markdown(d, report)
    check_csv(d, report)
    check_plots(d, report)
    check_images(d, report)
    for spec in sys.argv[2:]:
        check_sample(d, report, spec)
    for f in failures[:30]:
        print("FAIL " + f)
    print(f"report_check: {len(report['rows'])} rows, {len(failures)} failures")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
