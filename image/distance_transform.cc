#include "image/distance_transform.h"

#include <limits>
#include <vector>

#include "core/errors.h"

namespace handlabel {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// 1D squared distance transform of f (in place) along n samples with the given stride:
// d(q) = min_p (q - p)^2 + f(p), by the lower envelope of parabolas.
void Transform1d(double* f, int n, int stride, std::vector<double>* buffer,
                 std::vector<int>* v, std::vector<double>* z) {
  buffer->resize(n);
  v->resize(n);
  z->resize(n + 1);
  double* d = buffer->data();
  int k = -1;
  for (int q = 0; q < n; ++q) {
    const double fq = f[q * stride];
    if (fq == kInf) continue;
    while (true) {
      if (k < 0) {
        k = 0;
        (*v)[0] = q;
        (*z)[0] = -kInf;
        (*z)[1] = kInf;
        break;
      }
      const int p = (*v)[k];
      const double s = ((fq + q * q) - (f[p * stride] + p * p)) / (2.0 * (q - p));
      if (s <= (*z)[k]) {
        --k;
        continue;
      }
      ++k;
      (*v)[k] = q;
      (*z)[k] = s;
      (*z)[k + 1] = kInf;
      break;
    }
  }
  if (k < 0) return;  // all infinite: stays infinite
  int j = 0;
  for (int q = 0; q < n; ++q) {
    while ((*z)[j + 1] < q) ++j;
    const int p = (*v)[j];
    d[q] = (q - p) * double(q - p) + f[p * stride];
  }
  for (int q = 0; q < n; ++q) f[q * stride] = d[q];
}

// In place: squared distances (0 on targets, +inf elsewhere) become distances.
void SeparableTransform(DistanceImage* image) {
  DistanceImage& d = *image;
  const int h = static_cast<int>(d.rows());
  const int w = static_cast<int>(d.cols());
  std::vector<double> buffer, z;
  std::vector<int> v;
  for (int c = 0; c < w; ++c) Transform1d(d.data() + c, h, w, &buffer, &v, &z);
  for (int r = 0; r < h; ++r) Transform1d(d.data() + r * w, w, 1, &buffer, &v, &z);
  d = d.cwiseSqrt();
}

DistanceImage DistanceToValue(const MaskImage& mask, bool target_nonzero) {
  const int h = static_cast<int>(mask.rows());
  const int w = static_cast<int>(mask.cols());
  DistanceImage d(h, w);
  for (int r = 0; r < h; ++r) {
    for (int c = 0; c < w; ++c) {
      d(r, c) = ((mask(r, c) != 0) == target_nonzero) ? 0.0 : kInf;
    }
  }
  SeparableTransform(&d);
  return d;
}

}  // namespace

DistanceImage DistanceToMask(const MaskImage& mask) {
  return DistanceToValue(mask, true);
}

DistanceImage DistanceToOutside(const MaskImage& mask) {
  return DistanceToValue(mask, false);
}

DistanceImage DistanceToMaskInWindow(const MaskImage& mask, const PixelWindow& window,
                                     const MaskImage* also) {
  HL_CHECK(!window.empty() && window.x0 >= 0 && window.y0 >= 0 &&
               window.x0 + window.width <= mask.cols() &&
               window.y0 + window.height <= mask.rows(),
           "distance window inside the image");
  HL_CHECK(
      also == nullptr || (also->rows() == mask.rows() && also->cols() == mask.cols()),
      "masks of one size");
  DistanceImage d(window.height, window.width);
  for (int r = 0; r < window.height; ++r) {
    for (int c = 0; c < window.width; ++c) {
      const int y = window.y0 + r, x = window.x0 + c;
      const bool target = mask(y, x) != 0 || (also != nullptr && (*also)(y, x) != 0);
      d(r, c) = target ? 0.0 : kInf;
    }
  }
  SeparableTransform(&d);
  return d;
}

}  // namespace handlabel
