#pragma once
// Writes a hand model as the official MANO pickle is laid out (Python 2, protocol 2:
// numpy arrays through numpy.core.multiarray._reconstruct with BINSTRING buffers,
// shapedirs as a chumpy Select over a Ch, J_regressor as a scipy.sparse.csc csc_matrix,
// kintree_table root parent 4294967295). For tests and benchmarks that need MANO-sized
// files, which cannot be committed. The committed Python-written fixtures
// (tests/data/mano) remain the reference for the exact byte layout.

#include <cstdint>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "hand/hand_model.h"

namespace handlabel::testing {

// Random values in MANO's sizes (778 vertices, 1538 faces, 10 betas, ~4 skinning
// weights per vertex, 45 x 45 pose PCA); deterministic for a seed.
inline HandModel RandomManoSizedModel(uint64_t seed) {
  constexpr int kVerts = 778, kFaces = 1538, kBetas = 10;
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  std::uniform_int_distribution<int> vertex(0, kVerts - 1);
  HandModel m;
  m.name = "MANO_RIGHT";
  m.v_template = 0.05 * Eigen::MatrixXd::NullaryExpr(kVerts, 3, [&]() { return g(rng); });
  m.faces.resize(kFaces, 3);
  for (int f = 0; f < kFaces; ++f)
    m.faces.row(f) << vertex(rng), vertex(rng), vertex(rng);
  m.shapedirs =
      0.01 * Eigen::MatrixXd::NullaryExpr(3 * kVerts, kBetas, [&]() { return g(rng); });
  m.posedirs =
      0.01 * Eigen::MatrixXd::NullaryExpr(3 * kVerts, 135, [&]() { return g(rng); });
  std::vector<Eigen::Triplet<double>> reg;
  for (int j = 0; j < kNumHandJoints; ++j) {
    for (int k = 0; k < 20; ++k) reg.emplace_back(j, vertex(rng), 0.05);
  }
  m.joint_regressor.resize(kNumHandJoints, kVerts);
  m.joint_regressor.setFromTriplets(reg.begin(), reg.end());
  m.skinning_weights.setZero(kVerts, kNumHandJoints);
  for (int v = 0; v < kVerts; ++v) {
    for (int k = 0; k < 4; ++k)
      m.skinning_weights(v, (v + 3 * k) % kNumHandJoints) = 0.25;
  }
  m.pose_pca_basis = Eigen::MatrixXd::NullaryExpr(45, 45, [&]() { return g(rng); });
  m.pose_mean = 0.2 * Eigen::VectorXd::NullaryExpr(45, [&]() { return g(rng); });
  m.Check("RandomManoSizedModel");
  return m;
}

class Py2PickleWriter {
 public:
  std::string Finish() { return out_ + "."; }

  void Proto() { out_ += "\x80\x02"; }
  void Mark() { out_ += "("; }
  void Str(const std::string& s) {  // Python 2 str
    if (s.size() < 256) {
      out_ += "U";
      out_ += static_cast<char>(s.size());
    } else {
      out_ += "T";
      Le(s.size(), 4);
    }
    out_ += s;
  }
  void Int(int64_t v) {
    out_ += "J";
    Le(static_cast<uint64_t>(v), 4);
  }
  void Global(const std::string& module, const std::string& name) {
    out_ += "c" + module + "\n" + name + "\n";
  }
  void IntTuple(const std::vector<int64_t>& dims) {
    Mark();
    for (int64_t d : dims) Int(d);
    out_ += "t";
  }
  // numpy ndarray with dtype descr like "f8", "i8", "u4", raw little-endian bytes.
  void Array(const std::vector<int64_t>& shape, const std::string& descr,
             const void* data, size_t bytes) {
    Global("numpy.core.multiarray", "_reconstruct");
    Global("numpy", "ndarray");
    Int(0);
    out_ += "\x85";  // TUPLE1
    Str("b");
    out_ += "\x87R";  // TUPLE3, REDUCE
    Mark();
    Int(1);
    IntTuple(shape);
    Global("numpy", "dtype");
    Str(descr);
    Int(0);
    Int(1);
    out_ += "\x87R";
    Mark();
    Int(3);
    Str("<");
    out_ += "NNN";
    Int(-1);
    Int(-1);
    Int(0);
    out_ += "tb";    // dtype state, BUILD
    out_ += "\x89";  // NEWFALSE: C order
    Str(std::string(static_cast<const char*>(data), bytes));
    out_ += "tb";
  }
  void Doubles(const std::vector<int64_t>& shape, const double* v, size_t n) {
    Array(shape, "f8", v, n * 8);
  }
  // Starts `module.name` instance state: NEWOBJ then a dict filled by key/value calls
  // and closed with EndObject().
  void BeginObject(const std::string& module, const std::string& name) {
    Global(module, name);
    out_ += ")\x81}(";  // EMPTY_TUPLE NEWOBJ EMPTY_DICT MARK
  }
  void EndObject() { out_ += "ub"; }  // SETITEMS BUILD
  void BeginDict() { out_ += "}("; }
  void EndDict() { out_ += "u"; }

