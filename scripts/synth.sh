#!/usr/bin/env bash
# synth.sh: synthesise one specular-unit (or span-unit) configuration with yosys for iCE40 and/or
# Xilinx 7-series and report its area.
#
# Usage: scripts/synth.sh [--top shd_spec_unit|shd_span_unit]
#          [--config vectors/config/spec_default.json] [--prom vectors/prom/spec_default.hex]
#          [--out out/synth/default] [--target ice40|xc7|both] [--check]
#
# --top defaults to shd_spec_unit; everything below is about it except where "--top shd_span_unit"
# says otherwise. --prom and --out default to vectors/prom/<config file name>.hex and
# out/synth/<name> (<name>: the file name without "spec_": out/synth/span_serial for a span unit).
# The "rtl" object of the configuration becomes one `chparam -set Name Value ... shd_spec_unit`
# (one command: separate chparams elaborate the module once per parameter, with old and new values
# mixed, and yosys warns about out-of-range selects in those intermediate modules); the PROM
# becomes RomFile, an absolute path (yosys reads it at elaboration: `initial $readmemh` under
# SYNTHESIS). The PROM must hold exactly 2^ShinBits words of the configuration's word width.
# Flows:
#   ice40  synth_ice40 -dsp                                  (flattens by default)
#   xc7    synth_xilinx -family xc7 -flatten -noiopad -noclkbuf
#          -flatten so both targets are counted the same way; -noiopad -noclkbuf because the unit
#          is a block inside a design, not a chip top (IBUF/OBUF/BUFG would be ~100 cells of noise).
#
# Output (in --out; every file is written under a temporary name and renamed):
#   <target>_stat.json  yosys `stat -json` of the synthesised netlist
#   <target>.log        the full yosys log
#   summary.json        {"config", "config_file", "prom_file", "yosys", "rtl": {...}, "prom": {...},
#                        "targets": {"<target>": {luts, ffs, carries, dsps, brams, bram_kbits,
#                        cells_total, wall_s, cells_by_type, expected, checks}}}
#     luts        iCE40 SB_LUT4; xc7 LUT1..LUT6 plus INV (yosys's name for an inverting LUT1)
#     ffs         every flip-flop primitive (SB_DFF*, FD*)
#     carries     iCE40 SB_CARRY (one per bit); xc7 CARRY4 (one per 4 bits): not comparable
#     dsps        SB_MAC16 / DSP48E1
#     brams       block-RAM primitives (SB_RAM40_4K*, RAMB18E1, RAMB36E1); bram_kbits their capacity
#     cells_total every cell of the netlist
#     wall_s      wall time of the yosys run
#
# --check makes the run fail (exit 1) unless the netlist is what the RTL is meant to become:
#   rom_bram  The PROM is entirely in block RAM, and in the least block RAM its contents need.
#             yosys drops PROM bit columns that are constant over all 2^ShinBits words, so the
#             geometry is depth 2^ShinBits x (columns that vary in the hex file). iCE40: the
#             SB_RAM40_4K count equals min over its read modes 256x16, 512x8, 1024x4, 2048x2 of
#             ceil(depth/d)*ceil(width/w). xc7: the capacity in kbit equals the least one over the
#             RAMB18E1 (16384x1 .. 512x36) and RAMB36E1 (32768x1 .. 512x72) aspect ratios (yosys
#             may pick either primitive when they tie, so kbit is compared, not the count). Also:
#             no $mem cell and no distributed-RAM/ROM primitive is left. Fails when the ROM falls
#             into LUTs (rom_style = "logic", an asynchronous read) or is duplicated.
#   dsps      The DSP count equals what the multipliers need. Operand widths come from the RTL
#             header's derivation (uQ1.Wc: CW = Wc+1; KW = Ci+Cf; DTW = Df-1; GTW = Ci+1+Hf;
#             FW = Wf+1; L = LightBits):
#               MUL1     c*c           CW x CW unsigned
#               MUL2     deg 2: a*dt   (KW+1) x DTW signed (a is unsigned: one zero sign bit)
#                        deg 3: gt*dt  GTW x DTW signed
#               Horner   deg 3: u*c    KW x (CW+1) signed
#               MUL3..5  f*L           FW x L unsigned (three of them)
#             and each is tiled the way yosys's share/mul2dsp.v does it (iCE40: 16x16 tiles;
#             pieces narrower than 2 bits or with a product under 11 bits go to LUTs. xc7:
#             signed-only 25x18 tiles, 17-bit A slices, products under 9 bits to LUTs). Fails
#             when a multiplier stays in LUTs or is wider than the derivation (e.g. a manual sign
#             extension that wreduce cannot remove costs whole extra DSP tiles).
#   warnings  yosys printed no warning except the known harmless ones in KNOWN_WARNINGS below
#             (multiple drivers, a memory turned into registers, a bad $readmemh are caught).
#
# --top shd_span_unit: the span unit (rtl/shd_span_unit.v) with the "rtl" object of a
# vectors/config/span_<mode>.json (--config defaults to span_serial.json); no PROM (--prom is an
# error), summary.json has no "prom_file"/"prom". Its --check has these checks instead of rom_bram:
#   dsps      The only multiplier is the row start icur = irow + didx*(xg - xref), one per
#             attribute: AttrBits x (CoordBits+1) signed, of which the low AttrBits are used
#             (the plane wraps at AttrBits). The DSP count equals NumAttr times its mul2dsp.v
#             tiling as above. Fails when the lanes' i*didx (constant multiples, built from
#             shifts and adds) or the LanesPerTri*didx step turn into multipliers, or the row
#             multiply stays in LUTs.
#   latches   proc_dlatch inferred no latch (the comb blocks assign every output on every path).
#   no_mem    no $mem cell, block RAM or distributed RAM: the unit is registers and logic only.
#   warnings  as above.
#
# Exit status: 0 success, 1 a failed check, 2 a usage or input error, 3 yosys failed.
set -euo pipefail

ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)

