#include "device/prom_io.h"

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <stdexcept>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "approx/fit.h"
#include "io/files.h"

#ifndef SHD_VERSION
#error "SHD_VERSION must be defined by the build"
#endif

namespace shd {

namespace {

// Lattice Memory Generator limits (srec_mem(5): #Depth=1 to 65536, #Width=1 to 256).
constexpr int kLatticeMaxDepth = 65536;
constexpr int kLatticeMaxWidth = 256;

// 17 significant digits: every double prints to a text that parses back to the same double.
std::string real17(double x) { return fmt::format("{:.17g}", x); }

struct Field {
  std::string name;    // "a", "a1", "v = a1+b1", "cut"
  std::string format;  // "uQ10.14"
  int msb = 0, lsb = 0;
};

// Everything the provenance says, computed once so that the comment lines of every format and
// the JSON sidecar state the same facts.
struct Provenance {
  SpecKind kind = SpecKind::Poly;
  int table_bits = 0;  // TableBits: the table kind's words per row, the explog kind's table size
  std::string spec_format;
  std::string tool;
  std::string fit;
  int degree = 2;
  double level = 0.5;
  bool level_used = false;
  std::string n_text;
  bool n_is_list = false;
  size_t n_count = 0;
  std::string coef_format, coef_round, cos_format;
  int word_bits = 0, depth = 0, shin_bits = 0, cos_frac_bits = 0;
  std::vector<Field> layout;  // MSB first
  size_t used = 0;            // addresses 0 .. used-1 hold entries
  RomPart part = RomPart::Prom;
  int segments = 1;
};

// The piecewise kind's two memories: the PROM of first codes, the segment ROM of scales and
// coefficients.
void piecewiseLayout(const PromTable& t, Provenance& p) {
  const SpecUnitParams& u = t.unit;
  p.segments = u.Segments;
  if (p.part == RomPart::Prom) {
    const int cw = u.CosFracBits + 1;
    for (int j = u.Segments - 1; j >= 0; --j)
      p.layout.push_back({j == 0 ? "B_0 (cut)" : fmt::format("B_{}", j), p.cos_format, (j + 1) * cw - 1, j * cw});
    return;
  }
  p.word_bits = u.segWordBits();
  p.depth = u.segDepth();
  p.used *= static_cast<size_t>(u.Segments);
  const int eb = u.segScaleBits(), kw = u.coefFormat().width();
  for (int j = u.Degree; j >= 0; --j)
    p.layout.push_back({fmt::format("K_{}", j), p.coef_format, eb + (j + 1) * kw - 1, eb + j * kw});
  p.layout.push_back({"e", fmt::format("u{}.0", eb), eb - 1, 0});
}

Provenance provenanceOf(const PromTable& t, RomPart part) {
  const SpecUnitParams& u = t.unit;
  Provenance p;
  p.tool = std::string("shadesim ") + SHD_VERSION;
  p.fit = toString(t.request.fit);
  p.degree = u.Degree;
  p.level = t.request.level;
  p.level_used = t.request.fit == FitKind::Level;
  p.n_text = t.request.n.text;
  p.n_is_list = t.request.n.is_list;
  p.n_count = t.request.n.values.size();
  p.coef_format = u.coefFormat().str();
  p.coef_round = toString(t.request.coef_round);
  p.cos_format = u.cosFormat().str();
  p.word_bits = u.promWordBits();
  p.depth = u.promDepth();
  p.shin_bits = u.ShinBits;
  p.cos_frac_bits = u.CosFracBits;
  p.kind = u.kind();
  p.spec_format = u.specFormat().str();
  const int cw = u.coefFormat().width();
  p.used = t.entries.size();
  p.table_bits = u.TableBits;
  p.part = part;
  if (part == RomPart::Segments && p.kind != SpecKind::Piecewise)
    throw std::invalid_argument(fmt::format("the {} kind has no segment ROM", specKindInfo(p.kind).name));
  if (p.kind == SpecKind::Piecewise) {
    piecewiseLayout(t, p);
  } else if (p.kind == SpecKind::Table) {
    p.used <<= u.TableBits;
    p.layout.push_back({"f = c^n", p.spec_format, u.SpecFracBits, 0});
  } else if (p.kind == SpecKind::Schlick) {
    p.layout.push_back({"m = n-1", p.coef_format, cw - 1, 0});
  } else if (p.kind == SpecKind::ExpLog) {
    p.layout.push_back({"n", p.coef_format, cw - 1, 0});
  } else if (u.Degree == 2) {
    p.layout.push_back({"a", p.coef_format, cw - 1, 0});
  } else {
    p.layout.push_back({"cut", p.cos_format, 2 * cw + u.CosFracBits, 2 * cw});
    p.layout.push_back({"v = a1+b1", p.coef_format, 2 * cw - 1, cw});
    p.layout.push_back({"a1", p.coef_format, cw - 1, 0});
  }
  return p;
}

std::string layoutText(const Provenance& p) {
  std::string s = "{";
  for (size_t i = 0; i < p.layout.size(); ++i) {
    const Field& f = p.layout[i];
    s += fmt::format("{}{} {} [{}:{}]", i ? ", " : "", f.name, f.format, f.msb, f.lsb);
  }
  return s + "}";
}

// The lines of the table, schlick and explog kinds after the first.
std::vector<std::string> altProvenanceLines(const Provenance& p, std::vector<std::string> l) {
  const bool table = p.kind == SpecKind::Table;
  l.push_back(fmt::format("kind: {}, fit: {}", specKindInfo(p.kind).name, p.fit));
  l.push_back(fmt::format("n: {} '{}', {} codes; {} i holds the i-th n{}", p.n_is_list ? "list" : "range",
                          p.n_text, p.n_count,
                          table ? "row"
                          : p.part == RomPart::Segments ? fmt::format("addresses i*{0}..i*{0}+{1}", p.segments, p.segments - 1)
                                                        : "address",
                          p.n_is_list ? " of the list (address map: <file>.map.csv)" : ""));
  if (table)
    l.push_back(fmt::format("content: row i is addresses i*{0}..i*{0}+{1}, word k the minimax value of c^n over the "
                            "cos codes c ({2}) with min(c >> {3}, {1}) = k, round-half-even to {4}",
                            1 << p.table_bits, (1 << p.table_bits) - 1, p.cos_format,
                            p.cos_frac_bits - p.table_bits, p.spec_format));
  else if (p.kind == SpecKind::Schlick)
    l.push_back(fmt::format("content: m = n - 1 {}, {}; f = c / (m (1 - c) + 1); cos: {}", p.coef_format,
                            p.coef_round, p.cos_format));
  else if (p.kind == SpecKind::Piecewise && p.part == RomPart::Prom)
    l.push_back(fmt::format("content: the first cos codes ({}) of the {} segments of degree {}, B_0 the cut (f = 0 "
                            "below); the segment ROM <file>{} holds each segment's scale and coefficients",
                            p.cos_format, p.segments, p.degree, kSegRomSuffix));
  else if (p.kind == SpecKind::Piecewise)
    l.push_back(fmt::format("content: segment ROM of the PROM <file> (without {}): address i*{} + s holds segment s "
                            "of the i-th n: the scale e and K_j {} (round-half-even), f = sum K_j u^j, u = (c - B_s) "
                            "2^e / 2^{}",
                            kSegRomSuffix, p.segments, p.coef_format, p.cos_frac_bits));
  else
    l.push_back(fmt::format("content: n {}, {}; f = 2^(n log2 c) by the unit's fixed log and exp tables (2^{} "
                            "intervals each); cos: {}",
                            p.coef_format, p.coef_round, p.table_bits, p.cos_format));
  l.push_back(fmt::format("word: {} bits = {} (MSB to LSB)", p.word_bits, layoutText(p)));
  l.push_back(fmt::format("depth: {} words, addresses 0..{} hold the {} codes", p.depth, p.used - 1, p.n_count));
  if (p.used < static_cast<size_t>(p.depth))
    l.push_back(fmt::format("padding: addresses {}..{} are unused and hold the all-zero word ({})", p.used,
                            p.depth - 1,
                            table                                ? "f = 0"
                            : p.kind == SpecKind::Schlick        ? "m = 0: f = c"
                            : p.kind == SpecKind::Piecewise ? "every B = 0 and K = 0: f = 0"
                                                                 : "n = 0: f = 1 above c = 0"));
  else
    l.push_back("padding: none, every address holds a code");
  return l;
}

// The provenance as comment lines without the comment marker.
std::vector<std::string> provenanceLines(const Provenance& p) {
  std::vector<std::string> l;
  l.push_back(p.part == RomPart::Segments
                  ? fmt::format("{}: piecewise specular unit segment ROM (rtl/shd_spec_piecewise.v)", p.tool)
                  : fmt::format("{}: specular unit coefficient PROM (rtl/shd_coef_rom.v)", p.tool));
  if (p.kind != SpecKind::Poly) return altProvenanceLines(p, l);
  l.push_back(fmt::format("fit: {}, degree {}, level {}{}", p.fit, p.degree, p.level,
                          p.level_used ? "" : " (not used by this fit)"));
  l.push_back(fmt::format("n: {} '{}', {} codes; address i holds the i-th n{}",
                          p.n_is_list ? "list" : "range", p.n_text, p.n_count,
                          p.n_is_list ? " of the list (address map: <file>.map.csv)" : ""));
  if (p.degree == 2) {
    l.push_back(fmt::format("coefficient: a {}, {}; cos: {}", p.coef_format, p.coef_round,
                            p.cos_format));
  } else {
    l.push_back(fmt::format(
        "coefficients: a1 and v = a1+b1 {}, {}; cos and cut: {}, cut code = ceil(cut * 2^{})",
        p.coef_format, p.coef_round, p.cos_format, p.cos_frac_bits));
  }
  l.push_back(fmt::format("word: {} bits = {} (MSB to LSB)", p.word_bits, layoutText(p)));
  l.push_back(fmt::format("depth: {} words (ShinBits = {}), addresses 0..{} hold the {} codes",
                          p.depth, p.shin_bits, p.used - 1, p.used));
  if (p.used < static_cast<size_t>(p.depth)) {
    l.push_back(fmt::format(
        "padding: addresses {}..{} are unused and hold the all-zero word ({}: f = c)", p.used,
        p.depth - 1, p.degree == 2 ? "a = 0" : "a1 = v = 0, no cut"));
  } else {
    l.push_back("padding: none, every address holds a code");
  }
  return l;
}

// A comment line must stay one line and, in a MIF, must not open a % block comment.
std::string commentBlock(const Provenance& p, std::string_view marker) {
  std::string out;
  for (std::string line : provenanceLines(p)) {
    for (char& ch : line)
      if (ch == '\n' || ch == '\r' || (marker == "--" && ch == '%')) ch = ' ';
    out += fmt::format("{} {}\n", marker, line);
  }
  return out;
}

void checkTable(const PromTable& t) {
  const size_t depth = static_cast<size_t>(t.unit.promDepth());
  if (t.words.size() != depth)
    throw std::invalid_argument(fmt::format("PROM table holds {} words, the unit addresses {}",
                                            t.words.size(), depth));
  if (t.seg_words.size() != static_cast<size_t>(t.unit.segDepth()))
    throw std::invalid_argument(fmt::format("segment ROM holds {} words, the unit addresses {}",
                                            t.seg_words.size(), t.unit.segDepth()));
  if (t.entries.empty())
    throw std::invalid_argument("PROM table has no entries");
  // hexWord checks each word's width when the data is rendered.
}

std::string csvTable(const PromTable& t) {
  std::string out;
  if (t.unit.kind() == SpecKind::Table) {
    out += "n,address,bucket,value_real,value_code\n";
    for (const PromEntry& e : t.entries)
      for (size_t k = 0; k < e.approx.table.size(); ++k) {
        const size_t a = (static_cast<size_t>(e.address) << t.unit.TableBits) | k;
        out += fmt::format("{},{},{},{},{}\n", real17(e.n), a, k, real17(e.approx.table[k]),
                           decodePromWord(t.words[a], t.unit).u);
      }
  } else if (t.unit.kind() == SpecKind::Piecewise) {
    const SpecUnitParams& u = t.unit;
    out += "n,address,segment,segment_address,first_code,scale";
    for (int j = 0; j <= u.Degree; ++j) out += fmt::format(",K{}_code", j);
    out += ",a_real,b_real\n";
    for (const PromEntry& e : t.entries) {
      const size_t base = static_cast<size_t>(e.address) * static_cast<size_t>(u.Segments);
      const PiecewiseCodes q = decodePiecewise(t.words[e.address], &t.seg_words[base], u);
      const auto& fit = e.approx.pieces->segments;  // from the top down; q.segs ascending
      for (size_t s = 0; s < fit.size(); ++s) {
        const PiecewiseCodes::Seg& g = q.segs[s];
        const SegmentFit& r = fit[fit.size() - 1 - s];
        out += fmt::format("{},{},{},{},{},{}", real17(e.n), e.address, s, base + s, g.B, g.e);
        for (int64_t k : g.K) out += fmt::format(",{}", k);
        out += fmt::format(",{},{}\n", real17(r.a), real17(r.b));
      }
    }
  } else if (t.unit.kind() != SpecKind::Poly) {  // schlick, explog: one code per n
    out += t.unit.kind() == SpecKind::Schlick ? "n,address,m_real,m_code\n" : "n,address,n_real,n_code\n";
    for (const PromEntry& e : t.entries)
      out += fmt::format("{},{},{},{}\n", real17(e.n), e.address, real17(e.u_real), e.code.u);
  } else if (t.unit.Degree == 2) {
    out += "n,address,a_real,a_code\n";
    for (const PromEntry& e : t.entries)
      out += fmt::format("{},{},{},{}\n", real17(e.n), e.address, real17(e.u_real), e.code.u);
  } else {
    out += "n,address,a1_real,a1_code,v_real,v_code,cut_real,cut_code\n";
    for (const PromEntry& e : t.entries)
      out += fmt::format("{},{},{},{},{},{},{},{}\n", real17(e.n), e.address, real17(e.u_real),
                         e.code.u, real17(e.v_real), e.code.v, real17(e.cut_real), e.code.cut);
  }
  return out;
}

bool isHexDigit(char c) {
  return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'f') || (c >= 'A' && c <= 'F');
}

int hexValue(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  return c - 'A' + 10;
}

std::string errnoText(int err) { return std::strerror(err); }

}  // namespace

