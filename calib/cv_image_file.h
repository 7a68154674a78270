#pragma once
// Writing an OpenCV image (calib's pictures and grey images) with the project's error
// rule. Internal to calib/: it includes OpenCV, which no other layer may see.

#include <opencv2/core/mat.hpp>
#include <string>

namespace handlabel {

// Format from the extension (.png, .jpg); throws InputError naming the path if the
// write fails.
void WriteCvImage(const cv::Mat& image, const std::string& path);

}  // namespace handlabel