usage() {
  sed -n '5,7p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'
}
die() {
  echo "synth.sh: error: $*" >&2
  exit 2
}
# Paths travel inside yosys commands (RomFile as a Verilog string): keep them plain.
plain_path() {
  [[ $2 =~ ^[^[:space:]\"\\\;]+$ ]] || die "$1 path '$2' must not contain whitespace, quotes, backslashes or ';'"
}

TOP=shd_spec_unit
config=""
prom=""
out=""
target=both
check=0
while (($# > 0)); do
  case $1 in
    --top) (($# >= 2)) || die "$1 needs a value"; TOP=$2; shift 2 ;;
    --config) (($# >= 2)) || die "$1 needs a value"; config=$2; shift 2 ;;
    --prom) (($# >= 2)) || die "$1 needs a value"; prom=$2; shift 2 ;;
    --out) (($# >= 2)) || die "$1 needs a value"; out=$2; shift 2 ;;
    --target) (($# >= 2)) || die "$1 needs a value"; target=$2; shift 2 ;;
    --check) check=1; shift ;;
    -h | --help) usage; exit 0 ;;
    *) usage >&2; die "unknown argument '$1'" ;;
  esac
done

case $target in
  ice40) targets=(ice40) ;;
  xc7) targets=(xc7) ;;
  both) targets=(ice40 xc7) ;;
  *) die "--target must be ice40, xc7 or both, not '$target'" ;;
esac

case $TOP in
  shd_spec_unit)
    RTL_FILES=("$ROOT/rtl/shd_spec_unit.v" "$ROOT/rtl/shd_coef_rom.v" "$ROOT/rtl/shd_pipe_reg.v")
    [[ -n $config ]] || config=$ROOT/vectors/config/spec_default.json
    ;;
  shd_span_unit)
    RTL_FILES=("$ROOT/rtl/shd_span_unit.v")
    [[ -n $config ]] || config=$ROOT/vectors/config/span_serial.json
    [[ -z $prom ]] || die "--prom applies to shd_spec_unit only"
    ;;
  *) die "--top must be shd_spec_unit or shd_span_unit, not '$TOP'" ;;
esac