PromFormat parsePromFormat(std::string_view s) {
  if (s == "hex") return PromFormat::Hex;
  if (s == "mem") return PromFormat::Mem;
  if (s == "coe") return PromFormat::Coe;
  if (s == "mif") return PromFormat::Mif;
  if (s == "csv") return PromFormat::Csv;
  throw std::invalid_argument(
      fmt::format("unknown PROM format '{}' (expected hex, mem, coe, mif or csv)", s));
}

const char* toString(PromFormat f) {
  switch (f) {
    case PromFormat::Hex: return "hex";
    case PromFormat::Mem: return "mem";
    case PromFormat::Coe: return "coe";
    case PromFormat::Mif: return "mif";
    case PromFormat::Csv: return "csv";
  }
  return "?";
}

std::string hexWord(PromWord w, int bits) {
  if (bits < 1 || bits > 128)
    throw std::invalid_argument(fmt::format("hexWord: width {} outside 1..128", bits));
  if (bits < 128 && (w >> bits) != 0)
    throw std::invalid_argument(fmt::format("hexWord: word has bits above the {}-bit width", bits));
  static constexpr char kDigits[] = "0123456789abcdef";
  const int digits = (bits + 3) / 4;
  std::string s(static_cast<size_t>(digits), '0');
  for (int i = digits - 1; i >= 0; --i) {
    s[static_cast<size_t>(i)] = kDigits[static_cast<unsigned>(w & 0xf)];
    w >>= 4;
  }
  return s;
}

