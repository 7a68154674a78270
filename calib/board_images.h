#pragma once
// Board detection over a capture folder laid out as one sub-folder per camera:
//   DIR/<camera>/<frame>.{png,jpg,jpeg,bmp,tif,tiff}
// Images with the same <frame> name in different camera folders were taken at the same
// moment (the same board pose). Cameras are sorted by folder name.

#include <iosfwd>
#include <string>
#include <vector>

#include "calib/board_calib.h"

namespace handlabel {

// Throws InputError when DIR has no camera folders, a camera folder has no images, the
// images of one camera differ in size (naming both files), or a camera has no image in
// which the board was found. `log` (optional) gets one line per camera.
std::vector<CameraBoardViews> DetectBoardsInFolders(
    const std::string& dir, const BoardSpec& board,
    const BoardDetectOptions& options = {}, std::ostream* log = nullptr);

}  // namespace handlabel
