#include "calib/cv_image_file.h"

#include <opencv2/imgcodecs.hpp>

#include "core/errors.h"

namespace handlabel {

void WriteCvImage(const cv::Mat& image, const std::string& path) {
  const char* expected = "a writable image path (.png, .jpg)";
  bool ok = false;
  try {
    ok = cv::imwrite(path, image);
  } catch (const cv::Exception& e) {
    throw InputError(path, "(file)", expected, e.what());
  }
  if (!ok) throw InputError(path, "(file)", expected, "write failed");
}

}  // namespace handlabel
