// PROM files: every format carries exactly the table's words (parsed back by small independent
// readers here), the strict hex reader rejects each kind of broken file with its line number,
// writes are atomic, and output is a pure function of the table.
#include "device/prom_io.h"

#include <gtest/gtest.h>

#include "test_util.h"
#include "io/files.h"
#include <nlohmann/json.hpp>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using shd::PromFormat;
using shd::PromTable;
using shd::PromWord;

namespace {

constexpr PromFormat kAllFormats[] = {PromFormat::Hex, PromFormat::Mem, PromFormat::Coe,
                                      PromFormat::Mif, PromFormat::Csv};

// Degree 2: 6 codes n = 1..6 in an 8-word PROM (2 padding words), uQ10.14, 24-bit words.
PromTable degree2Table() {
  shd::SpecUnitParams u;
  u.ShinBits = 3;
  shd::PromRequest r;
  r.n = shd::NSpec::parse("1:6", false);
  return shd::buildPromTable(r, u);
}

// Degree 3: n list 8, 32, 200 in an 8-word PROM, sQ16.12 coefficients, 72-bit words (wider
// than 64 bits, so the 128-bit paths are exercised).
PromTable degree3Table() {
  shd::SpecUnitParams u;
  u.Degree = 3;
  u.CoefIntBits = 16;
  u.CoefFracBits = 12;
  u.HornerFracBits = 12;
  u.DiffFracBits = 24;
  u.ShinBits = 3;
  shd::PromRequest r;
  r.n = shd::NSpec::parse("8,32,200", true);
  return shd::buildPromTable(r, u);
}

std::vector<PromTable> tables() { return {degree2Table(), degree3Table()}; }

std::vector<std::string> lines(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  std::string l;
  while (std::getline(in, l)) out.push_back(l);
  return out;
}

bool startsWith(const std::string& s, const std::string& prefix) {
  return s.compare(0, prefix.size(), prefix) == 0;
}

std::string trim(const std::string& s) {
  const size_t b = s.find_first_not_of(" \t");
  if (b == std::string::npos) return "";
  const size_t e = s.find_last_not_of(" \t");
  return s.substr(b, e - b + 1);
}

// Independent hex parse (not prom_io's): up to 32 digits into 128 bits.
PromWord parseHex(const std::string& s) {
  EXPECT_FALSE(s.empty());
  EXPECT_LE(s.size(), 32u) << s;
  PromWord w = 0;
  for (char c : s) {
    int d = -1;
    if (c >= '0' && c <= '9') d = c - '0';
    if (c >= 'a' && c <= 'f') d = c - 'a' + 10;
    EXPECT_GE(d, 0) << "'" << s << "' is not lowercase hex";
    w = (w << 4) | static_cast<PromWord>(d);
  }
  return w;
}

// Data lines of a hex or mem file: neither a comment nor a header line nor blank.
std::vector<std::string> dataLines(const std::string& text) {
  std::vector<std::string> out;
  for (const std::string& l : lines(text))
    if (!l.empty() && !startsWith(l, "//") && !startsWith(l, "#")) out.push_back(l);
  return out;
}

// Xilinx COE: ';' comment lines, radix line, then the vector: words separated by ',' up to ';'.
std::vector<PromWord> parseCoe(const std::string& text) {
  std::string body;
  bool radix = false, vector = false;
  for (const std::string& l : lines(text)) {
    if (startsWith(l, ";")) continue;
    if (l == "memory_initialization_radix=16;") {
      radix = true;
      continue;
    }
    if (l == "memory_initialization_vector=") {
      vector = true;
      continue;
    }
    EXPECT_TRUE(vector) << "data before the vector keyword: " << l;
    body += l;
  }
  EXPECT_TRUE(radix);
  EXPECT_TRUE(vector);
  EXPECT_FALSE(body.empty());
  EXPECT_EQ(body.back(), ';');
  EXPECT_EQ(body.find(';'), body.size() - 1) << "';' before the last word";
  body.pop_back();
  std::vector<PromWord> words;
  std::istringstream in(body);
  std::string tok;
  while (std::getline(in, tok, ',')) words.push_back(parseHex(trim(tok)));
  return words;
}

// Intel MIF: '--' comments, WIDTH/DEPTH/radices, CONTENT BEGIN, "addr : word;" lines, END;
std::vector<PromWord> parseMif(const std::string& text, int width, int depth) {
  bool in_content = false, ended = false;
  bool has_width = false, has_depth = false, has_arad = false, has_drad = false;
  std::vector<PromWord> words(static_cast<size_t>(depth), PromWord{0});
  std::vector<bool> seen(static_cast<size_t>(depth), false);
  for (const std::string& raw : lines(text)) {
    const std::string l = trim(raw);
    if (l.empty() || startsWith(l, "--")) continue;
    EXPECT_EQ(l.find('%'), std::string::npos) << "a % would open a MIF block comment: " << l;
    if (!in_content) {
      if (l == "WIDTH=" + std::to_string(width) + ";") has_width = true;
      else if (l == "DEPTH=" + std::to_string(depth) + ";") has_depth = true;
      else if (l == "ADDRESS_RADIX=UNS;") has_arad = true;
      else if (l == "DATA_RADIX=HEX;") has_drad = true;
      else if (l == "CONTENT BEGIN") in_content = true;
      else ADD_FAILURE() << "unexpected MIF header line: " << l;
      continue;
    }
    if (l == "END;") {
      ended = true;
      in_content = false;
      continue;
    }
    const size_t colon = l.find(" : ");
    EXPECT_NE(colon, std::string::npos) << l;
    EXPECT_EQ(l.back(), ';') << l;
    const int addr = std::stoi(l.substr(0, colon));
    EXPECT_TRUE(addr >= 0 && addr < depth) << l;
    EXPECT_FALSE(seen[static_cast<size_t>(addr)]) << "address twice: " << l;
    seen[static_cast<size_t>(addr)] = true;
    words[static_cast<size_t>(addr)] = parseHex(l.substr(colon + 3, l.size() - colon - 4));
  }
  EXPECT_TRUE(has_width && has_depth && has_arad && has_drad);
  EXPECT_TRUE(ended);
  for (int a = 0; a < depth; ++a) EXPECT_TRUE(seen[static_cast<size_t>(a)]) << "address " << a;
  return words;
}

std::vector<std::string> splitCsv(const std::string& l) {
  std::vector<std::string> out;
  std::istringstream in(l);
  std::string tok;
  while (std::getline(in, tok, ',')) out.push_back(tok);
  return out;
}

void writePlain(const fs::path& p, const std::string& text) {
  std::ofstream(p) << text;
}

std::string readAll(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// The error message of f(), or "" if it does not throw std::runtime_error.
template <typename F>
std::string runtimeError(F f) {
  try {
    f();
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(PromFormat, ParsesEveryNameAndRejectsOthers) {
  for (PromFormat f : kAllFormats) EXPECT_EQ(shd::parsePromFormat(shd::toString(f)), f);
  try {
    shd::parsePromFormat("bin");
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "unknown PROM format 'bin' (expected hex, mem, coe, mif or csv)");
  }
}

TEST(HexWord, ZeroPaddedLowercaseOfCeilBitsOver4Digits) {
  EXPECT_EQ(shd::hexWord(0xabc, 24), "000abc");
  EXPECT_EQ(shd::hexWord(0x1, 1), "1");
  EXPECT_EQ(shd::hexWord(0x1f, 5), "1f");
  EXPECT_EQ(shd::hexWord(0, 72), std::string(18, '0'));
  const PromWord all = ~PromWord{0};
  EXPECT_EQ(shd::hexWord(all, 128), std::string(32, 'f'));
  EXPECT_EQ(shd::hexWord(all >> 56, 72), std::string(18, 'f'));
  EXPECT_THROW(shd::hexWord(0x20, 5), std::invalid_argument);
  EXPECT_THROW(shd::hexWord(0, 0), std::invalid_argument);
  EXPECT_THROW(shd::hexWord(0, 129), std::invalid_argument);
}

TEST(PromTables, FixtureShapes) {
  const PromTable d2 = degree2Table(), d3 = degree3Table();
  EXPECT_EQ(d2.words.size(), 8u);
  EXPECT_EQ(d2.entries.size(), 6u);
  EXPECT_EQ(d2.unit.promWordBits(), 24);
  EXPECT_EQ(d3.words.size(), 8u);
  EXPECT_EQ(d3.entries.size(), 3u);
  EXPECT_EQ(d3.unit.promWordBits(), 72);
  // The degree 3 words use bits above 64 (the cut field) for the high-n entries.
  bool high = false;
  for (PromWord w : d3.words) high = high || (w >> 64) != 0;
  EXPECT_TRUE(high);
}

TEST(PromHex, RoundTripsThroughReader) {
  const fs::path dir = shd::testutil::freshTestDir("test_prom_io");
  for (const PromTable& t : tables()) {
    const std::string text = shd::renderProm(t, PromFormat::Hex);
    const std::vector<std::string> data = dataLines(text);
    ASSERT_EQ(data.size(), t.words.size());
    for (size_t i = 0; i < data.size(); ++i) {
      EXPECT_EQ(data[i].size(), static_cast<size_t>((t.unit.promWordBits() + 3) / 4));
      EXPECT_EQ(parseHex(data[i]), t.words[i]) << "address " << i;
    }
    // Every other line is a // comment; the data is the tail; the file ends in a newline.
    const std::vector<std::string> all = lines(text);
    const size_t comments = all.size() - data.size();
    for (size_t i = 0; i < all.size(); ++i)
      EXPECT_EQ(startsWith(all[i], "//"), i < comments) << all[i];
    EXPECT_EQ(text.back(), '\n');
    const fs::path p = dir / ("degree" + std::to_string(t.unit.Degree) + ".hex");
    shd::writeFileAtomic(p.string(), text);
    EXPECT_EQ(shd::readPromHex(p.string(), t.unit.promWordBits(), t.unit.promDepth()), t.words);
  }
}

TEST(PromHex, ProvenanceNamesEverything) {
  const std::string d2 = shd::renderProm(degree2Table(), PromFormat::Hex);
  EXPECT_TRUE(startsWith(d2, std::string("// shadesim ") + SHD_VERSION)) << d2;
  for (const char* s : {"fit: inflection, degree 2, level 0.5", "range '1:6', 6 codes",
                        "a uQ10.14, round-half-even", "cos: uQ1.15", "word: 24 bits = {a uQ10.14 [23:0]}",
                        "depth: 8 words (ShinBits = 3)", "addresses 6..7 are unused and hold the all-zero word"})
    EXPECT_NE(d2.find(s), std::string::npos) << s << "\n" << d2;
  const std::string d3 = shd::renderProm(degree3Table(), PromFormat::Hex);
  for (const char* s : {"degree 3", "list '8,32,200', 3 codes", "sQ16.12, round-half-even",
                        "ceil(cut * 2^15)",
                        "72 bits = {cut uQ1.15 [71:56], v = a1+b1 sQ16.12 [55:28], a1 sQ16.12 [27:0]} (MSB to LSB)",
                        "addresses 3..7 are unused"})
    EXPECT_NE(d3.find(s), std::string::npos) << s << "\n" << d3;
}

TEST(PromMem, LatticeHeaderThenWords) {
  for (const PromTable& t : tables()) {
    const std::string text = shd::renderProm(t, PromFormat::Mem);
    const std::vector<std::string> l = lines(text);
    ASSERT_GE(l.size(), 6u);
    // The header, exactly, with no comment inside it (srec_mem(5)).
    EXPECT_EQ(l[0], "#Format=Hex");
    EXPECT_EQ(l[1], "#Depth=" + std::to_string(t.unit.promDepth()));
    EXPECT_EQ(l[2], "#Width=" + std::to_string(t.unit.promWordBits()));
    EXPECT_EQ(l[3], "#AddrRadix=3");
    EXPECT_EQ(l[4], "#DataRadix=3");
    EXPECT_EQ(l[5], "#Data");
    for (size_t i = 6; i < l.size(); ++i) EXPECT_FALSE(startsWith(l[i], "#")) << l[i];
    const std::vector<std::string> data = dataLines(text);
    ASSERT_EQ(data.size(), t.words.size());
    for (size_t i = 0; i < data.size(); ++i) EXPECT_EQ(parseHex(data[i]), t.words[i]);
    EXPECT_NE(text.find("// shadesim"), std::string::npos);
  }
}

TEST(PromCoe, ParsesBackToTheWords) {
  for (const PromTable& t : tables()) {
    const std::string text = shd::renderProm(t, PromFormat::Coe);
    EXPECT_TRUE(startsWith(text, "; shadesim")) << text;
    EXPECT_NE(text.find("memory_initialization_radix=16;"), std::string::npos);
    EXPECT_NE(text.find("memory_initialization_vector="), std::string::npos);
    EXPECT_EQ(parseCoe(text), t.words);
  }
}

TEST(PromMif, ParsesBackToTheWords) {
  for (const PromTable& t : tables()) {
    const std::string text = shd::renderProm(t, PromFormat::Mif);
    EXPECT_TRUE(startsWith(text, "-- shadesim")) << text;
    for (const char* k : {"WIDTH=", "DEPTH=", "ADDRESS_RADIX=UNS;", "DATA_RADIX=HEX;",
                          "CONTENT BEGIN", "END;"})
      EXPECT_NE(text.find(k), std::string::npos) << k;
    EXPECT_EQ(parseMif(text, t.unit.promWordBits(), t.unit.promDepth()), t.words);
  }
}

TEST(PromCsv, OneRowPerEntryWithItsCodes) {
  for (const PromTable& t : tables()) {
    const std::vector<std::string> l = lines(shd::renderProm(t, PromFormat::Csv));
    ASSERT_EQ(l.size(), t.entries.size() + 1);
    const bool d3 = t.unit.Degree == 3;
    EXPECT_EQ(l[0], d3 ? "n,address,a1_real,a1_code,v_real,v_code,cut_real,cut_code"
                       : "n,address,a_real,a_code");
    for (size_t i = 0; i < t.entries.size(); ++i) {
      const shd::PromEntry& e = t.entries[i];
      const std::vector<std::string> f = splitCsv(l[i + 1]);
      ASSERT_EQ(f.size(), d3 ? 8u : 4u) << l[i + 1];
      EXPECT_EQ(std::stod(f[0]), e.n);
      EXPECT_EQ(std::stoul(f[1]), e.address);
      // 17 significant digits round-trip the double exactly.
      EXPECT_EQ(std::stod(f[2]), e.u_real);
      EXPECT_EQ(std::stoll(f[3]), e.code.u);
      if (d3) {
        EXPECT_EQ(std::stod(f[4]), e.v_real);
        EXPECT_EQ(std::stoll(f[5]), e.code.v);
        EXPECT_EQ(std::stod(f[6]), e.cut_real);
        EXPECT_EQ(std::stoll(f[7]), e.code.cut);
      }
    }
  }
}

TEST(PromCsv, ProvenanceSidecarIsJsonWithTheFacts) {
  const auto j = nlohmann::json::parse(shd::renderProvenanceJson(degree3Table()));
  EXPECT_EQ(j.at("tool"), std::string("shadesim ") + SHD_VERSION);
  EXPECT_EQ(j.at("fit"), "inflection");
  EXPECT_EQ(j.at("degree"), 3);
  EXPECT_EQ(j.at("n").at("spec"), "8,32,200");
  EXPECT_EQ(j.at("n").at("count"), 3);
  EXPECT_EQ(j.at("coef_format"), "sQ16.12");
  EXPECT_EQ(j.at("coef_round"), "round-half-even");
  EXPECT_EQ(j.at("cos_format"), "uQ1.15");
  EXPECT_EQ(j.at("word_bits"), 72);
  EXPECT_EQ(j.at("depth"), 8);
  EXPECT_EQ(j.at("layout_msb_first").size(), 3u);
  EXPECT_EQ(j.at("padding").at("first"), 3);
  EXPECT_EQ(j.at("padding").at("last"), 7);
  EXPECT_EQ(j.at("rtl").at("CoefIntBits"), 16);
}

TEST(PromAddressMap, OneRowPerEntry) {
  const PromTable t = degree3Table();
  EXPECT_EQ(shd::renderAddressMap(t), "address,n\n0,8\n1,32\n2,200\n");
}

TEST(PromRender, DeterministicAcrossRendersAndBuilds) {
  for (PromFormat f : kAllFormats) {
    EXPECT_EQ(shd::renderProm(degree2Table(), f), shd::renderProm(degree2Table(), f)) << toString(f);
    const PromTable t = degree3Table();
    EXPECT_EQ(shd::renderProm(t, f), shd::renderProm(t, f)) << toString(f);
  }
  EXPECT_EQ(shd::renderProvenanceJson(degree2Table()), shd::renderProvenanceJson(degree2Table()));
}

TEST(PromRender, RejectsATableOfTheWrongDepth) {
  PromTable t = degree2Table();
  t.words.pop_back();
  EXPECT_THROW(shd::renderProm(t, PromFormat::Hex), std::invalid_argument);
}

TEST(PromHexReader, RejectsBrokenFilesNamingTheLine) {
  const fs::path dir = shd::testutil::freshTestDir("test_prom_io");
  const PromTable t = degree2Table();  // 8 words of 24 bits
  const std::string good = shd::renderProm(t, PromFormat::Hex);
  const int header = static_cast<int>(lines(good).size()) - 8;  // comment lines before the data
  const auto read = [&](const fs::path& p) {
    return runtimeError([&] { shd::readPromHex(p.string(), 24, 8); });
  };

  // Missing file.
  std::string e = read(dir / "missing.hex");
  EXPECT_NE(e.find("cannot read PROM file"), std::string::npos) << e;
  EXPECT_NE(e.find("no such file"), std::string::npos) << e;
  EXPECT_NE(e.find("missing.hex"), std::string::npos) << e;

  // Short: the last word dropped.
  std::string shortText = good.substr(0, good.size() - 7);
  writePlain(dir / "short.hex", shortText);
  e = read(dir / "short.hex");
  EXPECT_NE(e.find("holds 7 words, the unit addresses 8"), std::string::npos) << e;
  EXPECT_NE(e.find("line " + std::to_string(header + 7)), std::string::npos) << e;

  // Long: one word too many.
  writePlain(dir / "long.hex", good + "000001\n");
  e = read(dir / "long.hex");
  EXPECT_NE(e.find("line " + std::to_string(header + 9) + ":"), std::string::npos) << e;
  EXPECT_NE(e.find("beyond the 8 words"), std::string::npos) << e;

  // Corrupt token on data line 3.
  std::vector<std::string> l = lines(good);
  auto withLine = [&](int data_index, const std::string& repl) {
    std::vector<std::string> m = l;
    m[static_cast<size_t>(header + data_index)] = repl;
    std::string s;
    for (const std::string& x : m) s += x + "\n";
    return s;
  };
  writePlain(dir / "corrupt.hex", withLine(2, "zz12"));
  e = read(dir / "corrupt.hex");
  EXPECT_NE(e.find("line " + std::to_string(header + 3) + ": 'zz12' is not a hex word"),
            std::string::npos) << e;

  // X/Z digits and underscores are not accepted either.
  writePlain(dir / "x.hex", withLine(0, "00x000"));
  EXPECT_NE(read(dir / "x.hex").find("'00x000' is not a hex word"), std::string::npos);
  writePlain(dir / "underscore.hex", withLine(0, "00_000"));
  EXPECT_NE(read(dir / "underscore.hex").find("is not a hex word"), std::string::npos);

  // An address directive.
  writePlain(dir / "at.hex", withLine(4, "@4"));
  e = read(dir / "at.hex");
  EXPECT_NE(e.find("line " + std::to_string(header + 5) + ": address directive '@4'"),
            std::string::npos) << e;

  // Too wide: 25 bits in a 24-bit word (leading zeros are fine, value is what counts).
  writePlain(dir / "wide.hex", withLine(4, "1ffffff"));
  e = read(dir / "wide.hex");
  EXPECT_NE(e.find("line " + std::to_string(header + 5) +
                   ": word 0x1ffffff has bits above the 24-bit width"),
            std::string::npos) << e;
  writePlain(dir / "zeros.hex", withLine(4, "0000ffffff"));
  EXPECT_EQ(read(dir / "zeros.hex"), "");

  // Beyond 128 bits entirely.
  writePlain(dir / "huge.hex", "1" + std::string(32, '0') + "\n");
  e = runtimeError([&] { shd::readPromHex((dir / "huge.hex").string(), 128, 1); });
  EXPECT_NE(e.find("line 1: word 0x1"), std::string::npos) << e;
  EXPECT_NE(e.find("above the 128-bit width"), std::string::npos) << e;
}

TEST(PromHexReader, AcceptsCommentsBlankLinesCrlfAndSeveralWordsPerLine) {
  const fs::path dir = shd::testutil::freshTestDir("test_prom_io");
  writePlain(dir / "loose.hex", "// a\r\n\r\n1 2 // two words\r\n\t3\r\nFF\r\n");
  const std::vector<PromWord> w = shd::readPromHex((dir / "loose.hex").string(), 8, 4);
  EXPECT_EQ(w, (std::vector<PromWord>{1, 2, 3, 0xff}));
}

TEST(WriteFileAtomic, WritesAndReplacesLeavingNoTemporary) {
  const fs::path dir = shd::testutil::freshTestDir("test_prom_io");
  const fs::path p = dir / "rom.hex";
  shd::writeFileAtomic(p.string(), "first\n");
  EXPECT_EQ(readAll(p), "first\n");
  shd::writeFileAtomic(p.string(), "second, longer content\n");
  EXPECT_EQ(readAll(p), "second, longer content\n");
  shd::writeFileAtomic((dir / "empty").string(), "");
  EXPECT_EQ(fs::file_size(dir / "empty"), 0u);
  std::vector<std::string> entries = shd::testutil::dirEntries(dir);
  std::sort(entries.begin(), entries.end());
  EXPECT_EQ(entries, (std::vector<std::string>{"empty", "rom.hex"}));
}

TEST(WriteFileAtomic, MissingDirectoryThrowsAndCreatesNothing) {
  const fs::path dir = shd::testutil::freshTestDir("test_prom_io");
  const fs::path p = dir / "no_such_dir" / "rom.hex";
  const std::string e = runtimeError([&] { shd::writeFileAtomic(p.string(), "x\n"); });
  EXPECT_NE(e.find(p.string()), std::string::npos) << e;
  EXPECT_NE(e.find("no directory"), std::string::npos) << e;  // the output policy, io/files.h
  EXPECT_FALSE(fs::exists(dir / "no_such_dir"));
  EXPECT_TRUE(shd::testutil::dirEntries(dir).empty());
}

TEST(WriteFileAtomic, TargetIsADirectoryThrowsAndRemovesTheTemporary) {
  const fs::path dir = shd::testutil::freshTestDir("test_prom_io");
  const fs::path target = dir / "rom.hex";
  fs::create_directory(target);
  const std::string e = runtimeError([&] { shd::writeFileAtomic(target.string(), "x\n"); });
  EXPECT_NE(e.find(target.string()), std::string::npos) << e;
  EXPECT_NE(e.find("it is a directory"), std::string::npos) << e;  // refused before a temporary exists
  EXPECT_EQ(shd::testutil::dirEntries(dir), std::vector<std::string>{"rom.hex"});
  EXPECT_TRUE(fs::is_directory(target));
  EXPECT_TRUE(fs::is_empty(target));
}
