#include "sweep/sweep_run.h"

#include <algorithm>
#include <atomic>
#include <exception>
#include <filesystem>
#include <limits>
#include <optional>
#include <mutex>
#include <stdexcept>
#include <thread>
#include <tuple>

#include <fmt/format.h>

#include "io/files.h"
#include "io/json_strict.h"

namespace shd {

namespace fs = std::filesystem;

namespace {

constexpr uint64_t kMaxRecordBytes = 1 << 20;
constexpr uint64_t kMaxPlanBytes = 1 << 20;

std::string planPath(const std::string& dir) { return (fs::path(dir) / "sweep-plan.json").string(); }
std::string fileName(const std::string& prefix, uint64_t index) { return fmt::format("{}-{:07}.json", prefix, index); }

// A JSON file of the sweep: std::runtime_error naming the file when it cannot be read, is no
// JSON or repeats a key ("<path>: not <what> (...)").
nlohmann::json readJsonFile(const std::string& path, uint64_t max_bytes, const char* what) {
  const std::string text = readInputFile(path, max_bytes);  // its errors name the file
  try {
    return parseJsonStrict(text);
  } catch (const std::exception& e) {  // malformed JSON, a repeated key
    throw std::runtime_error(fmt::format("{}: not {} ({})", path, what, e.what()));
  }
}

void requireDir(const std::string& dir) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec))
    throw std::runtime_error(
        fmt::format("{}: {}", dir, fs::exists(dir, ec) ? "not a directory" : "no such directory (create it first)"));
}

uint64_t planPoints(const SweepPlan& plan) { return plan.json.at("points").get<uint64_t>(); }

// A CSV field: numbers as they are, text quoted when it holds a comma or a quote, null empty.
std::string csvField(const nlohmann::json& v) {
  if (v.is_null()) return "";
  if (v.is_string()) {
    const std::string s = v.get<std::string>();
    if (s.find_first_of(",\"\n") == std::string::npos) return s;
    std::string q = "\"";
    for (char ch : s) q += ch == '"' ? std::string("\"\"") : std::string(1, ch);
    return q + "\"";
  }
  return v.dump();
}

// A column: where its value is in a record, and its header.
struct Column {
  std::vector<std::string> path;
  std::string header;
};

// The columns of sweep.csv: index, hash, every parameter (the plan's "params" member), every
// "error" figure, the record's other numbers, then "area" per target (<target>_<figure>) and
// "area_pruned_by"; taken from the first record and, for the area, the first synthesised one
// (every record of a sweep has the same members).
std::vector<Column> csvColumns(const nlohmann::json& first, const std::string& params,
                               const nlohmann::json* with_area) {
  std::vector<Column> cols = {{{"index"}, "index"}, {{"hash"}, "hash"}};
  for (const auto& item : first.at(params).items()) cols.push_back({{params, item.key()}, item.key()});
  // Error figures, those of a nested object (per scene) as <key>_<figure>.
  for (const auto& item : first.at("error").items()) {
    if (!item.value().is_object()) {
      cols.push_back({{"error", item.key()}, item.key()});
      continue;
    }
    for (const auto& sub : item.value().items())
      for (const auto& fig : sub.value().items())
        cols.push_back({{"error", item.key(), sub.key(), fig.key()}, sub.key() + "_" + fig.key()});
  }
  for (const auto& item : first.items())
    if (item.value().is_number() && item.key() != "index" && item.key() != "area_pruned_by") cols.push_back({{item.key()}, item.key()});
  if (with_area != nullptr) {
    for (const auto& target : with_area->at("area").items())
      for (const auto& fig : target.value().items())
        cols.push_back({{"area", target.key(), fig.key()}, target.key() + "_" + fig.key()});
    cols.push_back({{"area_pruned_by"}, "area_pruned_by"});
  }
  return cols;
}

// The value at `path` in a record, null where it has none (a pruned point's area).
const nlohmann::json& at(const nlohmann::json& record, const std::vector<std::string>& path) {
  static const nlohmann::json none;
  const nlohmann::json* v = &record;
  for (const std::string& key : path) {
    if (!v->is_object() || !v->contains(key)) return none;
    v = &v->at(key);
  }
  return *v;
}