std::string renderProm(const PromTable& t, PromFormat f, RomPart part) {
  checkTable(t);
  const Provenance p = provenanceOf(t, part);
  const std::vector<PromWord>& words = part == RomPart::Prom ? t.words : t.seg_words;
  const int bits = p.word_bits;
  std::string out;
  switch (f) {
    case PromFormat::Hex:
      out += commentBlock(p, "//");
      out += fmt::format("// $readmemh: {} words of {} hex digits follow, address 0 first\n",
                         p.depth, (bits + 3) / 4);
      for (PromWord w : words) out += hexWord(w, bits) + "\n";
      break;
    case PromFormat::Mem:
      if (p.depth > kLatticeMaxDepth || bits > kLatticeMaxWidth)
        throw std::invalid_argument(fmt::format(
            "Lattice .mem allows depth <= {} and width <= {}; this PROM is {} x {}",
            kLatticeMaxDepth, kLatticeMaxWidth, p.depth, bits));
      // The header admits no comments (srec_mem(5)); radix index 3 = hexadecimal.
      out += fmt::format("#Format=Hex\n#Depth={}\n#Width={}\n#AddrRadix=3\n#DataRadix=3\n#Data\n",
                         p.depth, bits);
      out += commentBlock(p, "//");
      for (PromWord w : words) out += hexWord(w, bits) + "\n";
      break;
    case PromFormat::Coe:
      out += commentBlock(p, ";");
      out += "memory_initialization_radix=16;\nmemory_initialization_vector=\n";
      for (size_t i = 0; i < words.size(); ++i)
        out += hexWord(words[i], bits) + (i + 1 < words.size() ? ",\n" : ";\n");
      break;
    case PromFormat::Mif:
      out += commentBlock(p, "--");
      out += fmt::format("WIDTH={};\nDEPTH={};\nADDRESS_RADIX=UNS;\nDATA_RADIX=HEX;\n\nCONTENT BEGIN\n",
                         bits, p.depth);
      for (size_t i = 0; i < words.size(); ++i)
        out += fmt::format("  {} : {};\n", i, hexWord(words[i], bits));
      out += "END;\n";
      break;
    case PromFormat::Csv:
      if (part == RomPart::Segments)
        throw std::invalid_argument("the csv table holds the segment ROM's contents with the PROM's (one file)");
      out += csvTable(t);
      break;
  }
  return out;
}

