#!/usr/bin/env python3
"""The unit configurations, for every tool that is not the C++ model.

A configuration is one JSON file `<unit>_<name>.json` in vectors/config/ (the registry; a build
may add directories with SHD_CONFIG_DIRS). The files generated from it live beside its
directory: the PROM table <dir>/../prom/spec_<name>.hex and the vector file
<dir>/../cycles/<unit>_<name>.vec (vectors/prom/ and vectors/cycles/ for the registry).

    { "name": "<name>", "description": "...", "rtl": { "<Parameter>": <integer>, ... }, ...,
      "expected": { "<group>": { "<figure>": <number>, ... }, ... } }

`expected` (optional) records the figures scripts/regress.py checks; EXPECTED lists them.

`rtl` holds the Verilog parameters of the unit's top module. This script is the one place that
turns a configuration into the options of Verilator (-G), Icarus (-P) and yosys (chparam), and
the one place that lists the registry for CMake. lint.sh, run_icarus.sh, synth.py and
CMakeLists.txt all go through it; the C++ model reads the same files (embedded at build time,
model/config/registry.h) and validates the parameters' ranges.

  shd_config.py list [--unit spec|span] [--dir DIR ...]      "<unit> <name> <file>" per line
  shd_config.py args --tool verilator|icarus|yosys [--top MODULE] CONFIG
        CONFIG: a JSON file, "<unit>:<name>" from the registry, or "-" (the JSON on stdin).
        verilator: one -G<Name>=<value> per line; icarus: -P<top>.<Name>=<value> (--top, default
        the unit's top module); yosys: one line "-set <Name> <value> ..." for chparam
  shd_config.py unit UNIT            the unit's top module, then its RTL files, one per line
  shd_config.py cmake --dir DIR ... --cmake-out F --cpp-out F  what CMake includes, and the C++
        source that embeds every configuration's text (written only when it changed)
Exit status 0, or 2 with "shd_config.py: error: ..." naming the file and the member.
"""
import argparse
import json
import os
import re
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
# The source tree, or an installation's <prefix>/share/shadesim (the same layout).
DEFAULT_DIR = os.path.join(ROOT, "vectors", "config")

# The units: their top module and RTL files (in rtl/, the top first).
UNITS = {
    "spec": {"top": "shd_spec_unit", "rtl": ["shd_spec_unit.v", "shd_spec_poly.v", "shd_spec_schlick.v",
                                             "shd_spec_explog.v", "shd_spec_piecewise.v", "shd_coef_rom.v",
                                             "shd_pipe_reg.v"]},
    "span": {"top": "shd_span_unit", "rtl": ["shd_span_unit.v"]},
}
# The figures a configuration's optional "expected" member may record, per unit: group -> figure
# names, or None for a group that is itself one number. scripts/regress.py computes and checks
# them (docs/configurations.md); model/config/registry.cpp holds the same table.
_AREA = ("luts", "ffs", "carries", "dsps", "brams")
_SPEC_SCENE = ("spec_cycles", "spec_evaluations", "max_abs_lsb")
_SPAN_SCENE = ("cycles", "fragments")
EXPECTED = {
    "spec": {"error": ("total_max_lsb", "total_peak_max_lsb", "datapath_max_lsb", "datapath_max_f_lsb"),
             "latency": None, "sphere": _SPEC_SCENE, "still_life": _SPEC_SCENE,
             "ice40": _AREA, "xc7": _AREA},
    "span": {"sphere": _SPAN_SCENE, "still_life": _SPAN_SCENE, "ice40": _AREA, "xc7": _AREA},
}
SCENES = ("sphere", "still_life")  # the named scenes: vectors/scenes/<scene>.json
TARGETS = ("ice40", "xc7")
NAME_RE = re.compile(r"[a-z][a-z0-9]*")  # a configuration name: also a C++ identifier part
PARAM_RE = re.compile(r"[A-Z][A-Za-z0-9]*")
RAW_END = ')shdjson"'  # the raw-string delimiter of the embedded text


class ConfigError(Exception):
    pass


class Config:
    def __init__(self, unit, name, rtl, path, text):
        self.unit, self.name, self.rtl, self.path, self.text = unit, name, rtl, path, text

    @property
    def top(self):
        return UNITS[self.unit]["top"]

    def generated(self, kind):
        """Where its generated file of `kind` ("prom" or "cycles") lives."""
        ext = {"prom": ".hex", "cycles": ".vec"}[kind]
        base = os.path.dirname(os.path.dirname(os.path.abspath(self.path)))
        return os.path.join(base, kind, f"{self.unit}_{self.name}{ext}")


