#include "calib/synthetic_board_capture.h"

#include <cstdio>
#include <filesystem>
#include <random>

#include "core/errors.h"
#include "core/option_checks.h"
#include "core/random.h"
#include "image/image.h"

namespace handlabel {
namespace {

std::string FrameKey(int i) {
  char buf[16];
  std::snprintf(buf, sizeof(buf), "%06d", i);
  return buf;
}

}  // namespace

void SyntheticBoardCaptureOptions::Check(const std::string& source) const {
  RequireAtLeast(source, "num_cameras", num_cameras, 1);
  if (width < 16 || height < 16) throw InputError(source, "width/height", ">= 16");
  RequireAtLeast(source, "num_frames", num_frames, 1);
  RequireAtLeast(source, "corner_noise_px", corner_noise_px, 0);
  if (!(ring_radius_min > 0 && ring_radius_max >= ring_radius_min)) {
    throw InputError(source, "ring_radius_min/max", "0 < min <= max");
  }
  if (!(height_max >= height_min)) {
    throw InputError(source, "height_min/max", "min <= max");
  }
  RequireAtLeast(source, "min_corners", min_corners, 4);
}

namespace {

constexpr double kPi = 3.14159265358979323846;

// Cameras on a ring around the table looking at its centre, with OpenCV distortion.
void AddRingCameras(const SyntheticBoardCaptureOptions& o, std::mt19937_64& rng,
                    SyntheticBoardCapture* capture) {
  for (int c = 0; c < o.num_cameras; ++c) {
    const double azimuth = 2 * kPi * c / o.num_cameras + Uniform(rng, -0.15, 0.15);
    const double radius = Uniform(rng, o.ring_radius_min, o.ring_radius_max);
    const Eigen::Vector3d eye(radius * std::cos(azimuth), radius * std::sin(azimuth),
                              Uniform(rng, o.height_min, o.height_max));
    const Eigen::Vector3d target(Uniform(rng, -0.05, 0.05), Uniform(rng, -0.05, 0.05),
                                 0.05);
    const double f = Uniform(rng, 600, 630);
    RigCamera rc;
    char name[16];
    std::snprintf(name, sizeof(name), "cam%d", c);
    rc.name = name;
    rc.camera =
        Camera(CameraModelId::kOpenCV, o.width, o.height,
               {f, f * Uniform(rng, 0.997, 1.003), o.width / 2.0 + Uniform(rng, -8, 8),
                o.height / 2.0 + Uniform(rng, -8, 8), Uniform(rng, 0.03, 0.1),
                Uniform(rng, -0.15, -0.05), Uniform(rng, -0.001, 0.001),
                Uniform(rng, -0.001, 0.001)});
    rc.cam_from_world = LookAt(eye, target, Eigen::Vector3d::UnitZ());
    capture->rig.Add(rc);
    capture->views.push_back({rc.name, o.width, o.height, {}});
  }
}

// Board poses lying on the table, tilted, seen by several cameras.
void AddTableFrames(const BoardSpec& board, const SyntheticBoardCaptureOptions& o,
                    std::mt19937_64& rng, SyntheticBoardCapture* capture) {
  // A board lying printed side up has z (into the board) pointing down.
  Eigen::Matrix3d flat;
  flat << 1, 0, 0, 0, -1, 0, 0, 0, -1;
  const Eigen::Vector3d board_centre(board.Width() / 2, board.Height() / 2, 0);
  const double max_tilt = o.max_board_tilt_deg * kPi / 180;
  for (int f = 0; f < o.num_frames; ++f) {
    const double tilt_axis = Uniform(rng, 0, 2 * kPi);
    const Eigen::Quaterniond rotation(
        Eigen::AngleAxisd(Uniform(rng, 0, max_tilt),
                          Eigen::Vector3d(std::cos(tilt_axis), std::sin(tilt_axis), 0)) *
        Eigen::AngleAxisd(Uniform(rng, 0, 2 * kPi), Eigen::Vector3d::UnitZ()) *
        Eigen::Quaterniond(flat));
    const Eigen::Vector3d centre(Uniform(rng, -0.12, 0.12), Uniform(rng, -0.12, 0.12),
                                 Uniform(rng, 0.02, 0.2));
    capture->world_from_board[FrameKey(f)] =
        Rigid3(rotation, centre - rotation * board_centre);
  }
}

// Close-ups held in front of each camera (they pin its principal point down).
void AddNearFrames(const BoardSpec& board, const SyntheticBoardCaptureOptions& o,
                   std::mt19937_64& rng, SyntheticBoardCapture* capture) {
  const Eigen::Vector3d board_centre(board.Width() / 2, board.Height() / 2, 0);
  for (size_t c = 0; c < capture->rig.size(); ++c) {
    const Rigid3 world_from_cam = capture->rig[c].cam_from_world.Inverse();
    for (int f = 0; f < o.near_frames_per_camera; ++f) {
      // Board facing the camera (its z, into the board, along the optical axis), at
      // an offset that moves it around the image.
      const Eigen::Vector3d direction =
          Eigen::Vector3d(Uniform(rng, -0.25, 0.25), Uniform(rng, -0.2, 0.2), 1.0)
              .normalized();
      const Eigen::Vector3d centre =
          world_from_cam *
          (Uniform(rng, o.near_distance_min, o.near_distance_max) * direction);
      const double tilt = o.near_tilt_deg * kPi / 180;
      const Eigen::Quaterniond rotation =
          world_from_cam.rotation *
          Eigen::Quaterniond(
              Eigen::AngleAxisd(Uniform(rng, -tilt, tilt), Eigen::Vector3d::UnitX()) *
              Eigen::AngleAxisd(Uniform(rng, -tilt, tilt), Eigen::Vector3d::UnitY()) *
              Eigen::AngleAxisd(Uniform(rng, -kPi, kPi), Eigen::Vector3d::UnitZ()));
      char key[64];
      std::snprintf(key, sizeof(key), "near%zu_%02d", c, f);
      capture->world_from_board[key] = Rigid3(rotation, centre - rotation * board_centre);
    }
  }
}

// Every camera's noisy view of the corners of every board pose it faces; views with
// too few corners (or an incomplete checkerboard) are not detections.
void ObserveCorners(const BoardSpec& board, const SyntheticBoardCaptureOptions& o,
                    std::mt19937_64& rng, SyntheticBoardCapture* capture) {
  std::normal_distribution<double> noise(0.0, o.corner_noise_px);
  const Eigen::Vector3d board_centre(board.Width() / 2, board.Height() / 2, 0);
  const double cos_max_view = std::cos(o.max_view_angle_deg * kPi / 180);
  for (const auto& [key, world_from_board] : capture->world_from_board) {
    const Eigen::Vector3d centre = world_from_board * board_centre;
    const Eigen::Vector3d printed_normal =
        -(world_from_board.rotation * Eigen::Vector3d::UnitZ());
    for (size_t c = 0; c < capture->rig.size(); ++c) {
      const RigCamera& rc = capture->rig[c];
      const Eigen::Vector3d to_camera = (rc.CenterInWorld() - centre).normalized();
      if (printed_normal.dot(to_camera) < cos_max_view) continue;
      BoardObservation obs;
      for (int id = 0; id < board.NumCorners(); ++id) {
        Eigen::Vector2d uv;
        if (!rc.ProjectWorld(world_from_board * board.Corner(id), &uv)) continue;
        if (!rc.camera.InImage(uv, 3.0)) continue;
        obs.ids.push_back(id);
        obs.pixels.push_back(uv + Eigen::Vector2d(noise(rng), noise(rng)));
      }
      const bool complete = static_cast<int>(obs.size()) == board.NumCorners();
      if (static_cast<int>(obs.size()) < o.min_corners ||
          (board.type == BoardType::kCheckerboard && !complete)) {
        continue;
      }
      capture->views[c].frames[key] = obs;
    }
  }
}

}  // namespace

SyntheticBoardCapture SynthesizeBoardCapture(const BoardSpec& board,
                                             const SyntheticBoardCaptureOptions& o) {
  o.Check("SyntheticBoardCaptureOptions");
  board.Check("board");
  std::mt19937_64 rng(o.seed);
  SyntheticBoardCapture capture;
  AddRingCameras(o, rng, &capture);
  AddTableFrames(board, o, rng, &capture);
  AddNearFrames(board, o, rng, &capture);
  ObserveCorners(board, o, rng, &capture);
  return capture;
}

int RenderBoardCapture(const SyntheticBoardCapture& capture, const BoardSpec& board,
                       const std::string& dir, const BoardRenderOptions& options,
                       uint64_t seed) {
  namespace fs = std::filesystem;
  int written = 0;
  for (size_t c = 0; c < capture.rig.size(); ++c) {
    const RigCamera& rc = capture.rig[c];
    const fs::path folder = fs::path(dir) / rc.name;
    fs::create_directories(folder);
    const BoardRenderer renderer(board, rc.camera, options);
    for (const auto& [key, world_from_board] : capture.world_from_board) {
      const ImageU8 image = renderer.Render(rc.cam_from_world * world_from_board,
                                            seed + 7919 * c + written);
      WritePng((folder / (key + ".png")).string(), image);
      ++written;
    }
  }
  return written;
}

}  // namespace handlabel
