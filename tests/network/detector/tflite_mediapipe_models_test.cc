// MediaPipe Hands' real models (scripts/fetch-mediapipe-models) in our interpreter:
// they load, contain only the operators the issue lists, and the landmark model finds
// a rendered hand (high presence, landmarks on the hand) but not noise.

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <set>
#include <sstream>

#include "core/data_dir.h"
#include "core/errors.h"
#include "core/file_bytes.h"
#include "hand/hand_model.h"
#include "hand/hand_model_io.h"
#include "image/image.h"
#include "image/image_file.h"
#include "image/mesh_render.h"
#include "network/detector/mediapipe_hands.h"
#include "network/detector/tflite_model.h"
#include "network/detector/tflite_reader.h"

namespace handlabel {
namespace {

std::string MediapipeModel(const std::string& name) {
  return ShippedModelPath("mediapipe/" + name);
}

// Skips when the models were not fetched (scripts/install-deps fetches them).
#define REQUIRE_MEDIAPIPE_MODELS()                                             \
  if (!std::filesystem::exists(MediapipeModel("hand_landmark_full.tflite"))) { \
    GTEST_SKIP() << "no MediaPipe models in " << MediapipeModel("")            \
                 << ": run scripts/fetch-mediapipe-models";                    \
  }

// RGB image -> float NHWC in [0, 1] (MediaPipe's landmark input range).
std::vector<float> ToInput(const ImageU8& image) {
  std::vector<float> x(image.data.size());
  for (size_t i = 0; i < x.size(); ++i) x[i] = image.data[i] / 255.0f;
  return x;
}

// The open right hand at rest, seen along its -y axis with the fingers up, filling 60 %
// of a 224 x 224 crop on a grey background (Lambert-shaded skin: image/mesh_render.h),
// and its 21 SNAP keypoints (joint regressor + fingertip vertices) projected the same
// way: the landmark model's ground truth.
struct RenderedHand {
  ImageU8 image;
  std::vector<Eigen::Vector2d> keypoints;
};
RenderedHand RenderHandCrop() {
  const HandModel hand = LoadHandModel(ShippedModelPath("open_hand_right.npz"));
  std::vector<Eigen::Vector3d> vertices;
  for (int v = 0; v < hand.num_vertices(); ++v)
    vertices.push_back(hand.v_template.row(v).transpose());
  std::vector<Eigen::Vector3i> faces;
  for (int f = 0; f < hand.num_faces(); ++f)
    faces.push_back(hand.faces.row(f).transpose());
  Eigen::Vector3d lo = vertices[0], hi = vertices[0];
  for (const auto& v : vertices) {
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
  // MANO-style rest hand: fingers along +x; view along -y with image up = +x.
  const int size = 224;
  const MeshView view = LookAlong(Eigen::Vector3d(0, -1, 0), Eigen::Vector3d(-1, 0, 0),
                                  (lo + hi) / 2, 0.6 * size / (hi - lo).maxCoeff());
  RenderedHand out{ImageU8(size, size, 3, 128), {}};
  DrawMeshOrthographic(vertices, faces, {}, view, &out.image);
  const Eigen::MatrixXd joints = hand.joint_regressor * hand.v_template;  // 16 x 3
  for (int k = 0; k < 21; ++k) {
    const int native = kSnapFromNative[k];
    const Eigen::Vector3d p =
        native < kNumHandJoints
            ? Eigen::Vector3d(joints.row(native).transpose())
            : Eigen::Vector3d(
                  hand.v_template.row(hand.tip_vertex_ids[native - kNumHandJoints])
                      .transpose());
    const Eigen::Vector3d v = view.view_from_model * (p - view.centre);
    // DrawMeshOrthographic's projection: image centre + view coordinates x scale.
    out.keypoints.push_back(Eigen::Vector2d(0.5 * (size - 1), 0.5 * (size - 1)) +
                            view.pixels_per_metre * v.head<2>());
  }
  return out;
}

TEST(TfliteMediapipeModels, LoadWithTheExpectedOpsAndShapes) {
  REQUIRE_MEDIAPIPE_MODELS();
  const std::set<std::string> listed{
      "DEQUANTIZE",   "CONV_2D",         "DEPTHWISE_CONV_2D", "ADD",
      "MEAN",         "FULLY_CONNECTED", "LOGISTIC",          "PRELU",
      "PAD",          "MAX_POOL_2D",     "RESIZE_BILINEAR",   "RESHAPE",
      "CONCATENATION"};
  for (const char* name : {"hand_landmark_full.tflite", "hand_landmark_lite.tflite"}) {
    auto model = TfliteModel::Load(MediapipeModel(name));
    for (const auto& op : model->op_names())
      EXPECT_TRUE(listed.count(op)) << name << " " << op;
    ASSERT_EQ(model->inputs().size(), 1u);
    EXPECT_EQ(model->inputs()[0].shape, (std::vector<int>{1, 224, 224, 3}));
    ASSERT_EQ(model->outputs().size(), 4u);
    EXPECT_EQ(model->outputs()[0].shape, (std::vector<int>{1, 63}));  // landmarks
    EXPECT_EQ(model->outputs()[1].shape, (std::vector<int>{1, 1}));   // presence
    EXPECT_EQ(model->outputs()[2].shape, (std::vector<int>{1, 1}));   // handedness
    EXPECT_EQ(model->outputs()[3].shape, (std::vector<int>{1, 63}));  // world landmarks
  }
  for (const char* name : {"palm_detection_full.tflite", "palm_detection_lite.tflite"}) {
    auto model = TfliteModel::Load(MediapipeModel(name));
    for (const auto& op : model->op_names())
      EXPECT_TRUE(listed.count(op)) << name << " " << op;
    EXPECT_EQ(model->inputs()[0].shape, (std::vector<int>{1, 192, 192, 3}));
    ASSERT_EQ(model->outputs().size(), 2u);
    EXPECT_EQ(model->outputs()[0].shape, (std::vector<int>{1, 2016, 18}));  // boxes
    EXPECT_EQ(model->outputs()[1].shape, (std::vector<int>{1, 2016, 1}));   // scores
  }
}

TEST(TfliteMediapipeModels, LandmarkModelFindsARenderedHandButNotNoise) {
  REQUIRE_MEDIAPIPE_MODELS();
  const RenderedHand hand = RenderHandCrop();
  for (const char* name : {"hand_landmark_full.tflite", "hand_landmark_lite.tflite"}) {
    auto model = TfliteModel::Load(MediapipeModel(name));
    const auto out = model->Run({ToInput(hand.image)});
    EXPECT_GT(out[1][0], 0.9f) << name << " presence";
    // Landmarks (crop pixels) on the drawn hand's keypoints. MediaPipe's landmarks are
    // not MANO's joint centres (e.g. its MCPs sit nearer the knuckle surface), so the
    // bound is a few pixels on a hand about 130 pixels long.
    double sum = 0;
    for (int k = 0; k < 21; ++k) {
      const Eigen::Vector2d p(out[0][3 * k], out[0][3 * k + 1]);
      const double error = (p - hand.keypoints[k]).norm();
      sum += error;
      EXPECT_LT(error, 15.0) << name << " landmark " << k << " at " << p.transpose()
                             << ", drawn at " << hand.keypoints[k].transpose();
    }
    EXPECT_LT(sum / 21, 7.0) << name << " mean landmark error (px)";
  }
  auto model = TfliteModel::Load(MediapipeModel("hand_landmark_full.tflite"));
  std::mt19937 rng(5);
  std::uniform_int_distribution<int> byte(0, 255);
  ImageU8 noise(224, 224, 3);
  for (auto& v : noise.data) v = static_cast<uint8_t>(byte(rng));
  EXPECT_LT(model->Run({ToInput(noise)})[1][0], 0.1f);
  ImageU8 grey(224, 224, 3, 128);
  EXPECT_LT(model->Run({ToInput(grey)})[1][0], 0.1f);
}

// Nearest-neighbour resize of a square RGB image to size x size floats in [0, 1].
std::vector<float> ResizedInput(const ImageU8& image, int size) {
  std::vector<float> x;
  for (int y = 0; y < size; ++y) {
    for (int xx = 0; xx < size; ++xx) {
      for (int c = 0; c < 3; ++c) {
        x.push_back(image.at(xx * image.width / size, y * image.height / size, c) /
                    255.0f);
      }
    }
  }
  return x;
}

// The palm box centre of the best-scoring anchor, in the input's [0, 1] coordinates:
// MediaPipe's SSD layout for 192 x 192 (2 anchors per cell of the 24 x 24 map, then 6
// per cell of the 12 x 12 map, anchor centres at cell centres), box offsets in pixels
// of the 192 input. Returns the best raw score logit.
float BestPalm(const std::vector<std::vector<float>>& out, Eigen::Vector2d* centre) {
  int best = 0;
  for (int i = 1; i < 2016; ++i) {
    if (out[1][i] > out[1][best]) best = i;
  }
  const bool fine = best < 24 * 24 * 2;
  const int grid = fine ? 24 : 12;
  const int cell = fine ? best / 2 : (best - 24 * 24 * 2) / 6;
  const Eigen::Vector2d anchor((cell % grid + 0.5) / grid, (cell / grid + 0.5) / grid);
  *centre = anchor + Eigen::Vector2d(out[0][18 * best], out[0][18 * best + 1]) / 192.0;
  return out[1][best];
}

TEST(TfliteMediapipeModels, PalmDetectorFindsTheRenderedPalm) {
  REQUIRE_MEDIAPIPE_MODELS();
  const RenderedHand hand = RenderHandCrop();
  // The palm: the box around the wrist and the four finger MCPs (SNAP 0, 5, 9, 13, 17).
  Eigen::AlignedBox2d palm;
  for (int k : {0, 5, 9, 13, 17}) palm.extend(hand.keypoints[k]);
  for (const char* name : {"palm_detection_full.tflite", "palm_detection_lite.tflite"}) {
    auto model = TfliteModel::Load(MediapipeModel(name));
    Eigen::Vector2d centre;
    const float logit = BestPalm(model->Run({ResizedInput(hand.image, 192)}), &centre);
    EXPECT_GT(logit, 0.0f) << name;  // sigmoid > 0.5
    EXPECT_TRUE(palm.contains(224 * centre))
        << name << " palm centre " << (224 * centre).transpose() << ", drawn palm box "
        << palm.min().transpose() << " - " << palm.max().transpose();
    const float grey_logit =
        BestPalm(model->Run({ResizedInput(ImageU8(224, 224, 3, 128), 192)}), &centre);
    EXPECT_LT(grey_logit, 0.0f) << name << " on a grey image";
  }
}

// The rendered hand shrunk by `factor` (mean of factor x factor pixels) and pasted
// into a grey width x height image at `left`, `top`; its keypoints follow (handlabel's
// pixel convention: pixel centres at integers).
RenderedHand SmallHandInLargeImage(int width, int height, int factor, int left, int top) {
  const RenderedHand hand = RenderHandCrop();
  RenderedHand out{ImageU8(width, height, 3, 128), {}};
  const int size = hand.image.width / factor;
  for (int y = 0; y < size; ++y) {
    for (int x = 0; x < size; ++x) {
      for (int c = 0; c < 3; ++c) {
        int sum = 0;
        for (int j = 0; j < factor; ++j) {
          for (int i = 0; i < factor; ++i)
            sum += hand.image.at(factor * x + i, factor * y + j, c);
        }
        out.image.at(left + x, top + y, c) =
            static_cast<uint8_t>(sum / (factor * factor));
      }
    }
  }
  for (const Eigen::Vector2d& k : hand.keypoints) {
    out.keypoints.push_back(Eigen::Vector2d(left, top) +
                            (k.array() + 0.5).matrix() / factor -
                            Eigen::Vector2d(0.5, 0.5));
  }
  return out;
}

// Palm detection over tiles (MediapipeHandsOptions::palm_tiles): a hand about 60 px
// long in a 1920x1080 view is 6 px in the whole image letterboxed to 192x192, where the
// palm model sees nothing; in tiles it is found, at the drawn palm, and the landmarks
// of its ROI lie on the drawn keypoints.
TEST(TfliteMediapipeModels, PalmTilesFindASmallHandTheWholeImageMisses) {
  REQUIRE_MEDIAPIPE_MODELS();
  const RenderedHand hand = SmallHandInLargeImage(1920, 1080, 2, 1350, 610);
  Eigen::AlignedBox2d palm;
  for (int k : {0, 5, 9, 13, 17}) palm.extend(hand.keypoints[k]);
  const auto near_palm = [&](const std::vector<PalmDetection>& palms) {
    for (const PalmDetection& p : palms) {
      const Eigen::Vector2d centre =
          NormToPixel({p.xmin + p.width / 2, p.ymin + p.height / 2}, 1920, 1080);
      if (palm.contains(centre)) return true;
    }
    return false;
  };
  ASSERT_EQ(PalmTilesAcross(MediapipeHandsOptions(), 1920, 1080), 4);  // auto
  ASSERT_EQ(PalmTilesAcross(MediapipeHandsOptions(), 1280, 720), 0);
  MediapipeHandsOptions options;
  options.palm_tiles = 0;
  MediapipeTrace trace;
  EXPECT_TRUE(MediapipeHands(options).Detect(hand.image, &trace).empty());
  EXPECT_FALSE(near_palm(trace.palms));
  options.palm_tiles = 3;  // 18 tiles: fewer model runs than auto's 32, as conclusive
  const std::vector<HandDetection> found =
      MediapipeHands(options).Detect(hand.image, &trace);
  EXPECT_TRUE(near_palm(trace.palms));
  ASSERT_EQ(found.size(), 1u);
  double sum = 0;
  for (int k = 0; k < 21; ++k) {
    sum += (found[0].hand.image_px.row(k).transpose() - hand.keypoints[k]).norm();
  }
  EXPECT_LT(sum / 21, 4.0) << "mean landmark error (px) on a hand "
                           << (palm.max() - palm.min()).transpose() << " px palm";
}

// Not a test: writes inputs and our outputs for the peer check against TFLite's own
// runtime (tests/network/detector/tflite_peer_parity.mjs;
// docs/model-card-mediapipe-hands.md):
//   HANDLABEL_TFLITE_PARITY_DIR=/tmp/parity [HANDLABEL_TFLITE_PARITY_IMAGES=a.jpg:b.png]
//     build/tests/detector_tests --gtest_also_run_disabled_tests
//     --gtest_filter='*WritePeerParityFiles'   (one command line)
// Inputs: the rendered hand, seeded noise, grey, and the listed images, each resized
// (nearest) to the model's input; files in_<size>_<name>.bin (float32 NHWC) and
// ours_<model>_<name>.bin (all outputs concatenated, float32).
// Damaged or swapped model files in a --model-dir (issue 46): the lite landmark model
// under the full model's name (same inputs and outputs: it ran without a word) and a
// palm model with one NaN weight (it found "no hand" everywhere) are refused when
// loaded, naming the file; the shipped files load.
TEST(TfliteMediapipeModels, ALiteModelUnderTheFullNameOrNanWeightsAreRefused) {
  REQUIRE_MEDIAPIPE_MODELS();
  namespace fs = std::filesystem;
  const std::string dir = ::testing::TempDir() + "/swapped_mediapipe_models";
  fs::create_directories(dir);
  for (const char* name : {"hand_landmark_full.tflite", "palm_detection_full.tflite"}) {
    fs::copy_file(MediapipeModel(name), dir + "/" + name,
                  fs::copy_options::overwrite_existing);
  }
  MediapipeHandsOptions options;
  options.model_dir = dir;
  EXPECT_NO_THROW(MediapipeHands{options});

  fs::copy_file(MediapipeModel("hand_landmark_lite.tflite"),
                dir + "/hand_landmark_full.tflite", fs::copy_options::overwrite_existing);
  std::string error;
  try {
    MediapipeHands hands(options);
  } catch (const InputError& e) {
    error = e.what();
  }
  EXPECT_NE(error.find(dir + "/hand_landmark_full.tflite: field 'content': expected the "
                             "bytes of hand_landmark_full.tflite (sha256 8c0268"),
            std::string::npos)
      << error;
  EXPECT_NE(error.find("got the bytes of hand_landmark_lite.tflite"), std::string::npos)
      << error;

  fs::copy_file(MediapipeModel("hand_landmark_full.tflite"),
                dir + "/hand_landmark_full.tflite", fs::copy_options::overwrite_existing);
  std::string palm = ReadFileBytes(MediapipeModel("palm_detection_full.tflite"), "model");
  const auto graph = ParseTflite(palm, "palm");
  const TfliteTensor* weights = nullptr;  // the last float32 or float16 constant
  for (const TfliteTensor& t : graph->tensors) {
    if (t.has_data && (t.type == 0 || t.type == 1) && t.data_size >= 4) weights = &t;
  }
  ASSERT_NE(weights, nullptr) << "no float constant in the palm model";
  const float nan32 = std::nanf("");
  const uint16_t nan16 = 0x7e00;  // IEEE half-precision quiet NaN
  if (weights->type == 0) {
    palm.replace(weights->data_offset, 4, reinterpret_cast<const char*>(&nan32), 4);
  } else {
    palm.replace(weights->data_offset, 2, reinterpret_cast<const char*>(&nan16), 2);
  }
  std::ofstream(dir + "/palm_detection_full.tflite", std::ios::binary) << palm;
  error.clear();
  try {
    MediapipeHands hands(options);
  } catch (const InputError& e) {
    error = e.what();
  }
  EXPECT_NE(error.find(dir + "/palm_detection_full.tflite: field 'tensor "),
            std::string::npos)
      << error;
  EXPECT_NE(error.find("expected finite weights"), std::string::npos) << error;
}

TEST(TfliteMediapipeModels, DISABLED_WritePeerParityFiles) {
  REQUIRE_MEDIAPIPE_MODELS();
  const char* dir = std::getenv("HANDLABEL_TFLITE_PARITY_DIR");
  ASSERT_NE(dir, nullptr) << "set HANDLABEL_TFLITE_PARITY_DIR";
  std::filesystem::create_directories(dir);
  std::vector<std::pair<std::string, ImageU8>> images{
      {"rendered_hand", RenderHandCrop().image}, {"grey", ImageU8(224, 224, 3, 128)}};
  std::mt19937 rng(3);
  std::uniform_int_distribution<int> byte(0, 255);
  ImageU8 noise(224, 224, 3);
  for (auto& v : noise.data) v = static_cast<uint8_t>(byte(rng));
  images.push_back({"noise", noise});
  if (const char* list = std::getenv("HANDLABEL_TFLITE_PARITY_IMAGES")) {
    std::stringstream paths(list);
    for (std::string path; std::getline(paths, path, ':');) {
      images.push_back(
          {std::filesystem::path(path).filename().string(), ReadImageFile(path)});
      ASSERT_GE(images.back().second.channels, 3) << path << ": expected an RGB image";
    }
  }
  auto write = [&](const std::string& name, const std::vector<float>& values) {
    std::ofstream f(std::string(dir) + "/" + name, std::ios::binary);
    f.write(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(float));
  };
  for (const char* name : {"hand_landmark_full", "hand_landmark_lite",
                           "palm_detection_full", "palm_detection_lite"}) {
    auto model = TfliteModel::Load(MediapipeModel(std::string(name) + ".tflite"));
    const int size = model->inputs()[0].shape[1];
    for (const auto& [image_name, image] : images) {
      const std::vector<float> x = ResizedInput(image, size);
      std::vector<float> all;
      for (const auto& out : model->Run({x}))
        all.insert(all.end(), out.begin(), out.end());
      write("in_" + std::to_string(size) + "_" + image_name + ".bin", x);
      write("ours_" + std::string(name) + "_" + image_name + ".bin", all);
    }
  }
}

}  // namespace
}  // namespace handlabel
