#!/usr/bin/env python3
"""pnr.py: place and route one specular-unit or span-unit configuration on iCE40 with nextpnr and
report its maximum clock frequency (fmax) and utilisation, so that cycles become nanoseconds.

Usage: scripts/pnr.py CONFIG [--unit spec|span] [--prom FILE] [--device up5k|hx8k|both]
                      [--out DIR] [--seed N] [--freq MHZ] [--no-dsp]

CONFIG, --unit and --prom are exactly synth.py's: this script imports scripts/synth.py for the
configuration and its checks, the PROM and its checks, the RTL files, the yosys commands that
read and parameterise the unit (one chparam of shd_config.py) and the iCE40 flow, and so shares
its path rule (no whitespace, quotes, backslashes or ';' in the PROM, output and RTL paths).
  --device  up5k: iCE40UP5K, package sg48: 5,280 logic cells, 8 SB_MAC16 DSPs, 30 block RAMs;
            hx8k: iCE40HX8K, package ct256: 7,680 logic cells, no DSP, 32 block RAMs;
            both (the default).
  --out     the output directory, default out/pnr/<unit>_<name> of the repository
            (<unit>_<name>_nodsp with --no-dsp).
  --seed    nextpnr's placement seed, default 1. The same netlist, seed and nextpnr give the same
            placement, routing and fmax; another seed gives another fmax (a few per cent apart).
  --freq    the target frequency given to nextpnr in MHz, default 12: low, so that no run fails
            timing on purpose (--timing-allow-fail as well). fmax is what the routed design
            achieves; the target only steers the timing-driven placer.
  --no-dsp  synthesise without -dsp: every multiplier in logic cells. The only way onto the HX8K
            for a unit with multipliers, and the only flow whose fmax is exact (see "DSP timing").

The flow. yosys synthesises the unit alone with synth.py's iCE40 flow, `synth_ice40 -dsp` (-dsp
left out with --no-dsp), into unit_netlist.json: synth.py's area, and what each port bit of the
unit meets. This script writes the wrapper below (pnr_top.v) and yosys synthesises wrapper and
unit with the same flow into netlist.json (-json). Per device, nextpnr-ice40 --<device> --package
<package> packs the unit alone (--pack-only: its own logic cells) and the design, then, when the
design's DSPs, block RAMs and logic cells are within the device's, places and routes it: --json
netlist.json --seed N --freq MHZ --timing-allow-fail --report <device>_report.json (nextpnr 0.4's
JSON report: fmax per clock, utilisation, critical paths) --sdf <device>.sdf (every cell and
routing delay). A design over a device's resources is not placed: "does not fit: needs 8
SB_MAC16, the HX8K has none", with its packed utilisation. So is one whose placement fails for
lack of room (nextpnr's error line).

The wrapper (shd_pnr_top). A unit is a block inside a design, not a chip: its ports (51 input
and 42 output bits for spec:default, 1,129 and 187 for span:serial) are many more than a package
has pins (39 on the UP5K sg48), and nextpnr 0.4 has neither an out-of-context mode nor virtual
pins (--pcf-allow-unconstrained still puts every port on a pin). The wrapper gives the unit what
its neighbours in a design give it, registers, on four pins (clk, rst_n, sin, sout), built from
what each port bit meets in the unit alone:
  - an input bit the unit feeds into logic comes from its own flip-flop of a shift register from
    pin sin: independent flip-flops, so that synthesis can simplify nothing in the unit (a shared
    or constant source would let it merge or drop logic), and the unit's input paths start at a
    register as in a design;
  - an input bit whose only sink is a flip-flop of the unit (a descriptor register of the span
    unit, loaded on accept) comes from an SB_LUT4 instance reading its own 4 bits of that shift
    register: opaque to yosys (nothing to simplify, no two alike to merge), and nextpnr packs it
    with that flip-flop into one logic cell, so such bits cost no cell (a flip-flop per bit would
    cost one each: 718 for span:serial, which then does not fit the UP5K);
  - an output bit driven by logic goes straight into its own flip-flop, the register a consumer
    would have, no logic between; an output bit driven by a flip-flop of the unit needs none;
  - those bits reach pin sout through a tree of XORs of 4, each level registered: every output
    stays observable (nothing is optimised away) and no wrapper path has more than one LUT;
  - an input bit the unit does not use is tied to 0; clk_i and rst_ni come from pins clk and rst_n
    (rst_n: an asynchronous reset, not timed).
So a register-to-register path with two or more logic levels (LUTs, carries, DSPs) runs through
the unit's logic: inside it, from an input register into it, or out of it into an output
register. The check `critical_path` fails the run (exit 1) when the critical path has fewer:
then fmax could be the wrapper's. The wrapper costs logic cells: `luts` counts the placed design,
`unit_luts` the unit alone as nextpnr packs it, `wrapper_luts` the difference. A design that does
not fit with its wrapper is reported as not fitting, with the unit's own figure beside.

DSP timing. nextpnr 0.4 times every SB_MAC16 port as a register of the DSP's CLK, with no delay
inside the DSP. yosys uses the DSPs without their registers (CLK tied to 0; the span unit's keep
the A input register), so nextpnr cuts every path through a DSP in two, times the halves in a
pseudo clock of the constant net and leaves them out of the clock's fmax (icetime from
fpga-icestorm cuts the same way). This script times the routed design again from the SDF:
nextpnr's cell and routing delays, a DSP without registers passed through from each input bit to
the output bits of no lower weight (arithmetic carries upwards only; C feeds the upper half), its
own delay 0. Paths through no DSP give nextpnr's critical path to the picosecond (the check
`sta` fails the run otherwise). fmax_mhz is 1000 / the longest path of all, DSPs included: exact
without SB_MAC16 (fmax_kind "exact", e.g. --no-dsp), otherwise an upper bound (fmax_kind "upper
bound ..."): the DSPs' own delays, unknown to these tools, only lengthen the paths. dsp_paths
gives the longest path through exactly k DSPs for each k, so that a DSP delay t from elsewhere
gives the period max over k of (delay_ns + k * t). Block RAM (the spec PROM) has a registered
read and is timed by nextpnr's data.

Output (in --out; every file is written under a temporary name and renamed):
  unit_netlist.json, unit_stat.json, yosys_unit.log   the unit alone (synth.py's flow)
  pnr_top.v                                           the wrapper
  netlist.json, netlist_stat.json, yosys.log          wrapper and unit: what nextpnr places
  <device>_unit_pack.log, <device>_pack.log           nextpnr --pack-only of the unit, the design
  <device>.log, <device>_report.json, <device>.sdf    nextpnr's place and route (when it fits)
  summary.json  {"config", "unit", "config_file", "prom_file" (spec), "top", "rtl", "yosys",
                 "nextpnr", "flow", "synth_wall_s", "wrapper": {...}, "unit_cells",
                 "netlist_cells", "devices": {"<device>": {...}}}
    per device:
    fits          the design was placed and routed on the device
    fmax_mhz      see DSP timing; null when it does not fit. fmax_kind "exact" or "upper bound
                  ..."; fmax_nextpnr_mhz nextpnr's own figure (paths through no DSP)
    luts          logic cells (ICESTORM_LC: a LUT4, a carry and a flip-flop) of the design;
                  luts_total the device's; unit_luts, wrapper_luts as above
    dsps, dsps_total          SB_MAC16; brams, brams_total  SB_RAM40_4K
    util_percent  {"luts", "dsps", "brams"}: used / the device's, in per cent (null when the
                  device has none)
    seed, freq_target_mhz, nextpnr (its version), wall_s (the device's wall time: nextpnr's
                  packing, placing and routing, and the timing from the SDF)
    critical_path {"delay_ns", "source", "sink", "dsps", "dsp_count", "logic_levels"}
    dsp_paths     [{"dsp_count": k, "delay_ns", ...}] per k, when there are SB_MAC16;
                  dsps_cut the DSPs left to nextpnr's model (paths through them cut: a pipeline
                  or accumulator register, which this model has not; 0 for both units)
    why_not       why it does not fit (only when it does not)

Exit status: 0 success, also when the unit does not fit (the fit is a result, not an error);
1 a failed check (critical_path, sta); 2 a usage or input error, a missing tool included;
3 yosys or nextpnr failed (other than by the design not fitting).
"""
import argparse
import itertools
import json
import math
import os
import re
import shutil
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.realpath(__file__))
sys.dont_write_bytecode = True  # no __pycache__ in scripts/ (a source tree or an installation)
sys.path.insert(0, HERE)
import shd_config  # noqa: E402  (found next to this script)
import synth  # noqa: E402
from synth import InputError, YosysError, plain_path, write_json  # noqa: E402

