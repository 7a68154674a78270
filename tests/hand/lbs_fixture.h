#pragma once
// Loads tests/data/lbs/lbs_fixture.json (written by make_lbs_fixture.py with NumPy):
// a random MANO-structured model plus parameter sets and expected outputs.

#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "hand/hand_lbs.h"
#include "hand/hand_model.h"
#include "hand/hand_params_json.h"

namespace handlabel::testing {

inline Eigen::MatrixXd JsonMatrix(const nlohmann::json& j) {
  const Eigen::Index rows = j.size();
  const Eigen::Index cols = rows ? j[0].size() : 0;
  Eigen::MatrixXd m(rows, cols);
  for (Eigen::Index r = 0; r < rows; ++r) {
    for (Eigen::Index c = 0; c < cols; ++c) m(r, c) = j[r][c].get<double>();
  }
  return m;
}

inline Eigen::VectorXd JsonVector(const nlohmann::json& j) {
  Eigen::VectorXd v(j.size());
  for (size_t i = 0; i < j.size(); ++i) v[i] = j[i].get<double>();
  return v;
}

inline nlohmann::json LoadLbsFixtureJson() {
  const std::string path =
      std::string(HANDLABEL_SOURCE_DIR) + "/tests/data/lbs/lbs_fixture.json";
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot open " + path);
  return nlohmann::json::parse(in);
}

inline HandModel LbsFixtureModel(const nlohmann::json& fixture) {
  const nlohmann::json& m = fixture["model"];
  HandModel model;
  model.name = "lbs_fixture";
  model.v_template = JsonMatrix(m["v_template"]);
  model.faces = JsonMatrix(m["faces"]).cast<int>();
  model.shapedirs = JsonMatrix(m["shapedirs"]);
  model.posedirs = JsonMatrix(m["posedirs"]);
  model.joint_regressor = JsonMatrix(m["J_regressor"]).sparseView();
  model.skinning_weights = JsonMatrix(m["weights"]);
  for (int j = 0; j < kNumHandJoints; ++j) model.parents[j] = fixture["parents"][j];
  for (int t = 0; t < 5; ++t) model.tip_vertex_ids[t] = m["tip_vertex_ids"][t];
  model.pose_pca_basis = JsonMatrix(m["hands_components"]);
  model.pose_mean = JsonVector(m["hands_mean"]);
  model.Check("lbs_fixture.json");
  return model;
}

inline HandParams JsonHandParams(const nlohmann::json& c) {
  HandParams p;
  p.global_orient = JsonVector(c["global_orient"]);
  p.hand_pose = JsonVector(c["hand_pose"]);
  p.betas = JsonVector(c["betas"]);
  p.transl = JsonVector(c["transl"]);
  return p;
}

}  // namespace handlabel::testing
