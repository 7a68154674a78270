#include "hand/hand_params_json.h"

#include <cmath>
#include <sstream>

#include "core/errors.h"

namespace handlabel {

using nlohmann::json;

json JsonHandParams(const HandParams& params) {
  return {{"global_orient", JsonArray(params.global_orient)},
          {"hand_pose", JsonArray(params.hand_pose)},
          {"betas", JsonArray(params.betas)},
          {"transl", JsonArray(params.transl)}};
}

HandParams HandParamsFromJson(const json& object, const std::string& source,
                              const std::string& where, JsonNull nulls) {
  auto vector = [&](const char* key, int size) {
    return JsonVector(JsonMember(object, key, source, where), source, where + key, size,
                      nulls);
  };
  // Plausible magnitudes: a typo such as 1e300 would otherwise reach the fitter and
  // come back as a label of NaNs. NaN (null with kAsNan) is left to the caller.
  const auto bounded = [&](const char* key, int size, double limit, const char* unit) {
    const Eigen::VectorXd v = vector(key, size);
    for (Eigen::Index i = 0; i < v.size(); ++i) {
      if (std::abs(v[i]) > limit) {
        std::ostringstream got;
        got << v[i];
        throw InputError(
            source, where + key + "[" + std::to_string(i) + "]",
            "a value within +-" + JsonNumberOrNull(limit).dump() + " " + unit, got.str());
      }
    }
    return v;
  };
  HandParams params;
  params.global_orient = bounded("global_orient", 3, kMaxAxisAngle, "rad");
  params.hand_pose = bounded("hand_pose", kNumPoseParams, kMaxAxisAngle, "rad");
  params.betas = bounded("betas", -1, kMaxBeta, "(shape coefficient)");
  params.transl = bounded("transl", 3, kMaxTranslationM, "m");
  return params;
}

}  // namespace handlabel
