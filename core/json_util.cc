#include "core/json_util.h"

#include <cmath>
#include <set>
#include <sstream>
#include <vector>

#include "core/errors.h"
#include "core/file_bytes.h"

namespace handlabel {

using nlohmann::json;

json JsonNumberOrNull(double x) { return std::isfinite(x) ? json(x) : json(nullptr); }

json JsonPoints(const Points3d& points) {
  json out = json::array();
  for (Eigen::Index i = 0; i < points.rows(); ++i) {
    out.push_back({points(i, 0), points(i, 1), points(i, 2)});
  }
  return out;
}

json ParseJsonStrict(const std::string& text, const std::string& source) {
  // The keys seen in each open object, innermost last.
  std::vector<std::set<std::string>> open_objects;
  std::string duplicate;
  const json::parser_callback_t check = [&](int /*depth*/, json::parse_event_t event,
                                            json& parsed) {
    if (event == json::parse_event_t::object_start) {
      open_objects.emplace_back();
    } else if (event == json::parse_event_t::object_end) {
      if (!open_objects.empty()) open_objects.pop_back();
    } else if (event == json::parse_event_t::key && !open_objects.empty() &&
               !open_objects.back().insert(parsed.get<std::string>()).second &&
               duplicate.empty()) {
      duplicate = parsed.get<std::string>();
    }
    return true;
  };
  json j;
  try {
    j = json::parse(text, check);
  } catch (const json::exception& e) {
    throw InputError(source, "(JSON syntax)", "valid JSON", e.what());
  }
  if (!duplicate.empty()) {
    throw InputError(source, duplicate, "each key once per object", "a duplicate key");
  }
  return j;
}

json ReadJsonFileStrict(const std::string& path) {
  return ParseJsonStrict(ReadFileBytes(path, "JSON file"), path);
}

void RejectUnknownKeys(const json& object, std::initializer_list<const char*> known,
                       const std::string& source, const std::string& where) {
  if (!object.is_object()) return;
  for (const auto& [key, value] : object.items()) {
    bool ok = false;
    for (const char* k : known) ok |= key == k;
    if (ok) continue;
    std::string names;
    for (const char* k : known) names += (names.empty() ? "" : ", ") + std::string(k);
    throw InputError(source, where + key, "one of the known keys (" + names + ")",
                     "an unknown key");
  }
}

const json& JsonMember(const json& object, const char* key, const std::string& source,
                       const std::string& where) {
  if (!object.is_object())
    throw InputError(source, where, "an object", object.dump().substr(0, 80));
  const auto it = object.find(key);
  if (it == object.end()) throw InputError(source, where + key, "a value", "missing");
  return *it;
}

std::string JsonString(const json& object, const char* key, const std::string& source,
                       const std::string& where) {
  const json& v = JsonMember(object, key, source, where);
  if (!v.is_string()) throw InputError(source, where + key, "a string", v.dump());
  return v.get<std::string>();
}

double JsonNumber(const json& value, const std::string& source, const std::string& field,
                  JsonNull nulls) {
  if (nulls == JsonNull::kAsNan && value.is_null()) return std::nan("");
  if (!value.is_number()) throw InputError(source, field, "a number", value.dump());
  return value.get<double>();
}

Eigen::VectorXd JsonVector(const json& value, const std::string& source,
                           const std::string& field, int size, JsonNull nulls) {
  if (!value.is_array() || (size >= 0 && static_cast<int>(value.size()) != size)) {
    throw InputError(source, field,
                     size >= 0 ? std::to_string(size) + " numbers" : "numbers",
                     value.dump().substr(0, 80));
  }
  Eigen::VectorXd v(value.size());
  for (size_t i = 0; i < value.size(); ++i) {
    v[i] = JsonNumber(value[i], source, field, nulls);
  }
  return v;
}

Points3d JsonPointList(const json& value, const std::string& source,
                       const std::string& field, Eigen::Index rows, JsonNull nulls) {
  if (!value.is_array() ||
      (rows >= 0 && static_cast<Eigen::Index>(value.size()) != rows)) {
    throw InputError(
        source, field,
        rows >= 0 ? std::to_string(rows) + " points [x, y, z]" : "an array of [x, y, z]",
        value.is_array() ? std::to_string(value.size()) + " entries"
                         : value.dump().substr(0, 80));
  }
  Points3d p(value.size(), 3);
  for (size_t i = 0; i < value.size(); ++i) {
    const std::string at = field + "[" + std::to_string(i) + "]";
    if (!value[i].is_array() || value[i].size() != 3) {
      throw InputError(source, at, "[x, y, z]", value[i].dump());
    }
    for (int c = 0; c < 3; ++c) p(i, c) = JsonNumber(value[i][c], source, at, nulls);
  }
  return p;
}

}  // namespace handlabel
