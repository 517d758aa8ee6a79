#!/usr/bin/env python3
"""synth.py: synthesise one specular-unit or span-unit configuration with yosys for iCE40 and/or
Xilinx 7-series and report its area.

Usage: scripts/synth.py CONFIG [--unit spec|span] [--prom FILE] [--out DIR]
                        [--target ice40|xc7|both] [--check]
       scripts/synth.py --dsps-of FILE --unit spec|span [--target ice40|xc7|both]

CONFIG is a configuration file (<unit>_<name>.json; --unit names the unit of a file named
otherwise) or "<unit>:<name>" of the registry vectors/config/ (scripts/shd_config.py reads it:
`shd_config.py list` prints the registry). The unit decides the top module and the RTL files:
spec is shd_spec_unit (rtl/shd_spec_unit.v, shd_spec_poly.v, shd_spec_schlick.v, shd_spec_explog.v,
shd_spec_piecewise.v, shd_coef_rom.v, shd_pipe_reg.v), span is shd_span_unit (rtl/shd_span_unit.v).
Everything below is about the spec unit except where "A span configuration" says otherwise. The
spec unit's parameter Kind chooses its datapath (0 poly, 1 table, 2 schlick, 3 explog, 4 piecewise;
rtl/shd_spec_unit.v); a parameter the configuration leaves out takes the Verilog default (Kind 0,
TableBits 8, Segments 1) here as in the RTL.
  --prom    the PROM ($readmemh hex file). Default: the repository's vectors/prom/spec_<name>.hex
            when it exists and CONFIG is the registry's configuration of that name (the same JSON);
            otherwise make one with `shadesim prom --config CONFIG --format hex -o FILE` and pass
            --prom FILE.
  --out     the output directory, default out/synth/<unit>_<name> of the repository (in an
            installation that is under <prefix>/share/shadesim: pass --out there).
  --target  ice40, xc7 or both (the default).
The rtl/, vectors/ and scripts/ directories are found relative to this script (the source tree,
or an installation's <prefix>/share/shadesim with the same layout), never via the current
directory.

The "rtl" object of the configuration becomes one `chparam -set Name Value ... shd_spec_unit`
(one command: separate chparams elaborate the module once per parameter, with old and new values
mixed, and yosys warns about out-of-range selects in those intermediate modules); the PROM
becomes RomFile, an absolute path (yosys reads it at elaboration: `initial $readmemh` under
SYNTHESIS). The PROM must hold exactly its depth of words of the configuration's word width:
2^ShinBits words (2^(ShinBits+TableBits) for Kind 1) of KW = CoefIntBits+CoefFracBits bits (Kind 0
degree 2, Kinds 2 and 3), 2*KW+CosFracBits+1 bits (Kind 0 degree 3), SpecFracBits+1 bits (Kind 1)
or Segments*(CosFracBits+1) bits (Kind 4). Kind 4 has a second such memory, its segment ROM: the
file PROM + ".seg" (the RTL appends the suffix to RomFile itself), 2^(ShinBits+log2 Segments)
words of clog2(CosFracBits+1) + (Degree+1)*KW bits, checked as strictly.
Paths travel inside yosys commands (RomFile as a Verilog string), so the PROM, the output
directory and the RTL directory must not contain whitespace, quotes, backslashes or ';'.
Flows:
  ice40  synth_ice40 -dsp                                  (flattens by default)
  xc7    synth_xilinx -family xc7 -flatten -noiopad -noclkbuf
         -flatten so both targets are counted the same way; -noiopad -noclkbuf because the unit
         is a block inside a design, not a chip top (IBUF/OBUF/BUFG would be ~100 cells of noise).

Output (in --out; every file is written under a temporary name and renamed):
  <target>_stat.json  yosys `stat -json` of the synthesised netlist
  <target>.log        the full yosys log
  summary.json        {"config", "config_file", "prom_file", "yosys", "rtl": {...}, "prom": {...},
                       "segment_rom": {...} (Kind 4; each {depth, word_bits, varying_bits}),
                       "targets": {"<target>": {luts, ffs, carries, dsps, brams, bram_kbits,
                       cells_total, wall_s, cells_by_type, expected, checks}}}
    luts        iCE40 SB_LUT4; xc7 LUT1..LUT6 plus INV (yosys's name for an inverting LUT1)
    ffs         every flip-flop primitive (SB_DFF*, FD*)
    carries     iCE40 SB_CARRY (one per bit); xc7 CARRY4 (one per 4 bits): not comparable
    dsps        SB_MAC16 / DSP48E1
    brams       block-RAM primitives (SB_RAM40_4K*, RAMB18E1, RAMB36E1); bram_kbits their capacity
    cells_total every cell of the netlist
    wall_s      wall time of the yosys run

--check makes the run fail (exit 1) unless the netlist is what the RTL is meant to become:
  rom_bram  The PROM is entirely in block RAM, and in the least block RAM its contents need.
            yosys drops PROM bit columns that are constant over all the words, so the
            geometry is depth (as above) x (columns that vary in the hex file). iCE40: the
            SB_RAM40_4K count equals min over its read modes 256x16, 512x8, 1024x4, 2048x2 of
            ceil(depth/d)*ceil(width/w). xc7: the capacity in kbit equals the least one over the
            RAMB18E1 (16384x1 .. 512x36) and RAMB36E1 (32768x1 .. 512x72) aspect ratios (yosys
            may pick either primitive when they tie, so kbit is compared, not the count). Also:
            no $mem cell and no distributed-RAM/ROM primitive is left. Fails when the ROM falls
            into LUTs (rom_style = "logic", an asynchronous read) or is duplicated. Kind 3 has
            two more ROMs, its fixed log and exp tables of 2^TableBits words (rtl/shd_spec_explog.v
            computes them at elaboration); their geometry comes from the same integer algorithm
            here (explog_tables), and each of the three memories is counted on its own. Kind 4
            has one more, its segment ROM (geometry from the .seg file), counted on its own too.
  dsps      The DSP count equals what the multipliers need. Operand widths come from the RTL
            header's derivation (uQ1.Wc: CW = Wc+1; KW = Ci+Cf; DTW = Df-1; GTW = Ci+1+Hf;
            AW = KW+3; FW = Wf+1; L = LightBits):
              MUL1     c*c           CW x CW unsigned                      (Kind 0)
              MUL2     deg 2: a*dt   (KW+1) x DTW signed (a is unsigned: one zero sign bit)
                       deg 3: gt*dt  GTW x DTW signed                      (Kind 0)
              Horner   deg 3: u*c    KW x (CW+1) signed                    (Kind 0)
              den      m*(1-c)       KW x CW unsigned                      (Kind 2)
              dg*r     log interp.   DGW x (Wc-T+1) unsigned               (Kind 3; GF, LF, EF,
              DN*G     D g(D)        CW x GW unsigned                       EX, GW = GF+2,
              N*L      y = n L       KW x (clog2(Wc+1)+LF) unsigned         DGW = GF-T+1,
              de*r2    exp interp.   DEW x (EX-T) unsigned, when EX > T     DEW = EF-T+1 as in
                                                                            rtl/shd_spec_explog.v)
              step 1   Kd*u + K      KW x (CW+1) signed (u: one zero sign  (Kind 4: the Horner
                                     bit; acc = Kd sign-extended, which    multiply-adds
                                     wreduce takes back to KW bits)        m = acc*u + K*2^Wc)
              step k   acc*u + K     AW x (CW+1) signed, k = 2..Degree     (Kind 4)
              MUL3..5  f*L           FW x L unsigned (three of them)       (every Kind)
            (Kind 1, the table, has MUL3..5 only; the Kind 2 divider has no multiplier.)
            and each is tiled the way yosys's share/mul2dsp.v does it (iCE40: 16x16 tiles;
            pieces narrower than 2 bits or with a product under 11 bits go to LUTs. xc7:
            signed-only 25x18 tiles, 17-bit A slices, products under 9 bits to LUTs). Fails
            when a multiplier stays in LUTs or is wider than the derivation (e.g. a manual sign
            extension that wreduce cannot remove costs whole extra DSP tiles).
  warnings  yosys printed no warning except the known harmless ones in KNOWN_WARNINGS below
            (multiple drivers, a memory turned into registers, a bad $readmemh are caught).

A span configuration (vectors/config/span_<mode>.json): the span unit shd_span_unit with the
configuration's "rtl" object; no PROM (--prom is an error), summary.json has "top" and no
"prom_file"/"prom". Its --check has these checks instead of rom_bram:
  dsps      The only multiplier is the row start icur = irow + didx*(xg - xref), one per
            attribute: AttrBits x (CoordBits+1) signed, of which the low AttrBits are used
            (the plane wraps at AttrBits). The DSP count equals NumAttr times its mul2dsp.v
            tiling as above. Fails when the lanes' i*didx (constant multiples, built from
            shifts and adds) or the LanesPerTri*didx step turn into multipliers, or the row
            multiply stays in LUTs.
  latches   proc_dlatch inferred no latch (the comb blocks assign every output on every path).
  no_mem    no $mem cell, block RAM or distributed RAM: the unit is registers and logic only.
  warnings  as above.

--dsps-of FILE runs no yosys: FILE holds a JSON array of "rtl" objects of --unit, and the output
(stdout) is a JSON array with, for each, {"<target>": the DSP count of the "dsps" check below}.
`shadesim sweep --area` uses it to tell points whose multipliers map alike (docs/sweeps.md).

yosys runs with jemalloc's malloc preloaded when Debian's libjemalloc2 is installed (the same
netlist in about 0.75 of the time); SHD_JEMALLOC=0 in the environment runs it with the C
library's.

Exit status: 0 success, 1 a failed check, 2 a usage or input error, 3 yosys failed.
"""
import argparse
import ctypes.util
import functools
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

