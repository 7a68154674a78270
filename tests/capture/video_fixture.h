#pragma once
// Writes test videos with OpenCV's VideoWriter (FFmpeg backend): FFV1 in Matroska is
// lossless for 8-bit BGR (checked: every pixel of random frames decodes back exactly),
// so an imported frame must equal the image it was made from.

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "image/image.h"

namespace handlabel::testing {

inline cv::Mat BgrFromRgb(const ImageU8& rgb) {
  cv::Mat wrapped(rgb.height, rgb.width, CV_8UC3, const_cast<uint8_t*>(rgb.data.data()));
  cv::Mat bgr;
  cv::cvtColor(wrapped, bgr, cv::COLOR_RGB2BGR);
  return bgr;
}

// `frames` are RGB images of one size; `path` should end in .mkv.
inline void WriteLosslessVideo(const std::string& path,
                               const std::vector<ImageU8>& frames, double fps = 30) {
  if (frames.empty()) throw std::runtime_error("no frames for " + path);
  cv::VideoWriter writer(path, cv::CAP_FFMPEG,
                         cv::VideoWriter::fourcc('F', 'F', 'V', '1'), fps,
                         cv::Size(frames[0].width, frames[0].height));
  if (!writer.isOpened()) throw std::runtime_error("cannot write " + path);
  for (const ImageU8& frame : frames) writer.write(BgrFromRgb(frame));
}

// The same as MPEG-4 part 2 (FFmpeg's own encoder, lossy: I and P frames), a codec
// whose decoder reports damaged data; `path` should end in .avi.
inline void WriteMpeg4Video(const std::string& path, const std::vector<ImageU8>& frames) {
  if (frames.empty()) throw std::runtime_error("no frames for " + path);
  cv::VideoWriter writer(path, cv::CAP_FFMPEG,
                         cv::VideoWriter::fourcc('F', 'M', 'P', '4'), 30,
                         cv::Size(frames[0].width, frames[0].height));
  if (!writer.isOpened()) throw std::runtime_error("cannot write " + path);
  for (const ImageU8& frame : frames) writer.write(BgrFromRgb(frame));
}

}  // namespace handlabel::testing
