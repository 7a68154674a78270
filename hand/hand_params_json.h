#pragma once
// The JSON form of hand parameters in labels, fit outputs and capture ground truth:
// {"betas": [...], "global_orient": [3], "hand_pose": [45], "transl": [3]}.

#include <nlohmann/json.hpp>
#include <string>

#include "core/json_util.h"
#include "hand/hand_lbs.h"

namespace handlabel {

// {"betas": [...], "global_orient": [3], "hand_pose": [45], "transl": [3]}.
nlohmann::json JsonHandParams(const HandParams& params);

// Largest magnitudes HandParamsFromJson accepts: far beyond any hand, so only typos
// and overflowed numbers are refused.
inline constexpr double kMaxAxisAngle = 100.0;   // rad, per component
inline constexpr double kMaxBeta = 100.0;        // shape coefficients (MANO: +-5)
inline constexpr double kMaxTranslationM = 1e4;  // metres

// The four parameter arrays of JsonHandParams from `object` (global_orient 3,
// hand_pose 45, betas any count, transl 3), each within the limits above; fields are
// named where + key.
HandParams HandParamsFromJson(const nlohmann::json& object, const std::string& source,
                              const std::string& where = "",
                              JsonNull nulls = JsonNull::kReject);

}  // namespace handlabel
