#include "training/sample_sheet.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/errors.h"
#include "hand/hand_skeleton.h"
#include "image/draw.h"

namespace handlabel {
namespace {

constexpr int kGap = 2;  // pixels between tiles

int CropSide(const TrainingView& view) {
  return static_cast<int>(std::lround(std::sqrt(view.image.size() / 3.0)));
}

void DrawTile(const TrainingView& view, int side, int x0, int y0, ImageU8* sheet) {
  for (int y = 0; y < side; ++y) {
    for (int x = 0; x < side; ++x) {
      for (int c = 0; c < 3; ++c) {
        const float v = view.image[(static_cast<size_t>(c) * side + y) * side + x];
        sheet->at(x0 + x, y0 + y, c) =
            static_cast<uint8_t>(std::clamp(std::lround((v + 0.5f) * 255.0f), 0L, 255L));
      }
    }
  }
  // Bones with both ends inside the crop (a target may lie outside it).
  const auto inside = [side](const Eigen::Vector2d& p) {
    return p.minCoeff() >= 0 && p.maxCoeff() <= side - 1;
  };
  const Eigen::Vector2d origin(x0, y0);
  for (int k = 1; k < static_cast<int>(kSnapParents.size()); ++k) {
    const int p = kSnapParents[k];
    const Eigen::Vector2d a = view.joints_2d.row(p).transpose();
    const Eigen::Vector2d b = view.joints_2d.row(k).transpose();
    if (view.joints_2d_weight[k] <= 0 || view.joints_2d_weight[p] <= 0 || !inside(a) ||
        !inside(b)) {
      continue;
    }
    DrawLine(sheet, origin + a, origin + b, SnapKeypointColor(k));
  }
  if (view.view_weight > 0) return;
  const Rgb red = {255, 0, 0};
  const Eigen::Vector2d c00(x0, y0), c10(x0 + side - 1, y0), c01(x0, y0 + side - 1),
      c11(x0 + side - 1, y0 + side - 1);
  DrawLine(sheet, c00, c10, red, 2);
  DrawLine(sheet, c00, c01, red, 2);
  DrawLine(sheet, c10, c11, red, 2);
  DrawLine(sheet, c01, c11, red, 2);
}

}  // namespace

ImageU8 MakeTrainingSampleSheet(const std::vector<TrainingSample>& samples) {
  if (samples.empty() || samples[0].views.empty()) {
    throw InputError("sample sheet", "samples", "at least one sample with views", "none");
  }
  const size_t views = samples[0].views.size();
  const int side = CropSide(samples[0].views[0]);
  for (size_t i = 0; i < samples.size(); ++i) {
    if (samples[i].views.size() != views) {
      throw InputError("sample sheet", "samples[" + std::to_string(i) + "].views",
                       std::to_string(views) + " views as samples[0]",
                       std::to_string(samples[i].views.size()));
    }
    for (const TrainingView& view : samples[i].views) {
      if (CropSide(view) != side ||
          view.image.size() != 3 * static_cast<size_t>(side) * side) {
        throw InputError("sample sheet", "samples[" + std::to_string(i) + "] crop",
                         "3 x " + std::to_string(side) + " x " + std::to_string(side),
                         std::to_string(view.image.size()) + " values");
      }
    }
  }
  const int cell = side + kGap;
  ImageU8 sheet(static_cast<int>(views) * cell - kGap,
                static_cast<int>(samples.size()) * cell - kGap, 3, 255);
  for (size_t i = 0; i < samples.size(); ++i) {
    for (size_t v = 0; v < views; ++v) {
      DrawTile(samples[i].views[v], side, static_cast<int>(v) * cell,
               static_cast<int>(i) * cell, &sheet);
    }
  }
  return sheet;
}

}  // namespace handlabel