PROG = "pnr.py"
NEXTPNR = "nextpnr-ice40"
TOP = "shd_pnr_top"
INST = "u_unit"
W = "pnrw_"  # the prefix of the wrapper's signals and cells
CLOCK_PORT, RESET_PORT = "clk_i", "rst_ni"  # the units' clock and (active-low) reset

DEVICES = {
    "up5k": dict(name="UP5K", flag="--up5k", package="sg48", luts=5280, dsps=8, brams=30),
    "hx8k": dict(name="HX8K", flag="--hx8k", package="ct256", luts=7680, dsps=0, brams=32),
}


class ToolError(Exception):
    """yosys or nextpnr failed: exit status 3."""


def write_text(path, text):
    tmp = os.path.join(os.path.dirname(path), "." + os.path.basename(path) + ".tmp")
    with open(tmp, "w") as f:
        f.write(text)
    os.replace(tmp, path)


def remove(path):
    if os.path.exists(path):
        os.remove(path)


def yosys_step(commands, outputs, log, what):
    """synth.yosys_run, its output files written as <file>.tmp and renamed on success."""
    for f in outputs:
        remove(f + ".tmp")
    try:
        wall = synth.yosys_run(commands, log, what)
    except YosysError:
        for f in outputs:
            remove(f + ".tmp")
        raise
    for f in outputs:
        os.replace(f + ".tmp", f)
    return wall


# ---------------------------------------------------------------- the wrapper

