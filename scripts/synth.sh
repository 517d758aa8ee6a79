#!/usr/bin/env bash
# synth.sh: synthesise one specular-unit configuration with yosys for iCE40 and/or Xilinx 7-series
# and report its area.
#
# Usage: scripts/synth.sh [--config vectors/config/spec_default.json]
#                         [--prom vectors/prom/spec_default.hex]
#                         [--out out/synth/default] [--target ice40|xc7|both] [--check]
#
# The "rtl" object of the configuration becomes one `chparam -set Name Value ... shd_spec_unit`;
# the PROM becomes RomFile (an absolute path: yosys reads it at elaboration, `initial $readmemh` under
# SYNTHESIS). Flows:
#   ice40  synth_ice40 -dsp                                   (flattens by default)
#   xc7    synth_xilinx -family xc7 -flatten -noiopad -noclkbuf
#          -flatten so both targets are counted the same way; -noiopad -noclkbuf because the unit
#          is a block inside a design, not a chip top (IBUF/OBUF/BUFG would be ~100 cells of noise).
#
# Output (in --out, each file written to a temporary name and renamed):
#   <target>_stat.json  yosys `stat -json` of the synthesised netlist
#   <target>.log        the full yosys log
#   summary.json        {"config", "config_file", "prom_file", "yosys", "rtl": {...},
#                        "targets": {"<target>": {luts, ffs, carries, dsps, brams, bram_kbits,
#                        cells_total, wall_s, cells_by_type, expected, checks}}}
#     luts        iCE40 SB_LUT4; xc7 LUT1..LUT6 plus INV (yosys's name for an inverting LUT1)
#     ffs         every flip-flop primitive (SB_DFF*, FD*)
#     carries     iCE40 SB_CARRY (one per bit); xc7 CARRY4 (one per 4 bits): not comparable
#     dsps        SB_MAC16 / DSP48E1
#     brams       block-RAM primitives (SB_RAM40_4K*, RAMB18E1, RAMB36E1); bram_kbits their capacity
#     cells_total every cell of the netlist
#
# --check makes the run fail unless the netlist is what the RTL is meant to become:
#   rom_bram  The PROM is entirely in block RAM, and in the least block RAM its contents need.
#             yosys drops PROM bit columns that are constant over all 2^ShinBits words, so the
#             geometry is depth 2^ShinBits x (columns that vary in the hex file). iCE40: the
#             SB_RAM40_4K count equals min over its read modes 256x16, 512x8, 1024x4, 2048x2 of
#             ceil(depth/d)*ceil(width/w). xc7: the capacity in kbit equals the least one over the
#             RAMB18E1 (18 kbit: 16384x1 .. 512x36) and RAMB36E1 (36 kbit: 32768x1 .. 512x72)
#             aspect ratios (yosys may pick either primitive when they tie, so kbit is compared,
#             not the count). Also: no $mem cell and no distributed-RAM/ROM primitive is left.
#             Fails when the ROM falls into LUTs (e.g. rom_style lost on xc7, an asynchronous read)
#             or gets duplicated.
#   dsps      The DSP count equals what the multipliers need. Operand widths come from the RTL
#             header's derivation (uQ1.Wc: CW = Wc+1; KW = Ci+Cf; DTW = Df-1; GTW = Ci+1+Hf;
#             FW = Wf+1; L = LightBits):
#               MUL1     c*c           CW x CW unsigned
#               MUL2     deg 2: a*dt   (KW+1) x DTW signed (a is unsigned, one zero sign bit)
#                        deg 3: gt*dt  GTW x DTW signed
#               Horner   deg 3: u*c    KW x (CW+1) signed
#               MUL3..5  f*L           FW x L unsigned (three of them)
#             and each is tiled the way yosys's mul2dsp.v does it (iCE40: 16x16 tiles, pieces
#             narrower than 2 bits or with a product under 11 bits go to LUTs; xc7: signed-only
#             25x18 tiles, 17-bit A slices, products under 9 bits to LUTs). Fails when a
#             multiplier stays in LUTs or is wider than the derivation (a sign extension that
#             wreduce cannot remove costs a whole extra DSP tile).
#   warnings  yosys printed no warning except the known harmless ones listed in KNOWN_WARNINGS
#             below (a short/missing $readmemh, multiple drivers, a memory turned into registers
#             would all be caught here).
#
# Exit status: 0 on success, 1 on a failed check, 2 on a usage or input error, 3 when yosys fails.
set -euo pipefail

ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
RTL_FILES=("$ROOT/rtl/shd_spec_unit.v" "$ROOT/rtl/shd_coef_rom.v" "$ROOT/rtl/shd_pipe_reg.v")
TOP=shd_spec_unit

