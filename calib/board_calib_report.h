#pragma once
// Reports of a board calibration: a per-camera table, a JSON summary and a residual
// plot (one panel per camera: residual vectors as dots, inliers blue, outliers red, with
// a 1 px circle and the RMS).

#include <nlohmann/json.hpp>
#include <string>

#include "calib/board_calib.h"

namespace handlabel {

std::string BoardCalibTable(const BoardCalibResult& result);
nlohmann::json BoardCalibJson(const BoardCalibResult& result, const BoardSpec& board,
                              const BoardCalibOptions& options);
// Drawn with image/draw.h; throws Error naming the path if the PNG cannot be written.
void PlotBoardResiduals(const BoardCalibResult& result, const std::string& png_path);

}  // namespace handlabel
