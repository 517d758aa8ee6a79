// JSON text parsed strictly for the files shadesim reads (configurations, scenes): nlohmann-json
// keeps the last of two equal keys in one object without a word, so that a file with "rtl"
// twice would run with whichever comes last. Here a repeated key is an error.
#pragma once

#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

namespace shd {

// The parsed value; nlohmann::json::exception for malformed text (parse_error) or a number out
// of range (out_of_range, e.g. 1e999); std::invalid_argument "key \"k\" appears twice in one
// object" for a repeated key.
inline nlohmann::json parseJsonStrict(const std::string& text) {
  std::vector<std::set<std::string>> keys;  // one set per open object
  using Event = nlohmann::json::parse_event_t;
  return nlohmann::json::parse(text, [&keys](int, Event event, nlohmann::json& value) {
    if (event == Event::object_start) keys.emplace_back();
    if (event == Event::object_end) keys.pop_back();
    if (event == Event::key && !keys.back().insert(value.get<std::string>()).second)
      throw std::invalid_argument(fmt::format("key \"{}\" appears twice in one object", value.get<std::string>()));
    return true;
  });
}

}  // namespace shd