def port_bits(netlist, top):
    """The unit's ports from its own synthesised netlist: [(name, direction, [class per bit])].
    An input bit is "reg" when its only sink is the D input of a flip-flop, "logic" when it has
    other sinks, "unused" when none; an output bit is "reg" when a flip-flop drives it, "logic"
    when anything else does, "const" when it is a constant, "same" when an earlier output bit
    is the same net (the wrapper observes each net once: two copies would cancel in an XOR)."""
    m = netlist["modules"][top]
    sinks, drivers = {}, {}
    for cell in m["cells"].values():
        dirs = cell.get("port_directions", {})
        for port, bits in cell["connections"].items():
            for b in bits:
                if not isinstance(b, int):
                    continue
                if dirs.get(port) == "output":
                    drivers[b] = cell["type"]
                else:
                    sinks.setdefault(b, []).append((cell["type"], port))
    outputs = {b for p in m["ports"].values() if p["direction"] == "output" for b in p["bits"]}
    seen, ports = set(), []
    for name, p in m["ports"].items():
        classes = []
        for b in p["bits"]:
            if p["direction"] == "input":
                s = sinks.get(b, []) + ([("port", "")] if b in outputs else [])
                if not s:
                    classes.append("unused")
                elif len(s) == 1 and s[0][0].startswith("SB_DFF") and s[0][1] == "D":
                    classes.append("reg")
                else:
                    classes.append("logic")
            elif not isinstance(b, int):
                classes.append("const")
            elif b in seen:
                classes.append("same")
            else:
                seen.add(b)
                classes.append("reg" if drivers.get(b, "").startswith("SB_DFF") else "logic")
        ports.append((name, p["direction"], classes))
    return ports


def wrapper_verilog(c, ports):
    """The wrapper's Verilog and its figures (see the docstring)."""
    names = [p[0] for p in ports]
    for need in (CLOCK_PORT, RESET_PORT):
        if need not in names:
            raise InputError(f"{c.top} has no port {need}: the wrapper needs the units' clk_i "
                             f"and rst_ni")
    if any(d not in ("input", "output") for _, d, _ in ports):
        raise InputError(f"{c.top} has an inout port: the wrapper drives inputs and outputs only")
    ins = [(n, cl) for n, d, cl in ports if d == "input" and n not in (CLOCK_PORT, RESET_PORT)]
    outs = [(n, cl) for n, d, cl in ports if d == "output"]
    n_reg = sum(cl.count("reg") for _, cl in ins)
    n_logic = sum(cl.count("logic") for _, cl in ins)
    # The LUTs' flip-flops: each LUT reads its own 4 of them, C(n_src, 4) >= n_reg.
    n_src = 0
    if n_reg:
        n_src = 8
        while math.comb(n_src, 4) < n_reg:
            n_src += 1
    n_sr = n_src + n_logic
    v = [f"// Generated by scripts/pnr.py for {c.unit}:{c.name}: the unit between registers on",
         "// four pins, for place and route (the docstring of scripts/pnr.py says why).",
         f"module {TOP} (",
         "  input  wire clk,",
         "  input  wire rst_n,",
         "  input  wire sin,",
         "  output wire sout",
         ");"]
    if n_sr:
        shift = "sin" if n_sr == 1 else f"{{{W}sr_q[{n_sr - 2}:0], sin}}"
        v += [f"  // A shift register from pin sin: {n_src} bits for the LUTs, then one bit per "
              f"input bit that feeds logic ({n_logic}).",
              f"  reg  [{n_sr - 1}:0] {W}sr_q;",
              f"  always @(posedge clk) {W}sr_q <= {shift};"]
    if n_reg:
        v += [f"  // The {n_reg} input bits the unit registers as they come: an SB_LUT4 each, "
              f"packed with that register.",
              f"  wire [{n_reg - 1}:0] {W}lut_o;"]
    combos = itertools.combinations(range(n_src), 4)
    conn, lut_i, logic_i = [], 0, n_src
    for name, cl in ins:
        bits = []
        for k in cl:
            if k == "reg":
                a, b, cc, d = next(combos)
                v.append(f"  SB_LUT4 #(.LUT_INIT(16'h6996)) {W}lut_{lut_i} (.O({W}lut_o[{lut_i}]), "
                         f".I0({W}sr_q[{a}]), .I1({W}sr_q[{b}]), .I2({W}sr_q[{cc}]), "
                         f".I3({W}sr_q[{d}]));")
                bits.append(f"{W}lut_o[{lut_i}]")
                lut_i += 1
            elif k == "logic":
                bits.append(f"{W}sr_q[{logic_i}]")
                logic_i += 1
            else:
                bits.append("1'b0")
        conn.append(f"   ,.{name}({{{', '.join(reversed(bits))}}})")
    nout = sum(len(cl) for _, cl in outs)
    v.append(f"  wire [{nout - 1}:0] {W}out_w;")
    lo, captured, direct = 0, [], []
    for name, cl in outs:
        conn.append(f"   ,.{name}({W}out_w[{lo + len(cl) - 1}:{lo}])")
        for i, k in enumerate(cl):
            if k == "logic":
                captured.append(lo + i)
            elif k == "reg":
                direct.append(lo + i)
        lo += len(cl)
    observed = [f"{W}out_w[{i}]" for i in direct]
    if captured:
        v += [f"  // The {len(captured)} output bits the unit drives from logic: a flip-flop each, "
              f"no logic between.",
              f"  reg  [{len(captured) - 1}:0] {W}cap_q;",
              f"  always @(posedge clk) {W}cap_q <= "
              f"{{{', '.join(f'{W}out_w[{i}]' for i in reversed(captured))}}};"]
        observed += [f"{W}cap_q[{j}]" for j in range(len(captured))]
    if not observed:
        raise InputError(f"{c.top} has no output that is not a constant")
    v += [f"  {c.top} {INST} (", f"    .{CLOCK_PORT}(clk),", f"    .{RESET_PORT}(rst_n)"]
    v += conn + ["  );",
                 f"  // The {len(observed)} observed bits (the unit's registered outputs and the "
                 f"flip-flops above) to pin sout: XORs of 4, each level registered."]
    prev, level = observed, 0
    while len(prev) > 1 or level == 0:
        level += 1
        m = (len(prev) + 3) // 4
        v += [f"  reg  [{m - 1}:0] {W}x{level}_q;", "  always @(posedge clk) begin"]
        for j in range(m):
            v.append(f"    {W}x{level}_q[{j}] <= ^{{{', '.join(prev[4 * j:4 * j + 4])}}};")
        v.append("  end")
        prev = [f"{W}x{level}_q[{j}]" for j in range(m)]
    v += [f"  assign sout = {prev[0]};", "endmodule", ""]
    n_in = sum(len(cl) for _, cl in ins)
    figures = dict(input_bits=n_in, inputs_into_flip_flops=n_reg, inputs_into_logic=n_logic,
                   inputs_unused=n_in - n_reg - n_logic, lut_source_flip_flops=n_src,
                   output_bits=nout, outputs_from_flip_flops=len(direct),
                   outputs_from_logic=len(captured), xor_levels=level,
                   pins=["clk", "rst_n", "sin", "sout"])
    return "\n".join(v), figures


