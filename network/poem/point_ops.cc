#include "network/poem/point_ops.h"

#include <ATen/Parallel.h>

#include <algorithm>
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

}  // namespace

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