ROOT = os.path.dirname(HERE)  # the source tree, or <prefix>/share/shadesim
PROG = "synth.py"

# The parameters the checks below use; the configuration must define them (the spec unit's per
# Kind; Kind, TableBits and Segments themselves may be left out: SPEC_DEFAULTS).
REQUIRED = {
    "spec": {0: ["Degree", "CosFracBits", "ShinBits", "CoefIntBits", "CoefFracBits",
                 "DiffFracBits", "HornerFracBits", "SpecFracBits", "LightBits"],
             1: ["ShinBits", "SpecFracBits", "LightBits"],
             2: ["CosFracBits", "ShinBits", "CoefIntBits", "CoefFracBits", "SpecFracBits", "LightBits"],
             3: ["CosFracBits", "ShinBits", "CoefIntBits", "CoefFracBits", "SpecFracBits", "LightBits"],
             4: ["Degree", "CosFracBits", "ShinBits", "CoefIntBits", "CoefFracBits", "SpecFracBits",
                 "LightBits", "PipeStages", "Segments"]},
    "span": ["NumTri", "LanesPerTri", "AlignLanes", "NumAttr", "AttrBits",
             "CoordBits", "RemBits", "PixBits", "TagBits"],
}
# The spec unit's Verilog defaults of the parameters a configuration may leave out.
SPEC_DEFAULTS = {"Kind": 0, "TableBits": 8, "Segments": 1}
SPEC_KINDS = {0: "poly", 1: "table", 2: "schlick", 3: "explog", 4: "piecewise"}
SEGMENT_BITS = {1: 0, 2: 1, 4: 2}  # Kind 4: log2 Segments, the segment ROM's extra address bits

