#include "network/poem/point_ops.h"

#include <ATen/Parallel.h>

#include <algorithm>
#include <cmath>
#include <numeric>

#include "core/errors.h"

namespace handlabel {
namespace {

inline float SquaredDistance(const float* a, const float* b) {
  const float dx = a[0] - b[0];
  const float dy = a[1] - b[1];
  const float dz = a[2] - b[2];
  // Kept as separate statements so the compiler cannot reorder the sum.
  float d = dx * dx;
  d = d + dy * dy;
  d = d + dz * dz;
  return d;
}

void CheckPoints(const torch::Tensor& t, const char* name) {
  HL_CHECK(t.dim() == 3 && t.size(2) == 3, std::string(name) + " must be (B, P, 3)");
  HL_CHECK(t.scalar_type() == torch::kFloat32, std::string(name) + " must be float32");
  HL_CHECK(t.device().is_cpu(), std::string(name) + " must be on the CPU");
}

// Keeps the k smallest of `dist` (indices in increasing order arrive first, so a
// strict comparison keeps the lower index on ties), nearest first, in `best_i`.
void KeepNearest(const std::vector<float>& dist, int k, std::vector<float>* best_d,
                 int64_t* best_i) {
  float* bd = best_d->data();
  int count = 0;
  const int64_t P = static_cast<int64_t>(dist.size());
  for (int64_t p = 0; p < P; ++p) {
    const float d = dist[p];
    if (count == k && !(d < bd[k - 1])) continue;
    int pos = count < k ? count++ : k - 1;
    while (pos > 0 && d < bd[pos - 1]) {
      bd[pos] = bd[pos - 1];
      best_i[pos] = best_i[pos - 1];
      --pos;
    }
    bd[pos] = d;
    best_i[pos] = p;
  }
}

// The four taps of one bilinear sample; taps outside the map get weight 0 and offset 0.
struct BilinearTaps {
  int64_t offset[4] = {0, 0, 0, 0};  // in pixels from the map's start
  float weight[4] = {0, 0, 0, 0};
};

// grid_sample's unnormalisation for align_corners = false: -1 and 1 are the outer
// edges of the border pixels.
BilinearTaps TapsAt(float gx, float gy, int64_t H, int64_t W) {
  BilinearTaps t;
  if (!std::isfinite(gx) || !std::isfinite(gy)) return t;
  const float ix = ((gx + 1.f) * W - 1.f) / 2.f, iy = ((gy + 1.f) * H - 1.f) / 2.f;
  const float fx = std::floor(ix), fy = std::floor(iy);
  // Beyond a pixel outside the map every tap is outside: also keeps the casts in range.
  if (fx < -1.f || fy < -1.f || fx > W || fy > H) return t;
  const int64_t x0 = static_cast<int64_t>(fx), y0 = static_cast<int64_t>(fy);
  const float wx1 = ix - fx, wy1 = iy - fy, wx0 = 1.f - wx1, wy0 = 1.f - wy1;
  const int64_t xs[4] = {x0, x0 + 1, x0, x0 + 1}, ys[4] = {y0, y0, y0 + 1, y0 + 1};
  const float ws[4] = {wx0 * wy0, wx1 * wy0, wx0 * wy1, wx1 * wy1};
  for (int i = 0; i < 4; ++i) {
    if (xs[i] < 0 || xs[i] >= W || ys[i] < 0 || ys[i] >= H) continue;
    t.offset[i] = ys[i] * W + xs[i];
    t.weight[i] = ws[i];
  }
  return t;
}

// out[c] (+)= sum of the taps' weights x the map's rows (channels-last: C per pixel).
void Blend(const BilinearTaps& t, const float* map, int64_t C, bool accumulate,
           float* out) {
  const float *r0 = map + t.offset[0] * C, *r1 = map + t.offset[1] * C,
              *r2 = map + t.offset[2] * C, *r3 = map + t.offset[3] * C;
  const float w0 = t.weight[0], w1 = t.weight[1], w2 = t.weight[2], w3 = t.weight[3];
  for (int64_t c = 0; c < C; ++c) {
    const float v = w0 * r0[c] + w1 * r1[c] + w2 * r2[c] + w3 * r3[c];
    out[c] = accumulate ? out[c] + v : v;
  }
}

void CheckMaps(const torch::Tensor& maps, int64_t BN, const char* name) {
  HL_CHECK(maps.dim() == 4 && maps.size(0) == BN,
           std::string(name) + " must be (B*N, C, H, W)");
  HL_CHECK(maps.scalar_type() == torch::kFloat32, std::string(name) + " must be float32");
}

}  // namespace

ViewSamples SampleViewsForMerge(const torch::Tensor& features, const torch::Tensor& grid,
                                int64_t B, int64_t N, const torch::Tensor& summed) {
  CheckMaps(features, B * N, "features");
  if (summed.defined()) CheckMaps(summed, B * N, "summed");
  HL_CHECK(grid.dim() == 4 && grid.size(0) == B * N && grid.size(2) == 1 &&
               grid.size(3) == 2 && grid.scalar_type() == torch::kFloat32,
           "grid must be (B*N, P, 1, 2) float32");
  const int64_t P = grid.size(1), H = features.size(2), W = features.size(3);
  const int64_t C = features.size(1), Cs = summed.defined() ? summed.size(1) : 0;
  HL_CHECK(!summed.defined() || (summed.size(2) == H && summed.size(3) == W),
           "summed must have the features' height and width");
  const torch::Tensor maps = features.detach().contiguous(at::MemoryFormat::ChannelsLast);
  const torch::Tensor maps2 =
      summed.defined() ? summed.detach().contiguous(at::MemoryFormat::ChannelsLast)
                       : summed;
  const torch::Tensor g = grid.detach().contiguous();
  ViewSamples out;
  out.per_view = torch::empty({B, P, N, C}, torch::kFloat32);
  if (summed.defined()) out.summed_views = torch::empty({B, P, Cs}, torch::kFloat32);
  const float* gd = g.data_ptr<float>();
  const float* fd = maps.data_ptr<float>();
  const float* sd = summed.defined() ? maps2.data_ptr<float>() : nullptr;
  float* od = out.per_view.data_ptr<float>();
  float* osd = summed.defined() ? out.summed_views.data_ptr<float>() : nullptr;
  at::parallel_for(0, B * P, 16, [&](int64_t begin, int64_t end) {
    for (int64_t bp = begin; bp < end; ++bp) {
      const int64_t b = bp / P, p = bp % P;
      for (int64_t n = 0; n < N; ++n) {
        const int64_t bn = b * N + n;
        const float* xy = gd + (bn * P + p) * 2;
        const BilinearTaps t = TapsAt(xy[0], xy[1], H, W);
        Blend(t, fd + bn * H * W * C, C, false, od + (bp * N + n) * C);
        if (sd) Blend(t, sd + bn * H * W * Cs, Cs, n > 0, osd + bp * Cs);
      }
    }
  });
  return out;
}

torch::Tensor KnnIndices(const torch::Tensor& query_in, const torch::Tensor& points_in,
                         int k) {
  CheckPoints(query_in, "query");
  CheckPoints(points_in, "points");
  const torch::Tensor query = query_in.detach().contiguous();
  const torch::Tensor points = points_in.detach().contiguous();
  const int64_t B = query.size(0), Q = query.size(1), P = points.size(1);
  HL_CHECK(points.size(0) == B, "batch sizes differ");
  HL_CHECK(k >= 1 && k <= P, "k must be in 1..P");
  torch::Tensor out = torch::empty({B, Q, k}, torch::kInt64);
  // The points as coordinate planes (B, 3, P): the distance loop below then reads
  // each coordinate contiguously and the compiler vectorises it.
  const torch::Tensor planes = points.transpose(1, 2).contiguous();
  const float* qd = query.data_ptr<float>();
  const float* sd = planes.data_ptr<float>();
  int64_t* od = out.data_ptr<int64_t>();
  // Grain: a few queries per task; each query scans all P points.
  const int64_t grain = std::max<int64_t>(1, 32768 / std::max<int64_t>(P, 1));
  at::parallel_for(0, B * Q, grain, [&](int64_t begin, int64_t end) {
    std::vector<float> dist(P), best_d(k);
    for (int64_t bq = begin; bq < end; ++bq) {
      const float* q = qd + bq * 3;
      const float* x = sd + (bq / Q) * 3 * P;
      const float* y = x + P;
      const float* z = y + P;
      // SquaredDistance's arithmetic, term by term, so the same floats.
      for (int64_t p = 0; p < P; ++p) {
        const float dx = q[0] - x[p], dy = q[1] - y[p], dz = q[2] - z[p];
        float d = dx * dx;
        d = d + dy * dy;
        d = d + dz * dz;
        dist[p] = d;
      }
      KeepNearest(dist, k, &best_d, od + bq * k);
    }
  });
  return out;
}

torch::Tensor GatherNeighbors(const torch::Tensor& values, const torch::Tensor& index) {
  HL_CHECK(values.dim() == 3 && index.dim() == 3, "values (B,P,C), index (B,Q,k)");
  const int64_t B = values.size(0), P = values.size(1), C = values.size(2);
  const int64_t Q = index.size(1), k = index.size(2);
  const torch::Tensor offset = torch::arange(B, index.options()).mul_(P).view({B, 1, 1});
  const torch::Tensor flat = (index + offset).reshape({-1});
  return values.reshape({B * P, C}).index_select(0, flat).view({B, Q, k, C});
}

torch::Tensor SelectBallPoints(const torch::Tensor& points_in,
                               const torch::Tensor& center_in, double radius, int count,
                               std::vector<int64_t>* num_inside) {
  CheckPoints(points_in, "points");
  const torch::Tensor points = points_in.detach().contiguous();
  const torch::Tensor center =
      center_in.detach().to(torch::kFloat32).reshape({-1, 3}).contiguous();
  const int64_t B = points.size(0), M = points.size(1);
  HL_CHECK(center.size(0) == B, "one centre per batch element");
  HL_CHECK(count >= 1 && count <= M, "count must be in 1..M");
  const float r2 = static_cast<float>(radius * radius);
  torch::Tensor out = torch::empty({B, count}, torch::kInt64);
  if (num_inside) num_inside->assign(B, 0);
  for (int64_t b = 0; b < B; ++b) {
    const float* pts = points.data_ptr<float>() + b * M * 3;
    const float* c = center.data_ptr<float>() + b * 3;
    int64_t* o = out.data_ptr<int64_t>() + b * count;
    std::vector<float> d2(M);
    std::vector<int64_t> inside;
    inside.reserve(M);
    for (int64_t p = 0; p < M; ++p) {
      d2[p] = SquaredDistance(pts + p * 3, c);
      if (d2[p] < r2) inside.push_back(p);
    }
    const int64_t m = static_cast<int64_t>(inside.size());
    if (num_inside) (*num_inside)[b] = m;
    if (m >= count) {
      for (int64_t j = 0; j < count; ++j) o[j] = inside[(j * m) / count];
      continue;
    }
    std::copy(inside.begin(), inside.end(), o);
    std::vector<int64_t> outside;
    outside.reserve(M - m);
    for (int64_t p = 0; p < M; ++p) {
      if (!(d2[p] < r2)) outside.push_back(p);
    }
    const int64_t need = count - m;
    std::partial_sort(outside.begin(), outside.begin() + need, outside.end(),
                      [&](int64_t a, int64_t b2) {
                        return d2[a] < d2[b2] || (d2[a] == d2[b2] && a < b2);
                      });
    std::copy(outside.begin(), outside.begin() + need, o + m);
  }
  return out;
}

torch::Tensor InverseSigmoid(const torch::Tensor& x_in, double eps) {
  const torch::Tensor x = x_in.clamp(0, 1);
  const torch::Tensor x1 = x.clamp_min(eps);
  const torch::Tensor x2 = (1 - x).clamp_min(eps);
  return torch::log(x1 / x2);
}

}  // namespace handlabel
