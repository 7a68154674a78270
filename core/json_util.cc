#include "core/json_util.h"

#include <cmath>

#include "core/errors.h"

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

json JsonHandParams(const HandParams& params) {
  return {{"global_orient", JsonArray(params.global_orient)},
          {"hand_pose", JsonArray(params.hand_pose)},
          {"betas", JsonArray(params.betas)},
          {"transl", JsonArray(params.transl)}};
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

HandParams HandParamsFromJson(const json& object, const std::string& source,
                              const std::string& where, JsonNull nulls) {
  auto vector = [&](const char* key, int size) {
    return JsonVector(JsonMember(object, key, source, where), source, where + key, size,
                      nulls);
  };
  HandParams params;
  params.global_orient = vector("global_orient", 3);
  params.hand_pose = vector("hand_pose", kNumPoseParams);
  params.betas = vector("betas", -1);
  params.transl = vector("transl", 3);
  return params;
}

}  // namespace handlabel
