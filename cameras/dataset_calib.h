#pragma once
// Rigs from dataset calibration files (see docs/cameras.md for the layouts):
//   dexycb  PATH = calibration/extrinsics_<id>/extrinsics.yml, or a sequence's
//           meta.yml (its `extrinsics` id is looked up under <root>/calibration);
//           intrinsics from calibration/intrinsics/<serial>_640x480.yml (the size
//           DexYCB's toolkit reads; another size only when it is the serial's only
//           file). World = DexYCB's common frame (camera_from_common = inverse of the
//           file's camera -> common 3x4); cameras named by serial. Without meta.yml
//           the cameras are the `extrinsics` keys except `apriltag` (the tag's pose
//           in the common frame, not a camera).
//   ho3d    PATH = calibration/<SEQ>/calibration folder: cam_orders.txt (camera
//           folder indices, whitespace-separated as np.loadtxt reads them),
//           trans_<i>.txt (4x4 camera -> common), cam_<i>_intrinsics.txt. The files
//           with index i belong to camera <SEQ><cams_order[i]> (HO3D's multi-camera
//           viewer pairs them so); the rig lists the cameras in file order.
//   oakink  PATH = a folder of OakInk general_info pickles (or one pickle): one
//           camera per <cam> suffix from cam_intr (3x3) and cam_extr (4x4 world ->
//           camera), taken from the first frame of each camera.

#include <string>
#include <vector>

#include "cameras/rig_json.h"
#include "geometry/rig.h"

namespace handlabel {

std::vector<std::string> DatasetRigFormats();

// Throws InputError naming the file and field for anything missing or malformed.
Rig ReadDatasetRig(const std::string& format, const std::string& path,
                   RigFileInfo* info = nullptr);

// One OakInk camera from one general_info pickle (cam_intr 3x3, cam_extr 4x4 world ->
// camera; PINHOLE 848x480), named `name`: what ReadDatasetRig("oakink", ...) reads per
// camera, for readers that already know which pickles form a frame. Throws InputError
// naming the file and key.
RigCamera ReadOakInkCamera(const std::string& path, const std::string& name);

}  // namespace handlabel
