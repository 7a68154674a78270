#pragma once
// Flags shared by the `model` subcommands that load a model file: the side and the
// fingertips for files that do not record them (hand/hand_model_io.h).

#include <CLI/CLI.hpp>
#include <algorithm>
#include <array>
#include <string>
#include <vector>

#include "hand/hand_model_io.h"

namespace handlabel {

struct ModelFileFlags {
  std::string side;  // "", "left" or "right"
  std::vector<int> tips;

  void Register(CLI::App& app) {
    app.add_option("--side", side,
                   "side for files that do not record it (MANO pickles, smplx npz); "
                   "default: from the file name (MANO_LEFT / MANO_RIGHT)")
        ->check(CLI::IsMember(
            {HandSideName(HandSide::kLeft), HandSideName(HandSide::kRight)}));
    app.add_option("--tips", tips,
                   "fingertip vertex ids thumb,index,middle,ring,pinky for files without "
                   "them; default for 778-vertex MANO: 745,317,444,556,673 (manopth)")
        ->delimiter(',')
        ->expected(5);
  }

  HandModelLoadOptions Options() const {
    HandModelLoadOptions options;
    if (!side.empty()) options.side = ParseHandSide(side, "--side", "value");
    if (!tips.empty()) {
      std::array<int, 5> t;
      std::copy(tips.begin(), tips.end(), t.begin());
      options.tip_vertex_ids = t;
    }
    return options;
  }
};

}  // namespace handlabel
