#pragma once
// The OakInk-Image fixture written from a synthetic capture; shared by the reader's tests
// (tests/capture) and the job tests (tests/pipeline/dataset_jobs_test.cc).

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>

#include "capture/oakink_frame_source.h"
#include "capture/synth_capture.h"
#include "core/errors.h"
#include "hand/capsule_hand.h"
#include "image/image.h"
#include "image/image_file.h"
#include "tests/hand/mano_sized_model.h"  // Py2PickleWriter
#include "tests/test_util.h"

namespace handlabel {
namespace testing {

namespace fs = std::filesystem;

inline const std::string kGroup = "A01001_0001_0000__2021-09-26-19-59-58__0__";

struct OakInkFixture {
  std::string image_dir;  // <root>/image
  Rig rig;                // cameras "0".."3"
  std::vector<SynthFrame> frames;
  std::vector<std::string> ids;
};

inline void WritePickle(const std::string& path, const std::string& bytes) {
  fs::create_directories(fs::path(path).parent_path());
  std::ofstream(path, std::ios::binary) << bytes;
}

// A pickled float32 N x 3 array of points in `cam_from_world`'s camera frame.
inline std::string PointsPickle(const Points3d& in_world, const Rigid3& cam_from_world) {
  std::vector<float> v;
  for (Eigen::Index i = 0; i < in_world.rows(); ++i) {
    const Eigen::Vector3d p =
        cam_from_world * Eigen::Vector3d(in_world.row(i).transpose());
    v.insert(v.end(), {float(p.x()), float(p.y()), float(p.z())});
  }
  testing::Py2PickleWriter w;
  w.Proto();
  w.Array({in_world.rows(), 3}, "f4", v.data(), v.size() * 4);
  return w.Finish();
}

inline OakInkFixture WriteOakInkFixture(const std::string& root, int num_frames = 2) {
  SynthCaptureOptions synth;
  synth.rig.preset = "dexycb";
  synth.rig.width = 848;  // OakInk's calibration implies 848x480
  synth.rig.height = 480;
  synth.seed = 6;
  synth.num_threads = 1;
  const Rig preset = MakePresetRig(synth.rig, 0);
  OakInkFixture fx;
  fx.image_dir = root + "/image";
  for (int c = 0; c < 4; ++c)
    fx.rig.Add({std::to_string(c), preset[c].camera, preset[c].cam_from_world});
  const SynthGenerator generator(MakeCapsuleHand(HandSide::kRight), fx.rig, synth);
  const std::string anno = fx.image_dir + "/anno";
  for (int f = 0; f < num_frames; ++f) {
    fx.frames.push_back(generator.Generate(f));
    const std::string frame = std::to_string(12 + f);  // unpadded, as oikit names them
    fx.ids.push_back(kGroup + frame);
    for (int c = 0; c < 4; ++c) {
      const RigCamera& camera = fx.rig[c];
      const std::string name = fx.ids.back() + "__" + camera.name + ".pkl";
      const std::vector<double>& k = camera.camera.params();
      const double intr[9] = {k[0], 0, k[2], 0, k[1], k[3], 0, 0, 1};
      Eigen::Matrix<double, 4, 4, Eigen::RowMajor> extr = Eigen::Matrix4d::Identity();
      extr.topRows<3>() = camera.cam_from_world.ToMatrix();  // world -> camera
      const float tsl[3] = {0.1f, 0.2f, 0.3f};
      testing::Py2PickleWriter w;
      w.Proto();
      w.BeginDict();
      w.Str("cam_intr");
      w.Doubles({3, 3}, intr, 9);
      w.Str("cam_extr");
      w.Doubles({4, 4}, extr.data(), 16);
      w.Str("hand_anno");
      w.BeginDict();
      w.Str("hand_tsl");
      w.Array({3}, "f4", tsl, 12);
      w.EndDict();
      w.EndDict();
      WritePickle(anno + "/general_info/" + name, w.Finish());
      WritePickle(anno + "/hand_j/" + name,
                  PointsPickle(fx.frames[f].scene.hand.keypoints, camera.cam_from_world));
      WritePickle(anno + "/hand_v/" + name,
                  PointsPickle(fx.frames[f].scene.hand.vertices, camera.cam_from_world));
      WritePng(fx.image_dir + "/stream_release_v2/A01001_0001_0000/2021-09-26-19-59-58/" +
                   OakInkStreamName(camera.name) + "_" + frame + ".png",
               fx.frames[f].views[c].rgb);
    }
  }
  return fx;
}

}  // namespace testing
}  // namespace handlabel
