#include "hand/shaped_hand.h"

#include <string>

#include "core/errors.h"

namespace handlabel {

ShapedHand ShapeHand(const HandModel& model, const Eigen::VectorXd& betas) {
  const int num_betas = model.num_betas();
  if (betas.size() > num_betas) {
    throw InputError("HandParams", "betas", "at most " + std::to_string(num_betas),
                     std::to_string(betas.size()));
  }
  Eigen::VectorXd all = Eigen::VectorXd::Zero(num_betas);
  all.head(betas.size()) = betas;
  // Row-major V x 3 storage flattens to index 3*v + c, the row order of the blend shapes.
  const int num_vertices = model.num_vertices();
  const Eigen::VectorXd flat =
      Eigen::Map<const Eigen::VectorXd>(model.v_template.data(), 3 * num_vertices) +
      model.shapedirs * all;
  ShapedHand hand;
  hand.vertices = Eigen::Map<const Points3d>(flat.data(), num_vertices, 3);
  hand.joints = model.joint_regressor * hand.vertices;
  return hand;
}

}  // namespace handlabel