FLOWS = {
    "ice40": "synth_ice40 -dsp",
    "xc7": "synth_xilinx -family xc7 -flatten -noiopad -noclkbuf",
}
# synth_ice40's last step (check) begins with `autoname`, which names a flattened netlist's wires
# and takes 18 % of a span unit's run; the cells are the same without it (sierpinskifull: the
# same 23,708 cells, only fewer public wire names). So the iCE40 run stops before that step and
# runs the step's other commands itself.
CHECK_WITHOUT_AUTONAME = {"ice40": ["hierarchy -check", "stat", "check -noinit", "blackbox =A:whitebox"]}

# Warnings seen in clean runs and known to be harmless.
KNOWN_WARNINGS = [
    # abc on a module or cone with no latches.
    r"ABC: Warning: The network is combinational",
    # xc7 block-RAM mapping: yosys declares the RAMB18E1/RAMB36E1 data and address ports at
    # their widest (TDP data, cascade address) and trims them to the mode it used; nothing is lost.
    r"Warning: Resizing cell port .*\.(DOADO|DOBDO|DOPADOP|DOPBDOP|DIADI|DIBDI|DIPADIP|DIPBDIP"
    r"|ADDRARDADDR|ADDRBWRADDR) from \d+ bits to \d+ bits\.",
]

# mul2dsp.v parameters as synth_ice40 -dsp and synth_xilinx -family xc7 pass them (yosys 0.23).
TECH = {
    "ice40": dict(amax=16, bmax=16, apart=16, bpart=16, amin=2, bmin=2, ymin=11, signed_only=False),
    "xc7": dict(amax=25, bmax=18, apart=18, bpart=18, amin=2, bmin=2, ymin=9, signed_only=True),
}


class InputError(Exception):
    """A usage or input error: exit status 2."""


class YosysError(Exception):
    """yosys failed: exit status 3."""


def plain_path(what, path):
    """Paths travel inside yosys commands (RomFile as a Verilog string): keep them plain."""
    if not re.fullmatch(r"[^\s\"\\;]+", path):
        raise InputError(f"{what} path '{path}' must not contain whitespace, quotes, "
                         f"backslashes or ';'")


# ---------------------------------------------------------------- configuration and PROM

def load_config(ref, unit):
    """The configuration CONFIG names (a file or <unit>:<name>), with the parameters checked."""
    try:
        c = shd_config.resolve(ref, [shd_config.DEFAULT_DIR], unit)
    except shd_config.ConfigError as e:
        raise InputError(str(e))
    if c.unit is None:
        raise InputError(f"{ref}: name the unit (--unit spec|span)")
    if unit is not None and c.unit != unit:
        raise InputError(f"{ref} is a {c.unit} configuration, not {unit} (--unit {unit})")
    try:
        missing = missing_params(c.unit, c.rtl)
    except ValueError as e:
        raise InputError(f"{c.path}: {e}")
    if missing:
        raise InputError(f"{c.path}: rtl.{missing[0]} is missing")
    return c


def spec_params(rtl):
    """A spec configuration's "rtl" object with the Verilog defaults of what it leaves out."""
    return dict(SPEC_DEFAULTS, **rtl)


def missing_params(unit, rtl):
    """The parameters the checks need that `rtl` lacks or holds as a non-integer (for spec, those
    of its Kind); a ValueError for a Kind that is not one of SPEC_KINDS or, for Kind 4, a
    Segments that is not 1, 2 or 4."""
    if unit == "span":
        need = REQUIRED[unit]
    else:
        kind = spec_params(rtl)["Kind"]
        if type(kind) is not int or kind not in SPEC_KINDS:
            raise ValueError(f"rtl.Kind = {json.dumps(kind)} is not one of "
                             + ", ".join(f"{k} ({n})" for k, n in SPEC_KINDS.items()))
        need = REQUIRED[unit][kind] + (["TableBits"] if kind in (1, 3) else [])
        rtl = spec_params(rtl)
        if kind == 4 and (type(rtl["Segments"]) is not int or rtl["Segments"] not in SEGMENT_BITS):
            raise ValueError(f"rtl.Segments = {json.dumps(rtl['Segments'])} is not 1, 2 or 4")
    return [n for n in need if not isinstance(rtl.get(n), int)]


def default_prom(c, ref):
    """The repository's PROM of a registry spec configuration, or an InputError."""
    path = os.path.join(ROOT, "vectors", "prom", f"spec_{c.name}.hex")
    how = (f"make one with 'shadesim prom --config {ref} --format hex -o <file>' "
           f"and pass --prom <file>")
    if not os.path.isfile(path):
        raise InputError(f"no PROM for spec:{c.name} ({path} does not exist): {how}")
    registry_file = os.path.join(shd_config.DEFAULT_DIR, f"spec_{c.name}.json")
    try:
        with open(registry_file, encoding="utf-8") as f:
            same = json.loads(f.read()) == json.loads(c.text)
    except (OSError, ValueError):
        same = False
    if not same:
        raise InputError(f"{c.path} is not the registry's configuration spec:{c.name}, so "
                         f"{path} may not be its PROM: {how}")
    return path


