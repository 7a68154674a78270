#include "calib/board_images.h"

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <opencv2/imgcodecs.hpp>
#include <ostream>

#include "core/errors.h"
#include "image/image.h"

namespace handlabel {
namespace {

bool IsImageFile(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
  return ext == ".png" || ext == ".jpg" || ext == ".jpeg" || ext == ".bmp" ||
         ext == ".tif" || ext == ".tiff";
}

// Any format OpenCV decodes (BMP and TIFF too, which image/image_file.h does not read),
// as OpenCV's own grey conversion: detections depend on these exact pixels.
ImageU8 ReadBoardImage(const std::string& path) {
  cv::Mat mat;
  try {
    mat = cv::imread(path, cv::IMREAD_GRAYSCALE);
  } catch (const cv::Exception& e) {
    throw InputError(path, "(image)", "a readable image", e.what());
  }
  if (mat.empty()) throw InputError(path, "(image)", "a readable image", "cannot decode");
  ImageU8 image(mat.cols, mat.rows, 1);
  for (int y = 0; y < mat.rows; ++y) {
    std::memcpy(&image.at(0, y), mat.ptr<uint8_t>(y), mat.cols);
  }
  return image;
}

}  // namespace

std::vector<CameraBoardViews> DetectBoardsInFolders(const std::string& dir,
                                                    const BoardSpec& board,
                                                    const BoardDetectOptions& options,
                                                    std::ostream* log) {
  namespace fs = std::filesystem;
  if (!fs::is_directory(dir)) {
    throw InputError(dir, "--images", "a folder with one sub-folder of images per camera",
                     "not a folder");
  }
  std::vector<fs::path> camera_dirs;
  for (const fs::directory_entry& e : fs::directory_iterator(dir)) {
    if (e.is_directory()) camera_dirs.push_back(e.path());
  }
  std::sort(camera_dirs.begin(), camera_dirs.end());
  if (camera_dirs.empty()) {
    throw InputError(dir, "--images",
                     "one sub-folder of images per camera (DIR/cam0/*.png)",
                     "no sub-folders");
  }
  std::vector<CameraBoardViews> all;
  for (const fs::path& camera_dir : camera_dirs) {
    std::vector<fs::path> images;
    for (const fs::directory_entry& e : fs::directory_iterator(camera_dir)) {
      if (e.is_regular_file() && IsImageFile(e.path())) images.push_back(e.path());
    }
    std::sort(images.begin(), images.end());
    if (images.empty()) {
      throw InputError(camera_dir.string(), "(images)", "image files (.png, .jpg, ...)",
                       "none");
    }
    CameraBoardViews views;
    views.name = camera_dir.filename().string();
    std::string first_image;
    for (const fs::path& path : images) {
      const ImageU8 image = ReadBoardImage(path.string());
      if (first_image.empty()) {
        first_image = path.string();
        views.width = image.width;
        views.height = image.height;
      } else if (image.width != views.width || image.height != views.height) {
        throw InputError(
            path.string(), "(image size)",
            "the size of " + first_image + ": " + std::to_string(views.width) + "x" +
                std::to_string(views.height),
            std::to_string(image.width) + "x" + std::to_string(image.height));
      }
      BoardObservation obs = DetectBoard(image, board, options);
      if (obs.size() > 0) views.frames[path.stem().string()] = std::move(obs);
    }
    if (views.frames.empty()) {
      throw InputError(
          camera_dir.string(), "(board detections)",
          "the board " + board.ToString() + " in at least one image",
          "no detections in " + std::to_string(images.size()) +
              " images (check the board spec: squares, marker size, dictionary)");
    }
    if (log) {
      *log << "  " << views.name << ": board found in " << views.frames.size() << " of "
           << images.size() << " images (" << views.width << "x" << views.height << ")\n";
    }
    all.push_back(std::move(views));
  }
  return all;
}

}  // namespace handlabel
