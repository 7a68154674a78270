#pragma once
// The HO3D v3 fixture written from a synthetic capture; shared by the reader's tests
// (tests/capture) and the job tests (tests/pipeline/dataset_jobs_test.cc).

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>

#include "capture/ho3d_frame_source.h"
#include "capture/synth_capture.h"
#include "core/errors.h"
#include "hand/capsule_hand.h"
#include "image/image_file.h"
#include "tests/hand/mano_sized_model.h"  // Py2PickleWriter
#include "tests/test_util.h"

namespace handlabel {
namespace testing {

namespace fs = std::filesystem;

inline const std::string kData = std::string(HANDLABEL_SOURCE_DIR) + "/tests/data/ho3d";

struct Ho3dFixture {
  std::string root;
  std::string split;  // <root>/train
  Rig rig;            // cameras ABF1<i>
  std::vector<SynthFrame> frames;
};

inline std::string Fid(int frame) {
  char text[16];
  std::snprintf(text, sizeof(text), "%04d", frame);
  return text;
}

// One meta pickle: handJoints3D (float32, OpenGL camera axes, MANO order + tips) and
// a few of HO3D's other keys.
inline void WriteMeta(const std::string& path, const Points3d& snap_in_camera) {
  std::vector<float> gl(3 * kNumHandKeypoints);
  for (int k = 0; k < kNumHandKeypoints; ++k) {
    const int n = kSnapFromNative[k];
    gl[3 * n] = static_cast<float>(snap_in_camera(k, 0));
    gl[3 * n + 1] = static_cast<float>(-snap_in_camera(k, 1));
    gl[3 * n + 2] = static_cast<float>(-snap_in_camera(k, 2));
  }
  const std::vector<float> pose(48, 0.1f);
  testing::Py2PickleWriter w;
  w.Proto();
  w.BeginDict();
  w.Str("handPose");
  w.Array({48}, "f4", pose.data(), pose.size() * 4);
  w.Str("handJoints3D");
  w.Array({kNumHandKeypoints, 3}, "f4", gl.data(), gl.size() * 4);
  w.Str("objName");
  w.Str("006_mustard_bottle");
  w.EndDict();
  fs::create_directories(fs::path(path).parent_path());
  std::ofstream(path, std::ios::binary) << w.Finish();
}

inline Ho3dFixture WriteHo3dFixture(const std::string& root, int num_frames = 2,
                                    int num_cameras = 3) {
  SynthCaptureOptions synth;
  synth.rig.preset = "dexycb";
  synth.rig.width = 640;  // HO3D's calibration files imply 640x480
  synth.rig.height = 480;
  synth.seed = 4;
  synth.num_threads = 1;
  const Rig preset = MakePresetRig(synth.rig, 0);
  Ho3dFixture fx;
  fx.root = root;
  fx.split = root + "/train";
  const std::string calib = root + "/calibration/ABF1/calibration";
  fs::create_directories(calib);
  // As in HO3D: the files with index i belong to camera folder ABF1<order[i]>, and the
  // order is not the identity; whitespace-separated (np.loadtxt).
  std::ofstream orders(calib + "/cam_orders.txt");
  for (int i = 0; i < num_cameras; ++i) {
    const int c = (i + 1) % num_cameras;
    const RigCamera& camera = preset[c];
    fx.rig.Add({"ABF1" + std::to_string(c), camera.camera, camera.cam_from_world});
    orders << (i ? " " : "") << c;
    const std::vector<double>& k = camera.camera.params();
    std::ofstream intr(calib + "/cam_" + std::to_string(i) + "_intrinsics.txt");
    intr.precision(17);
    intr << "fx:" << k[0] << ", fy:" << k[1] << ", ppx:" << k[2] << ", ppy:" << k[3]
         << "\n";
    std::ofstream trans(calib + "/trans_" + std::to_string(i) + ".txt");
    trans.precision(17);
    const Matrix3x4d m = camera.cam_from_world.Inverse().ToMatrix();  // cam -> common
    for (int r = 0; r < 3; ++r)
      trans << m(r, 0) << " " << m(r, 1) << " " << m(r, 2) << " " << m(r, 3) << "\n";
    trans << "0 0 0 1\n";
  }
  const SynthGenerator generator(MakeCapsuleHand(HandSide::kRight), fx.rig, synth);
  JpegWriteOptions jpeg;
  jpeg.quality = 100;
  for (int f = 0; f < num_frames; ++f) {
    fx.frames.push_back(generator.Generate(f));
    for (size_t v = 0; v < fx.rig.size(); ++v) {
      const std::string dir = fx.split + "/" + fx.rig[v].name;
      WriteJpeg(dir + "/rgb/" + Fid(f) + ".jpg", fx.frames[f].views[v].rgb, jpeg);
      Points3d in_camera(kNumHandKeypoints, 3);
      for (int k = 0; k < kNumHandKeypoints; ++k) {
        in_camera.row(k) =
            (fx.rig[v].cam_from_world *
             Eigen::Vector3d(fx.frames[f].scene.hand.keypoints.row(k).transpose()))
                .transpose();
      }
      WriteMeta(dir + "/meta/" + Fid(f) + ".pkl", in_camera);
    }
  }
  return fx;
}

}  // namespace testing
}  // namespace handlabel