std::string csvTable(const std::vector<const nlohmann::json*>& rows, const std::vector<Column>& cols,
                     const std::string& first_col, const std::vector<std::string>& first_vals) {
  std::string out;
  if (!first_col.empty()) out += first_col + ",";
  for (size_t c = 0; c < cols.size(); ++c) out += (c ? "," : "") + cols[c].header;
  out += "\n";
  for (size_t r = 0; r < rows.size(); ++r) {
    if (!first_col.empty()) out += first_vals[r] + ",";
    for (size_t c = 0; c < cols.size(); ++c) out += (c ? "," : "") + csvField(at(*rows[r], cols[c].path));
    out += "\n";
  }
  return out;
}

// The points not dominated in (front error, cost): no other point has both at most as large
// and one smaller; of points equal in both, one: the fewest parameter bits, then the least
// index. Points without the cost (pruned from synthesis) take no part. In index order. The
// error is what the widths control (for the specular unit the datapath error; the approximation
// error is the fit's, the same at every point of a sweep). By error, then cost: a point is on
// the front when its cost is below every smaller error's least (O(n log n): a sweep may hold
// 10^6 points).
std::vector<const nlohmann::json*> paretoFront(const std::vector<const nlohmann::json*>& records,
                                               const std::string& error, const std::vector<std::string>& cost,
                                               const std::string& params) {
  struct Point {
    double err, cost;
    int64_t bits;
    uint64_t index;
    const nlohmann::json* record;
  };
  std::vector<Point> all;
  for (const nlohmann::json* r : records) {
    const nlohmann::json& c = at(*r, cost);
    if (c.is_null()) continue;
    all.push_back({r->at("error").at(error).get<double>(), c.get<double>(), paramBits(*r, params),
                   r->at("index").get<uint64_t>(), r});
  }
  std::sort(all.begin(), all.end(), [](const Point& a, const Point& b) {
    return std::tie(a.err, a.cost, a.bits, a.index) < std::tie(b.err, b.cost, b.bits, b.index);
  });
  std::vector<Point> front;
  double least = std::numeric_limits<double>::infinity();  // over every smaller error
  for (size_t i = 0; i < all.size();) {
    size_t j = i;
    while (j < all.size() && all[j].err == all[i].err) ++j;
    if (all[i].cost < least) front.push_back(all[i]);
    least = std::min(least, all[i].cost);
    i = j;
  }
  std::sort(front.begin(), front.end(), [](const Point& a, const Point& b) { return a.index < b.index; });
  std::vector<const nlohmann::json*> out;
  for (const Point& p : front) out.push_back(p.record);
  return out;
}

// The records of files <prefix>-<index>.json in DIR, each checked against the plan (its "plan"
// hash, an index below the plan's point count, the index in its name).
SweepRecords readRecords(const std::string& dir, const SweepPlan& plan, const std::string& prefix, const char* what) {
  SweepRecords records;
  const uint64_t points = planPoints(plan);
  for (const fs::directory_entry& e : fs::directory_iterator(dir)) {
    const std::string name = e.path().filename().string();
    if (name.rfind(prefix + "-", 0) != 0 || e.path().extension() != ".json") continue;
    const std::string path = e.path().string();
    nlohmann::json r = readJsonFile(path, kMaxRecordBytes, what);
    const bool ok = r.is_object() && r.contains("plan") && r.at("plan") == plan.hash && r.contains("index") &&
                    r.at("index").is_number_unsigned() && r.at("index").get<uint64_t>() < points &&
                    fileName(prefix, r.at("index").get<uint64_t>()) == name;
    if (!ok)
      throw std::runtime_error(fmt::format("{}: not {} of sweep {} (corrupted, edited or of another sweep)", path,
                                           prefix == "point" ? "a point" : "an area", plan.hash));
    const uint64_t index = r.at("index").get<uint64_t>();
    records[index] = std::move(r);
  }
  return records;
}

}  // namespace

SweepPlan SweepPlan::make(nlohmann::json plan) {
  SweepPlan p;
  p.json = std::move(plan);
  p.hash = textHash(p.json.dump());
  return p;
}