def rom_layouts(p):
    """[(name, file suffix, depth, word bits, depth as the parameters give it)] of the memories
    whose contents come from files: the PROM and, for Kind 4, its segment ROM (PROM + ".seg")."""
    p = spec_params(p)
    kind = p["Kind"]
    if kind == 1:
        return [("PROM", "", 1 << (p["ShinBits"] + p["TableBits"]), p["SpecFracBits"] + 1,
                 "2^(ShinBits+TableBits)")]
    kw = p["CoefIntBits"] + p["CoefFracBits"]
    depth, wc = 1 << p["ShinBits"], p["CosFracBits"]
    if kind != 4:
        word_bits = kw if kind in (2, 3) or p["Degree"] == 2 else 2 * kw + wc + 1
        return [("PROM", "", depth, word_bits, "2^ShinBits")]
    sb = SEGMENT_BITS[p["Segments"]]                        # log2 Segments
    seg_bits = wc.bit_length() + (p["Degree"] + 1) * kw    # {K_d..K_0, e}, e clog2(Wc+1) bits
    return [("PROM", "", depth, p["Segments"] * (wc + 1), "2^ShinBits"),
            ("segment ROM", ".seg", depth << sb, seg_bits, "2^(ShinBits+log2 Segments)")]


def prom_geometry(path, p):
    """[(name, depth, word bits, bit columns that vary)] of the PROM's $readmemh file and, for
    Kind 4, of its segment ROM's (path + ".seg"); fails on a missing or malformed one."""
    geometry = []
    for name, suffix, depth, word_bits, depth_text in rom_layouts(p):
        if suffix and not os.path.isfile(path + suffix):
            raise InputError(f"{path + suffix}: no {name} beside the PROM {path} ('shadesim prom "
                             f"--format hex -o <file>' writes both)")
        words = read_hex(path + suffix, name, depth, word_bits, depth_text)
        geometry.append((name, depth, word_bits, varying_bits(words, word_bits)))
    return geometry


def read_hex(path, name, depth, word_bits, depth_text):
    """The words of memory `name` from its $readmemh file, which must fill exactly its depth."""
    try:
        with open(path, encoding="utf-8") as f:
            text = f.read()
    except (OSError, UnicodeDecodeError) as e:
        raise InputError(f"{path}: cannot read the {name}: {getattr(e, 'strerror', None) or e}")
    text = re.sub(r"/\*.*?\*/", " ", text, flags=re.S)
    text = re.sub(r"//[^\n]*", " ", text)
    words, addr = {}, 0
    for tok in text.split():
        if tok.startswith("@"):
            if re.fullmatch(r"@[0-9a-fA-F_]+", tok) is None:
                raise InputError(f"{path}: '{tok}' is not a hex address")
            addr = int(tok[1:].replace("_", ""), 16)
            continue
        if addr >= depth:
            raise InputError(f"{path}: more than {depth} words ({depth_text})")
        if re.fullmatch(r"[0-9a-fA-F_]+", tok) is None:
            raise InputError(f"{path}: '{tok}' is not a hex word")
        v = int(tok.replace("_", ""), 16)
        if v >> word_bits:
            raise InputError(f"{path}: word {tok} at address {addr} exceeds {word_bits} bits")
        words[addr] = v
        addr += 1
    if len(words) != depth:
        raise InputError(f"{path}: {len(words)} words, the {name} needs {depth} ({depth_text})")
    return words.values()


def varying_bits(words, bits):
    """The bit columns of a ROM's words that are not the same in every word (yosys drops the rest)."""
    words = list(words)
    return sum(1 for b in range(bits) if len({(v >> b) & 1 for v in words}) > 1)


def prepare(ref, unit, prom_arg):
    """CONFIG, --unit and --prom as the command line gives them: (the configuration, its file's
    real path, the PROM's real path or None for span, prom_geometry's list or None). Refuses --prom
    for a span configuration and a PROM that is missing, malformed or not a plain path."""
    c = load_config(ref, unit)
    config_file = os.path.realpath(c.path) if os.path.isfile(c.path) else c.path
    prom = None
    geometry = None
    if c.unit == "span":
        if prom_arg is not None:
            raise InputError(f"--prom: {c.unit}:{c.name} is a span configuration, which has no "
                             f"PROM (--prom applies to spec configurations only)")
    else:
        prom = prom_arg if prom_arg is not None else default_prom(c, ref)
        if not os.path.isfile(prom):
            raise InputError(f"PROM file '{prom}' not found (make it with 'shadesim prom "
                             f"--config {ref} --format hex -o {prom}')")
        prom = os.path.realpath(prom)
        plain_path("PROM", prom)
        geometry = prom_geometry(prom, c.rtl)
    return c, config_file, prom, geometry


def unit_rtl_files(c):
    """The unit's RTL files (absolute, the top module's first); an InputError if one is missing."""
    rtl_files = [os.path.join(ROOT, "rtl", f) for f in shd_config.UNITS[c.unit]["rtl"]]
    for f in rtl_files:
        if not os.path.isfile(f):
            raise InputError(f"RTL file '{f}' not found")
    return rtl_files


# ---------------------------------------------------------------- yosys

