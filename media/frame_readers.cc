#include "media/frame_readers.h"

#include <algorithm>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "core/errors.h"

namespace handlabel {
namespace {

ImageU8 RgbFromBgr(const cv::Mat& bgr) {
  HL_CHECK(bgr.type() == CV_8UC3, "expected an 8-bit 3-channel image");
  cv::Mat rgb;
  cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
  ImageU8 out(rgb.cols, rgb.rows, 3);
  for (int y = 0; y < rgb.rows; ++y) {
    std::copy(rgb.ptr<uint8_t>(y), rgb.ptr<uint8_t>(y) + 3 * rgb.cols,
              out.data.begin() + out.index(0, y));
  }
  return out;
}

class ImageFolderReader : public FrameReader {
 public:
  explicit ImageFolderReader(const std::vector<CameraSource>& cameras)
      : cameras_(cameras) {}
  ImageU8 Read(int camera, int index) override {
    const std::string path = Where(camera, index);
    // 8-bit BGR whatever the file holds (gray is replicated, 16 bits are scaled down).
    const cv::Mat bgr = cv::imread(path, cv::IMREAD_COLOR);
    if (bgr.empty()) {
      throw InputError(path, "image",
                       "an image file OpenCV can decode (PNG, JPEG, BMP, TIFF)",
                       "unreadable");
    }
    return RgbFromBgr(bgr);
  }
  std::string Where(int camera, int index) const override {
    return cameras_[camera].images[index].string();
  }

 private:
  std::vector<CameraSource> cameras_;  // a copy: the reader may outlive the caller's list
};

}  // namespace

std::unique_ptr<FrameReader> MakeImageFolderReader(
    const std::vector<CameraSource>& cameras) {
  return std::make_unique<ImageFolderReader>(cameras);
}

struct VideoReader::Stream {
  cv::VideoCapture capture;
  int next = 0;  // index of the frame the next read() returns
};

VideoReader::VideoReader(const std::vector<CameraSource>& cameras) : cameras_(cameras) {
  for (const CameraSource& source : cameras) {
    auto stream = std::make_unique<Stream>();
    const std::string path = source.path.string();
    if (!stream->capture.open(path, cv::CAP_FFMPEG)) {
      throw InputError(
          path, "video",
          "a video OpenCV's FFmpeg backend can open (camera " + source.camera + ")",
          "cannot open it");
    }
    streams_.push_back(std::move(stream));
  }
}

VideoReader::~VideoReader() = default;

int VideoReader::DeclaredCount(int camera) const {
  const double n = streams_[camera]->capture.get(cv::CAP_PROP_FRAME_COUNT);
  return n >= 1 ? static_cast<int>(n) : -1;
}

std::pair<int, int> VideoReader::DeclaredSize(int camera) const {
  const cv::VideoCapture& c = streams_[camera]->capture;
  return {static_cast<int>(c.get(cv::CAP_PROP_FRAME_WIDTH)),
          static_cast<int>(c.get(cv::CAP_PROP_FRAME_HEIGHT))};
}

int VideoReader::CountByDecoding(int camera) const {
  cv::VideoCapture counter(cameras_[camera].path.string(), cv::CAP_FFMPEG);
  int n = 0;
  while (counter.grab()) ++n;
  return n;
}

ImageU8 VideoReader::Read(int camera, int index) {
  Stream& s = *streams_[camera];
  HL_CHECK(index >= s.next, "video frames are read in increasing order");
  while (s.next < index) {
    if (!s.capture.grab()) throw VideoEnded{camera, s.next};
    ++s.next;
  }
  cv::Mat frame;
  if (!s.capture.read(frame) || frame.empty()) throw VideoEnded{camera, s.next};
  ++s.next;
  if (frame.type() == CV_8UC1) cv::cvtColor(frame, frame, cv::COLOR_GRAY2BGR);
  if (frame.type() == CV_8UC4) cv::cvtColor(frame, frame, cv::COLOR_BGRA2BGR);
  if (frame.type() != CV_8UC3) {
    throw InputError(Where(camera, index), "pixels", "8-bit colour or gray frames",
                     "OpenCV type " + std::to_string(frame.type()));
  }
  return RgbFromBgr(frame);
}

std::string VideoReader::Where(int camera, int index) const {
  return cameras_[camera].path.string() + " frame " + std::to_string(index);
}

}  // namespace handlabel
