#include "fitting/robust_loss.h"

#include "core/errors.h"

namespace handlabel {

RobustLossType RobustLossFromName(const std::string& name, const std::string& source) {
  if (name == "trivial") return RobustLossType::kTrivial;
  if (name == "huber") return RobustLossType::kHuber;
  if (name == "cauchy") return RobustLossType::kCauchy;
  throw InputError(source, "robust loss", "one of trivial, huber, cauchy", name);
}

std::string RobustLossName(RobustLossType type) {
  switch (type) {
    case RobustLossType::kTrivial:
      return "trivial";
    case RobustLossType::kHuber:
      return "huber";
    case RobustLossType::kCauchy:
      return "cauchy";
  }
  return "?";
}

}  // namespace handlabel