def parse(text, where, unit=None, name=None):
    """A Config from JSON text; unit and name, when known from the file name, must match."""
    try:
        j = json.loads(text)
    except ValueError as e:
        raise ConfigError(f"{where}: not valid JSON: {e}")
    if not isinstance(j, dict):
        raise ConfigError(f"{where}: must hold a JSON object")
    jname = j.get("name")
    if not isinstance(jname, str) or not NAME_RE.fullmatch(jname):
        raise ConfigError(f"{where}: \"name\" must be a string of lower-case letters and digits, "
                          f"starting with a letter (got {jname!r})")
    if name is not None and jname != name:
        raise ConfigError(f"{where}: \"name\" is {jname!r}, the file name says {name!r}")
    rtl = j.get("rtl")
    if not isinstance(rtl, dict) or not rtl:
        raise ConfigError(f"{where}: \"rtl\" must be a non-empty object of Verilog parameters")
    for k, v in rtl.items():
        if not PARAM_RE.fullmatch(k):
            raise ConfigError(f"{where}: rtl.{k}: a parameter name is UpperCamelCase letters and digits")
        if type(v) is not int:
            raise ConfigError(f"{where}: rtl.{k} = {json.dumps(v)} is not an integer")
        # Verilog parameters are 32-bit integers: a larger value would wrap (4294967304 to 8).
        if not -2**31 <= v < 2**31:
            raise ConfigError(f"{where}: rtl.{k} = {v} does not fit a 32-bit Verilog parameter")
    if "expected" in j:
        check_expected(j["expected"], where, unit)
    if RAW_END in text:
        raise ConfigError(f"{where}: contains {RAW_END!r}, which cannot be embedded")
    return Config(unit, jname, rtl, where, text)


def _is_number(v):
    return type(v) in (int, float)


def check_expected(exp, where, unit):
    """Refuses an "expected" member that is not groups of known figures holding numbers."""
    if unit is None:  # unit unknown (stdin): any unit's table
        table = {g: f for u in EXPECTED.values() for g, f in u.items()}
    else:
        table = EXPECTED[unit]
    if not isinstance(exp, dict):
        raise ConfigError(f"{where}: \"expected\" must be an object of figure groups")
    for g, v in exp.items():
        if g not in table:
            raise ConfigError(f"{where}: expected.{g}: unknown group (known: {', '.join(table)})")
        if table[g] is None:
            if not _is_number(v):
                raise ConfigError(f"{where}: expected.{g} = {json.dumps(v)} is not a number")
            continue
        if not isinstance(v, dict):
            raise ConfigError(f"{where}: expected.{g} must be an object of figures")
        for f, x in v.items():
            if f not in table[g]:
                raise ConfigError(f"{where}: expected.{g}.{f}: unknown figure "
                                  f"(known: {', '.join(table[g])})")
            if not _is_number(x):
                raise ConfigError(f"{where}: expected.{g}.{f} = {json.dumps(x)} is not a number")


def load_file(path, unit=None):
    """A configuration file; its unit from the file name <unit>_<name>.json when not given."""
    base = os.path.basename(path)
    m = re.fullmatch(r"(spec|span)_([a-z][a-z0-9]*)\.json", base)
    try:
        with open(path, encoding="utf-8") as f:
            text = f.read()
    except OSError as e:
        raise ConfigError(f"{path}: cannot read: {e.strerror}")
    except UnicodeDecodeError as e:
        raise ConfigError(f"{path}: not UTF-8 text ({e.reason} at byte {e.start})")
    if m:
        if unit not in (None, m.group(1)):
            raise ConfigError(f"{path}: the file name says unit {m.group(1)}, not {unit}")
        return parse(text, path, m.group(1), m.group(2))
    if unit is None:
        raise ConfigError(f"{path}: name it <unit>_<name>.json (unit spec or span), or name the unit")
    return parse(text, path, unit)


def registry(dirs):
    """Every <unit>_<name>.json of the directories, sorted by unit then name; names unique."""
    found = {}
    for d in dirs:
        if not os.path.isdir(d):
            raise ConfigError(f"{d}: not a configuration directory")
        for base in sorted(os.listdir(d)):
            if not base.endswith(".json"):
                continue
            if not re.fullmatch(r"(spec|span)_[a-z][a-z0-9]*\.json", base):
                raise ConfigError(f"{os.path.join(d, base)}: a configuration file is named "
                                  f"spec_<name>.json or span_<name>.json (<name>: a-z, 0-9)")
            c = load_file(os.path.join(d, base))
            key = (c.unit, c.name)
            if key in found:
                raise ConfigError(f"{c.path}: configuration {c.unit}:{c.name} is also {found[key].path}")
            found[key] = c
    return [found[k] for k in sorted(found)]


def resolve(ref, dirs, unit=None):
    """A JSON file, "<unit>:<name>" of the registry, or "-" for stdin."""
    if ref == "-":
        return parse(sys.stdin.read(), "<stdin>", unit)
    m = re.fullmatch(r"(spec|span):([a-z][a-z0-9]*)", ref)
    if m and not os.path.exists(ref):
        if unit not in (None, m.group(1)):
            raise ConfigError(f"{ref} is a {m.group(1)} configuration, not {unit}")
        for c in registry(dirs):
            if (c.unit, c.name) == (m.group(1), m.group(2)):
                return c
        names = ", ".join(c.name for c in registry(dirs) if c.unit == m.group(1))
        raise ConfigError(f"no configuration {ref} (known {m.group(1)} configurations: {names})")
    return load_file(ref, unit)


