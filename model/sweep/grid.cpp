#include "sweep/grid.h"

#include <algorithm>
#include <set>
#include <stdexcept>

#include <fmt/format.h>

#include "io/text.h"

namespace shd {

namespace {

constexpr int kMaxValue = 1 << 20;

int parseValue(std::string_view s, const std::string& whole) {
  bool digits = !s.empty() && s.size() <= 8;
  for (char ch : s) digits = digits && ch >= '0' && ch <= '9';
  const long v = digits ? std::stol(std::string(s)) : -1;
  if (!digits || v > kMaxValue)
    throw std::invalid_argument(fmt::format("--param {}: '{}' is not a whole number in [0, {}]", whole, s, kMaxValue));
  return static_cast<int>(v);
}

}  // namespace

GridAxis parseGridAxis(const std::string& text, const std::vector<std::string>& known) {
  const size_t eq = text.find('=');
  if (eq == std::string::npos || eq == 0 || eq + 1 == text.size())
    throw std::invalid_argument(fmt::format("--param '{}': expected Name=lo:hi[:step] or Name=v1,v2,...", text));
  GridAxis a;
  a.name = text.substr(0, eq);
  a.text = text.substr(eq + 1);
  if (std::find(known.begin(), known.end(), a.name) == known.end()) {
    std::string names;
    for (const std::string& k : known) names += (names.empty() ? "" : ", ") + k;
    throw std::invalid_argument(fmt::format("--param {}: the unit has no parameter {} (it has {})", text, a.name, names));
  }
  if (a.text.find(':') != std::string::npos) {
    const auto parts = splitFields(a.text, ':');
    if (parts.size() > 3) throw std::invalid_argument(fmt::format("--param {}: a range is lo:hi or lo:hi:step", text));
    const int lo = parseValue(parts[0], text), hi = parseValue(parts[1], text);
    const int step = parts.size() == 3 ? parseValue(parts[2], text) : 1;
    if (lo > hi) throw std::invalid_argument(fmt::format("--param {}: the range is reversed ({} > {})", text, lo, hi));
    if (step == 0) throw std::invalid_argument(fmt::format("--param {}: the step is 0", text));
    for (int v = lo; v <= hi; v += step) a.values.push_back(v);
  } else {
    std::set<int> seen;
    for (const std::string_view s : splitFields(a.text, ',')) {
      const int v = parseValue(s, text);
      if (!seen.insert(v).second) throw std::invalid_argument(fmt::format("--param {}: {} is given twice", text, v));
      a.values.push_back(v);
    }
  }
  return a;
}

Grid::Grid(std::vector<GridAxis> axes) : axes_(std::move(axes)) {
  std::set<std::string> names;
  for (const GridAxis& a : axes_) {
    if (!names.insert(a.name).second) throw std::invalid_argument(fmt::format("--param: {} is given twice", a.name));
    if (a.values.empty()) throw std::invalid_argument(fmt::format("--param {}: no values", a.name));
    size_ *= a.values.size();
    if (size_ > kMaxGridPoints)
      throw std::invalid_argument(
          fmt::format("the grid has more than {} points; split the sweep or narrow the ranges", kMaxGridPoints));
  }
}

std::string describePoint(const PointValues& values) {
  std::string where;
  for (const auto& [name, value] : values) where += fmt::format("{}{}={}", where.empty() ? "" : " ", name, value);
  return where;
}

PointValues Grid::point(uint64_t index) const {
  if (index >= size_) throw std::out_of_range(fmt::format("grid point {} of {}", index, size_));
  PointValues p(axes_.size());
  for (size_t k = axes_.size(); k-- > 0;) {  // the last axis varies fastest
    const uint64_t n = axes_[k].values.size();
    p[k] = {axes_[k].name, axes_[k].values[index % n]};
    index /= n;
  }
  return p;
}

Shard Shard::parse(const std::string& text) {
  const size_t slash = text.find('/');
  Shard s;
  try {
    if (slash == std::string::npos) throw std::invalid_argument("");
    s.index = static_cast<uint64_t>(parseValue(text.substr(0, slash), text));
    s.count = static_cast<uint64_t>(parseValue(text.substr(slash + 1), text));
  } catch (const std::invalid_argument&) {
    throw std::invalid_argument(fmt::format("--shard '{}': expected i/N (the i-th of N parts)", text));
  }
  if (s.count < 1 || s.count > 10000 || s.index < 1 || s.index > s.count)
    throw std::invalid_argument(fmt::format("--shard {}: must be i/N with 1 <= i <= N <= 10000", text));
  return s;
}

std::string textHash(const std::string& text) {
  uint64_t h = 0xcbf29ce484222325ULL;
  for (unsigned char ch : text) {
    h ^= ch;
    h *= 0x100000001b3ULL;
  }
  return fmt::format("{:016x}", h);
}

}  // namespace shd
