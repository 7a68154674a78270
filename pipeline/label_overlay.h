#pragma once
// Overlay pictures of a label: on every view's image, the label's mesh (shaded,
// half transparent, drawn with the real camera model, distortion included) and its 21
// keypoints with the hand skeleton, one colour per finger. Written atomically as
// <output.dir>/overlays/<frame>/<camera>.jpg (or .png: output.overlay_format). When the
// job's 2D came from the hand detector, its palms, ROI, keypoints and per-view reason are
// drawn too.

#include <memory>
#include <string>

#include "hand/hand_model.h"
#include "image/image.h"
#include "image/rasterizer.h"
#include "pipeline/detect_frame_source.h"
#include "pipeline/label_job.h"

namespace handlabel {

// Draws the label onto one view's image (RGB, the camera's size); `rays` are
// PixelRays(camera.camera).
void DrawLabelOverlay(const RigCamera& camera, const PixelRays& rays,
                      const LabelRecord& label, const Faces& faces, ImageU8* rgb);

class RasterOverlayWriter : public OverlayWriter {
 public:
  // `detections`: the detector's answers when the job's 2D comes from it
  // (evidence.keypoints_2d: detector); each view then also shows its detection
  // (network/detector/detector_overlay.h). Null: the label only.
  // `format`: jpg | png (output.overlay_format).
  RasterOverlayWriter(const HandModel& model, std::string format,
                      std::shared_ptr<DetectionStore> detections = nullptr)
      : faces_(model.faces),
        format_(std::move(format)),
        detections_(std::move(detections)) {}
  // Takes each view's image (the frame's decoded one, else its file; a grey picture
  // for a view without an image file), draws, writes. An image that cannot be read or has
  // another size than its camera throws (the frame fails naming the file): never a grey
  // overlay over a broken capture.
  void Write(const std::string& output_dir, const FrameInput& frame,
             const LabelRecord& label) const override;

 private:
  Faces faces_;
  std::string format_;
  std::shared_ptr<DetectionStore> detections_;
  mutable PixelRaysCache rays_;
};

}  // namespace handlabel