def read_commands(c, rtl_files, chparams, prom):
    """The yosys commands that read the unit's RTL (deferred) and set its parameters: the
    configuration's "rtl" object and, for spec, RomFile = the PROM, in one chparam. After them
    the module c.top is the configured unit (scripts/pnr.py instantiates it in a wrapper)."""
    rom = f' -set RomFile "{prom}"' if c.unit == "spec" else ""
    return [f"read_verilog -defer {' '.join(rtl_files)}", f"chparam {chparams}{rom} {c.top}"]


@functools.lru_cache(maxsize=None)
def tool_env():
    """The environment of a yosys run: jemalloc preloaded when it is installed (Debian's
    libjemalloc2, scripts/install_deps.sh), unless SHD_JEMALLOC=0. yosys spends much of its time
    allocating the netlist's many small objects; with jemalloc a run of span:sierpinski took 0.80
    (iCE40) and 0.73 (xc7) of its time with the C library's malloc (medians of 3 interleaved runs,
    2-core AMD EPYC VM), and the netlist (write_json) was the same byte for byte. The
    preload reaches yosys-abc, which yosys starts, too."""
    env = dict(os.environ)
    if env.get("SHD_JEMALLOC", "1") != "0":
        lib = ctypes.util.find_library("jemalloc")  # e.g. libjemalloc.so.2, found as ld.so finds it
        if lib:
            env["LD_PRELOAD"] = (env["LD_PRELOAD"] + " " + lib) if env.get("LD_PRELOAD") else lib
    return env


def yosys_run(commands, log, what):
    """Runs `yosys -q` on the commands, its log in `log` (written under a temporary name and
    renamed, also on failure); returns the wall time. Raises YosysError naming `what` with the
    log's ERROR lines (or yosys's last stderr lines)."""
    if os.path.exists(log + ".tmp"):
        os.remove(log + ".tmp")
    t0 = time.monotonic()
    r = subprocess.run(["yosys", "-q", "-l", log + ".tmp", "-p", "\n".join(commands)],
                       stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, env=tool_env())
    wall = time.monotonic() - t0
    if os.path.exists(log + ".tmp"):
        os.replace(log + ".tmp", log)
    if r.returncode != 0:
        lines = []
        if os.path.exists(log):
            with open(log, errors="replace") as f:
                lines = [l.rstrip("\n") for l in f if "ERROR" in l][:5]
        if not lines:
            lines = r.stderr.decode(errors="replace").splitlines()[-20:]
        raise YosysError("\n".join([f"yosys failed for {what} (full log: {log}):"] + lines))
    return wall


def run_yosys(c, tgt, rtl_files, chparams, prom, out):
    """Synthesises for one target; writes <tgt>.log and <tgt>_stat.json; returns the wall time."""
    top = c.top
    log = os.path.join(out, f"{tgt}.log")
    stat = os.path.join(out, f"{tgt}_stat.json")
    flow, check = f"{FLOWS[tgt]} -top {top}", []
    if tgt in CHECK_WITHOUT_AUTONAME:
        flow, check = flow + " -run :check", CHECK_WITHOUT_AUTONAME[tgt]
    commands = (read_commands(c, rtl_files, chparams, prom) + [f"hierarchy -check -top {top}", flow] + check
                + [f"tee -q -o {stat}.tmp stat -json"])
    if os.path.exists(stat + ".tmp"):
        os.remove(stat + ".tmp")
    try:
        wall = yosys_run(commands, log, f"{c.name} / {tgt}")
    except YosysError:
        if os.path.exists(stat + ".tmp"):
            os.remove(stat + ".tmp")
        raise
    os.replace(stat + ".tmp", stat)
    return float(f"{wall:.2f}")


# ---------------------------------------------------------------- the checks

def tiles(t, aw, bw, asg, bsg, yw, cell="$mul"):
    """DSP primitives mul2dsp.v makes of one $mul/$__mul cell (it recurses on its own pieces)."""
    if aw < t["amin"] or bw < t["bmin"] or yw < t["ymin"]:
        return 0                                   # _TECHMAP_FAIL_: left to LUTs
    if t["signed_only"] and cell == "$mul" and not asg and not bsg:
        return tiles(t, aw + 1, bw + 1, True, True, yw, "$mul")
    if cell == "$mul" and aw < bw:
        return tiles(t, bw, aw, bsg, asg, yw, "$mul")
    h = 1 if t["signed_only"] else 0               # sign_headroom
    if aw > t["amax"]:
        step = t["apart"] - h
        n = (aw - t["amax"] + step - 1) // step
        last = aw - n * step
        return (n * tiles(t, t["apart"], bw, bool(h), bsg, min(yw, bw + t["apart"]), "$__mul")
                + tiles(t, last, bw, asg, bsg, bw + last, "$__mul"))
    if bw > t["bmax"]:
        step = t["bpart"] - h
        n = (bw - t["bmax"] + step - 1) // step
        last = bw - n * step
        return (n * tiles(t, aw, t["bpart"], asg, bool(h), min(yw, aw + t["bpart"]), "$__mul")
                + tiles(t, aw, last, asg, bsg, aw + last, "$__mul"))
    return 1


