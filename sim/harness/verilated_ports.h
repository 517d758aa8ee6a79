// Bit fields of verilated ports: a port of up to 64 bits is an integer member, a wider one a
// VlWide of 32-bit words. put()/get() address a field by its LSB and width either way, so a
// harness packs flattened Verilog vectors ([n*W +: W]) without caring which.
#pragma once

#include <algorithm>
#include <cstdint>
#include <type_traits>
#include <vector>

#include <verilated.h>

namespace shd::ports {

template <class T>
std::enable_if_t<std::is_integral_v<T>> put(T& port, int lsb, int width, uint64_t v) {
  const uint64_t mask = width >= 64 ? ~uint64_t{0} : (uint64_t{1} << width) - 1;
  uint64_t p = static_cast<uint64_t>(port);
  p = (p & ~(mask << lsb)) | ((v & mask) << lsb);
  port = static_cast<T>(p);
}

template <std::size_t N>
void put(VlWide<N>& port, int lsb, int width, uint64_t v) {
  // Word by word: the field covers bits [lsb, lsb + width) of the 32-bit words.
  while (width > 0) {
    const std::size_t w = static_cast<std::size_t>(lsb / 32);
    const int off = lsb % 32, n = std::min(width, 32 - off);
    const uint32_t mask = (n == 32 ? ~uint32_t{0} : ((uint32_t{1} << n) - 1)) << off;
    port[w] = (port[w] & ~mask) | ((static_cast<uint32_t>(v) << off) & mask);
    v >>= n;
    lsb += n;
    width -= n;
  }
}

template <class T>
std::enable_if_t<std::is_integral_v<T>, uint64_t> get(const T& port, int lsb, int width) {
  const uint64_t mask = width >= 64 ? ~uint64_t{0} : (uint64_t{1} << width) - 1;
  return (static_cast<uint64_t>(port) >> lsb) & mask;
}

template <std::size_t N>
uint64_t get(const VlWide<N>& port, int lsb, int width) {
  // The field covers bits [lsb, lsb + width) of the 32-bit words: at most three of them.
  std::size_t w = static_cast<unsigned>(lsb) / 32;
  const unsigned off = static_cast<unsigned>(lsb) % 32;
  uint64_t v = static_cast<uint64_t>(port[w]) >> off;
  for (int done = 32 - static_cast<int>(off); done < width; done += 32)
    v |= static_cast<uint64_t>(port[++w]) << done;
  return width >= 64 ? v : v & ((uint64_t{1} << width) - 1);
}

inline int64_t signExtend(uint64_t v, int width) {
  const uint64_t sign = uint64_t{1} << (width - 1);
  return static_cast<int64_t>((v ^ sign) - sign);
}

// A ROM's words as Verilator stores an unpacked array of them: CData/SData/IData/QData, or
// VlWide for words wider than 64 bits (at most 128: unsigned __int128, the PROM word type).
inline unsigned __int128 romWord(uint64_t v) { return v; }
template <std::size_t N>
unsigned __int128 romWord(const VlWide<N>& w) {
  static_assert(N <= 4, "ROM words are at most 128 bits");
  unsigned __int128 r = 0;
  for (std::size_t i = 0; i < N; ++i) r |= static_cast<unsigned __int128>(w[i]) << (32 * i);
  return r;
}
template <class T, std::size_t Depth>
std::vector<unsigned __int128> romWords(const VlUnpacked<T, Depth>& rom) {
  std::vector<unsigned __int128> words;
  words.reserve(Depth);
  for (std::size_t i = 0; i < Depth; ++i) words.push_back(romWord(rom[i]));
  return words;
}

}  // namespace shd::ports