[[ -f $config ]] || die "configuration file '$config' not found"
config=$(realpath "$config")
cfg_base=$(basename "$config" .json)
[[ -n $out ]] || out=$ROOT/out/synth/${cfg_base#spec_}
if [[ $TOP == shd_spec_unit ]]; then
  [[ -n $prom ]] || prom=$ROOT/vectors/prom/$cfg_base.hex
  [[ -f $prom ]] || die "PROM file '$prom' not found (make it with 'shadesim prom', or pass --prom)"
  prom=$(realpath "$prom")
  plain_path PROM "$prom"
fi
command -v yosys >/dev/null || die "yosys not found (apt-get install yosys)"
mkdir -p "$out"
out=$(realpath "$out")
plain_path output "$out"
plain_path RTL "$ROOT"

# The Python half: "params" validates the configuration and the PROM and prints the config name
# and the chparam options; "summary" counts cells, runs the checks and writes summary.json.
read -r -d '' PY <<'EOF' || true
import json, math, os, re, sys

def fail(msg):
    print(f"synth.sh: error: {msg}", file=sys.stderr)
    sys.exit(2)

def load_config(path, top):
    try:
        with open(path) as f:
            cfg = json.load(f)
        rtl = cfg["rtl"]
        if not isinstance(rtl, dict):
            raise TypeError("not an object")
    except (OSError, ValueError, KeyError, TypeError) as e:
        fail(f"{path}: cannot read the 'rtl' object: {e!r}")
    for name, value in rtl.items():
        if not re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*", name) or type(value) is not int:
            fail(f"{path}: rtl.{name} = {value!r} is not an integer parameter")
    required = {
        "shd_spec_unit": ["Degree", "CosFracBits", "ShinBits", "CoefIntBits", "CoefFracBits",
                          "DiffFracBits", "HornerFracBits", "SpecFracBits", "LightBits"],
        "shd_span_unit": ["NumTri", "LanesPerTri", "AlignLanes", "NumAttr", "AttrBits",
                          "CoordBits", "RemBits", "PixBits", "TagBits"],
    }[top]
    for name in required:
        if name not in rtl:
            fail(f"{path}: rtl.{name} is missing")
    return cfg.get("name", os.path.basename(path)), rtl

def prom_geometry(path, p):
    """(depth, word bits, bit columns that vary) of a $readmemh file; fails on a malformed one."""
    depth = 1 << p["ShinBits"]
    kw = p["CoefIntBits"] + p["CoefFracBits"]
    word_bits = kw if p["Degree"] == 2 else 2 * kw + p["CosFracBits"] + 1
    text = open(path).read()
    text = re.sub(r"/\*.*?\*/", " ", text, flags=re.S)
    text = re.sub(r"//[^\n]*", " ", text)
    words, addr = {}, 0
    for tok in text.split():
        if tok.startswith("@"):
            addr = int(tok[1:], 16)
            continue
        if addr >= depth:
            fail(f"{path}: more than {depth} words (2^ShinBits)")
        if re.fullmatch(r"[0-9a-fA-F_]+", tok) is None:
            fail(f"{path}: '{tok}' is not a hex word")
        v = int(tok.replace("_", ""), 16)
        if v >> word_bits:
            fail(f"{path}: word {tok} at address {addr} exceeds {word_bits} bits")
        words[addr] = v
        addr += 1
    if len(words) != depth:
        fail(f"{path}: {len(words)} words, the unit needs {depth} (2^ShinBits)")
    vals = list(words.values())
    varying = sum(1 for b in range(word_bits) if len({(v >> b) & 1 for v in vals}) > 1)
    return depth, word_bits, varying

mode, top = sys.argv[1], sys.argv[2]
if mode == "params":
    name, p = load_config(sys.argv[3], top)
    if top == "shd_spec_unit":
        prom_geometry(sys.argv[4], p)
    print(name)
    print(" ".join(f"-set {k} {v}" for k, v in p.items()))
    sys.exit(0)

# ---------------------------------------------------------------- mode "summary"
config_file, prom_file, out, check, yosys_version = sys.argv[3:8]
check = check == "1"
walls = dict(w.split("=", 1) for w in sys.argv[8:])
name, p = load_config(config_file, top)
span = top == "shd_span_unit"
if not span:
    depth, word_bits, varying = prom_geometry(prom_file, p)

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

def multipliers():
    """(name, a bits, b bits, a signed, b signed, product bits used) per multiplier."""
    if span:
        # icur = irow + didx*(xg - xref): AttrBits x (CoordBits+1) signed, low AttrBits used.
        return [(f"row start didx{a}*(xg-xref)", p["AttrBits"], p["CoordBits"] + 1, True, True,
                 p["AttrBits"]) for a in range(p["NumAttr"])]
    wc = p["CosFracBits"]; cw = wc + 1
    kw = p["CoefIntBits"] + p["CoefFracBits"]
    dtw = p["DiffFracBits"] - 1
    gtw = p["CoefIntBits"] + 1 + p["HornerFracBits"]
    fw = p["SpecFracBits"] + 1
    lb = p["LightBits"]
    m = [("MUL1 c*c", cw, cw, False, False, 2 * wc - 1)]      # only c^2 - c's bits are used
    if p["Degree"] == 2:
        m.append(("MUL2 a*dt", kw + 1, dtw, True, True, kw + dtw))
    else:
        m.append(("Horner u*c", kw, cw + 1, True, True, kw + wc))
        m.append(("MUL2 gt*dt", gtw, dtw, True, True, gtw + dtw))
    for k, ch in enumerate("RGB"):
        m.append((f"MUL{3 + k} f*L{ch}", fw, lb, False, False, fw - 1 + lb))
    return m

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

if span:
    summary = dict(config=name, config_file=config_file, top=top, yosys=yosys_version, rtl=p,
                   targets={})
else:
    summary = dict(config=name, config_file=config_file, prom_file=prom_file, yosys=yosys_version,
                   rtl=p, prom=dict(depth=depth, word_bits=word_bits, varying_bits=varying),
                   targets={})
failed = []
for tgt, wall in walls.items():
    with open(os.path.join(out, f"{tgt}_stat.json")) as f:
        cells = json.load(f)["design"]["num_cells_by_type"]
    r = classify(tgt, cells)
    r["wall_s"] = float(wall)
    r["cells_by_type"] = cells

    per_mul = {f"{m[0]} {m[1]}x{m[2]} {'signed' if m[3] else 'unsigned'}": tiles(TECH[tgt], *m[1:])
               for m in multipliers()}
    exp = dict(dsps=sum(per_mul.values()), dsps_per_multiplier=per_mul)
    leftover_mem = count(cells, r"\$mem\w*")
    with open(os.path.join(out, f"{tgt}.log")) as f:
        log = f.read().splitlines()
    warns = [l for l in log if re.search(r"warning", l, re.I) and not l.startswith("Warnings:")
             and not any(re.search(k, l) for k in KNOWN_WARNINGS)]

    if span:
        latches = [l for l in log if l.startswith("Latch inferred for signal")]
        mem_ok = leftover_mem == 0 and r["brams"] == 0 and r["distributed_ram"] == 0
        checks = dict(dsps=r["dsps"] == exp["dsps"], latches=not latches, no_mem=mem_ok,
                      warnings=not warns)
        r.update(expected=exp, checks=checks, unexpected_warnings=warns[:20])
        summary["targets"][tgt] = r
        print(f"  {name:10s} {tgt:5s} {r['wall_s']:5.1f} s  LUT {r['luts']:5d}  FF {r['ffs']:5d}  "
              f"carry {r['carries']:4d}  DSP {r['dsps']:2d}  cells {r['cells_total']:5d}  "
              f"latches {len(latches)}")
        if not checks["latches"]:
            failed.append(f"{name}/{tgt} latches: " + "; ".join(latches[:5]))
        if not checks["no_mem"]:
            failed.append(f"{name}/{tgt} no_mem: {leftover_mem} $mem, {r['brams']} block RAM, "
                          f"{r['distributed_ram']} distributed RAM/ROM cells (expected none)")
    else:
        if tgt == "ice40":
            exp["brams"] = ice40_brams(depth, varying)
            rom_ok = r["brams"] == exp["brams"]
        else:
            exp["bram_kbits"] = xc7_bram_kbits(depth, varying)
            rom_ok = r["bram_kbits"] == exp["bram_kbits"]
        rom_ok = rom_ok and leftover_mem == 0 and r["distributed_ram"] == 0
        checks = dict(rom_bram=rom_ok, dsps=r["dsps"] == exp["dsps"], warnings=not warns)
        r.update(expected=exp, checks=checks, unexpected_warnings=warns[:20])
        summary["targets"][tgt] = r

        bram = f"{r['brams']} ({r['bram_kbits']} kbit)"
        print(f"  {name:8s} {tgt:5s} {r['wall_s']:5.1f} s  LUT {r['luts']:5d}  FF {r['ffs']:5d}  "
              f"carry {r['carries']:4d}  DSP {r['dsps']:2d}  BRAM {bram:13s} "
              f"cells {r['cells_total']:5d}  ROM in BRAM: {'yes' if rom_ok else 'NO'}")
        if not checks["rom_bram"]:
            want = f"{exp['brams']} SB_RAM40_4K" if tgt == "ice40" else f"{exp['bram_kbits']} kbit"
            failed.append(f"{name}/{tgt} rom_bram: PROM {depth}x{varying} (of {word_bits} bits; "
                          f"constant columns dropped) should take {want}; got {bram}, "
                          f"{leftover_mem} $mem, {r['distributed_ram']} distributed RAM/ROM cells")
    if not checks["dsps"]:
        failed.append(f"{name}/{tgt} dsps: {r['dsps']} DSPs, expected {exp['dsps']} = {per_mul}")
    if not checks["warnings"]:
        failed.append(f"{name}/{tgt} warnings: unexpected yosys warnings:\n      "
                      + "\n      ".join(warns[:10]))

tmp = os.path.join(out, ".summary.json.tmp")
with open(tmp, "w") as f:
    json.dump(summary, f, indent=2)
    f.write("\n")
os.replace(tmp, os.path.join(out, "summary.json"))
print(f"  summary: {os.path.join(out, 'summary.json')}")
sys.stdout.flush()
for msg in failed:
    print(("CHECK FAILED: " if check else "note: ") + msg, file=sys.stderr)
if check:
    if failed:
        sys.exit(1)
    if span:
        print("  checks passed: DSPs = row-start multiplier tiling, no latches, no memories, "
              "no unexpected warnings")
    else:
        print("  checks passed: ROM in least block RAM, DSPs = multiplier tiling, "
              "no unexpected warnings")
EOF

params=$(python3 -c "$PY" params "$TOP" "$config" "$prom") || exit 2
cfg_name=$(head -n 1 <<<"$params")
chparams=$(tail -n 1 <<<"$params")
yosys_version=$(yosys -V)

# Runs yosys for one target; sets wall_s.
run_yosys() {
  local tgt=$1 synth log stat err script t0 t1
  case $tgt in
    ice40) synth="synth_ice40 -dsp -top $TOP" ;;
    xc7) synth="synth_xilinx -family xc7 -flatten -noiopad -noclkbuf -top $TOP" ;;
  esac
  log=$out/$tgt.log
  stat=$out/${tgt}_stat.json
  err=$out/.$tgt.stderr
  local rom=""
  [[ $TOP != shd_spec_unit ]] || rom="-set RomFile \"$prom\""
  script="read_verilog -defer ${RTL_FILES[*]}
chparam $chparams $rom $TOP
hierarchy -check -top $TOP
$synth
tee -q -o $stat.tmp stat -json"
  rm -f "$stat.tmp"
  t0=$EPOCHREALTIME
  if ! yosys -q -l "$log.tmp" -p "$script" >/dev/null 2>"$err"; then
    mv -f "$log.tmp" "$log"
    {
      echo "synth.sh: error: yosys failed for $cfg_name / $tgt (full log: $log):"
      grep -m 5 'ERROR' "$log" || tail -n 20 "$err"
    } >&2
    rm -f "$err" "$stat.tmp"
    exit 3
  fi
  t1=$EPOCHREALTIME
  rm -f "$err"
  mv -f "$log.tmp" "$log"
  mv -f "$stat.tmp" "$stat"
  wall_s=$(python3 -c "print(f'{$t1 - $t0:.2f}')")
}

walls=()
for tgt in "${targets[@]}"; do
  echo "synth.sh: $cfg_name / $tgt ..."
  run_yosys "$tgt"
  walls+=("$tgt=$wall_s")
done

python3 -c "$PY" summary "$TOP" "$config" "$prom" "$out" "$check" "$yosys_version" "${walls[@]}"