# ---------------------------------------------------------------- nextpnr

UTIL_RE = re.compile(r"^Info:\s+(\w+):\s+(\d+)/\s*(\d+)\s+\d+%", re.M)


def nextpnr_version():
    r = subprocess.run([NEXTPNR, "--version"], stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                       text=True)
    m = re.search(r"\(Version ([^)]*)\)", r.stdout)
    return m.group(1) if m else r.stdout.strip()


def nextpnr(dev, netlist, top, log, seed, freq, products=None):
    """Runs nextpnr-ice40 on the device: --pack-only without `products`, else place and route
    writing products["report"] and products["sdf"] (each as .tmp, renamed on success). Writes
    the log the same way. Returns (return code, log text, wall time in s)."""
    d = DEVICES[dev]
    files = [log] + list((products or {}).values())
    for f in files:
        remove(f + ".tmp")
    cmd = [NEXTPNR, d["flag"], "--package", d["package"], "--json", netlist, "--top", top,
           "--seed", str(seed), "--freq", f"{freq:g}", "-q", "-l", log + ".tmp"]
    if products is None:
        cmd.append("--pack-only")
    else:
        cmd += ["--timing-allow-fail", "--report", products["report"] + ".tmp",
                "--sdf", products["sdf"] + ".tmp"]
    t0 = time.monotonic()
    r = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    wall = time.monotonic() - t0
    ok = r.returncode == 0 and all(os.path.exists(f + ".tmp") for f in files)
    if os.path.exists(log + ".tmp"):
        os.replace(log + ".tmp", log)
    for f in files[1:]:
        if os.path.exists(f + ".tmp"):
            if ok:
                os.replace(f + ".tmp", f)
            else:
                os.remove(f + ".tmp")
    text = ""
    if os.path.exists(log):
        with open(log, errors="replace") as f:
            text = f.read()
    if r.returncode == 0 and not ok:
        raise ToolError(f"{NEXTPNR} wrote no log, report or SDF for {dev} (log: {log})")
    if r.returncode != 0 and not text.strip():
        text = r.stderr
    return r.returncode, text, wall


def tool_failure(dev, what, log, text):
    errors = [l for l in text.splitlines() if "ERROR" in l] or text.splitlines()[-10:]
    return ToolError("\n".join([f"{NEXTPNR} failed for {dev} ({what}; full log: {log}):"]
                               + errors[:5]))


def packed_luts(dev, netlist, top, log, seed, freq):
    """Logic cells of a netlist as nextpnr packs it for the device."""
    rc, text, _ = nextpnr(dev, netlist, top, log, seed, freq)
    util = {m.group(1): int(m.group(2)) for m in UTIL_RE.finditer(text)}
    if rc != 0 or "ICESTORM_LC" not in util:
        raise tool_failure(dev, f"packing {top}", log, text)
    return util["ICESTORM_LC"]


# ---------------------------------------------------------------- timing through the DSPs

CLOCK_PINS = {"ICESTORM_LC": {"CLK"}, "ICESTORM_RAM": {"RCLK", "WCLK"}, "ICESTORM_DSP": {"CLK"},
              "ICESTORM_SPRAM": {"CLOCK"}}
SDF_DELAY = r"\((\d+):(\d+):(\d+)\)(?: \((\d+):(\d+):(\d+)\))?"
SDF_IOPATH = re.compile(r"\(IOPATH (\S+) (\S+) " + SDF_DELAY)
SDF_SETUP = re.compile(r"\(SETUPHOLD \((?:posedge|negedge) (\S+)\) \((?:posedge|negedge) (\S+)\) "
                       r"\((\d+):(\d+):(\d+)\)")
SDF_WIRE = re.compile(r"\(INTERCONNECT (\S+) (\S+) " + SDF_DELAY)
SDF_ESCAPE = re.compile(r"\\(.)")


def sdf_name(s):
    return SDF_ESCAPE.sub(r"\1", s)


def sdf_pin(s):
    inst, _, port = s.rpartition("/")
    return sdf_name(inst), port


def sdf_ps(groups):
    return max(int(g) for g in groups if g is not None)


