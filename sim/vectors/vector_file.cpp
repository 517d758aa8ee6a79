#include "vectors/vector_file.h"

#include <cstring>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "device/prom_io.h"
#include "device/spec_params.h"
#include "io/files.h"

namespace shd {

namespace {

const char* const kHeaderKeys[] = {"unit", "config", "params", "prom", "latency", "source"};

const char* const kSpecParamOrder = "Degree CosFracBits ShinBits CoefIntBits CoefFracBits DiffFracBits HornerFracBits "
                                    "SpecFracBits LightBits PipeStages Kind TableBits Segments";
const char* const kSpanParamOrder = "NumTri LanesPerTri AlignLanes NumAttr AttrBits CoordBits RemBits PixBits TagBits RowAhead Interleave";

std::vector<int> specParamList(const SpecUnitParams& p) {
  return {p.Degree,       p.CosFracBits,    p.ShinBits,     p.CoefIntBits, p.CoefFracBits,
          p.DiffFracBits, p.HornerFracBits, p.SpecFracBits, p.LightBits,   p.PipeStages,
          p.Kind,         p.TableBits,      p.Segments};
}

std::vector<int> spanParamList(const SpanParams& p) {
  return {p.NumTri, p.LanesPerTri, p.AlignLanes, p.NumAttr, p.AttrBits, p.CoordBits, p.RemBits, p.PixBits, p.TagBits, p.RowAhead, p.Interleave};
}

uint64_t lowBits(int64_t v, int bits) {
  const uint64_t u = static_cast<uint64_t>(v);
  return bits >= 64 ? u : u & ((uint64_t{1} << bits) - 1);
}

// The value's port bits in hex.
std::string hx(int64_t v, int bits) { return fmt::format("{:x}", lowBits(v, bits)); }

std::string header(const std::string& unit, const std::string& config, const nlohmann::json& rtl,
                   const std::vector<int>& params, const std::string& source, const std::vector<std::string>& notes) {
  std::string h = fmt::format(
      "# shadesim vector file, format {} (described in sim/vectors/vector_file.h)\n"
      "# unit {}\n# config {} {}\n# params {}\n",
      kVectorFormat, unit, config, rtl.dump(), fmt::join(params, " "));
  if (!source.empty()) h += fmt::format("# source {}\n", source);
  for (const std::string& n : notes) {
    // A note is a comment: it must not read as a header field.
    const std::string first = n.substr(0, n.find(' '));
    for (const char* k : kHeaderKeys)
      if (first == k) throw std::invalid_argument(fmt::format("vector file note '{}' starts with the key '{}'", n, k));
    if (n.find('\n') != std::string::npos) throw std::invalid_argument("vector file note with a line break");
    h += "# " + n + "\n";
  }
  return h;
}

// ------------------------------------------------------------------ reading

struct Line {
  long no = 0;
  std::string text;
};

// A vector file opened for reading after the input checks (io/files.h): a regular file of at
// most 1 GB (the largest file `shadesim vectors` writes, 10^7 cycles, is well under it).
std::ifstream openVectorFile(const std::string& path) {
  if (const std::string why = inputFileProblem(path, uint64_t{1} << 30); !why.empty())
    throw std::runtime_error(fmt::format("cannot read vector file {}: {}", path, why));
  std::ifstream in(path);
  if (!in) throw std::runtime_error(fmt::format("cannot open vector file {}: {}", path, std::strerror(errno)));
  noteInput(path);
  return in;
}

class VectorReader {
 public:
  explicit VectorReader(const std::string& path) : path_(path) {
    std::ifstream in = openVectorFile(path);
    std::string s;
    long no = 0;
    while (std::getline(in, s)) {
      ++no;
      if (!s.empty() && s.back() == '\r') s.pop_back();
      // Blank: whitespace only, as the record tokenizer (operator>>) sees it, \v and \f included.
      if (s.find_first_not_of(" \t\n\v\f\r") == std::string::npos) continue;
      if (s[0] == '#') {
        // The first line names the format; a file of another format is not read as this one.
        static const std::string kFormatLine = "# shadesim vector file, format ";
        if (no == 1 && s.compare(0, kFormatLine.size(), kFormatLine) == 0) {
          const std::string version = s.substr(kFormatLine.size(), s.find(' ', kFormatLine.size()) - kFormatLine.size());
          if (version != std::to_string(kVectorFormat))
            throw error(no, fmt::format("format {}; this shadesim reads format {}", version, kVectorFormat));
        }
        // "# <key> <value>" header lines; every other '#' line is a comment.
        const size_t k0 = s.find_first_not_of(' ', 1);
        if (k0 != std::string::npos) {
          const size_t k1 = std::min(s.find(' ', k0), s.size());
          const std::string key = s.substr(k0, k1 - k0);
          for (const char* k : kHeaderKeys)
            if (key == k) {
              if (fields_.count(key)) throw error(no, fmt::format("header field '{}' given twice", key));
              const size_t v = s.find_first_not_of(' ', k1);
              fields_[key] = {no, v == std::string::npos ? "" : s.substr(v)};
            }
        }
        continue;
      }
      data_.push_back({no, s});
    }
  }

