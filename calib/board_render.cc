#include "calib/board_render.h"

#include <cmath>
#include <opencv2/aruco/charuco.hpp>
#include <random>

#include "core/errors.h"
#include "core/option_checks.h"

namespace handlabel {

void BoardRenderOptions::Check(const std::string& source) const {
  RequireInRange(source, "supersampling", supersampling, 1, 16);
  RequireAtLeast(source, "white_margin", white_margin, 0);
  RequireAtLeast(source, "noise_sigma", noise_sigma, 0);
  RequireAtLeast(source, "texture_pixels_per_square", texture_pixels_per_square, 10);
}

struct BoardRenderer::Impl {
  BoardSpec board;
  Camera camera;
  BoardRenderOptions options;
  // Normalised rays (z = 1) through the pixel-corner lattice: (W+1) x (H+1) points at
  // (i - 0.5, j - 0.5).
  std::vector<Eigen::Vector2d> rays;
  // ChArUco texture (0 black, 255 white), rows top to bottom.
  cv::Mat texture;
  std::vector<bool> square_black;  // per square, row-major

  // Board-plane point -> grey level in [0, 1] of the board, or -1 off the board.
  double Lookup(double x, double y) const {
    const double s = board.square, margin = options.white_margin * s;
    const double w = board.Width(), h = board.Height();
    if (x < -margin || y < -margin || x > w + margin || y > h + margin) return -1;
    if (x < 0 || y < 0 || x >= w || y >= h) return 1;
    const int i = static_cast<int>(x / s), j = static_cast<int>(y / s);
    if (board.type == BoardType::kCheckerboard) return (i + j) % 2 == 0 ? 0.0 : 1.0;
    // Squares are drawn exactly; only marker cells come from OpenCV's board image,
    // whose squares are not placed to sub-texel accuracy.
    if (square_black[size_t(j) * board.cols + i]) return 0.0;
    const double inset = (s - board.marker) / 2;
    const double mx = x - i * s, my = y - j * s;
    if (mx < inset || my < inset || mx > s - inset || my > s - inset) return 1.0;
    // OpenCV 4.6's drawn ChArUco image has board x along columns, board y along rows
    // (as its chessboard corner ids run).
    const int u = static_cast<int>(x / w * texture.cols);
    const int v = static_cast<int>(y / h * texture.rows);
    return texture.at<uint8_t>(std::min(v, texture.rows - 1),
                               std::min(u, texture.cols - 1)) /
           255.0;
  }
};

BoardRenderer::BoardRenderer(const BoardSpec& board, const Camera& camera,
                             const BoardRenderOptions& options)
    : impl_(std::make_unique<Impl>()) {
  board.Check("board");
  options.Check("BoardRenderOptions");
  impl_->board = board;
  impl_->camera = camera;
  impl_->options = options;
  const int w = camera.width(), h = camera.height();
  // Undistortion (Newton) is exact on every kStep-th lattice point and bilinear in
  // between: lens distortion is smooth, so the error is far below 1e-3 px.
  constexpr int kStep = 4;
  const int gw = w / kStep + 2, gh = h / kStep + 2;
  std::vector<Eigen::Vector2d> grid(size_t(gw) * gh);
  for (int j = 0; j < gh; ++j) {
    for (int i = 0; i < gw; ++i) {
      grid[size_t(j) * gw + i] =
          camera.NormalizedFromImage(Eigen::Vector2d(i * kStep - 0.5, j * kStep - 0.5));
    }
  }
  impl_->rays.resize(size_t(w + 1) * (h + 1));
  for (int j = 0; j <= h; ++j) {
    const int gj = j / kStep;
    const double fy = double(j % kStep) / kStep;
    for (int i = 0; i <= w; ++i) {
      const int gi = i / kStep;
      const double fx = double(i % kStep) / kStep;
      const size_t g = size_t(gj) * gw + gi;
      impl_->rays[size_t(j) * (w + 1) + i] =
          (1 - fy) * ((1 - fx) * grid[g] + fx * grid[g + 1]) +
          fy * ((1 - fx) * grid[g + gw] + fx * grid[g + gw + 1]);
    }
  }
  if (board.type == BoardType::kCharuco) {
    int dict_id = 0;
    for (const ArucoDictionaryInfo& d : ArucoDictionaries()) {
      if (board.dictionary == d.name) dict_id = d.opencv_id;
    }
    const auto dictionary = cv::aruco::getPredefinedDictionary(dict_id);
    const auto cv_board = cv::aruco::CharucoBoard::create(
        board.cols, board.rows, static_cast<float>(board.square),
        static_cast<float>(board.marker), dictionary);
    const int px = options.texture_pixels_per_square;
    cv_board->draw(cv::Size(board.cols * px, board.rows * px), impl_->texture, 0, 1);
    // Square colours from the texture, sampled between a square's corner and its marker.
    const int probe = std::max(
        1, static_cast<int>(px * (board.square - board.marker) / board.square / 4));
    for (int j = 0; j < board.rows; ++j) {
      for (int i = 0; i < board.cols; ++i) {
        impl_->square_black.push_back(
            impl_->texture.at<uint8_t>(j * px + probe, i * px + probe) < 128);
      }
    }
  }
}

BoardRenderer::~BoardRenderer() = default;

ImageU8 BoardRenderer::Render(const Rigid3& cam_from_board, uint64_t seed) const {
  const Impl& m = *impl_;
  const int w = m.camera.width(), h = m.camera.height();
  const BoardRenderOptions& o = m.options;
  const Eigen::Matrix3d r = cam_from_board.rotation.toRotationMatrix();
  const Eigen::Vector3d t = cam_from_board.translation;
  const Eigen::Vector3d normal = r.col(2);
  const double plane = normal.dot(t);
  // The printed side faces -z (board z points into the board, as in OpenCV); seen
  // from behind, a ChArUco board is plain grey cardboard. Checkerboards look the same
  // from both sides.
  const bool front = m.board.type == BoardType::kCheckerboard ||
                     cam_from_board.Inverse().translation.z() < 0;

  // Board coordinates of every lattice point (NaN where the ray misses the plane).
  const size_t lattice = size_t(w + 1) * (h + 1);
  std::vector<Eigen::Vector2d> board_xy(lattice);
  std::vector<double> corner_value(lattice);
  const auto shade = [&](double v) {
    if (v < 0) return double(o.background);
    if (!front) return 90.0;
    return o.black + v * (o.white - o.black);
  };
  for (size_t k = 0; k < lattice; ++k) {
    const Eigen::Vector3d ray(m.rays[k].x(), m.rays[k].y(), 1.0);
    const double denom = normal.dot(ray);
    const double lambda = std::abs(denom) > 1e-12 ? plane / denom : -1;
    if (!(lambda > 0)) {
      board_xy[k].setConstant(std::numeric_limits<double>::quiet_NaN());
      corner_value[k] = o.background;
      continue;
    }
    const Eigen::Vector3d p = r.transpose() * (lambda * ray - t);
    board_xy[k] = p.head<2>();
    corner_value[k] = shade(m.Lookup(p.x(), p.y()));
  }

  ImageU8 image(w, h, 1);
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, o.noise_sigma);
  const int s = o.supersampling;
  for (int j = 0; j < h; ++j) {
    for (int i = 0; i < w; ++i) {
      const size_t k00 = size_t(j) * (w + 1) + i, k10 = k00 + 1, k01 = k00 + w + 1,
                   k11 = k01 + 1;
      const Eigen::Vector2d& a = board_xy[k00];
      const Eigen::Vector2d& b = board_xy[k10];
      const Eigen::Vector2d& c = board_xy[k01];
      const Eigen::Vector2d& d = board_xy[k11];
      double value;
      if (!a.allFinite() || !b.allFinite() || !c.allFinite() || !d.allFinite()) {
        value = o.background;
      } else {
        const Eigen::Vector2d centre = 0.25 * (a + b + c + d);
        const double v_centre = shade(m.Lookup(centre.x(), centre.y()));
        if (corner_value[k00] == v_centre && corner_value[k10] == v_centre &&
            corner_value[k01] == v_centre && corner_value[k11] == v_centre) {
          value = v_centre;  // uniform pixel: no need to supersample
        } else {
          double sum = 0;
          for (int sy = 0; sy < s; ++sy) {
            const double fy = (sy + 0.5) / s;
            for (int sx = 0; sx < s; ++sx) {
              const double fx = (sx + 0.5) / s;
              const Eigen::Vector2d p =
                  (1 - fy) * ((1 - fx) * a + fx * b) + fy * ((1 - fx) * c + fx * d);
              sum += shade(m.Lookup(p.x(), p.y()));
            }
          }
          value = sum / (s * s);
        }
      }
      if (o.noise_sigma > 0) value += noise(rng);
      image.at(i, j) = static_cast<uint8_t>(std::clamp(std::lround(value), 0L, 255L));
    }
  }
  return image;
}

}  // namespace handlabel
