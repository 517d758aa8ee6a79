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

#include <fmt/format.h>

#include "io/files.h"
#include "io/json_strict.h"

namespace shd {

namespace fs = std::filesystem;

namespace {

constexpr uint64_t kMaxRecordBytes = 1 << 20;
constexpr uint64_t kMaxPlanBytes = 1 << 20;

std::string planPath(const std::string& dir) { return (fs::path(dir) / "sweep-plan.json").string(); }
std::string pointName(uint64_t index) { return fmt::format("point-{:07}.json", index); }

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

// A CSV field: numbers as they are, text quoted when it holds a comma or a quote.
std::string csvField(const nlohmann::json& v) {
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

// The columns of sweep.csv: index, hash, every "rtl" parameter, every "error" figure, the
// record's other numbers, then "area" per target (<target>_<figure>); taken from the first
// record (every record of a sweep has the same members).
std::vector<Column> csvColumns(const nlohmann::json& first) {
  std::vector<Column> cols = {{{"index"}, "index"}, {{"hash"}, "hash"}};
  for (const auto& item : first.at("rtl").items()) cols.push_back({{"rtl", item.key()}, item.key()});
  for (const auto& item : first.at("error").items()) cols.push_back({{"error", item.key()}, item.key()});
  for (const auto& item : first.items())
    if (item.value().is_number() && item.key() != "index") cols.push_back({{item.key()}, item.key()});
  if (first.contains("area"))
    for (const auto& target : first.at("area").items())
      for (const auto& fig : target.value().items())
        cols.push_back({{"area", target.key(), fig.key()}, target.key() + "_" + fig.key()});
  return cols;
}

const nlohmann::json& at(const nlohmann::json& record, const std::vector<std::string>& path) {
  const nlohmann::json* v = &record;
  for (const std::string& key : path) v = &v->at(key);
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

// The points not dominated in (datapath error, cost): no other point has both at most as large
// and one smaller. In index order. The datapath error is what the widths control; the
// approximation error is the fit's, the same at every point of a sweep. By error, then cost: a
// point is on the front when its cost is the least among its error's and below every smaller
// error's least (O(n log n): a sweep may hold 10^6 points).
std::vector<const nlohmann::json*> paretoFront(const SweepRecords& records, const std::vector<std::string>& cost) {
  struct Point {
    double err, cost;
    uint64_t index;
    const nlohmann::json* record;
  };
  std::vector<Point> all;
  for (const auto& [k, r] : records)
    all.push_back({r.at("error").at("datapath_max_lsb").get<double>(), at(r, cost).get<double>(), k, &r});
  std::sort(all.begin(), all.end(), [](const Point& a, const Point& b) {
    return a.err != b.err ? a.err < b.err : a.cost < b.cost;
  });
  std::vector<Point> front;
  double least = std::numeric_limits<double>::infinity();  // over every smaller error
  for (size_t i = 0; i < all.size();) {
    size_t j = i;
    while (j < all.size() && all[j].err == all[i].err) ++j;
    if (all[i].cost < least)
      for (size_t k = i; k < j && all[k].cost == all[i].cost; ++k) front.push_back(all[k]);
    least = std::min(least, all[i].cost);
    i = j;
  }
  std::sort(front.begin(), front.end(), [](const Point& a, const Point& b) { return a.index < b.index; });
  std::vector<const nlohmann::json*> out;
  for (const Point& p : front) out.push_back(p.record);
  return out;
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

SweepRecords readSweepRecords(const std::string& dir, const SweepPlan& plan) {
  SweepRecords records;
  const uint64_t points = planPoints(plan);
  for (const fs::directory_entry& e : fs::directory_iterator(dir)) {
    const std::string name = e.path().filename().string();
    if (name.rfind("point-", 0) != 0 || e.path().extension() != ".json") continue;
    const std::string path = e.path().string();
    nlohmann::json r = readJsonFile(path, kMaxRecordBytes, "a point record");
    const bool ok = r.is_object() && r.contains("plan") && r.at("plan") == plan.hash && r.contains("index") &&
                    r.at("index").is_number_unsigned() && r.at("index").get<uint64_t>() < points &&
                    pointName(r.at("index").get<uint64_t>()) == name;
    if (!ok)
      throw std::runtime_error(fmt::format("{}: not a point of sweep {} (corrupted, edited or of another sweep)", path,
                                           plan.hash));
    const uint64_t index = r.at("index").get<uint64_t>();
    records[index] = std::move(r);
  }
  return records;
}

void runSweepPoints(const std::string& dir, const SweepPlan& plan, const Shard& shard, unsigned jobs,
                    const std::function<nlohmann::json(uint64_t)>& evaluate, SweepRecords& done,
                    const std::function<void(uint64_t, uint64_t)>& progress) {
  std::vector<uint64_t> todo;
  uint64_t total = 0;
  for (uint64_t k = 0; k < planPoints(plan); ++k)
    if (shard.holds(k)) {
      ++total;
      if (done.count(k) == 0) todo.push_back(k);
    }
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
        nlohmann::json r = evaluate(todo[i]);
        r["plan"] = plan.hash;
        writeFileAtomic((fs::path(dir) / pointName(todo[i])).string(), r.dump(1) + "\n");
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

void writeSweepResults(const std::string& dir, const SweepPlan& plan, const SweepRecords& records) {
  if (records.empty() || !missingPoints(plan, records).empty())
    throw std::logic_error("writeSweepResults: the sweep is incomplete");
  nlohmann::json all = plan.json;
  all["hash"] = plan.hash;
  nlohmann::json points = nlohmann::json::array();
  std::vector<const nlohmann::json*> rows;
  for (const auto& kv : records) {
    nlohmann::json r = kv.second;
    r.erase("plan");
    points.push_back(std::move(r));
  }
  for (const nlohmann::json& r : points) rows.push_back(&r);
  const auto cols = csvColumns(points.at(0));
  std::vector<const nlohmann::json*> front_rows;
  std::vector<std::string> front_names;
  std::vector<Column> costs = {{{"latency"}, "latency"}, {{"prom_bits"}, "prom_bits"}};
  for (const Column& c : cols)
    if (c.path.size() == 3 && c.path[0] == "area" && c.path[2] == "luts") costs.push_back(c);
  for (const Column& cost : costs) {
    for (const nlohmann::json* r : paretoFront(records, cost.path)) {
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

void mergeSweeps(const std::vector<std::string>& dirs, const std::string& out) {
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
  writeSweepResults(out, *plan, all);
}

}  // namespace shd
