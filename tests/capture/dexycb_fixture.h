#pragma once
// A small synthetic capture written in the DexYCB layout (../shared/datasets.md): the
// calibration folder, meta.yml, color_%06d.jpg and labels_%06d.npz per camera, from
// frames rendered by SynthGenerator, so tests know the truth of every file.

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "capture/synth_capture.h"
#include "formats/npz.h"
#include "image/image_file.h"

namespace handlabel::testing {

struct DexYcbFixture {
  std::string root;      // DexYCB root (holds calibration/)
  std::string sequence;  // <root>/<subject>/<sequence>
  Rig rig;               // what the calibration files say, cameras named by serial
  std::vector<SynthFrame> frames;
};

struct DexYcbFixtureOptions {
  std::string subject = "20200709-subject-01";
  std::string sequence = "20200709_141754";
  std::string side = "right";  // mano_sides[0]
  int num_frames = 3;
  int num_cameras = 4;  // the first ones of the DexYCB preset
  uint64_t seed = 3;
  bool labels = true;  // write labels_%06d.npz
};

inline std::string DexYcbNumber(int frame) {
  char text[16];
  std::snprintf(text, sizeof(text), "%06d", frame);
  return text;
}

inline DexYcbFixture WriteDexYcbFixture(const std::string& root, const HandModel& model,
                                        const DexYcbFixtureOptions& o = {}) {
  namespace fs = std::filesystem;
  const std::vector<std::string> serials = {
      "836212060125", "839512060362", "840412060917", "841412060263",
      "932122060857", "932122060861", "932122061900", "932122062010"};
  SynthCaptureOptions synth;
  synth.rig.preset = "dexycb";
  synth.rig.width = 160;
  synth.rig.height = 120;
  synth.seed = o.seed;
  synth.num_threads = 1;
  const Rig preset = MakePresetRig(synth.rig, 0);
  DexYcbFixture fixture;
  fixture.root = root;
  fixture.sequence = root + "/" + o.subject + "/" + o.sequence;
  for (int c = 0; c < o.num_cameras; ++c)
    fixture.rig.Add({serials[c], preset[c].camera, preset[c].cam_from_world});

  const std::string calib_id = o.subject;
  const std::string intrinsics = root + "/calibration/intrinsics";
  const std::string extrinsics = root + "/calibration/extrinsics_" + calib_id;
  fs::create_directories(intrinsics);
  fs::create_directories(extrinsics);
  std::ofstream extr(extrinsics + "/extrinsics.yml");
  extr.precision(17);
  extr << "extrinsics:\n";
  for (const RigCamera& camera : fixture.rig.cameras()) {
    const std::vector<double>& k = camera.camera.params();  // fx fy cx cy
    std::ofstream intr(intrinsics + "/" + camera.name + "_160x120.yml");
    intr.precision(17);
    intr << "color:\n  fx: " << k[0] << "\n  fy: " << k[1] << "\n  ppx: " << k[2]
         << "\n  ppy: " << k[3] << "\ndepth:\n  fx: 1\n  fy: 1\n  ppx: 0\n  ppy: 0\n";
    // camera -> common, 3x4 row-major
    const Matrix3x4d m = camera.cam_from_world.Inverse().ToMatrix();
    extr << "  '" << camera.name << "': [";
    for (int i = 0; i < 12; ++i) extr << (i ? ", " : "") << m(i / 4, i % 4);
    extr << "]\n";
  }
  extr << "master: '" << fixture.rig[0].name << "'\n";

  fs::create_directories(fixture.sequence);
  std::ofstream meta(fixture.sequence + "/meta.yml");
  meta << "serials:\n";
  for (const RigCamera& camera : fixture.rig.cameras())
    meta << "- '" << camera.name << "'\n";
  meta << "extrinsics: " << calib_id << "\nnum_frames: " << o.num_frames
       << "\nmano_sides:\n- " << o.side << "\nmano_calib: " << calib_id
       << "\nycb_ids:\n- 2\n";

  const SynthGenerator generator(model, fixture.rig, synth);
  JpegWriteOptions jpeg;
  jpeg.quality = 100;
  for (int f = 0; f < o.num_frames; ++f) {
    fixture.frames.push_back(generator.Generate(f));
    const SynthFrame& frame = fixture.frames.back();
    for (size_t v = 0; v < fixture.rig.size(); ++v) {
      const std::string dir = fixture.sequence + "/" + fixture.rig[v].name;
      WriteJpeg(dir + "/color_" + DexYcbNumber(f) + ".jpg", frame.views[v].rgb, jpeg);
      if (!o.labels) continue;
      Points3d in_camera(kNumHandKeypoints, 3);
      for (int k = 0; k < kNumHandKeypoints; ++k) {
        in_camera.row(k) =
            (fixture.rig[v].cam_from_world *
             Eigen::Vector3d(frame.scene.hand.keypoints.row(k).transpose()))
                .transpose();
      }
      const Eigen::MatrixXd uv = frame.views[v].keypoints;
      const Eigen::MatrixXd xyz = in_camera;
      NdArray joint_2d = NdArray::FromMatrix(uv);
      joint_2d.shape = {1, kNumHandKeypoints, 2};
      NdArray joint_3d = NdArray::FromMatrix(xyz);
      joint_3d.shape = {1, kNumHandKeypoints, 3};
      WriteNpzFile(dir + "/labels_" + DexYcbNumber(f) + ".npz",
                   {{"joint_2d", joint_2d}, {"joint_3d", joint_3d}});
    }
  }
  return fixture;
}

}  // namespace handlabel::testing
