#pragma once
// Renders a calibration board seen by a camera, for tests and demos. The board is a
// plane, so every pixel is traced: its ray (through the camera's distortion, inverted
// once per camera) is intersected with the board plane and the
// board texture is looked up there; S x S samples per pixel give anti-aliased edges.

#include <cstdint>
#include <memory>

#include "calib/board_spec.h"
#include "geometry/camera.h"
#include "geometry/rigid3.h"
#include "image/image.h"

namespace handlabel {

struct BoardRenderOptions {
  int supersampling = 4;      // S: S x S samples per pixel (even: none on pixel centres)
  double white_margin = 0.5;  // white paper around the squares, in squares
  uint8_t background = 110;   // grey level off the board
  uint8_t black = 25;         // grey level of black squares / marker cells
  uint8_t white = 230;        // grey level of white paper
  double noise_sigma = 2.0;   // Gaussian pixel noise, grey levels
  int texture_pixels_per_square = 100;  // resolution of the ChArUco texture
  void Check(const std::string& source) const;
};

// One camera and one board; renders any number of board poses.
class BoardRenderer {
 public:
  BoardRenderer(const BoardSpec& board, const Camera& camera,
                const BoardRenderOptions& options = {});
  ~BoardRenderer();
  // A grey (1-channel) image of the camera's size; `seed` drives the pixel noise.
  ImageU8 Render(const Rigid3& cam_from_board, uint64_t seed) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace handlabel