 private:
  void Le(uint64_t v, int bytes) {
    for (int k = 0; k < bytes; ++k) out_ += static_cast<char>((v >> (8 * k)) & 0xFF);
  }
  std::string out_;
};

// The whole model dict in MANO's layout.
inline std::string ManoStylePickle(const HandModel& m) {
  Py2PickleWriter w;
  const int64_t nv = m.num_vertices(), nb = m.num_betas();
  w.Proto();
  w.BeginDict();
  w.Str("v_template");
  const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> vt = m.v_template;
  w.Doubles({nv, 3}, vt.data(), vt.size());
  w.Str("f");
  std::vector<uint32_t> f(m.faces.data(), m.faces.data() + m.faces.size());
  w.Array({m.num_faces(), 3}, "u4", f.data(), f.size() * 4);
  w.Str("shapedirs");  // Select(a=Ch(x), idxs=arange, preferred_shape=(V, 3, S))
  w.BeginObject("chumpy.reordering", "Select");
  w.Str("a");
  w.BeginObject("chumpy.ch", "Ch");
  w.Str("x");
  const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> sd =
      m.shapedirs;
  w.Doubles({nv, 3, nb}, sd.data(), sd.size());
  w.EndObject();
  w.Str("idxs");
  std::vector<int64_t> idxs(sd.size());
  for (size_t i = 0; i < idxs.size(); ++i) idxs[i] = static_cast<int64_t>(i);
  w.Array({static_cast<int64_t>(idxs.size())}, "i8", idxs.data(), idxs.size() * 8);
  w.Str("preferred_shape");
  w.IntTuple({nv, 3, nb});
  w.EndObject();
  w.Str("posedirs");
  const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> pd =
      m.posedirs;
  w.Doubles({nv, 3, 135}, pd.data(), pd.size());
  w.Str("J_regressor");
  const Eigen::SparseMatrix<double, Eigen::ColMajor> csc = m.joint_regressor;
  w.BeginObject("scipy.sparse.csc", "csc_matrix");
  w.Str("_shape");
  w.IntTuple({kNumHandJoints, nv});
  w.Str("data");
  w.Doubles({csc.nonZeros()}, csc.valuePtr(), csc.nonZeros());
  w.Str("indices");
  std::vector<int32_t> indices(csc.innerIndexPtr(), csc.innerIndexPtr() + csc.nonZeros());
  w.Array({csc.nonZeros()}, "i4", indices.data(), indices.size() * 4);
  w.Str("indptr");
  std::vector<int32_t> indptr(csc.outerIndexPtr(), csc.outerIndexPtr() + nv + 1);
  w.Array({nv + 1}, "i4", indptr.data(), indptr.size() * 4);
  w.EndObject();
  w.Str("weights");
  w.BeginObject("chumpy.ch", "Ch");
  w.Str("x");
  const Eigen::Matrix<double, Eigen::Dynamic, kNumHandJoints, Eigen::RowMajor> sw =
      m.skinning_weights;
  w.Doubles({nv, kNumHandJoints}, sw.data(), sw.size());
  w.EndObject();
  w.Str("kintree_table");
  std::vector<int64_t> kintree(2 * kNumHandJoints);
  for (int j = 0; j < kNumHandJoints; ++j) {
    kintree[j] = m.parents[j] < 0 ? 4294967295 : m.parents[j];
    kintree[kNumHandJoints + j] = j;
  }
  w.Array({2, kNumHandJoints}, "i8", kintree.data(), kintree.size() * 8);
  if (m.pose_pca_basis.size()) {
    w.Str("hands_components");
    const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> pca =
        m.pose_pca_basis;
    w.Doubles({pca.rows(), pca.cols()}, pca.data(), pca.size());
  }
  if (m.pose_mean.size()) {
    w.Str("hands_mean");
    w.Doubles({kNumPoseParams}, m.pose_mean.data(), kNumPoseParams);
  }
  w.Str("bs_style");
  w.Str("lbs");
  w.Str("bs_type");
  w.Str("lrotmin");
  w.EndDict();
  return w.Finish();
}

}  // namespace handlabel::testing