def multipliers(unit, p):
    """(name, a bits, b bits, a signed, b signed, product bits used) per multiplier."""
    if unit == "span":
        # icur = irow + didx*(xg - xref): AttrBits x (CoordBits+1) signed, low AttrBits used.
        return [(f"row start didx{a}*(xg-xref)", p["AttrBits"], p["CoordBits"] + 1, True, True,
                 p["AttrBits"]) for a in range(p["NumAttr"])]
    p = spec_params(p)
    fw = p["SpecFracBits"] + 1
    lb = p["LightBits"]
    m = []
    if p["Kind"] == 0:
        wc = p["CosFracBits"]
        cw = wc + 1
        kw = p["CoefIntBits"] + p["CoefFracBits"]
        dtw = p["DiffFracBits"] - 1
        gtw = p["CoefIntBits"] + 1 + p["HornerFracBits"]
        m.append(("MUL1 c*c", cw, cw, False, False, 2 * wc - 1))  # only c^2 - c's bits are used
        if p["Degree"] == 2:
            m.append(("MUL2 a*dt", kw + 1, dtw, True, True, kw + dtw))
        else:
            m.append(("Horner u*c", kw, cw + 1, True, True, kw + wc))
            m.append(("MUL2 gt*dt", gtw, dtw, True, True, gtw + dtw))
    elif p["Kind"] == 2:
        cw = p["CosFracBits"] + 1
        kw = p["CoefIntBits"] + p["CoefFracBits"]
        m.append(("den m*omc", kw, cw, False, False, kw + cw))    # den = m*(1-c) + 1
    elif p["Kind"] == 3:
        wc, t = p["CosFracBits"], p["TableBits"]
        kw = p["CoefIntBits"] + p["CoefFracBits"]
        gf, lf, ef, ex = explog_widths(p)
        dgw, rw, gw, llw, dew = gf - t + 1, wc - t + 1, gf + 2, (wc).bit_length() + lf, ef - t + 1
        m.append(("dg*r", dgw, rw, False, False, dgw + rw))
        m.append(("DN*G", wc + 1, gw, False, False, wc + 1 + gw))
        m.append(("N*L", kw, llw, False, False, kw + llw))
        if ex > t:
            m.append(("de*r2", dew, ex - t, False, False, dew + ex - t))
    elif p["Kind"] == 4:
        wc = p["CosFracBits"]
        kw = p["CoefIntBits"] + p["CoefFracBits"]
        # m = acc*u + K*2^Wc, u with a zero sign bit; step 1's acc is K_d sign-extended, which
        # wreduce takes back to KW bits; later steps' acc has AW = KW+3, bits [AW+Wc-1:Wc] used.
        m.append(("step 1 Kd*u", kw, wc + 2, True, True, kw + wc + 2))
        for k in range(2, p["Degree"] + 1):
            m.append((f"step {k} acc*u", kw + 3, wc + 2, True, True, kw + 3 + wc))
    for k, ch in enumerate("RGB"):
        m.append((f"MUL{3 + k} f*L{ch}", fw, lb, False, False, fw - 1 + lb))
    return m


def explog_widths(p):
    """GF, LF, EF, EX of the explog kind (rtl/shd_spec_explog.v, SpecUnitParams::expLogWidths)."""
    wf, ci, wc = p["SpecFracBits"], p["CoefIntBits"], p["CosFracBits"]
    return wf + 6 + max(0, ci - wc - 4), wf + ci + 3, wf + 4, wf + 3


def explog_tables(p):
    """[(name, depth, word bits, varying bits)] of the explog kind's log and exp ROMs: their words
    by the integer algorithm of rtl/shd_spec_explog.v (60-bit fixed point, floors, rounded half up),
    so that the check knows which bit columns are constant."""
    p = spec_params(p)
    t = p["TableBits"]
    gf, _, ef, _ = explog_widths(p)
    q, log2e, ln2 = 60, 1663314137230540311, 799144290325165978

    def g(i):
        d, s, term = i << (q - t - 1), 0, 1 << q
        for k in range(62):
            s, term = s + term // (k + 1), (term * d) >> q
        return (((s * log2e) >> q) + (1 << (q - gf - 1))) >> (q - gf)

    def e(j):
        z, pos, neg, term = ((j << (q - t)) * ln2) >> q, 0, 0, 1 << q
        for k in range(30):
            pos, neg = (pos + term, neg) if k % 2 == 0 else (pos, neg + term)
            term = ((term * z) >> q) // (k + 1)
        return (pos - neg + (1 << (q - ef - 1))) >> (q - ef)

    gs, es = [g(i) for i in range((1 << t) + 1)], [e(j) for j in range((1 << t) + 1)]
    gw, dgw, ew, dew = gf + 2, gf - t + 1, ef + 1, ef - t + 1
    logw = [((gs[i + 1] - gs[i]) << gw) | gs[i] for i in range(1 << t)]
    expw = [((es[j] - es[j + 1]) << ew) | es[j] for j in range(1 << t)]
    return [(name, 1 << t, bits, varying_bits(words, bits))
            for name, words, bits in (("log table", logw, dgw + gw), ("exp table", expw, dew + ew))]


def ice40_brams(d_need, w_need):
    if w_need == 0:
        return 0
    return min(math.ceil(d_need / d) * math.ceil(w_need / w)
               for d, w in [(256, 16), (512, 8), (1024, 4), (2048, 2)])


def xc7_bram_kbits(d_need, w_need):
    if w_need == 0:
        return 0
    prims = [(18, [(16384, 1), (8192, 2), (4096, 4), (2048, 9), (1024, 18), (512, 36)]),
             (36, [(32768, 1), (16384, 2), (8192, 4), (4096, 9), (2048, 18), (1024, 36), (512, 72)])]
    return min(math.ceil(d_need / d) * math.ceil(w_need / w) * kbit
               for kbit, modes in prims for d, w in modes)


def count(cells, pattern):
    return sum(n for t, n in cells.items() if re.fullmatch(pattern, t))


