#include "media/video_decoder.h"

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/display.h>
#include <libavutil/error.h>
#include <libavutil/log.h>
#include <libswscale/swscale.h>
}

#include <cmath>
#include <cstdarg>
#include <mutex>
#include <opencv2/core.hpp>

#include "core/errors.h"

namespace handlabel {
namespace {

// What FFmpeg logs at error level while this thread decodes; null when no decoder of
// ours runs on it (messages then go to FFmpeg's default logger as before).
thread_local std::string* t_errors = nullptr;

void CollectErrors(void* object, int level, const char* format, va_list args) {
  if (t_errors == nullptr) {
    av_log_default_callback(object, level, format, args);
    return;
  }
  if (level > AV_LOG_ERROR) return;
  char line[400];
  int print_prefix = 0;  // "[h264 @ 0x55...]" names a pointer: the class name instead
  av_log_format_line2(object, level, format, args, line, sizeof(line), &print_prefix);
  std::string text(line);
  while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.pop_back();
  if (text.empty() || t_errors->size() > 300) return;
  const AVClass* cls = object ? *static_cast<const AVClass* const*>(object) : nullptr;
  if (cls) text = std::string(cls->item_name(object)) + ": " + text;
  *t_errors += (t_errors->empty() ? "" : "; ") + text;
}

// Collects FFmpeg's error messages into `errors` for the life of the object.
class ErrorsOfThisThread {
 public:
  explicit ErrorsOfThisThread(std::string* errors) : previous_(t_errors) {
    static std::once_flag installed;
    std::call_once(installed, [] { av_log_set_callback(CollectErrors); });
    t_errors = errors;
  }
  ~ErrorsOfThisThread() { t_errors = previous_; }

 private:
  std::string* previous_;
};

std::string AvError(int code) {
  char text[AV_ERROR_MAX_STRING_SIZE] = {0};
  av_strerror(code, text, sizeof(text));
  return text;
}

}  // namespace

struct VideoDecoder::State {
  AVFormatContext* format = nullptr;
  AVCodecContext* codec = nullptr;
  AVPacket* packet = nullptr;
  AVFrame* frame = nullptr;
  SwsContext* scale = nullptr;
  int stream = -1;
  int rotation = 0;    // clockwise degrees, as OpenCV's CAP_PROP_ORIENTATION_META
  std::string damage;  // since the last clean key frame: "frame N: message"