PromFiles renderPromFiles(const PromTable& t, PromFormat f) {
  PromFiles files = {{"", renderProm(t, f)}};
  if (t.unit.segDepth() > 0 && f != PromFormat::Csv)
    files.emplace_back(kSegRomSuffix, renderProm(t, f, RomPart::Segments));
  return files;
}

void writePromHexFiles(const std::string& path, const PromTable& t) {
  OutputFiles out;
  for (const auto& [suffix, text] : renderPromFiles(t, PromFormat::Hex)) out.add(path + suffix, text);
  out.commit();
}

std::string renderAddressMap(const PromTable& t) {
  std::string out = "address,n\n";
  for (const PromEntry& e : t.entries) out += fmt::format("{},{}\n", e.address, real17(e.n));
  return out;
}

std::string renderProvenanceJson(const PromTable& t) {
  checkTable(t);
  const Provenance p = provenanceOf(t, RomPart::Prom);
  nlohmann::ordered_json j;
  j["tool"] = p.tool;
  j["content"] = "specular unit coefficient PROM";
  j["kind"] = specKindInfo(p.kind).name;
  j["fit"] = p.fit;
  j["degree"] = p.degree;
  j["level"] = p.level;
  j["level_used"] = p.level_used;
  j["n"] = {{"spec", p.n_text}, {"is_list", p.n_is_list}, {"count", p.n_count}};
  j["coef_format"] = p.coef_format;
  j["coef_round"] = p.coef_round;
  j["cos_format"] = p.cos_format;
  if (p.degree == 3) j["cut_code"] = fmt::format("ceil(cut * 2^{})", p.cos_frac_bits);
  j["word_bits"] = p.word_bits;
  j["depth"] = p.depth;
  const auto layoutJson = [](const Provenance& q) {
    nlohmann::ordered_json layout = nlohmann::ordered_json::array();
    for (const Field& f : q.layout)
      layout.push_back({{"field", f.name}, {"format", f.format}, {"msb", f.msb}, {"lsb", f.lsb}});
    return layout;
  };
  j["layout_msb_first"] = layoutJson(p);
  if (p.kind == SpecKind::Piecewise) {
    const Provenance s = provenanceOf(t, RomPart::Segments);
    j["segment_rom"] = {{"file", std::string("<file>") + kSegRomSuffix},
                        {"address", fmt::format("i*{} + s", s.segments)},
                        {"word_bits", s.word_bits},
                        {"depth", s.depth},
                        {"layout_msb_first", layoutJson(s)}};
  }
  j["used_addresses"] = {0, p.used - 1};
  if (p.used < static_cast<size_t>(p.depth))
    j["padding"] = {{"first", p.used}, {"last", p.depth - 1}, {"word", "all-zero"}};
  else
    j["padding"] = nullptr;
  nlohmann::ordered_json rtl;
  const nlohmann::json params = t.unit.toJson();  // std::map order: alphabetical, deterministic
  for (const auto& [key, value] : params.items()) rtl[key] = value;
  j["rtl"] = rtl;
  return j.dump(2) + "\n";
}