def classify(tgt, cells):
    if tgt == "ice40":
        r = dict(luts=count(cells, r"SB_LUT4"), ffs=count(cells, r"SB_DFF\w*"),
                 carries=count(cells, r"SB_CARRY"), dsps=count(cells, r"SB_MAC16"),
                 brams=count(cells, r"SB_RAM40_4K\w*"))
        r["bram_kbits"] = 4 * r["brams"]
        r["distributed_ram"] = 0
    else:
        r = dict(luts=count(cells, r"LUT[1-6]|INV"), ffs=count(cells, r"FD[CPRS]E(_1)?|LD[CP]E?"),
                 carries=count(cells, r"CARRY4"), dsps=count(cells, r"DSP48E1"),
                 brams=count(cells, r"RAMB(18|36)E1"))
        r["bram_kbits"] = 18 * count(cells, r"RAMB18E1") + 36 * count(cells, r"RAMB36E1")
        r["distributed_ram"] = count(cells, r"RAM\d+X\d+\w*|RAM\d+M\w*|ROM\d+X1")
    r["cells_total"] = sum(cells.values())
    return r


def evaluate(c, tgt, wall, out, geometry, failed):
    """The target's summary entry; prints its line and appends failed checks to `failed`."""
    name, p, span = c.name, c.rtl, c.unit == "span"
    with open(os.path.join(out, f"{tgt}_stat.json")) as f:
        cells = json.load(f)["design"]["num_cells_by_type"]
    r = classify(tgt, cells)
    r["wall_s"] = wall
    r["cells_by_type"] = cells

    per_mul = {f"{m[0]} {m[1]}x{m[2]} {'signed' if m[3] else 'unsigned'}": tiles(TECH[tgt], *m[1:])
               for m in multipliers(c.unit, p)}
    exp = dict(dsps=sum(per_mul.values()), dsps_per_multiplier=per_mul)
    leftover_mem = count(cells, r"\$mem\w*")
    with open(os.path.join(out, f"{tgt}.log"), errors="replace") as f:
        log = f.read().splitlines()
    warns = [l for l in log if re.search(r"warning", l, re.I) and not l.startswith("Warnings:")
             and not any(re.search(k, l) for k in KNOWN_WARNINGS)]

    if span:
        latches = [l for l in log if l.startswith("Latch inferred for signal")]
        mem_ok = leftover_mem == 0 and r["brams"] == 0 and r["distributed_ram"] == 0
        checks = dict(dsps=r["dsps"] == exp["dsps"], latches=not latches, no_mem=mem_ok,
                      warnings=not warns)
        r.update(expected=exp, checks=checks, unexpected_warnings=warns[:20])
        print(f"  {name:10s} {tgt:5s} {r['wall_s']:5.1f} s  LUT {r['luts']:5d}  FF {r['ffs']:5d}  "
              f"carry {r['carries']:4d}  DSP {r['dsps']:2d}  cells {r['cells_total']:5d}  "
              f"latches {len(latches)}")
        if not checks["latches"]:
            failed.append(f"{name}/{tgt} latches: " + "; ".join(latches[:5]))
        if not checks["no_mem"]:
            failed.append(f"{name}/{tgt} no_mem: {leftover_mem} $mem, {r['brams']} block RAM, "
                          f"{r['distributed_ram']} distributed RAM/ROM cells (expected none)")
    else:
        mems = list(geometry)
        if spec_params(p)["Kind"] == 3:
            mems += explog_tables(p)
        if tgt == "ice40":
            exp["brams"] = sum(ice40_brams(d, v) for _, d, _, v in mems)
            rom_ok = r["brams"] == exp["brams"]
        else:
            exp["bram_kbits"] = sum(xc7_bram_kbits(d, v) for _, d, _, v in mems)
            rom_ok = r["bram_kbits"] == exp["bram_kbits"]
        rom_ok = rom_ok and leftover_mem == 0 and r["distributed_ram"] == 0
        checks = dict(rom_bram=rom_ok, dsps=r["dsps"] == exp["dsps"], warnings=not warns)
        r.update(expected=exp, checks=checks, unexpected_warnings=warns[:20])

        bram = f"{r['brams']} ({r['bram_kbits']} kbit)"
        print(f"  {name:8s} {tgt:5s} {r['wall_s']:5.1f} s  LUT {r['luts']:5d}  FF {r['ffs']:5d}  "
              f"carry {r['carries']:4d}  DSP {r['dsps']:2d}  BRAM {bram:13s} "
              f"cells {r['cells_total']:5d}  ROM in BRAM: {'yes' if rom_ok else 'NO'}")
        if not checks["rom_bram"]:
            want = f"{exp['brams']} SB_RAM40_4K" if tgt == "ice40" else f"{exp['bram_kbits']} kbit"
            geo = " + ".join(f"{n} {d}x{v} (of {b} bits)" for n, d, b, v in mems)
            failed.append(f"{name}/{tgt} rom_bram: {geo}, constant columns dropped, should take {want}; got {bram}, "
                          f"{leftover_mem} $mem, {r['distributed_ram']} distributed RAM/ROM cells")
    if not checks["dsps"]:
        failed.append(f"{name}/{tgt} dsps: {r['dsps']} DSPs, expected {exp['dsps']} = {per_mul}")
    if not checks["warnings"]:
        failed.append(f"{name}/{tgt} warnings: unexpected yosys warnings:\n      "
                      + "\n      ".join(warns[:10]))
    return r


def write_json(path, obj):
    tmp = os.path.join(os.path.dirname(path), "." + os.path.basename(path) + ".tmp")
    with open(tmp, "w") as f:
        json.dump(obj, f, indent=2)
        f.write("\n")
    os.replace(tmp, path)