  ~State() {
    sws_freeContext(scale);
    av_frame_free(&frame);
    av_packet_free(&packet);
    avcodec_free_context(&codec);
    avformat_close_input(&format);
  }
};

VideoDecoder::VideoDecoder(const std::string& path, const std::string& camera)
    : state_(std::make_unique<State>()), path_(path), camera_(camera) {
  State& s = *state_;
  std::string errors;
  ErrorsOfThisThread collect(&errors);
  auto fail = [&](const std::string& got) {
    throw InputError(path, "video",
                     "a video FFmpeg can open and decode (camera " + camera + ")", got);
  };
  int r = avformat_open_input(&s.format, path.c_str(), nullptr, nullptr);
  if (r < 0) fail("cannot open it: " + AvError(r));
  if ((r = avformat_find_stream_info(s.format, nullptr)) < 0) fail(AvError(r));
  const AVCodec* codec = nullptr;
  s.stream = av_find_best_stream(s.format, AVMEDIA_TYPE_VIDEO, -1, -1, &codec, 0);
  if (s.stream < 0 || codec == nullptr) fail("no video stream with a known codec");
  s.codec = avcodec_alloc_context3(codec);
  AVStream* stream = s.format->streams[s.stream];
  if (!s.codec || avcodec_parameters_to_context(s.codec, stream->codecpar) < 0)
    fail("codec parameters FFmpeg cannot use");
  s.codec->thread_count = 1;  // every message then comes from the frame being read
  s.codec->err_recognition |= AV_EF_CRCCHECK;
  if ((r = avcodec_open2(s.codec, codec, nullptr)) < 0) fail(AvError(r));
  s.packet = av_packet_alloc();
  s.frame = av_frame_alloc();
  HL_CHECK(s.packet && s.frame, "FFmpeg allocation");
  if (const uint8_t* matrix =
          av_stream_get_side_data(stream, AV_PKT_DATA_DISPLAYMATRIX, nullptr)) {
    const double degrees =
        av_display_rotation_get(reinterpret_cast<const int32_t*>(matrix));
    if (std::isfinite(degrees))
      s.rotation = ((-static_cast<int>(std::lround(degrees))) % 360 + 360) % 360;
  }
}

VideoDecoder::~VideoDecoder() = default;

int VideoDecoder::DeclaredCount() const {
  const AVStream* stream = state_->format->streams[state_->stream];
  if (stream->nb_frames > 0) return static_cast<int>(stream->nb_frames);
  double seconds = state_->format->duration > 0
                       ? static_cast<double>(state_->format->duration) / AV_TIME_BASE
                       : 0.0;
  if (seconds <= 0 && stream->duration > 0)
    seconds = stream->duration * av_q2d(stream->time_base);
  const double count = std::floor(seconds * Fps() + 0.5);
  return count >= 1 ? static_cast<int>(count) : -1;
}

std::pair<int, int> VideoDecoder::Size() const {
  const AVCodecParameters* p = state_->format->streams[state_->stream]->codecpar;
  if (state_->rotation % 180 != 0) return {p->height, p->width};
  return {p->width, p->height};
}

double VideoDecoder::Fps() const {
  const AVRational rate = av_guess_frame_rate(
      state_->format, state_->format->streams[state_->stream], nullptr);
  return rate.num > 0 && rate.den > 0 ? av_q2d(rate) : 0.0;
}

// The next frame into state_->frame; false at the end. Damage goes to state_->damage.
bool VideoDecoder::Decode() {
  State& s = *state_;
  std::string errors;
  ErrorsOfThisThread collect(&errors);
  auto note = [&](const std::string& what) {
    errors += (errors.empty() ? "" : "; ") + what;
  };
  bool got = false;
  while (!got) {
    int r = avcodec_receive_frame(s.codec, s.frame);
    if (r == 0) {
      got = true;
      break;
    }
    if (r == AVERROR_EOF) break;
    if (r != AVERROR(EAGAIN)) {
      note("decoding failed: " + AvError(r));
      break;
    }
    r = av_read_frame(s.format, s.packet);
    if (r < 0) {
      if (r != AVERROR_EOF) note("reading the file failed: " + AvError(r));
      avcodec_send_packet(s.codec, nullptr);  // drain the frames the decoder holds
      continue;
    }
    if (s.packet->stream_index == s.stream) {
      r = avcodec_send_packet(s.codec, s.packet);
      if (r < 0 && r != AVERROR(EAGAIN)) note("a packet failed to decode: " + AvError(r));
    }
    av_packet_unref(s.packet);
  }
  if (got &&
      (s.frame->decode_error_flags != 0 || (s.frame->flags & AV_FRAME_FLAG_CORRUPT)))
    note("the decoder marked the frame corrupt or concealed");
  if (!errors.empty() && s.damage.empty())
    s.damage = "frame " + std::to_string(next_) + ": " + errors;
  else if (got && errors.empty() && s.frame->key_frame)
    s.damage.clear();  // a clean key frame: later frames no longer depend on the damage
  return got;
}

bool VideoDecoder::Skip() {
  if (!Decode()) return false;
  ++next_;
  return true;
}

bool VideoDecoder::Read(ImageU8* rgb) {
  State& s = *state_;
  const bool got = Decode();
  if (!s.damage.empty()) {
    throw InputError(path_ + " frame " + std::to_string(next_), "pixels",
                     "a frame FFmpeg decodes without error (camera " + camera_ + ")",
                     "damaged since " + s.damage);
  }
  if (!got) return false;
  ++next_;
  const int w = s.frame->width, h = s.frame->height;
  s.scale =
      sws_getCachedContext(s.scale, w, h, static_cast<AVPixelFormat>(s.frame->format), w,
                           h, AV_PIX_FMT_RGB24, SWS_BICUBIC, nullptr, nullptr, nullptr);
  HL_CHECK(s.scale != nullptr, "FFmpeg colour conversion");
  cv::Mat decoded(h, w, CV_8UC3);
  uint8_t* rows[4] = {decoded.data, nullptr, nullptr, nullptr};
  const int strides[4] = {static_cast<int>(decoded.step), 0, 0, 0};
  sws_scale(s.scale, s.frame->data, s.frame->linesize, 0, h, rows, strides);
  if (s.rotation == 90) cv::rotate(decoded, decoded, cv::ROTATE_90_CLOCKWISE);
  if (s.rotation == 180) cv::rotate(decoded, decoded, cv::ROTATE_180);
  if (s.rotation == 270) cv::rotate(decoded, decoded, cv::ROTATE_90_COUNTERCLOCKWISE);
  *rgb = ImageU8(decoded.cols, decoded.rows, 3);
  for (int y = 0; y < decoded.rows; ++y) {
    std::copy(decoded.ptr<uint8_t>(y), decoded.ptr<uint8_t>(y) + 3 * decoded.cols,
              rgb->data.begin() + rgb->index(0, y));
  }
  return true;
}

}  // namespace handlabel
