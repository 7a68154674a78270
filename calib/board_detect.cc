#include "calib/board_detect.h"

#include <opencv2/aruco/charuco.hpp>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "core/errors.h"
#include "core/option_checks.h"

namespace handlabel {
namespace {

cv::Ptr<cv::aruco::CharucoBoard> MakeCharucoBoard(const BoardSpec& board) {
  int dict_id = 0;
  for (const ArucoDictionaryInfo& d : ArucoDictionaries()) {
    if (board.dictionary == d.name) dict_id = d.opencv_id;
  }
  return cv::aruco::CharucoBoard::create(
      board.cols, board.rows, static_cast<float>(board.square),
      static_cast<float>(board.marker), cv::aruco::getPredefinedDictionary(dict_id));
}

BoardObservation DetectCharuco(const cv::Mat& gray, const BoardSpec& board) {
  const auto cv_board = MakeCharucoBoard(board);
  std::vector<std::vector<cv::Point2f>> marker_corners, rejected;
  std::vector<int> marker_ids;
  const auto params = cv::aruco::DetectorParameters::create();
  cv::aruco::detectMarkers(gray, cv_board->dictionary, marker_corners, marker_ids, params,
                           rejected);
  BoardObservation obs;
  if (marker_ids.empty()) return obs;
  // Markers of other boards or false positives would pull in wrong corners.
  std::vector<std::vector<cv::Point2f>> kept_corners;
  std::vector<int> kept_ids;
  for (size_t i = 0; i < marker_ids.size(); ++i) {
    if (marker_ids[i] < board.NumMarkers()) {
      kept_corners.push_back(marker_corners[i]);
      kept_ids.push_back(marker_ids[i]);
    }
  }
  if (kept_ids.empty()) return obs;
  std::vector<cv::Point2f> corners;
  std::vector<int> ids;
  cv::aruco::interpolateCornersCharuco(kept_corners, kept_ids, gray, cv_board, corners,
                                       ids, cv::noArray(), cv::noArray(), 2);
  // OpenCV refines with windows that can reach the marker edges next to a corner,
  // which biases corners by several tenths of a pixel; refine again with a window
  // that stays inside the white gap between corner and marker.
  const double gap_fraction = (board.square - board.marker) / (2 * board.square);
  for (size_t i = 0; i < ids.size(); ++i) {
    double square_px = 1e9;
    for (size_t k = 0; k < ids.size(); ++k) {
      if (k != i) square_px = std::min(square_px, cv::norm(corners[k] - corners[i]));
    }
    const int half =
        static_cast<int>(std::clamp(0.8 * gap_fraction * square_px, 2.0, 10.0));
    std::vector<cv::Point2f> one = {corners[i]};
    cv::cornerSubPix(
        gray, one, cv::Size(half, half), cv::Size(-1, -1),
        cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 50, 1e-4));
    // A corner that wanders off is not trusted.
    if (cv::norm(one[0] - corners[i]) > half) continue;
    obs.ids.push_back(ids[i]);
    obs.pixels.emplace_back(one[0].x, one[0].y);
  }
  return obs;
}

BoardObservation DetectCheckerboard(const cv::Mat& gray, const BoardSpec& board) {
  const cv::Size pattern(board.cols - 1, board.rows - 1);
  std::vector<cv::Point2f> corners;
  BoardObservation obs;
  if (!cv::findChessboardCorners(
          gray, pattern, corners,
          cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE)) {
    return obs;
  }
  cv::cornerSubPix(
      gray, corners, cv::Size(5, 5), cv::Size(-1, -1),
      cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 50, 1e-3));
  // Canonical order: corner 0 nearest the top-left of the image.
  const cv::Point2f first = corners.front(), last = corners.back();
  if (first.x + first.y > last.x + last.y) std::reverse(corners.begin(), corners.end());
  for (size_t i = 0; i < corners.size(); ++i) {
    obs.ids.push_back(static_cast<int>(i));
    obs.pixels.emplace_back(corners[i].x, corners[i].y);
  }
  return obs;
}

}  // namespace

void BoardDetectOptions::Check(const std::string& source) const {
  RequireAtLeast(source, "min_corners", min_corners, 4);
}

BoardObservation DetectBoard(const ImageU8& image, const BoardSpec& board,
                             const BoardDetectOptions& options) {
  options.Check("BoardDetectOptions");
  HL_CHECK(image.channels == 1, "board detection takes grey images, not " +
                                    std::to_string(image.channels) + " channels");
  // A view of the pixels, not a copy: OpenCV only reads them.
  const cv::Mat gray(image.height, image.width, CV_8UC1,
                     const_cast<uint8_t*>(image.data.data()));
  BoardObservation obs = board.type == BoardType::kCharuco
                             ? DetectCharuco(gray, board)
                             : DetectCheckerboard(gray, board);
  if (static_cast<int>(obs.size()) < options.min_corners) return {};
  return obs;
}

}  // namespace handlabel