  std::runtime_error error(long line, const std::string& what) const {
    return std::runtime_error(fmt::format("{}:{}: {}", path_, line, what));
  }
  std::runtime_error error(const std::string& what) const { return std::runtime_error(fmt::format("{}: {}", path_, what)); }

  bool has(const std::string& key) const { return fields_.count(key) != 0; }
  const Line& field(const std::string& key) const {
    auto it = fields_.find(key);
    if (it == fields_.end()) throw error(fmt::format("no '# {} ...' header line", key));
    return it->second;
  }

  std::string unit() const { return field("unit").text; }
  // "# config <name> <rtl parameters as one-line JSON>"
  std::string config() const {
    const Line& c = field("config");
    const std::string name = c.text.substr(0, c.text.find(' '));
    if (name.empty() || name.find_first_of("\t/{") != std::string::npos)
      throw error(c.no, fmt::format("config '{}' does not start with a configuration name", c.text));
    return name;
  }
  nlohmann::json rtl() const {
    const Line& c = field("config");
    const size_t sp = c.text.find(' ');
    if (sp == std::string::npos) throw error(c.no, "config without the rtl parameters (JSON)");
    try {
      nlohmann::json j = nlohmann::json::parse(c.text.substr(sp + 1));
      if (!j.is_object()) throw error(c.no, "the config's rtl parameters are not a JSON object");
      return j;
    } catch (const nlohmann::json::exception& e) {
      throw error(c.no, fmt::format("the config's rtl parameters are not valid JSON: {}", e.what()));
    }
  }
  // The params line must list exactly `expected` (the rtl object's values in the fixed order).
  void checkParams(const std::vector<int>& expected, const char* order) const {
    const Line& p = field("params");
    std::istringstream s(p.text);
    std::vector<int> got;
    for (long v; s >> v;) got.push_back(static_cast<int>(v));
    if (!s.eof() || got != expected)
      throw error(p.no, fmt::format("params '{}' differ from the rtl object ({}: {})", p.text, order,
                                    fmt::join(expected, " ")));
  }

  const std::vector<Line>& data() const { return data_; }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
  std::map<std::string, Line> fields_;
  std::vector<Line> data_;
};

std::vector<std::string> tokens(const std::string& s) {
  std::istringstream in(s);
  std::vector<std::string> out;
  for (std::string t; in >> t;) out.push_back(t);
  return out;
}

// A hex token of a `bits`-bit port; signed: sign-extended from `bits`.
int64_t parseField(const VectorReader& r, const Line& line, const std::string& tok, int bits, bool is_signed,
                   const std::string& name) {
  if (tok.empty() || tok.find_first_not_of("0123456789abcdefABCDEF") != std::string::npos)
    throw r.error(line.no, fmt::format("{}: '{}' is not a hex value", name, tok));
  if (tok.size() > 16)
    throw r.error(line.no, fmt::format("{}: 0x{} has {} hex digits: wider than its {}-bit port", name, tok,
                                       tok.size(), bits));
  const uint64_t v = std::stoull(tok, nullptr, 16);
  if (bits < 64 && (v >> bits) != 0)
    throw r.error(line.no, fmt::format("{}: 0x{} does not fit its {}-bit port", name, tok, bits));
  if (!is_signed || bits >= 64) return static_cast<int64_t>(v);
  const uint64_t sign = uint64_t{1} << (bits - 1);
  return static_cast<int64_t>((v ^ sign) - sign);
}

// Reads the fields of a record in order.
class FieldCursor {
 public:
  FieldCursor(const VectorReader& r, const Line& line, std::vector<std::string> toks, size_t first)
      : r_(r), line_(line), toks_(std::move(toks)), i_(first) {}
  int64_t next(int bits, bool is_signed, const std::string& name) {
    if (i_ >= toks_.size())
      throw r_.error(line_.no, fmt::format("the record ends before field {} ({} fields)", name, toks_.size()));
    return parseField(r_, line_, toks_[i_++], bits, is_signed, name);
  }
  void end() const {
    if (i_ != toks_.size())
      throw r_.error(line_.no, fmt::format("{} fields, {} expected", toks_.size(), i_));
  }