def tool_args(c, tool, top=None):
    """The parameter options of one tool, as a list of strings."""
    if tool == "verilator":
        return [f"-G{k}={v}" for k, v in c.rtl.items()]
    if tool == "icarus":
        return [f"-P{top or c.top}.{k}={v}" for k, v in c.rtl.items()]
    if tool == "yosys":  # one chparam: separate ones elaborate the module once per parameter
        return [" ".join(f"-set {k} {v}" for k, v in c.rtl.items())]
    raise ConfigError(f"unknown tool {tool!r}")


def write_if_changed(path, text):
    try:
        with open(path, encoding="utf-8") as f:
            if f.read() == text:
                return
    except OSError:
        pass
    tmp = path + ".tmp"
    with open(tmp, "w", encoding="utf-8") as f:
        f.write(text)
    os.replace(tmp, path)


def cmake_outputs(configs):
    """(CMake code, C++ source) for the registry."""
    cm = ["# Generated by scripts/shd_config.py cmake: the unit configurations of this build."]
    for u, spec in UNITS.items():
        names = [c.name for c in configs if c.unit == u]
        cm.append(f"set(SHD_{u.upper()}_CONFIGS {' '.join(names)})")
        cm.append(f"set(SHD_{u.upper()}_TOP {spec['top']})")
        cm.append(f"set(SHD_{u.upper()}_RTL {' '.join('${SHD_ROOT}/rtl/' + f for f in spec['rtl'])})")
    for c in configs:
        key = f"SHD_CFG_{c.unit}_{c.name}"
        cm.append(f"set({key}_FILE \"{c.path}\")")
        cm.append(f"set({key}_PROM \"{c.generated('prom')}\")")
        cm.append(f"set({key}_VEC \"{c.generated('cycles')}\")")
        cm.append(f"set({key}_GARGS {' '.join(tool_args(c, 'verilator'))})")
        cm.append(f"set({key}_KIND {c.rtl.get('Kind', 0)})")
        assign = "".join(f"  p.{k} = {v};\\n" for k, v in c.rtl.items())
        cm.append(f"set({key}_ASSIGN \"{assign}\")")
    cpp = ["// Generated by scripts/shd_config.py from the configuration files of this build.",
           '#include "config/registry.h"', "", "namespace shd::config_detail {", "",
           "extern const BuiltinConfig kBuiltin[];", "extern const size_t kBuiltinCount;",
           "const BuiltinConfig kBuiltin[] = {"]
    for c in configs:
        rel = os.path.relpath(c.path, ROOT) if c.path.startswith(ROOT + os.sep) else c.path
        cpp.append(f'    {{"{c.unit}", "{c.name}", {json.dumps(rel)}, R"shdjson({c.text})shdjson"}},')
    cpp += ["};", "const size_t kBuiltinCount = sizeof(kBuiltin) / sizeof(kBuiltin[0]);", "",
            "}  // namespace shd::config_detail", ""]
    return "\n".join(cm) + "\n", "\n".join(cpp)


def main(argv):
    p = argparse.ArgumentParser(prog="shd_config.py", description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = p.add_subparsers(dest="cmd", required=True)
    ls = sub.add_parser("list")
    ls.add_argument("--unit", choices=sorted(UNITS))
    ls.add_argument("--dir", action="append")
    ar = sub.add_parser("args")
    ar.add_argument("--tool", required=True, choices=["verilator", "icarus", "yosys"])
    ar.add_argument("--top")
    ar.add_argument("--unit", choices=sorted(UNITS))
    ar.add_argument("--dir", action="append")
    ar.add_argument("config")
    un = sub.add_parser("unit")
    un.add_argument("unit", choices=sorted(UNITS))
    cm = sub.add_parser("cmake")
    cm.add_argument("--dir", action="append", required=True)
    cm.add_argument("--cmake-out", required=True)
    cm.add_argument("--cpp-out", required=True)
    a = p.parse_args(argv)
    try:
        if a.cmd == "list":
            for c in registry(a.dir or [DEFAULT_DIR]):
                if a.unit in (None, c.unit):
                    print(f"{c.unit} {c.name} {c.path}")
        elif a.cmd == "args":
            c = resolve(a.config, a.dir or [DEFAULT_DIR], a.unit)
            if c.unit is None:
                raise ConfigError(f"{a.config}: name the unit (--unit spec|span)")
            print("\n".join(tool_args(c, a.tool, a.top)))
        elif a.cmd == "unit":
            u = UNITS[a.unit]
            print(u["top"])
            for f in u["rtl"]:
                print(os.path.join(ROOT, "rtl", f))
        else:
            configs = registry([os.path.abspath(d) for d in a.dir])
            for u in UNITS:
                if not any(c.unit == u for c in configs):
                    raise ConfigError(f"no {u} configuration in {', '.join(a.dir)}")
            cmake_text, cpp_text = cmake_outputs(configs)
            write_if_changed(a.cmake_out, cmake_text)
            write_if_changed(a.cpp_out, cpp_text)
    except ConfigError as e:
        print(f"shd_config.py: error: {e}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