config=$ROOT/vectors/config/spec_default.json
prom=""
out=""
target=both
check=0

usage() {
  sed -n '4,6p' "${BASH_SOURCE[0]}" | sed 's/^# \{0,1\}//'
}
die() {
  echo "synth.sh: error: $*" >&2
  exit 2
}

while (($# > 0)); do
  case $1 in
    --config) config=${2:?--config needs a file}; shift 2 ;;
    --prom) prom=${2:?--prom needs a file}; shift 2 ;;
    --out) out=${2:?--out needs a directory}; shift 2 ;;
    --target) target=${2:?--target needs ice40, xc7 or both}; shift 2 ;;
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

[[ -f $config ]] || die "configuration file '$config' not found"
config=$(realpath "$config")
# Default PROM and output directory follow the configuration's file name: spec_<name>.json.
cfg_base=$(basename "$config" .json)
cfg_name=${cfg_base#spec_}
[[ -n $prom ]] || prom=$ROOT/vectors/prom/$cfg_base.hex
[[ -n $out ]] || out=$ROOT/out/synth/$cfg_name
[[ -f $prom ]] || die "PROM file '$prom' not found (make it with 'shadesim prom', or pass --prom)"
prom=$(realpath "$prom")
# RomFile travels as a Verilog string inside a yosys command: no quote, backslash or whitespace.
[[ $prom =~ ^[^[:space:]\"\\\;]+$ ]] || die "PROM path '$prom' must not contain whitespace, quotes, backslashes or ';'"
command -v yosys >/dev/null || die "yosys not found (apt-get install yosys)"
mkdir -p "$out"
out=$(realpath "$out")

# chparam -set options from the configuration's "rtl" object (integers only, names checked).
chparams=$(python3 - "$config" <<'EOF'
import json, re, sys
path = sys.argv[1]
try:
    with open(path) as f:
        rtl = json.load(f)["rtl"]
except (OSError, ValueError, KeyError, TypeError) as e:
    sys.exit(f"synth.sh: error: {path}: cannot read the 'rtl' object: {e!r}")
sets = []
for name, value in rtl.items():
    if not re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*", name) or type(value) is not int:
        sys.exit(f"synth.sh: error: {path}: rtl.{name} = {value!r} is not an integer parameter")
    sets.append(f"-set {name} {value}")
# One chparam for all of them: separate chparam commands would elaborate the module once per
# parameter, with mixed old/new values (e.g. narrow's CosFracBits with the default DiffFracBits),
# and yosys warns about selects that are out of range only in those intermediate modules.
print(" ".join(sets))
EOF
) || exit 2

yosys_version=$(yosys -V)

# Runs one target; sets the global wall_s.
run_yosys() {
  local tgt=$1 synth log stat t0 t1 script
  case $tgt in
    ice40) synth="synth_ice40 -dsp -top $TOP" ;;
    xc7) synth="synth_xilinx -family xc7 -flatten -noiopad -noclkbuf -top $TOP" ;;
  esac
  log=$out/$tgt.log
  stat=$out/${tgt}_stat.json
  script="read_verilog -defer ${RTL_FILES[*]}
chparam ${chparams} -set RomFile \"$prom\" $TOP
hierarchy -check -top $TOP
$synth
tee -q -o $stat.tmp stat -json"
  rm -f "$stat.tmp"
  t0=$EPOCHREALTIME
  if ! yosys -q -l "$log.tmp" -p "$script" >/dev/null 2>"$out/$tgt.stderr"; then
    mv -f "$log.tmp" "$log"
    {
      echo "synth.sh: error: yosys failed for $cfg_name / $tgt; full log: $log"
      grep -m5 -i 'error' "$log" || tail -n 20 "$log"
    } >&2
    exit 3
  fi
  t1=$EPOCHREALTIME
  mv -f "$log.tmp" "$log"
  mv -f "$stat.tmp" "$stat"
  rm -f "$out/$tgt.stderr"
  wall_s=$(python3 -c "print(f'{$t1 - $t0:.2f}')")
}

walls=()
for tgt in "${targets[@]}"; do
  echo "synth.sh: $cfg_name / $tgt ..."
  run_yosys "$tgt"
  walls+=("$tgt=$wall_s")
done

# Summary, checks and summary.json.
python3 - "$config" "$prom" "$out" "$check" "$yosys_version" "${walls[@]}" <<'EOF'
import json, math, os, re, sys

config_file, prom_file, out, check, yosys_version = sys.argv[1:6]
check = check == "1"
walls = dict(w.split("=", 1) for w in sys.argv[6:])
cfg = json.load(open(config_file))
p = cfg["rtl"]
name = cfg.get("name", os.path.basename(config_file))

# Warnings seen in every clean run and known to be harmless:
KNOWN_WARNINGS = [
    # abc on a module or cone with no latches.
    r'ABC: Warning: The network is combinational',
    # xc7 block-RAM mapping: yosys declares the RAMB18E1/RAMB36E1 data and address ports at
    # their widest (TDP data, cascade address) and trims them to the mode it used; nothing is lost.
    r'Warning: Resizing cell port .*\.(DOADO|DOBDO|DOPADOP|DOPBDOP|DIADI|DIBDI|DIPADIP|DIPBDIP'
    r'|ADDRARDADDR|ADDRBWRADDR) from \d+ bits to \d+ bits\.',
]

# ---- expected DSP count: mul2dsp.v's tiling, applied to the derived operand widths
TECH = {
    "ice40": dict(amax=16, bmax=16, apart=16, bpart=16, amin=2, bmin=2, ymin=11, signed_only=False),
    "xc7": dict(amax=25, bmax=18, apart=18, bpart=18, amin=2, bmin=2, ymin=9, signed_only=True),
}

def tiles(t, aw, bw, asg, bsg, yw, cell="$mul"):
    """Number of DSP primitives mul2dsp.v makes of one $mul/$__mul cell (recursive)."""
    if aw < t["amin"] or bw < t["bmin"] or yw < t["ymin"]:
        return 0                                   # _TECHMAP_FAIL_: left to LUTs
    if t["signed_only"] and cell == "$mul" and not asg and not bsg:
        return tiles(t, aw + 1, bw + 1, True, True, yw, "$mul")
    if cell == "$mul" and aw < bw:
        return tiles(t, bw, aw, bsg, asg, yw, "$mul")
    h = 1 if t["signed_only"] else 0               # sign_headroom
    if aw > t["amax"]:
        step = t["apart"] - h
        n = (aw - t["amax"] + t["apart"] - h - 1) // step
        last = aw - n * step
        return (n * tiles(t, t["apart"], bw, bool(h), bsg, min(yw, bw + t["apart"]), "$__mul")
                + tiles(t, last, bw, asg, bsg, bw + last, "$__mul"))
    if bw > t["bmax"]:
        step = t["bpart"] - h
        n = (bw - t["bmax"] + t["bpart"] - h - 1) // step
        last = bw - n * step
        return (n * tiles(t, aw, t["bpart"], asg, bool(h), min(yw, aw + t["bpart"]), "$__mul")
                + tiles(t, aw, last, asg, bsg, aw + last, "$__mul"))
    return 1

def multipliers():
    """(name, a_width, b_width, a_signed, b_signed, used_product_width) per multiplier."""
    wc = p["CosFracBits"]; cw = wc + 1
    kw = p["CoefIntBits"] + p["CoefFracBits"]
    dtw = p["DiffFracBits"] - 1
    gtw = p["CoefIntBits"] + 1 + p["HornerFracBits"]
    fw = p["SpecFracBits"] + 1
    lb = p["LightBits"]
    m = [("MUL1 c*c", cw, cw, False, False, 2 * wc - 1)]
    if p["Degree"] == 2:
        m.append(("MUL2 a*dt", kw + 1, dtw, True, True, kw + dtw))
    else:
        m.append(("Horner u*c", kw, cw + 1, True, True, kw + wc))
        m.append(("MUL2 gt*dt", gtw, dtw, True, True, gtw + dtw))
    for ch in "RGB":
        m.append((f"MUL{3 + 'RGB'.index(ch)} f*L{ch}", fw, lb, False, False, fw - 1 + lb))
    return m

# ---- expected block RAM: the PROM's geometry after yosys drops constant bit columns
def prom_geometry():
    depth = 1 << p["ShinBits"]
    kw = p["CoefIntBits"] + p["CoefFracBits"]
    word_bits = kw if p["Degree"] == 2 else 2 * kw + p["CosFracBits"] + 1
    text = open(prom_file).read()
    text = re.sub(r"/\*.*?\*/", " ", text, flags=re.S)
    text = re.sub(r"//[^\n]*", " ", text)
    words, addr = {}, 0
    for tok in text.split():
        if tok.startswith("@"):
            addr = int(tok[1:], 16)
            continue
        if addr >= depth:
            sys.exit(f"synth.sh: error: {prom_file}: more than {depth} words")
        if re.fullmatch(r"[0-9a-fA-F_]+", tok) is None:
            sys.exit(f"synth.sh: error: {prom_file}: '{tok}' is not a hex word "
                     "(x/z digits are not supported here)")
        v = int(tok.replace("_", ""), 16)
        if v >> word_bits:
            sys.exit(f"synth.sh: error: {prom_file}: word {tok} at address {addr} exceeds "
                     f"{word_bits} bits")
        words[addr] = v
        addr += 1
    if len(words) != depth:
        sys.exit(f"synth.sh: error: {prom_file}: {len(words)} words, the unit needs {depth}")
    vals = list(words.values())
    varying = sum(1 for b in range(word_bits) if len({(v >> b) & 1 for v in vals}) > 1)
    return depth, word_bits, varying

def ice40_brams(depth, width):
    if width == 0:
        return 0
    return min(math.ceil(depth / d) * math.ceil(width / w)
               for d, w in [(256, 16), (512, 8), (1024, 4), (2048, 2)])

def xc7_bram_kbits(depth, width):
    if width == 0:
        return 0
    best = None
    for kbit, modes in [(18, [(16384, 1), (8192, 2), (4096, 4), (2048, 9), (1024, 18), (512, 36)]),
                        (36, [(32768, 1), (16384, 2), (8192, 4), (4096, 9), (2048, 18), (1024, 36),
                              (512, 72)])]:
        for d, w in modes:
            cost = math.ceil(depth / d) * math.ceil(width / w) * kbit
            best = cost if best is None else min(best, cost)
    return best

# ---- counting
def count(cells, pred):
    return sum(n for t, n in cells.items() if pred(t))

def classify(tgt, cells):
    if tgt == "ice40":
        luts = count(cells, lambda t: t == "SB_LUT4")
        ffs = count(cells, lambda t: t.startswith("SB_DFF"))
        carries = count(cells, lambda t: t == "SB_CARRY")
        dsps = count(cells, lambda t: t == "SB_MAC16")
        bram_cells = {t: n for t, n in cells.items() if t.startswith("SB_RAM40_4K")}
        kbits = 4 * sum(bram_cells.values())
        distributed = 0
    else:
        luts = count(cells, lambda t: re.fullmatch(r"LUT[1-6]|INV", t) is not None)
        ffs = count(cells, lambda t: re.fullmatch(r"FD[CPRS]E(_1)?|LD[CP]E?", t) is not None)
        carries = count(cells, lambda t: t == "CARRY4")
        dsps = count(cells, lambda t: t.startswith("DSP48"))
        bram_cells = {t: n for t, n in cells.items() if re.fullmatch(r"RAMB(18|36)E1", t)}
        kbits = sum((18 if t.startswith("RAMB18") else 36) * n for t, n in bram_cells.items())
        distributed = count(cells, lambda t: re.fullmatch(r"RAM\d+X\d+\w*|RAM\d+M\w*|ROM\d+X1", t) is not None)
    return dict(luts=luts, ffs=ffs, carries=carries, dsps=dsps,
                brams=sum(bram_cells.values()), bram_kbits=kbits,
                distributed_ram=distributed,
                cells_total=sum(cells.values()))

depth, word_bits, varying = prom_geometry()
summary = dict(config=name, config_file=config_file, prom_file=prom_file,
               yosys=yosys_version, rtl=p,
               prom=dict(depth=depth, word_bits=word_bits, varying_bits=varying),
               targets={})
failed = []
for tgt, wall in walls.items():
    stat = json.load(open(os.path.join(out, f"{tgt}_stat.json")))
    cells = stat["design"]["num_cells_by_type"]
    r = classify(tgt, cells)
    r["wall_s"] = float(wall)
    r["cells_by_type"] = cells
    muls = multipliers()
    exp_dsps = sum(tiles(TECH[tgt], *m[1:]) for m in muls)
    exp = dict(dsps=exp_dsps,
               dsps_per_multiplier={
                   f"{m[0]} {m[1]}x{m[2]} {'signed' if m[3] else 'unsigned'}": tiles(TECH[tgt], *m[1:])
                   for m in muls})
    if tgt == "ice40":
        exp["brams"] = ice40_brams(depth, varying)
        rom_ok = r["brams"] == exp["brams"]
    else:
        exp["bram_kbits"] = xc7_bram_kbits(depth, varying)
        rom_ok = r["bram_kbits"] == exp["bram_kbits"]
    leftover_mem = count(cells, lambda t: t.startswith("$mem"))
    rom_ok = rom_ok and leftover_mem == 0 and r["distributed_ram"] == 0
    log = open(os.path.join(out, f"{tgt}.log")).read().splitlines()
    warns = [l for l in log if re.search(r"warning", l, re.I)
             and not any(re.search(k, l) for k in KNOWN_WARNINGS)
             and not l.startswith("Warnings:")]
    checks = dict(rom_bram=rom_ok, dsps=r["dsps"] == exp_dsps, warnings=not warns)
    r["expected"] = exp
    r["checks"] = checks
    r["unexpected_warnings"] = warns[:20]
    summary["targets"][tgt] = r

    bram_txt = f"{r['brams']} ({r['bram_kbits']} kbit)"
    print(f"  {name:8s} {tgt:5s} {r['wall_s']:6.1f} s  LUT {r['luts']:5d}  FF {r['ffs']:5d}  "
          f"carry {r['carries']:4d}  DSP {r['dsps']:2d}  BRAM {bram_txt:12s} cells {r['cells_total']:5d}  "
          f"ROM in BRAM: {'yes' if rom_ok else 'NO'}")
    for k, ok in checks.items():
        if ok:
            continue
        if k == "rom_bram":
            want = (f"{exp['brams']} SB_RAM40_4K" if tgt == "ice40" else f"{exp['bram_kbits']} kbit")
            msg = (f"PROM {depth}x{varying} (of {word_bits} bits, constant columns dropped) should "
                   f"take {want}; got {bram_txt}, {leftover_mem} $mem, "
                   f"{r['distributed_ram']} distributed RAM/ROM cells")
        elif k == "dsps":
            msg = f"{r['dsps']} DSPs, expected {exp_dsps}: {exp['dsps_per_multiplier']}"
        else:
            msg = "unexpected yosys warnings:\n      " + "\n      ".join(warns[:10])
        failed.append(f"{name}/{tgt} {k}: {msg}")

tmp = os.path.join(out, ".summary.json.tmp")
with open(tmp, "w") as f:
    json.dump(summary, f, indent=2, sort_keys=False)
    f.write("\n")
os.replace(tmp, os.path.join(out, "summary.json"))
print(f"  summary: {os.path.join(out, 'summary.json')}")

for msg in failed:
    print(("CHECK FAILED: " if check else "note: ") + msg, file=sys.stderr)
if check:
    if failed:
        sys.exit(1)
    print(f"  checks passed: ROM in least block RAM, DSP count = multiplier tiling, no unexpected warnings")
EOF