SweepPlan readSweepPlan(const std::string& dir) {
  const std::string path = planPath(dir);
  nlohmann::json j = readJsonFile(path, kMaxPlanBytes, "a sweep plan");
  if (!j.is_object() || !j.contains("hash") || !j.at("hash").is_string() || !j.contains("points") ||
      !j.at("points").is_number_unsigned())
    throw std::runtime_error(fmt::format("{}: not a sweep plan", path));
  const std::string hash = j.at("hash").get<std::string>();
  j.erase("hash");
  SweepPlan p = SweepPlan::make(std::move(j));
  if (p.hash != hash)
    throw std::runtime_error(fmt::format("{}: its hash {} does not match its content ({}): edited or corrupted", path,
                                         hash, p.hash));
  return p;
}

void claimSweepDir(const std::string& dir, const SweepPlan& plan) {
  requireDir(dir);
  std::error_code ec;
  if (fs::exists(planPath(dir), ec)) {
    const SweepPlan there = readSweepPlan(dir);
    if (there.hash != plan.hash)
      throw std::runtime_error(fmt::format("{} holds another sweep (plan {}, this one {}: {}); use another directory",
                                           dir, there.hash, plan.hash, there.json.value("command", "")));
    return;
  }
  nlohmann::json j = plan.json;
  j["hash"] = plan.hash;
  writeFileAtomic(planPath(dir), j.dump(2) + "\n");
}

Grid planGrid(const SweepPlan& plan) {
  std::vector<GridAxis> axes;
  for (const nlohmann::json& a : plan.json.at("axes"))
    axes.push_back({a.at("name").get<std::string>(), a.at("text").get<std::string>(), a.at("values").get<std::vector<int>>()});
  return Grid(std::move(axes));
}

SweepRecords readSweepRecords(const std::string& dir, const SweepPlan& plan) {
  return readRecords(dir, plan, "point", "a point record");
}

SweepRecords readSweepAreas(const std::string& dir, const SweepPlan& plan) {
  return readRecords(dir, plan, "area", "an area record");
}

std::vector<uint64_t> shardPoints(const SweepPlan& plan, const Shard& shard) {
  std::vector<uint64_t> points;
  for (uint64_t k = 0; k < planPoints(plan); ++k)
    if (shard.holds(k)) points.push_back(k);
  return points;
}

void runSweepJobs(const std::string& dir, const SweepPlan& plan, const std::string& prefix,
                  const std::vector<uint64_t>& indices, unsigned jobs,
                  const std::function<nlohmann::json(uint64_t)>& work, SweepRecords& done,
                  const std::function<void(uint64_t, uint64_t)>& progress) {
  std::vector<uint64_t> todo;
  for (uint64_t k : indices)
    if (done.count(k) == 0) todo.push_back(k);
  const uint64_t total = indices.size();
  std::atomic<size_t> next{0};
  std::atomic<bool> stop{false};
  std::mutex m;
  std::exception_ptr error;
  uint64_t recorded = total - todo.size();
  if (progress) progress(recorded, total);
  auto worker = [&] {
    for (;;) {
      const size_t i = next++;
      if (i >= todo.size() || stop) return;
      try {
        nlohmann::json r = work(todo[i]);
        r["plan"] = plan.hash;
        writeFileAtomic((fs::path(dir) / fileName(prefix, todo[i])).string(), r.dump(1) + "\n");
        std::lock_guard<std::mutex> lock(m);
        done[todo[i]] = std::move(r);
        if (progress) progress(++recorded, total);
      } catch (...) {
        std::lock_guard<std::mutex> lock(m);
        if (!error) error = std::current_exception();
        stop = true;
        return;
      }
    }
  };
  std::vector<std::thread> pool;
  for (unsigned t = 1; t < std::max(1u, jobs); ++t) pool.emplace_back(worker);
  worker();
  for (std::thread& t : pool) t.join();
  if (error) std::rethrow_exception(error);
}