def parse_sdf(path):
    """(cell types, IOPATHs, setup checks, interconnects) of nextpnr's SDF, delays in ps."""
    types, iopaths, setups, wires = {}, [], [], []
    inst = ctype = None
    with open(path) as f:
        for n, line in enumerate(f, 1):
            s = line.strip()
            m = True
            if s.startswith("(CELLTYPE "):
                ctype = s[len("(CELLTYPE "):].strip('")')
            elif s.startswith("(INSTANCE"):
                inst = sdf_name(s[len("(INSTANCE"):].strip().rstrip(")"))
                types[inst] = ctype
            elif s.startswith("(INTERCONNECT "):
                m = SDF_WIRE.match(s)
                if m:
                    wires.append((sdf_pin(m.group(1)), sdf_pin(m.group(2)),
                                  sdf_ps(m.groups()[2:])))
            elif s.startswith("(IOPATH "):
                m = SDF_IOPATH.match(s)
                if m:
                    iopaths.append((inst, m.group(1), m.group(2), sdf_ps(m.groups()[2:])))
            elif s.startswith("(SETUPHOLD "):
                m = SDF_SETUP.match(s)
                if m:
                    setups.append((inst, m.group(1), m.group(2), sdf_ps(m.groups()[2:])))
            elif s.startswith("(TIMESCALE") and s != "(TIMESCALE 1ps)":
                m = None
            if not m:
                raise ToolError(f"{path}:{n}: unexpected SDF line: {s[:120]}")
    return types, iopaths, setups, wires


DSP_PIPELINE = ("TOP_8x8_MULT_REG", "BOT_8x8_MULT_REG", "PIPELINE_16x16_MULT_REG1",
                "PIPELINE_16x16_MULT_REG2")


def dsp_input_registers(netlist, top):
    """{nextpnr's name of each SB_MAC16: {"A".."D": its input register used (0/1)}, or None
    when it uses a register this model has not (a pipeline or accumulator register)}."""
    def bits(v):
        return int(v, 2) if isinstance(v, str) and re.fullmatch(r"[01]+", v) else v
    regs = {}
    for name, cell in netlist["modules"][top]["cells"].items():
        if cell["type"] != "SB_MAC16":
            continue
        p = {k: bits(v) for k, v in cell["parameters"].items()}
        ok = (all(p.get(k, 0) == 0 for k in DSP_PIPELINE)
              and p.get("TOPOUTPUT_SELECT", 0) != 1 and p.get("BOTOUTPUT_SELECT", 0) != 1)
        regs[name + "_DSP"] = {g: p.get(f"{g}_REG", 0) for g in "ABCD"} if ok else None
    return regs


