#pragma once
// A frame source that reads its frames from another and replaces their 2D keypoints
// (from a folder of detections, from a detector): frame ids, hand side and the inner
// source's description are forwarded; subclasses say where the 2D comes from
// (KeypointsSource) and fill it in Load.

#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "capture/frame_source.h"

namespace handlabel {

class Replaced2dFrameSource : public FrameSource {
 public:
  explicit Replaced2dFrameSource(std::unique_ptr<FrameSource> inner)
      : inner_(std::move(inner)) {}
  std::vector<std::string> FrameIds() const override { return inner_->FrameIds(); }
  std::optional<HandSide> side() const override { return inner_->side(); }
  std::string Describe() const override {
    return inner_->Describe() + "; 2D keypoints from " + KeypointsSource();
  }

 protected:
  std::unique_ptr<FrameSource> inner_;
};

}  // namespace handlabel