 private:
  const VectorReader& r_;
  const Line& line_;
  std::vector<std::string> toks_;
  size_t i_;
};

}  // namespace

// ------------------------------------------------------------------ spec

std::string renderSpecVectors(const SpecVectors& v) {
  if (v.in.size() != v.expected.size())
    throw std::invalid_argument(fmt::format("spec vectors: {} input cycles, {} expected", v.in.size(), v.expected.size()));
  const SpecUnitParams& p = v.params;
  std::string t = header("spec", v.config, p.toJson(), specParamList(p), v.source, v.notes);
  t += fmt::format("# prom {}\n# latency {}\n", v.prom, p.latency());
  t += fmt::format(
      "# parameter order: {}\n"
      "# columns (hex, port widths): valid shin cos light_r light_g light_b  exp_valid exp_spec exp_r exp_g exp_b\n"
      "#   one line per clock cycle after reset (rst_ni low for two cycles, valid_i 0): the inputs before the\n"
      "#   rising edge, every output expected right after it\n",
      kSpecParamOrder);
  const int cw = p.CosFracBits + 1, lw = p.LightBits, sw = p.SpecFracBits + 1;
  for (size_t i = 0; i < v.in.size(); ++i) {
    const SpecIn& in = v.in[i];
    const SpecOut& e = v.expected[i];
    t += fmt::format("{:x} {} {} {} {} {}  {:x} {} {} {} {}\n", in.valid ? 1 : 0, hx(in.shin, p.ShinBits),
                     hx(in.cos, cw), hx(in.light[0], lw), hx(in.light[1], lw), hx(in.light[2], lw), e.valid ? 1 : 0,
                     hx(e.spec, sw), hx(e.rgb[0], lw), hx(e.rgb[1], lw), hx(e.rgb[2], lw));
  }
  return t;
}

void writeSpecVectors(const std::string& path, const SpecVectors& v) { writeFileAtomic(path, renderSpecVectors(v)); }

SpecVectors loadSpecVectors(const std::string& path) {
  const VectorReader r(path);
  if (r.unit() != "spec") throw r.error(r.field("unit").no, fmt::format("unit '{}', a spec-unit file expected", r.unit()));
  SpecVectors v;
  v.config = r.config();
  try {
    v.params = SpecUnitParams::fromJson(r.rtl(), path);
    v.params.validate();
  } catch (const std::invalid_argument& e) {
    throw r.error(r.field("config").no, e.what());
  }
  r.checkParams(specParamList(v.params), kSpecParamOrder);
  if (r.has("latency")) {
    const Line& l = r.field("latency");
    if (l.text != std::to_string(v.params.latency()))
      throw r.error(l.no, fmt::format("latency {}, the parameters give {}", l.text, v.params.latency()));
  }
  v.prom = r.field("prom").text;
  if (v.prom.empty()) throw r.error(r.field("prom").no, "empty prom path");
  if (r.has("source")) v.source = r.field("source").text;
  const SpecUnitParams& p = v.params;
  const int cw = p.CosFracBits + 1, lw = p.LightBits, sw = p.SpecFracBits + 1;
  for (const Line& line : r.data()) {
    FieldCursor c(r, line, tokens(line.text), 0);
    SpecIn in;
    SpecOut e;
    in.valid = c.next(1, false, "valid") != 0;
    in.shin = static_cast<uint32_t>(c.next(p.ShinBits, false, "shin"));
    in.cos = static_cast<uint32_t>(c.next(cw, false, "cos"));
    in.light[0] = static_cast<uint32_t>(c.next(lw, false, "light_r"));
    in.light[1] = static_cast<uint32_t>(c.next(lw, false, "light_g"));
    in.light[2] = static_cast<uint32_t>(c.next(lw, false, "light_b"));
    e.valid = c.next(1, false, "exp_valid") != 0;
    e.spec = static_cast<uint32_t>(c.next(sw, false, "exp_spec"));
    e.rgb[0] = static_cast<uint32_t>(c.next(lw, false, "exp_r"));
    e.rgb[1] = static_cast<uint32_t>(c.next(lw, false, "exp_g"));
    e.rgb[2] = static_cast<uint32_t>(c.next(lw, false, "exp_b"));
    c.end();
    v.in.push_back(in);
    v.expected.push_back(e);
  }
  if (v.in.empty()) throw r.error("no cycles");
  return v;
}

// ------------------------------------------------------------------ span

std::string renderSpanVectors(const SpanVectors& v) {
  const SpanParams& p = v.params;
  const int CB = p.CoordBits, AB = p.AttrBits, RB = p.RemBits, PB = p.PixBits, K = p.NumAttr, L = p.lanes();
  std::string t = header("span", v.config, p.toJson(), spanParamList(p), v.source, v.notes);
  t += fmt::format(
      "# parameter order: {}\n"
      "# Records (hex, port widths, signed values in two's complement; see sim/vectors/vector_file.h):\n"
      "# D tag row_first row_last xref {{iref didx didy}}*NumAttr interleave {{row_first row_last clip_x0 clip_x1 ox oy flip\n"
      "#   {{aoff}}*NumAttr {{right row_first row_last q r div k m}}*3}}*NumTri: the descriptor ports from the next C on\n"
      "# C desc_valid out_ready  exp_desc_ready exp_out_valid exp_tag exp_lane_valid {{x y {{attr}}*NumAttr}}*valid lanes:\n"
      "#   one clock cycle after reset (rst_ni low for two cycles, desc_valid 0, out_ready 1), inputs and the outputs\n"
      "#   expected during it, before its rising edge\n",
      kSpanParamOrder);
  auto check = [&](bool ok, const std::string& what) {
    if (!ok) throw std::invalid_argument("span vectors: " + what);
  };
  int on_ports = -1;
  bool pending = false;  // the previous cycle offered a descriptor that was not accepted
  for (size_t ci = 0; ci < v.cycles.size(); ++ci) {
    const SpanVectorCycle& c = v.cycles[ci];
    check(c.desc >= -1 && c.desc < static_cast<int>(v.descs.size()), fmt::format("cycle {}: no descriptor {}", ci + 1, c.desc));
    check(!c.desc_valid || c.desc >= 0, fmt::format("cycle {} offers no descriptor", ci + 1));
    if (c.desc != on_ports) {
      check(c.desc == on_ports + 1, fmt::format("cycle {}: descriptor {} follows {} (each appears once, in order)",
                                                ci + 1, c.desc, on_ports));
      check(!pending, fmt::format("cycle {}: the descriptor changes while an offer is pending", ci + 1));
      on_ports = c.desc;
      const SpanDesc& d = v.descs[static_cast<size_t>(c.desc)];
      check(d.iref.size() == static_cast<size_t>(K) && d.didx.size() == static_cast<size_t>(K) &&
                d.didy.size() == static_cast<size_t>(K) && d.tri.size() == static_cast<size_t>(p.NumTri),
            fmt::format("descriptor {} (tag {}) has not NumAttr attributes and NumTri lane-triangles", c.desc, d.tag));
      t += fmt::format("D {} {} {} {}", hx(d.tag, p.TagBits), hx(d.row_first, CB), hx(d.row_last, CB), hx(d.xref, CB));
      for (size_t a = 0; a < static_cast<size_t>(K); ++a)
        t += fmt::format(" {} {} {}", hx(d.iref[a], AB), hx(d.didx[a], AB), hx(d.didy[a], AB));
      t += fmt::format(" {:x}", d.interleave ? 1 : 0);
      for (const SpanLaneTri& lt : d.tri) {
        check(lt.aoff.size() == static_cast<size_t>(K), fmt::format("descriptor {}: aoff has not NumAttr entries", d.tag));
        t += fmt::format("  {} {} {} {} {} {} {:x}", hx(lt.row_first, CB), hx(lt.row_last, CB), hx(lt.clip_x0, CB),
                         hx(lt.clip_x1, CB), hx(lt.ox, CB), hx(lt.oy, CB), lt.flip ? 1 : 0);
        for (size_t a = 0; a < static_cast<size_t>(K); ++a) t += " " + hx(lt.aoff[a], AB);
        for (const SpanEdge& e : lt.edge)
          t += fmt::format("  {:x} {} {} {} {} {} {} {}", e.right ? 1 : 0, hx(e.row_first, CB), hx(e.row_last, CB),
                           hx(e.q, CB), hx(e.r, RB), hx(e.div, RB), hx(e.k, CB), hx(e.m, RB));
      }
      t += "\n";
    }
    const SpanOut& o = c.expected;
    uint64_t mask = 0;
    for (size_t l = 0; l < o.lane.size(); ++l)
      if (o.lane[l].valid) {
        check(l < static_cast<size_t>(L), fmt::format("cycle {}: lane {} valid, the unit has {} lanes", ci + 1, l, L));
        mask |= uint64_t{1} << l;
      }
    t += fmt::format("C {:x} {:x}  {:x} {:x} {} {:x}", c.desc_valid ? 1 : 0, c.out_ready ? 1 : 0, o.desc_ready ? 1 : 0,
                     o.out_valid ? 1 : 0, hx(o.tag, p.TagBits), mask);
    for (size_t l = 0; l < o.lane.size(); ++l) {
      const SpanLaneOut& lane = o.lane[l];
      if (!lane.valid) continue;
      check(lane.attr.size() == static_cast<size_t>(K), fmt::format("cycle {}: lane {} has not NumAttr attributes", ci + 1, l));
      t += fmt::format("  {} {}", hx(lane.x, PB), hx(lane.y, PB));
      for (size_t a = 0; a < static_cast<size_t>(K); ++a) t += " " + hx(lane.attr[a], AB);
    }
    t += "\n";
    pending = c.desc_valid && !o.desc_ready;
  }
  return t;
}

void writeSpanVectors(const std::string& path, const SpanVectors& v) { writeFileAtomic(path, renderSpanVectors(v)); }

SpanVectors loadSpanVectors(const std::string& path) {
  const VectorReader r(path);
  if (r.unit() != "span") throw r.error(r.field("unit").no, fmt::format("unit '{}', a span-unit file expected", r.unit()));
  SpanVectors v;
  v.config = r.config();
  try {
    v.params = SpanParams::fromJson(r.rtl(), path);
  } catch (const std::invalid_argument& e) {
    throw r.error(r.field("config").no, e.what());
  }
  r.checkParams(spanParamList(v.params), kSpanParamOrder);
  if (r.has("source")) v.source = r.field("source").text;
  const SpanParams& p = v.params;
  const int CB = p.CoordBits, AB = p.AttrBits, RB = p.RemBits, PB = p.PixBits, K = p.NumAttr, L = p.lanes();
  bool pending = false;  // the last cycle offered a descriptor that was not accepted
  long unused_d = 0;     // the line of a D record no C record has followed yet (0: none)
  for (const Line& line : r.data()) {
    std::vector<std::string> toks = tokens(line.text);
    const std::string kind = toks[0];
    FieldCursor f(r, line, std::move(toks), 1);
    if (kind == "D") {
      if (pending)
        throw r.error(line.no, "a D record while the previous descriptor is offered and not accepted (valid/ready rule)");
      // A descriptor is on the ports from its D record on: one that no cycle saw is no stimulus.
      if (unused_d != 0)
        throw r.error(line.no, fmt::format("a D record replaces the descriptor of line {} before any C record", unused_d));
      unused_d = line.no;
      SpanDesc d;
      d.tag = static_cast<uint32_t>(f.next(p.TagBits, false, "tag"));
      d.row_first = static_cast<int32_t>(f.next(CB, true, "row_first"));
      d.row_last = static_cast<int32_t>(f.next(CB, true, "row_last"));
      d.xref = static_cast<int32_t>(f.next(CB, true, "xref"));
      for (int a = 0; a < K; ++a) {
        d.iref.push_back(f.next(AB, true, fmt::format("iref[{}]", a)));
        d.didx.push_back(f.next(AB, true, fmt::format("didx[{}]", a)));
        d.didy.push_back(f.next(AB, true, fmt::format("didy[{}]", a)));
      }
      d.interleave = f.next(1, false, "interleave") != 0;
      if (d.interleave && !p.Interleave) throw r.error(line.no, "interleave is 1 and the unit's Interleave is 0");
      for (int j = 0; j < p.NumTri; ++j) {
        SpanLaneTri lt;
        const std::string n = fmt::format("lane-triangle {} ", j);
        lt.row_first = static_cast<int32_t>(f.next(CB, true, n + "row_first"));
        lt.row_last = static_cast<int32_t>(f.next(CB, true, n + "row_last"));
        lt.clip_x0 = static_cast<int32_t>(f.next(CB, true, n + "clip_x0"));
        lt.clip_x1 = static_cast<int32_t>(f.next(CB, true, n + "clip_x1"));
        lt.ox = static_cast<int32_t>(f.next(CB, true, n + "ox"));
        lt.oy = static_cast<int32_t>(f.next(CB, true, n + "oy"));
        lt.flip = f.next(1, false, n + "flip") != 0;
        for (int a = 0; a < K; ++a) lt.aoff.push_back(f.next(AB, true, fmt::format("{}aoff[{}]", n, a)));
        for (int s = 0; s < 3; ++s) {
          SpanEdge& e = lt.edge[s];
          const std::string en = fmt::format("{}edge {} ", n, s);
          e.right = f.next(1, false, en + "right") != 0;
          e.row_first = static_cast<int32_t>(f.next(CB, true, en + "row_first"));
          e.row_last = static_cast<int32_t>(f.next(CB, true, en + "row_last"));
          e.q = static_cast<int32_t>(f.next(CB, true, en + "q"));
          e.r = f.next(RB, false, en + "r");
          e.div = f.next(RB, false, en + "div");
          e.k = static_cast<int32_t>(f.next(CB, true, en + "k"));
          e.m = f.next(RB, false, en + "m");
        }
        d.tri.push_back(lt);
      }
      f.end();
      v.descs.push_back(std::move(d));
    } else if (kind == "C") {
      SpanVectorCycle c;
      c.desc_valid = f.next(1, false, "desc_valid") != 0;
      c.out_ready = f.next(1, false, "out_ready") != 0;
      c.desc = static_cast<int>(v.descs.size()) - 1;
      if (c.desc_valid && c.desc < 0) throw r.error(line.no, "desc_valid is 1 before any D record");
      SpanOut& o = c.expected;
      o.desc_ready = f.next(1, false, "exp_desc_ready") != 0;
      o.out_valid = f.next(1, false, "exp_out_valid") != 0;
      o.tag = static_cast<uint32_t>(f.next(p.TagBits, false, "exp_tag"));
      const uint64_t mask = static_cast<uint64_t>(f.next(L, false, "exp_lane_valid"));
      if ((mask != 0) != o.out_valid)
        throw r.error(line.no, fmt::format("exp_out_valid {} with exp_lane_valid {:x} (out_valid is the OR of the lanes)",
                                           o.out_valid ? 1 : 0, mask));
      o.lane.resize(static_cast<size_t>(L));
      for (int l = 0; l < L; ++l) {
        SpanLaneOut& lane = o.lane[static_cast<size_t>(l)];
        lane.valid = (mask >> l) & 1;
        if (!lane.valid) continue;
        lane.x = static_cast<int32_t>(f.next(PB, false, fmt::format("lane {} x", l)));
        lane.y = static_cast<int32_t>(f.next(PB, false, fmt::format("lane {} y", l)));
        for (int a = 0; a < K; ++a) lane.attr.push_back(f.next(AB, true, fmt::format("lane {} attr[{}]", l, a)));
      }
      f.end();
      pending = c.desc_valid && !o.desc_ready;
      unused_d = 0;
      v.cycles.push_back(std::move(c));
    } else {
      throw r.error(line.no, fmt::format("unknown record '{}' (D or C expected)", kind));
    }
  }
  if (unused_d != 0) throw r.error(unused_d, "a D record after the last C record (no cycle puts it on the ports)");
  if (v.cycles.empty()) throw r.error("no C records (cycles)");
  return v;
}

std::string vectorFileUnit(const std::string& path) {
  std::ifstream in = openVectorFile(path);
  for (std::string s; std::getline(in, s);) {
    if (s.rfind("# unit ", 0) == 0) {
      const size_t v = s.find_first_not_of(' ', 7);
      std::string unit = v == std::string::npos ? "" : s.substr(v);
      while (!unit.empty() && (unit.back() == '\r' || unit.back() == ' ')) unit.pop_back();
      if (unit != "spec" && unit != "span")
        throw std::runtime_error(fmt::format("{}: unit '{}' (spec or span expected)", path, unit));
      return unit;
    }
    if (s.empty() || s[0] != '#') break;  // the header ends at the first record
  }
  throw std::runtime_error(fmt::format("{}: no '# unit' header line: not a shadesim vector file", path));
}

}  // namespace shd