std::vector<uint64_t> missingPoints(const SweepPlan& plan, const SweepRecords& records) {
  std::vector<uint64_t> missing;
  for (uint64_t k = 0; k < planPoints(plan); ++k)
    if (records.count(k) == 0) missing.push_back(k);
  return missing;
}

std::vector<int64_t> areaDominators(const SweepPlan& plan, const SweepRecords& records,
                                    const std::vector<std::string>& classes) {
  const Grid grid = planGrid(plan);
  const uint64_t n = grid.size();
  if (!classes.empty() && classes.size() != n) throw std::logic_error("areaDominators: not one class per point");
  std::vector<int64_t> dominator(n, -1);
  if (plan.json.value("area_all", false)) return dominator;
  const std::string error = plan.json.at("front").at("error").get<std::string>();
  // Per axis: each position's rank among the axis's values and the position of the next lower
  // value (-1 for the least); the stride of a position in the point index.
  const auto& axes = grid.axes();
  std::vector<std::vector<int64_t>> lower(axes.size());
  std::vector<std::vector<int>> rank(axes.size());
  std::vector<uint64_t> stride(axes.size(), 1);
  for (size_t a = axes.size(); a-- > 0;) {
    const std::vector<int>& v = axes[a].values;
    if (a + 1 < axes.size()) stride[a] = stride[a + 1] * axes[a + 1].values.size();
    std::vector<size_t> order(v.size());
    for (size_t i = 0; i < v.size(); ++i) order[i] = i;
    std::sort(order.begin(), order.end(), [&](size_t x, size_t y) { return v[x] < v[y]; });
    lower[a].assign(v.size(), -1);
    rank[a].assign(v.size(), 0);
    for (size_t r = 0; r < order.size(); ++r) {
      rank[a][order[r]] = static_cast<int>(r);
      if (r > 0) lower[a][order[r]] = static_cast<int64_t>(order[r - 1]);
    }
  }
  auto position = [&](uint64_t k, size_t a) { return (k / stride[a]) % axes[a].values.size(); };
  // The points by the sum of their ranks: every point below p comes before p.
  std::vector<uint64_t> order(n);
  std::vector<int> rank_sum(n, 0);
  for (uint64_t k = 0; k < n; ++k) {
    order[k] = k;
    for (size_t a = 0; a < axes.size(); ++a) rank_sum[k] += rank[a][position(k, a)];
  }
  std::stable_sort(order.begin(), order.end(), [&](uint64_t x, uint64_t y) { return rank_sum[x] < rank_sum[y]; });
  // below[p]: the least (error, index) over the points below p (not p itself).
  using Best = std::pair<double, int64_t>;
  const Best none = {std::numeric_limits<double>::infinity(), -1};
  std::vector<Best> below(n, none);
  auto err = [&](uint64_t k) { return records.at(k).at("error").at(error).get<double>(); };
  for (uint64_t p : order) {
    Best best = none;
    for (size_t a = 0; a < axes.size(); ++a) {
      const int64_t lo = lower[a][position(p, a)];
      if (lo < 0) continue;
      const uint64_t q = p - position(p, a) * stride[a] + static_cast<uint64_t>(lo) * stride[a];
      if (!classes.empty() && classes[q] != classes[p]) continue;
      best = std::min({best, below[q], Best{err(q), static_cast<int64_t>(q)}});
    }
    below[p] = best;
    if (best.second >= 0 && best.first <= err(p)) dominator[p] = best.second;
  }
  return dominator;
}

nlohmann::json sweepResults(const SweepPlan& plan, const SweepRecords& records, const SweepRecords& areas,
                            const std::vector<int64_t>& dominator) {
  if (records.empty() || !missingPoints(plan, records).empty())
    throw std::logic_error("sweepResults: the sweep is incomplete");
  const bool with_area = plan.json.value("area", "none") != "none";
  if (with_area && dominator.size() != records.size())
    throw std::logic_error("sweepResults: the area phase's decision is not one per point");
  nlohmann::json points = nlohmann::json::array();
  for (const auto& [k, record] : records) {
    nlohmann::json r = record;
    r.erase("plan");
    if (with_area && dominator[k] >= 0) {
      r["area_pruned_by"] = dominator[k];
    } else if (with_area) {
      const auto it = areas.find(k);
      if (it == areas.end()) throw std::logic_error(fmt::format("sweepResults: point {} has no area", k));
      r["area"] = it->second.at("area");
    }
    points.push_back(std::move(r));
  }
  return points;
}

