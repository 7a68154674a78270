#pragma once
// A picture of training samples as the network sees them: one row per sample, one tile
// per view (the input crop), the sample's 2D keypoint targets drawn as the hand's
// skeleton over it (the finger colours of hand/hand_skeleton.h). It shows at a glance
// whether targets lie on the hands and what the crops of each source look like
// (`handlabel adapt` writes train/samples.jpg). Views of weight 0 (no hand located; the
// crop is the whole image) get a red frame.

#include <vector>

#include "image/image.h"
#include "network/poem/training_sample.h"

namespace handlabel {

// Throws InputError if `samples` is empty or their views or crop sizes differ.
ImageU8 MakeTrainingSampleSheet(const std::vector<TrainingSample>& samples);

}  // namespace handlabel