std::vector<PromWord> readPromHex(const std::string& path, int word_bits, int depth) {
  if (word_bits < 1 || word_bits > 128)
    throw std::invalid_argument(fmt::format("readPromHex: word width {} outside 1..128", word_bits));
  if (depth < 1) throw std::invalid_argument(fmt::format("readPromHex: depth {} below 1", depth));

  // A hex file of the widest table: 2^16 words of 32 digits and a newline, with room for comments.
  constexpr uint64_t kMaxPromFileBytes = uint64_t{16} << 20;
  if (const std::string why = inputFileProblem(path, kMaxPromFileBytes); !why.empty())
    throw std::runtime_error(fmt::format("cannot read PROM file {}: {}", path, why));
  std::ifstream in(path);
  if (!in) throw std::runtime_error(fmt::format("cannot open PROM file {}: {}", path, errnoText(errno)));
  noteInput(path);

  auto lineError = [&](long line, const std::string& what) {
    return std::runtime_error(fmt::format("PROM file {}, line {}: {}", path, line, what));
  };

  std::vector<PromWord> words;
  words.reserve(static_cast<size_t>(depth));
  std::string line;
  long line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    const size_t comment = line.find("//");
    if (comment != std::string::npos) line.resize(comment);
    size_t pos = 0;
    for (;;) {
      // Whitespace as $readmemh defines it: space, tab, newline (a CR of a CRLF file), form-feed.
      pos = line.find_first_not_of(" \t\r\f\v", pos);
      if (pos == std::string::npos) break;
      const size_t end = std::min(line.find_first_of(" \t\r\f\v", pos), line.size());
      const std::string tok = line.substr(pos, end - pos);
      pos = end;

      if (tok[0] == '@')
        throw lineError(line_no, fmt::format("address directive '{}' is not supported (the file "
                                             "must list every word from address 0)", tok));
      for (char c : tok)
        if (!isHexDigit(c)) throw lineError(line_no, fmt::format("'{}' is not a hex word", tok));
      if (words.size() == static_cast<size_t>(depth))
        throw lineError(line_no, fmt::format("word '{}' is beyond the {} words the unit addresses",
                                             tok, depth));

      const size_t first = std::min(tok.find_first_not_of('0'), tok.size());
      const std::string sig = tok.substr(first);  // significant digits
      const auto tooWide = [&] {
        return lineError(line_no, fmt::format("word 0x{} has bits above the {}-bit width",
                                              sig, word_bits));
      };
      if (sig.size() > 32) throw tooWide();
      PromWord w = 0;
      for (char c : sig) w = (w << 4) | static_cast<PromWord>(hexValue(c));
      if (word_bits < 128 && (w >> word_bits) != 0) throw tooWide();
      words.push_back(w);
    }
  }
  if (in.bad())
    throw std::runtime_error(fmt::format("cannot read PROM file {}: {}", path, errnoText(errno)));
  if (words.size() != static_cast<size_t>(depth))
    throw std::runtime_error(fmt::format("PROM file {} holds {} words, the unit addresses {} "
                                         "(file ends at line {})",
                                         path, words.size(), depth, line_no));
  return words;
}

RomImage readPromHexFiles(const std::string& path, const SpecUnitParams& p) {
  RomImage r;
  r.prom = readPromHex(path, p.promWordBits(), p.promDepth());
  if (p.segDepth() > 0) r.seg = readPromHex(path + kSegRomSuffix, p.segWordBits(), p.segDepth());
  return r;
}

std::string romImageDiff(const RomImage& got, const RomImage& want, const SpecUnitParams& p) {
  const auto diff = [](const char* what, const std::vector<PromWord>& g, const std::vector<PromWord>& w,
                       int bits) -> std::string {
    if (g.size() != w.size()) return fmt::format("{} has {} words, expected {}", what, g.size(), w.size());
    for (size_t i = 0; i < g.size(); ++i)
      if (g[i] != w[i])
        return fmt::format("{} word {} is 0x{}, expected 0x{}", what, i, hexWord(g[i], bits), hexWord(w[i], bits));
    return "";
  };
  std::string d = diff("PROM", got.prom, want.prom, p.promWordBits());
  if (d.empty() && p.segDepth() > 0) d = diff("segment ROM", got.seg, want.seg, p.segWordBits());
  return d;
}

}  // namespace shd
