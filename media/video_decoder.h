#pragma once
// One video file decoded forward, frame by frame, with FFmpeg's libraries (the ones
// OpenCV's FFmpeg backend uses), for capture import. It exists because OpenCV's
// VideoCapture hides damage: a corrupt H.264 frame was logged by FFmpeg naming nothing
// and returned as a concealed (garbage) frame, and a packet that decoded to no frame
// shifted every later frame by one. Here a frame is damaged when its packet or any
// earlier one since the last clean key frame failed to decode, was reported at error
// level by the demuxer or decoder, or came out marked corrupt or concealed (CRCs that
// the stream carries are checked, e.g. FFV1 with slice CRCs); reading a damaged frame
// throws InputError naming the file, the frame and FFmpeg's message. Damage that the
// stream gives no sign of (FFV1 without CRCs) cannot be found. Not thread-safe: one
// decoder per thread at a time (decoding itself is single-threaded, so every message
// FFmpeg logs is attributed to the frame being read).

#include <memory>
#include <string>
#include <utility>

#include "image/image.h"

namespace handlabel {

class VideoDecoder {
 public:
  // Opens `path`; `camera` names it in messages. Throws InputError when FFmpeg cannot
  // open it or it has no video stream it can decode.
  VideoDecoder(const std::string& path, const std::string& camera);
  ~VideoDecoder();
  VideoDecoder(const VideoDecoder&) = delete;
  VideoDecoder& operator=(const VideoDecoder&) = delete;

  // Frame count the container declares, else its duration x frame rate rounded (as
  // OpenCV's CAP_PROP_FRAME_COUNT); -1 if it declares neither.
  int DeclaredCount() const;
  // Frame size after the stream's rotation (width, height).
  std::pair<int, int> Size() const;
  // Frames per second the stream declares (FFmpeg's guess from the container and
  // codec); 0 if unknown.
  double Fps() const;
  // Index of the frame the next Read or Skip returns.
  int next_index() const { return next_; }

  // Decodes the next frame as RGB, turned by the stream's rotation metadata as OpenCV
  // does. Returns false at the end of the stream; throws InputError when the frame is
  // damaged (see the header comment).
  bool Read(ImageU8* rgb);
  // Decodes the next frame without converting it; false at the end. Damage is noted
  // (it fails the frames that depend on it), not thrown.
  bool Skip();

 private:
  struct State;
  bool Decode();
  std::unique_ptr<State> state_;
  std::string path_;
  std::string camera_;
  int next_ = 0;
};

}  // namespace handlabel
