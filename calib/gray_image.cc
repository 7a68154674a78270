#include "calib/gray_image.h"

#include <cstring>
#include <opencv2/imgcodecs.hpp>

#include "calib/cv_image_file.h"
#include "core/errors.h"

namespace handlabel {

GrayImage ReadGrayImage(const std::string& path) {
  cv::Mat mat;
  try {
    mat = cv::imread(path, cv::IMREAD_GRAYSCALE);
  } catch (const cv::Exception& e) {
    throw InputError(path, "(image)", "a readable image", e.what());
  }
  if (mat.empty()) throw InputError(path, "(image)", "a readable image", "cannot decode");
  GrayImage image(mat.cols, mat.rows);
  for (int y = 0; y < mat.rows; ++y) {
    std::memcpy(&image.pixels[size_t(y) * mat.cols], mat.ptr<uint8_t>(y), mat.cols);
  }
  return image;
}

void WriteGrayImage(const GrayImage& image, const std::string& path) {
  const cv::Mat mat(image.height, image.width, CV_8UC1,
                    const_cast<uint8_t*>(image.pixels.data()));
  WriteCvImage(mat, path);
}

}  // namespace handlabel
