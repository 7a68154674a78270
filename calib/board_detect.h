#pragma once
// Board corner detection in one grey image: ChArUco through OpenCV 4.6's contrib
// aruco module (markers, then interpolated and sub-pixel refined chessboard corners),
// checkerboards through cv::findChessboardCorners + cornerSubPix.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "calib/board_spec.h"
#include "image/image.h"

namespace handlabel {

// The corners found in one image: ids as in BoardSpec, pixels in OpenCV convention
// (centre of the top-left pixel = (0, 0)).
struct BoardObservation {
  std::vector<int> ids;
  std::vector<Eigen::Vector2d> pixels;
  size_t size() const { return ids.size(); }
};

struct BoardDetectOptions {
  // Fewer corners than this count as "board not seen" (a homography needs 4; more
  // keeps wrong detections out).
  int min_corners = 6;
  void Check(const std::string& source) const;
};

// `image` is grey (1 channel). Empty observation if the board is not found.
//
// Checkerboards are symmetric, so their corner order is ambiguous: it is chosen so
// that corner 0 is the one nearest the image's top-left. This is consistent across
// cameras only when all cameras see the board upright from the same side; prefer
// ChArUco boards for multi-camera rigs.
BoardObservation DetectBoard(const ImageU8& image, const BoardSpec& board,
                             const BoardDetectOptions& options = {});

}  // namespace handlabel