def dsp_sta(sdf, dsp_regs, nextpnr_model=False):
    """The longest register-to-register paths of the routed design by the number k of DSPs
    they pass, the DSPs timed as the docstring says (DSP timing). dsp_regs: from
    dsp_input_registers; sdf: parse_sdf's. Returns ({k: {"delay_ns", "source", "sink", "dsps",
    "logic_levels"}}, the number of DSPs left to nextpnr's register model). With nextpnr_model
    every DSP keeps nextpnr's model, and the longest path is nextpnr's critical path."""
    types, iopaths, setups, wires = sdf
    # A clock pin is live when its net is not a constant (a DSP used without registers, the
    # write port of a ROM).
    live = set()
    for (src, _), (dst, dport), _ in wires:
        if dport in CLOCK_PINS.get(types.get(dst), ()) and "$PACKER_" not in src:
            live.add((dst, dport))
    # The DSPs modelled here, with their input registers (none when CLK is a constant); the
    # others keep nextpnr's model (every port a register: the paths through them are cut).
    model = {}
    for inst, t in types.items():
        if t == "ICESTORM_DSP" and not nextpnr_model:
            regs = dsp_regs.get(inst)
            if (inst, "CLK") not in live:
                model[inst] = dict.fromkeys("ABCD", 0)
            elif regs is not None:
                model[inst] = regs
    edges = {}  # pin -> [(pin, ps, tag)]; tag: None, "cell" (a logic cell) or the DSP left

    def edge(a, b, ps, tag=None):
        edges.setdefault(a, []).append((b, ps, tag))

    def weight(port):
        m = re.fullmatch(r"([ABCD])_(\d+)", port)
        return (None, 0) if m is None else (m.group(1), int(m.group(2)) + 16 * (m.group(1) == "C"))

    starts, ends, clk_to_q = {}, {}, {}
    for inst, frm, to, ps in iopaths:
        if frm in CLOCK_PINS.get(types[inst], ()):
            if inst in model:
                clk_to_q[inst] = max(clk_to_q.get(inst, 0), ps)
            elif (inst, frm) in live:  # clock to output: a register's output
                starts[(inst, to)] = max(starts.get((inst, to), 0), ps)
        elif inst not in model:
            edge((inst, frm), (inst, to), ps, "cell" if types[inst] == "ICESTORM_LC" else None)
    for inst, data, clk, ps in setups:
        if (inst, clk) not in live:
            continue
        if inst in model:
            group, _ = weight(data)
            if group is None or not model[inst][group]:
                continue  # a DSP input through which paths pass
        ends[(inst, data)] = max(ends.get((inst, data), 0), ps)
    dsp_ins, dsp_outs = set(), set()
    for src, dst, ps in wires:
        edge(src, dst, ps)
        if dst[0] in model and dst[1] != "CLK":
            dsp_ins.add(dst)
        if src[0] in model:
            dsp_outs.add(src)
    # Inside a modelled DSP: output bit O_j depends on the input bits of weight <= j only:
    # A_i, B_i (the product) and D_i (the lower adder) for j >= i, C_i (the upper adder) for
    # j >= 16 + i. Through a chain of level nodes (inst, "#j"), 0 ps each: level j holds the
    # latest input of weight <= j. An input register launches at its bit's level (clock to
    # output: nextpnr's DSP figure). Other inputs (carry, sign extension, add/sub controls)
    # enter at level 0; other outputs (CO, ACCUMCO, SIGNEXTOUT) leave from level 31.
    for inst in model:
        for j in range(31):
            edge((inst, f"#{j}"), (inst, f"#{j + 1}"), 0)
    for inst, port in dsp_ins:
        group, level = weight(port)
        node = (inst, f"#{min(level, 31)}")
        if group is not None and model[inst][group]:
            starts[node] = max(starts.get(node, 0), clk_to_q.get(inst, 0))
        else:
            edge((inst, port), node, 0)
    for inst, port in dsp_outs:
        m = re.fullmatch(r"O_(\d+)", port)
        edge((inst, f"#{31 if m is None else int(m.group(1))}"), (inst, port), 0, inst)
    # Longest arrival per (pin, DSPs passed), the pins in topological order.
    indeg = {}
    for a, outs in edges.items():
        indeg.setdefault(a, 0)
        for b, _, _ in outs:
            indeg[b] = indeg.get(b, 0) + 1
    arr = {p: {0: (ps, None)} for p, ps in starts.items()}  # pin -> {k: (ps, (pin, k, tag))}
    order = [p for p, n in indeg.items() if n == 0]
    done = 0
    while order:
        a = order.pop()
        done += 1
        for b, ps, tag in edges.get(a, ()):
            dsp = tag is not None and tag != "cell"
            for k, (t, _) in arr.get(a, {}).items():
                k2 = k + dsp
                if t + ps > arr.setdefault(b, {}).get(k2, (-1, None))[0]:
                    arr[b][k2] = (t + ps, (a, k, tag))
            indeg[b] -= 1
            if indeg[b] == 0:
                order.append(b)
    if done != len(indeg):
        raise ToolError("the timing graph of the SDF has a combinational loop")
    worst = {}
    for p, setup in ends.items():
        for k, (t, _) in arr.get(p, {}).items():
            if t + setup > worst.get(k, (-1,))[0]:
                worst[k] = (t + setup, p)
    result = {}
    for k, (t, p) in sorted(worst.items()):
        node, kk, dsps, levels = p, k, [], 0
        while arr[node][kk][1] is not None:
            prev, pk, tag = arr[node][kk][1]
            if tag == "cell":
                levels += 1
            elif tag is not None:  # from a DSP's level node to its output pin `node`
                dsps.append([tag, node[1]])
                levels += 1
            elif node[1].startswith("#") and not prev[1].startswith("#"):
                dsps[-1][1] = f"{prev[1]}->{dsps[-1][1]}"  # from the DSP's input pin `prev`
            node, kk = prev, pk
        result[k] = dict(delay_ns=round(t / 1000.0, 3), source=f"{node[0]}/{node[1]}",
                         sink=f"{p[0]}/{p[1]}", dsps=[f"{n} ({ports})" for n, ports in dsps[::-1]],
                         logic_levels=levels)
    as_registers = sum(1 for i, t in types.items() if t == "ICESTORM_DSP" and i not in model)
    return result, as_registers


# ---------------------------------------------------------------- one device

def evaluate(dev, sdf, report, has_dsps, dsp_regs, failed):
    """fmax and the paths of a routed design; appends failed checks to `failed`."""
    clocks = [k for k in report["fmax"] if not k.startswith(("$PACKER_GND", "$PACKER_VCC"))]
    if len(clocks) != 1:
        raise ToolError(f"{NEXTPNR} reported the clocks {sorted(report['fmax'])} for {dev}; "
                        f"expected one clock (clk)")
    clk = clocks[0]
    edge = f"posedge {clk}"
    own = [cp for cp in report["critical_paths"] if cp["from"] == edge and cp["to"] == edge]
    nextpnr_ns = round(sum(seg["delay"] for seg in own[0]["path"]), 3) if own else None
    parsed = parse_sdf(sdf)
    theirs, _ = dsp_sta(parsed, dsp_regs, nextpnr_model=True)
    paths, as_registers = dsp_sta(parsed, dsp_regs)
    mine = max((p["delay_ns"] for p in theirs.values()), default=None)
    if mine is None or nextpnr_ns is None or abs(mine - nextpnr_ns) > 0.002:
        failed.append(f"{dev} sta: with nextpnr's DSP model the longest path takes {mine} ns by "
                      f"the SDF, {nextpnr_ns} ns by nextpnr: the SDF does not reproduce nextpnr's "
                      f"timing")
    k, crit = max(paths.items(), key=lambda kv: (kv[1]["delay_ns"], -kv[0]))
    if crit["logic_levels"] < 2:
        failed.append(f"{dev} critical_path: the critical path ({crit['source']} -> "
                      f"{crit['sink']}) has {crit['logic_levels']} logic level(s), no more than "
                      f"a wrapper path: fmax may be the wrapper's, not the unit's")
    r = dict(fmax_mhz=round(1000.0 / crit["delay_ns"], 2),
             fmax_kind="exact" if not has_dsps else
             "upper bound: the SB_MAC16 delays are not in it",
             fmax_nextpnr_mhz=round(report["fmax"][clk]["achieved"], 2),
             critical_path=dict(crit, dsp_count=k))
    if has_dsps:
        r["dsp_paths"] = [dict(dsp_count=kk, **p) for kk, p in sorted(paths.items())]
        r["dsps_cut"] = as_registers
    return r


