#pragma once
// Overlay pictures of a label: on every view's image, the label's mesh (shaded,
// half transparent, drawn with the real camera model, distortion included) and its 21
// keypoints with the hand skeleton, one colour per finger. Written atomically as
// <output.dir>/overlays/<frame>/<camera>.png.

#include <string>

#include "core/hand_model.h"
#include "core/image.h"
#include "pipeline/label_job.h"

namespace handlabel {

// Draws the label onto one view's image (RGB, the camera's size).
void DrawLabelOverlay(const RigCamera& camera, const LabelRecord& label,
                      const Faces& faces, ImageU8* rgb);

class RasterOverlayWriter : public OverlayWriter {
 public:
  explicit RasterOverlayWriter(const HandModel& model) : faces_(model.faces) {}
  // Reads each view's image (a grey picture for a view without an image file), draws,
  // writes. An image that cannot be read or has another size than its camera throws
  // (the frame fails naming the file): never a grey overlay over a broken capture.
  void Write(const std::string& output_dir, const FrameInput& frame,
             const LabelRecord& label) const override;

 private:
  Faces faces_;
};

}  // namespace handlabel
