#pragma once
// Reading a frame of a camera's recording as RGB, from an image folder (any format
// OpenCV decodes; JPEGs checked by image/'s strict reader first) or a video (FFmpeg's
// libraries, media/video_decoder.h), for capture import. OpenCV and FFmpeg stay inside
// media/'s .cc files: capture/ links media/, not them.

#include <exception>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <filesystem>

#include "image/image.h"
#include "media/video_decoder.h"

namespace handlabel {

// One rig camera's recording: an image folder or a video file.
struct CameraSource {
  std::string camera;
  std::filesystem::path path;
  std::vector<std::filesystem::path> images;  // image folders: the images, sorted by name
};

// A video ended before the frame asked for (containers may declare more frames than
// they hold): the import stops there.
struct VideoEnded : std::exception {
  VideoEnded(int c, int n) : camera(c), frames_read(n) {}
  const char* what() const noexcept override { return "video ended"; }
  int camera;
  int frames_read;
};

// Reads frame `index` of camera `camera` as RGB; Where() names it in messages.
class FrameReader {
 public:
  virtual ~FrameReader() = default;
  virtual ImageU8 Read(int camera, int index) = 0;
  virtual std::string Where(int camera, int index) const = 0;
};

// Images by their position in the camera's sorted folder.
std::unique_ptr<FrameReader> MakeImageFolderReader(
    const std::vector<CameraSource>& cameras);

// Decodes each video forward only (media/video_decoder.h: exact for every codec,
// unlike seeking; a damaged frame throws InputError naming the file and the frame).
// Throws InputError for a video FFmpeg cannot open.
class VideoReader : public FrameReader {
 public:
  explicit VideoReader(const std::vector<CameraSource>& cameras);
  ~VideoReader() override;
  // Frame count the container declares; -1 if it declares none.
  int DeclaredCount(int camera) const;
  // Size the stream declares (width, height), after its rotation metadata.
  std::pair<int, int> DeclaredSize(int camera) const;
  // Frames per second the stream declares; 0 if unknown.
  double DeclaredFps(int camera) const;
  // Counts by decoding on a second handle (for containers that declare no count).
  int CountByDecoding(int camera) const;
  ImageU8 Read(int camera, int index) override;
  std::string Where(int camera, int index) const override;

 private:
  std::vector<CameraSource> cameras_;  // a copy: the reader may outlive the caller's list
  std::vector<std::unique_ptr<VideoDecoder>> streams_;
};

}  // namespace handlabel
