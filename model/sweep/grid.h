// The grid of a sweep: unit parameters, each over a range or a list of values
// (`shadesim sweep --param Name=8:16 --param Name=4,6,9`), the others kept at the base
// configuration's values. The points are the grid's cross product in a fixed order (the first
// axis varies slowest), each named by its index and by a hash of its parameters.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace shd {

// A point's parameter values, in the order of the grid's axes.
using PointValues = std::vector<std::pair<std::string, int>>;

// "Name=v Name2=w": a point as messages name it.
std::string describePoint(const PointValues& values);

struct GridAxis {
  std::string name;         // a parameter of the unit ("CoefFracBits")
  std::string text;         // as given: "8:16", "8:16:2", "4,6,9"
  std::vector<int> values;  // in the order given (a range ascending)
};

// "Name=lo:hi[:step]" (lo <= hi, step >= 1) or "Name=v1,v2,..." (distinct values). `known`:
// the unit's parameter names. std::invalid_argument naming the text: an unknown parameter (with
// the known ones), an empty or reversed range, a zero step, a repeated value, a value that is no
// integer in [0, 2^20].
GridAxis parseGridAxis(const std::string& text, const std::vector<std::string>& known);

class Grid {
 public:
  // std::invalid_argument for a parameter named twice.
  explicit Grid(std::vector<GridAxis> axes);

  const std::vector<GridAxis>& axes() const { return axes_; }
  uint64_t size() const { return size_; }
  // The parameter values of point `index` (< size()), in the order of the axes.
  PointValues point(uint64_t index) const;

 private:
  std::vector<GridAxis> axes_;
  uint64_t size_ = 1;
};

constexpr uint64_t kMaxGridPoints = 1'000'000;

// A sweep's part: "i/N" with 1 <= i <= N <= 10^4. std::invalid_argument otherwise.
struct Shard {
  uint64_t index = 1, count = 1;  // the i-th of N
  static Shard parse(const std::string& text);
  // Point k belongs to shard i of N when k mod N = i - 1 (neighbouring points, often of similar
  // cost, spread over the shards).
  bool holds(uint64_t point) const { return point % count == index - 1; }
};

// 64-bit FNV-1a of a text, as 16 hex digits: the name of a point's parameters and of a sweep's
// plan (stable across runs, builds and machines).
std::string textHash(const std::string& text);

}  // namespace shd