def percent(used, total):
    return None if total == 0 else round(100.0 * used / total, 1)


def device_result(dev, a, out, cells, version, failed):
    """The summary entry of one device; prints its line."""
    d = DEVICES[dev]
    netlist = os.path.join(out, "netlist.json")
    need_dsps = cells.get("SB_MAC16", 0)
    need_brams = sum(n for t, n in cells.items() if t.startswith("SB_RAM40_4K"))
    t0 = time.monotonic()
    for f in (f"{dev}.log", f"{dev}_report.json", f"{dev}.sdf"):  # an earlier run's
        remove(os.path.join(out, f))
    unit_luts = packed_luts(dev, os.path.join(out, "unit_netlist.json"), a.top,
                            os.path.join(out, f"{dev}_unit_pack.log"), a.seed, a.freq)
    luts = packed_luts(dev, netlist, TOP, os.path.join(out, f"{dev}_pack.log"), a.seed, a.freq)
    why_not = None
    if need_dsps > d["dsps"]:
        has = "none" if d["dsps"] == 0 else f"only {d['dsps']}"
        why_not = f"does not fit: needs {need_dsps} SB_MAC16, the {d['name']} has {has}"
    elif need_brams > d["brams"]:
        why_not = f"does not fit: needs {need_brams} SB_RAM40_4K, the {d['name']} has {d['brams']}"
    elif luts > d["luts"]:
        why_not = (f"does not fit: needs {luts} logic cells, the {d['name']} has {d['luts']}")
    r = dict(fits=False, fmax_mhz=None, luts=luts, luts_total=d["luts"], unit_luts=unit_luts,
             wrapper_luts=luts - unit_luts, dsps=need_dsps, dsps_total=d["dsps"],
             brams=need_brams, brams_total=d["brams"])
    if why_not is None:
        log = os.path.join(out, f"{dev}.log")
        products = dict(report=os.path.join(out, f"{dev}_report.json"),
                        sdf=os.path.join(out, f"{dev}.sdf"))
        rc, text, _ = nextpnr(dev, netlist, TOP, log, a.seed, a.freq, products)
        if rc != 0:
            room = [l for l in text.splitlines() if l.startswith("ERROR") and re.search(
                r"no BELs remaining|legal placement|utilisation|fail\w* to route|routing\b.*fail",
                l, re.I)]
            if not room:
                raise tool_failure(dev, "place and route", log, text)
            why_not = "does not fit: " + room[0][len("ERROR: "):]
        else:
            with open(products["report"]) as f:
                report = json.load(f)
            r["fits"] = True
            r["luts"] = report["utilization"]["ICESTORM_LC"]["used"]
            r["wrapper_luts"] = r["luts"] - unit_luts
            r.update(evaluate(dev, products["sdf"], report, need_dsps > 0, a.dsp_regs, failed))
    if why_not is not None and unit_luts <= d["luts"] and need_dsps <= d["dsps"] \
            and need_brams <= d["brams"]:
        why_not += (f" (the unit alone packs into {unit_luts} logic cells; the measurement "
                    f"wrapper adds {luts - unit_luts})")
    wall = float(f"{time.monotonic() - t0:.2f}")
    r["util_percent"] = dict(luts=percent(r["luts"], d["luts"]),
                             dsps=percent(need_dsps, d["dsps"]),
                             brams=percent(need_brams, d["brams"]))
    r.update(seed=a.seed, freq_target_mhz=a.freq, nextpnr=version, wall_s=wall)
    use = (f"LC {r['luts']:5d}/{d['luts']} (unit {unit_luts})  DSP {need_dsps}/{d['dsps']}  "
           f"BRAM {need_brams}/{d['brams']}")
    if r["fits"]:
        kind = "" if r["fmax_kind"] == "exact" else " at most (DSP delays not in it)"
        line = f"fits, fmax {r['fmax_mhz']:6.2f} MHz{kind}  {use}"
    else:
        r["why_not"] = why_not
        line = f"{why_not}  {use}"
    print(f"  {d['name']:5s} {wall:5.1f} s  {line}", flush=True)
    return r


# ---------------------------------------------------------------- main

