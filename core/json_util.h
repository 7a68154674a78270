#pragma once
// JSON forms of the project's arrays (numbers, vectors, point lists)
// and checked readers for them, shared by every file format (capture manifests and
// records, labels, fit outputs). Writers give the same bytes whoever calls them;
// readers throw InputError naming the source (file), the field and what was expected.
// JSON has no NaN or infinity: nlohmann writes them as null; readers decide per field
// whether null reads back as NaN (JsonNull::kAsNan) or is an error.

#include <Eigen/Core>
#include <initializer_list>
#include <nlohmann/json.hpp>
#include <string>

#include "core/point_arrays.h"

namespace handlabel {

// What a reader does with null where a number is expected.
enum class JsonNull { kReject, kAsNan };

// x, or null when x is not finite.
nlohmann::json JsonNumberOrNull(double x);

// [v0, v1, ...] of any Eigen vector.
template <typename Derived>
nlohmann::json JsonArray(const Eigen::DenseBase<Derived>& v) {
  nlohmann::json out = nlohmann::json::array();
  for (Eigen::Index i = 0; i < v.size(); ++i) out.push_back(v.derived()[i]);
  return out;
}

// [[x, y, z], ...], one entry per row.
nlohmann::json JsonPoints(const Points3d& points);

// Parses JSON text strictly: a syntax error, or a key given twice in one object
// (nlohmann would silently keep the last), throws InputError naming `source`.
nlohmann::json ParseJsonStrict(const std::string& text, const std::string& source);
// The same for a file; a file that cannot be read is an InputError too.
nlohmann::json ReadJsonFileStrict(const std::string& path);

// Throws InputError naming source, where + the key and the known keys when `object`
// has a key outside `known` (a misspelt field must not be silently ignored).
void RejectUnknownKeys(const nlohmann::json& object,
                       std::initializer_list<const char*> known,
                       const std::string& source, const std::string& where = "");

// object[key]; throws when `object` is not an object or has no `key`. `where` is
// prepended to the key in messages ("views[2].").
const nlohmann::json& JsonMember(const nlohmann::json& object, const char* key,
                                 const std::string& source,
                                 const std::string& where = "");

// object[key] as a string.
std::string JsonString(const nlohmann::json& object, const char* key,
                       const std::string& source, const std::string& where = "");

// A number (or, with kAsNan, null as NaN).
double JsonNumber(const nlohmann::json& value, const std::string& source,
                  const std::string& field, JsonNull nulls = JsonNull::kReject);

// An array of `size` numbers (any count when size < 0).
Eigen::VectorXd JsonVector(const nlohmann::json& value, const std::string& source,
                           const std::string& field, int size,
                           JsonNull nulls = JsonNull::kReject);

// An array of `rows` points [x, y, z] (any count when rows < 0).
Points3d JsonPointList(const nlohmann::json& value, const std::string& source,
                       const std::string& field, Eigen::Index rows,
                       JsonNull nulls = JsonNull::kReject);

}  // namespace handlabel