# ---------------------------------------------------------------- main

def parse_args(argv):
    p = argparse.ArgumentParser(prog=PROG, description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("config", metavar="CONFIG", nargs="?",
                   help="a configuration file, or <unit>:<name> of the registry")
    p.add_argument("--dsps-of", metavar="FILE",
                   help="print the DSP counts of the rtl objects in FILE (no synthesis)")
    p.add_argument("--unit", choices=sorted(shd_config.UNITS),
                   help="the unit of a configuration file not named <unit>_<name>.json")
    p.add_argument("--prom", metavar="FILE", help="spec: the PROM hex file")
    p.add_argument("--out", metavar="DIR", help="output directory")
    p.add_argument("--target", choices=["ice40", "xc7", "both"], default="both")
    p.add_argument("--check", action="store_true", help="fail (exit 1) unless the checks pass")
    return p.parse_args(argv)


def predict_dsps(path, unit, targets):
    """The DSP count per target of each rtl object of the JSON array in `path` (--dsps-of)."""
    if unit is None:
        raise InputError("--dsps-of: name the unit (--unit spec|span)")
    try:
        with open(path) as f:
            points = json.load(f)
    except (OSError, ValueError) as e:
        raise InputError(f"--dsps-of {path}: {e}")
    if not isinstance(points, list):
        raise InputError(f"--dsps-of {path}: not a JSON array of rtl objects")
    out = []
    for i, rtl in enumerate(points):
        try:
            missing = missing_params(unit, rtl if isinstance(rtl, dict) else {})
        except ValueError as e:
            raise InputError(f"--dsps-of {path}: item {i}: {e}")
        if missing:
            raise InputError(f"--dsps-of {path}: item {i}: rtl.{missing[0]} is missing or not an integer")
        out.append({t: sum(tiles(TECH[t], *m[1:]) for m in multipliers(unit, rtl)) for t in targets})
    json.dump(out, sys.stdout)
    print()
    return 0


def main(argv):
    a = parse_args(argv)
    targets = ["ice40", "xc7"] if a.target == "both" else [a.target]
    if a.dsps_of is not None:
        if a.config is not None or a.prom is not None or a.out is not None or a.check:
            raise InputError("--dsps-of takes only --unit and --target")
        return predict_dsps(a.dsps_of, a.unit, targets)
    if a.config is None:
        raise InputError("name a CONFIG (or --dsps-of FILE)")
    c, config_file, prom, geometry = prepare(a.config, a.unit, a.prom)

    if shutil.which("yosys") is None:
        raise InputError("yosys not found (apt-get install yosys)")
    out = a.out if a.out is not None else os.path.join(ROOT, "out", "synth", f"{c.unit}_{c.name}")
    out = os.path.realpath(out)
    plain_path("output", out)
    plain_path("RTL", ROOT)
    try:
        os.makedirs(out, exist_ok=True)
    except OSError as e:
        raise InputError(f"cannot create the output directory '{out}': {e.strerror}"
                         + ("" if a.out else " (pass --out DIR)"))

    rtl_files = unit_rtl_files(c)
    chparams = shd_config.tool_args(c, "yosys")[0]
    yosys_version = subprocess.run(["yosys", "-V"], stdout=subprocess.PIPE,
                                   text=True).stdout.strip()

    walls = {}
    for tgt in targets:
        print(f"{PROG}: {c.name} / {tgt} ...", flush=True)
        walls[tgt] = run_yosys(c, tgt, rtl_files, chparams, prom, out)

    if c.unit == "span":
        summary = dict(config=c.name, config_file=config_file, top=c.top, yosys=yosys_version,
                       rtl=c.rtl, targets={})
    else:
        summary = dict(config=c.name, config_file=config_file, prom_file=prom,
                       yosys=yosys_version, rtl=c.rtl)
        for name, depth, word_bits, varying in geometry:   # "prom", "segment_rom" (Kind 4)
            summary[name.lower().replace(" ", "_")] = dict(depth=depth, word_bits=word_bits,
                                                           varying_bits=varying)
        summary["targets"] = {}
    failed = []
    for tgt, wall in walls.items():
        summary["targets"][tgt] = evaluate(c, tgt, wall, out, geometry, failed)

    write_json(os.path.join(out, "summary.json"), summary)
    print(f"  summary: {os.path.join(out, 'summary.json')}", flush=True)
    for msg in failed:
        print(("CHECK FAILED: " if a.check else "note: ") + msg, file=sys.stderr)
    if a.check:
        if failed:
            return 1
        if c.unit == "span":
            print("  checks passed: DSPs = row-start multiplier tiling, no latches, no memories, "
                  "no unexpected warnings")
        else:
            print("  checks passed: ROM in least block RAM, DSPs = multiplier tiling, "
                  "no unexpected warnings")
    return 0


def run_main(main_fn, prog, tool_errors=(YosysError,)):
    """Runs main_fn(argv) and exits with its status; an InputError exits 2 and a tool's error
    (tool_errors) 3, each with one line "<prog>: error: ..." (shared with pnr.py)."""
    try:
        sys.exit(main_fn(sys.argv[1:]))
    except InputError as e:
        print(f"{prog}: error: {e}", file=sys.stderr)
        sys.exit(2)
    except tool_errors as e:
        print(f"{prog}: error: {e}", file=sys.stderr)
        sys.exit(3)


if __name__ == "__main__":
    run_main(main, PROG)