def parse_args(argv):
    p = argparse.ArgumentParser(prog=PROG, description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("config", metavar="CONFIG",
                   help="a configuration file, or <unit>:<name> of the registry")
    p.add_argument("--unit", choices=sorted(shd_config.UNITS),
                   help="the unit of a configuration file not named <unit>_<name>.json")
    p.add_argument("--prom", metavar="FILE", help="spec: the PROM hex file")
    p.add_argument("--device", choices=["up5k", "hx8k", "both"], default="both")
    p.add_argument("--out", metavar="DIR", help="output directory")
    p.add_argument("--seed", metavar="N", default="1", help="nextpnr's seed (default 1)")
    p.add_argument("--freq", metavar="MHZ", default="12",
                   help="nextpnr's target frequency in MHz (default 12)")
    p.add_argument("--no-dsp", action="store_true",
                   help="synthesise without -dsp (multipliers in logic cells)")
    a = p.parse_args(argv)
    if re.fullmatch(r"\d{1,10}", a.seed) is None or int(a.seed) >= 2**31:
        raise InputError(f"--seed '{a.seed}' is not an integer in [0, 2147483647]")
    a.seed = int(a.seed)
    try:
        freq = float(a.freq)
    except ValueError:
        freq = math.nan
    if not (math.isfinite(freq) and 0 < freq <= 1000):
        raise InputError(f"--freq '{a.freq}' is not a frequency in MHz in (0, 1000]")
    a.freq = freq
    return a


def main(argv):
    a = parse_args(argv)
    devices = ["up5k", "hx8k"] if a.device == "both" else [a.device]
    c, config_file, prom, _ = synth.prepare(a.config, a.unit, a.prom)
    a.top = c.top
    for tool in ("yosys", NEXTPNR):
        if shutil.which(tool) is None:
            raise InputError(f"{tool} not found (apt-get install {tool})")
    suffix = "_nodsp" if a.no_dsp else ""
    out = a.out if a.out is not None else os.path.join(synth.ROOT, "out", "pnr",
                                                       f"{c.unit}_{c.name}{suffix}")
    out = os.path.realpath(out)
    plain_path("output", out)
    plain_path("RTL", synth.ROOT)
    try:
        os.makedirs(out, exist_ok=True)
    except OSError as e:
        raise InputError(f"cannot create the output directory '{out}': {e.strerror}"
                         + ("" if a.out else " (pass --out DIR)"))
    rtl_files = synth.unit_rtl_files(c)
    chparams = shd_config.tool_args(c, "yosys")[0]
    base = synth.read_commands(c, rtl_files, chparams, prom)
    yosys_version = subprocess.run(["yosys", "-V"], stdout=subprocess.PIPE,
                                   text=True).stdout.strip()
    version = nextpnr_version()
    flow = synth.FLOWS["ice40"].replace(" -dsp", "") if a.no_dsp else synth.FLOWS["ice40"]
    print(f"{PROG}: {c.unit}:{c.name} / {flow} ...", flush=True)

    # The unit alone, as synth.py synthesises it: its area and what each port bit meets.
    unit_netlist = os.path.join(out, "unit_netlist.json")
    unit_stat = os.path.join(out, "unit_stat.json")
    synth_wall = yosys_step(base + [f"hierarchy -check -top {c.top}",
                                    f"{flow} -top {c.top} -json {unit_netlist}.tmp",
                                    f"tee -q -o {unit_stat}.tmp stat -json"],
                            [unit_netlist, unit_stat], os.path.join(out, "yosys_unit.log"),
                            f"{c.name} / {flow}")
    with open(unit_netlist) as f:
        ports = port_bits(json.load(f), c.top)
    verilog, wrapper = wrapper_verilog(c, ports)
    wrapper_file = os.path.join(out, "pnr_top.v")
    write_text(wrapper_file, verilog)
    # The unit in its wrapper: what nextpnr places. synth_ice40 elaborates the deferred modules
    # (the unit as chparam set it) and finds SB_LUT4 in its cell library.
    netlist = os.path.join(out, "netlist.json")
    stat = os.path.join(out, "netlist_stat.json")
    synth_wall += yosys_step(base + [f"read_verilog -defer {wrapper_file}",
                                     f"{flow} -top {TOP} -json {netlist}.tmp",
                                     f"tee -q -o {stat}.tmp stat -json"],
                             [netlist, stat], os.path.join(out, "yosys.log"),
                             f"{c.name} / {TOP} / {flow}")
    with open(unit_stat) as f:
        unit_cells = json.load(f)["design"]["num_cells_by_type"]
    with open(netlist) as f:
        a.dsp_regs = dsp_input_registers(json.load(f), TOP)
    with open(stat) as f:
        cells = json.load(f)["design"]["num_cells_by_type"]
    ffs = sum(n for t, n in unit_cells.items() if t.startswith("SB_DFF"))
    print(f"  synthesis {synth_wall:5.1f} s  unit: {unit_cells.get('SB_LUT4', 0)} SB_LUT4, {ffs} "
          f"flip-flops, {unit_cells.get('SB_MAC16', 0)} SB_MAC16; wrapper: "
          f"{wrapper['input_bits']} input bits ({wrapper['inputs_into_flip_flops']} through "
          f"LUTs), {wrapper['output_bits']} output bits", flush=True)

    summary = dict(config=c.name, unit=c.unit, config_file=config_file)
    if prom is not None:
        summary["prom_file"] = prom
    summary.update(top=c.top, rtl=c.rtl, yosys=yosys_version, nextpnr=version, flow=flow,
                   synth_wall_s=float(f"{synth_wall:.2f}"), wrapper=dict(top=TOP, **wrapper),
                   unit_cells=unit_cells, netlist_cells=cells, devices={})
    failed = []
    for dev in devices:
        summary["devices"][dev] = device_result(dev, a, out, cells, version, failed)
    write_json(os.path.join(out, "summary.json"), summary)
    print(f"  summary: {os.path.join(out, 'summary.json')}", flush=True)
    for msg in failed:
        print("CHECK FAILED: " + msg, file=sys.stderr)
    return 1 if failed else 0


if __name__ == "__main__":
    synth.run_main(main, PROG, (YosysError, ToolError))
