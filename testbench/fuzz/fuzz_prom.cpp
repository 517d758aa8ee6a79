// libFuzzer target: the PROM hex reader (model/device/prom_io.h readPromHex).
// Input: two bytes choosing the reader's parameters, then the file's bytes:
//   byte 0: word_bits = 1 + byte % 128 (the reader's whole range 1..128)
//   byte 1: depth     = 1 + byte (1..256; the reader's checks do not depend on its size)
// Clean rejection: std::runtime_error (the documented one: path, line and what is wrong).
// Properties of an accepted file: exactly `depth` words, none with a bit at or above
// word_bits, and the same words again when written back as renderProm writes them (hexWord per
// line) and read a second time.
#include <stdexcept>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "device/prom_io.h"
#include "fuzz_util.h"

namespace {

using shd::fuzz::finding;

void checkWords(const std::vector<shd::PromWord>& words, int word_bits, int depth) {
  if (words.size() != static_cast<size_t>(depth))
    finding(fmt::format("{} words read, depth {}", words.size(), depth));
  for (size_t i = 0; i < words.size(); ++i)
    if (word_bits < 128 && (words[i] >> word_bits) != 0)
      finding(fmt::format("word {} has bits above the {}-bit width", i, word_bits));
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  shd::fuzz::ByteReader in(data, size);
  const int word_bits = 1 + in.u8() % 128;
  const int depth = 1 + in.u8();
  const std::string path = shd::fuzz::writeInput("prom.hex", in.pos(), in.left());
  std::vector<shd::PromWord> words;
  try {
    words = shd::readPromHex(path, word_bits, depth);
  } catch (const std::runtime_error& e) {
    shd::fuzz::rejected(e);
    return 0;
  }
  checkWords(words, word_bits, depth);
  std::string text = "// written back\n";
  for (shd::PromWord w : words) text += shd::hexWord(w, word_bits) + "\n";
  const std::string again = shd::fuzz::writeInput("again.hex", reinterpret_cast<const uint8_t*>(text.data()), text.size());
  if (shd::readPromHex(again, word_bits, depth) != words) finding("the words differ after writing them back");
  return 0;
}
