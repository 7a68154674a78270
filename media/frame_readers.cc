#include "media/frame_readers.h"

#include <algorithm>
#include <fstream>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "core/errors.h"
#include "image/image_file.h"

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

bool IsJpegFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  unsigned char head[3] = {0, 0, 0};
  in.read(reinterpret_cast<char*>(head), 3);
  return in.gcount() == 3 && head[0] == 0xFF && head[1] == 0xD8 && head[2] == 0xFF;
}

class ImageFolderReader : public FrameReader {
 public:
  explicit ImageFolderReader(const std::vector<CameraSource>& cameras)
      : cameras_(cameras) {}
  ImageU8 Read(int camera, int index) override {
    const std::string path = Where(camera, index);
    // OpenCV decodes a truncated or corrupt JPEG with a warning on stderr and a grey
    // rest: such a file must fail its frame by name, not become a complete capture of
    // damaged images. The strict reader the label jobs use checks it first (OpenCV
    // still decodes it: it applies the EXIF orientation, which ReadJpeg does not).
    if (IsJpegFile(path)) ReadJpeg(path);
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

VideoReader::VideoReader(const std::vector<CameraSource>& cameras) : cameras_(cameras) {
  for (const CameraSource& source : cameras) {
    streams_.push_back(std::make_unique<VideoDecoder>(source.path.string(), source.camera));
  }
}

VideoReader::~VideoReader() = default;

int VideoReader::DeclaredCount(int camera) const {
  return streams_[camera]->DeclaredCount();
}

std::pair<int, int> VideoReader::DeclaredSize(int camera) const {
  return streams_[camera]->Size();
}

double VideoReader::DeclaredFps(int camera) const { return streams_[camera]->Fps(); }

int VideoReader::CountByDecoding(int camera) const {
  VideoDecoder counter(cameras_[camera].path.string(), cameras_[camera].camera);
  while (counter.Skip()) {
  }
  return counter.next_index();
}

ImageU8 VideoReader::Read(int camera, int index) {
  VideoDecoder& video = *streams_[camera];
  HL_CHECK(index >= video.next_index(), "video frames are read in increasing order");
  while (video.next_index() < index) {
    if (!video.Skip()) throw VideoEnded{camera, video.next_index()};
  }
  ImageU8 rgb;
  if (!video.Read(&rgb)) throw VideoEnded{camera, video.next_index()};
  return rgb;
}

std::string VideoReader::Where(int camera, int index) const {
  return cameras_[camera].path.string() + " frame " + std::to_string(index);
}

}  // namespace handlabel