int64_t paramBits(const nlohmann::json& record, const std::string& params) {
  int64_t sum = 0;
  for (const auto& item : record.at(params).items())
    if (item.value().is_number_integer()) sum += item.value().get<int64_t>();
  return sum;
}

void writeSweepResults(const std::string& dir, const SweepPlan& plan, const nlohmann::json& results) {
  nlohmann::json points = results;
  nlohmann::json all = plan.json;
  all["hash"] = plan.hash;
  const nlohmann::json* synthesised = nullptr;  // the first record with an area
  std::vector<const nlohmann::json*> rows;
  for (const nlohmann::json& r : points) {
    rows.push_back(&r);
    if (synthesised == nullptr && r.contains("area")) synthesised = &r;
  }
  const std::string params = plan.json.at("params").get<std::string>();
  const nlohmann::json& front = plan.json.at("front");
  const auto cols = csvColumns(points.at(0), params, synthesised);
  std::vector<const nlohmann::json*> front_rows;
  std::vector<std::string> front_names;
  std::vector<Column> costs;
  for (const nlohmann::json& c : front.at("costs")) costs.push_back({{c.get<std::string>()}, c.get<std::string>()});
  for (const Column& c : cols)
    if (c.path.size() == 3 && c.path[0] == "area" && c.path[2] == "luts") costs.push_back(c);
  for (const Column& cost : costs) {
    for (const nlohmann::json* r : paretoFront(rows, front.at("error").get<std::string>(), cost.path, params)) {
      front_rows.push_back(r);
      front_names.push_back("error-" + cost.header);
    }
  }
  OutputFiles out;
  out.add((fs::path(dir) / "sweep.csv").string(), csvTable(rows, cols, "", {}));
  out.add((fs::path(dir) / "pareto.csv").string(), csvTable(front_rows, cols, "front", front_names));
  all["results"] = std::move(points);
  out.add((fs::path(dir) / "sweep.json").string(), all.dump(1) + "\n");
  out.commit();
}

std::pair<SweepPlan, SweepRecords> mergeSweeps(const std::vector<std::string>& dirs, const std::string& out) {
  if (dirs.empty()) throw std::runtime_error("no shard directories given");
  requireDir(out);  // before the work
  std::optional<SweepPlan> plan;  // the first directory's
  SweepRecords all;
  for (const std::string& d : dirs) {
    const SweepPlan p = readSweepPlan(d);
    if (!plan) plan = p;
    if (p.hash != plan->hash)
      throw std::runtime_error(fmt::format("{} and {} hold different sweeps (plans {} and {})", dirs[0], d, plan->hash,
                                           p.hash));
    for (auto& kv : readSweepRecords(d, p)) {
      const auto it = all.find(kv.first);
      if (it != all.end() && it->second != kv.second)
        throw std::runtime_error(fmt::format("{}: point {} differs from the same point in another shard", d, kv.first));
      all[kv.first] = std::move(kv.second);
    }
  }
  const std::vector<uint64_t> missing = missingPoints(*plan, all);
  if (!missing.empty()) {
    std::string some;
    for (size_t i = 0; i < std::min<size_t>(missing.size(), 8); ++i) some += fmt::format("{}{}", i ? ", " : "", missing[i]);
    throw std::runtime_error(fmt::format("{} of the sweep's {} points are in none of the directories ({}{}): a shard "
                                         "is missing or unfinished",
                                         missing.size(), planPoints(*plan), some, missing.size() > 8 ? ", ..." : ""));
  }
  claimSweepDir(out, *plan);
  for (const auto& [k, r] : all) {
    const std::string path = (fs::path(out) / fileName("point", k)).string();
    std::error_code ec;
    if (!fs::exists(path, ec)) writeFileAtomic(path, r.dump(1) + "\n");
  }
  return {*plan, std::move(all)};
}

}  // namespace shd
