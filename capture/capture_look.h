#pragma once
// A capture's own look for synthetic training hands (docs/adapt.md, --synth-share): each
// camera's empty scene taken from the recording (the per-pixel median over frames with
// the labelled hand and a forearm band left out), and synthetic-capture options that
// draw hands with the capture's cameras over those pictures, where its labels put the
// hand.

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "capture/frame_source.h"
#include "capture/synth_capture.h"
#include "geometry/rig.h"
#include "image/image.h"

namespace handlabel {

// Where a hand with these 21 world keypoints covers the camera's image: discs around
// the keypoints and a band along the forearm (the wrist continued away from the
// fingers for three hand lengths), as wide as a third of the hand's extent. 255 =
// covered; nothing for a hand behind the camera.
ImageU8 HandCoverMask(const RigCamera& camera, const Points3d& keypoints);

// Per camera of `source`'s rig (rig order), the median of `frames`' images with each
// frame's hand (`hand_keypoints[i]`, world) left out. Throws InputError naming the
// camera when none of the frames has an image of it.
std::vector<ImageU8> EmptySceneBackgrounds(const FrameSource& source,
                                           const std::vector<std::string>& frames,
                                           const std::vector<Points3d>& hand_keypoints,
                                           Rig* rig);

// The cameras without lens distortion (training crops are pinhole).
Rig PinholeRig(const Rig& rig);

// The rig's "up": against the cameras' mean viewing direction (cameras look down at
// the hand more often than up at it); +z when their directions cancel (a dome, a ring
// of cameras at the hand's height), where the mean says nothing.
Eigen::Vector3d RigUp(const Rig& rig);

// Realistic hands (half of them holding objects) over `photos` (one per camera of
// `rig`), lit from the rig's up, placed around the labelled hands' median centre within
// the distance that holds 80 % of them (3-25 cm).
SynthCaptureOptions CaptureLookSynthOptions(
    const Rig& rig, const std::vector<Points3d>& hand_keypoints,
    std::shared_ptr<const std::vector<ImageU8>> photos, uint64_t seed);

}  // namespace handlabel
