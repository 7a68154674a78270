#include "hand/hand_model_io.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <memory>

#include "core/errors.h"
#include "core/file_bytes.h"
#include "formats/npy.h"
#include "formats/npz.h"
#include "formats/pickle_reader.h"
#include "formats/zip_reader.h"

namespace handlabel {
namespace {

constexpr std::array<int, 5> kManopthTipIds = {745, 317, 444, 556, 673};
constexpr int kManoVertexCount = 778;
constexpr int64_t kUint32MinusOne = 4294967295;  // MANO's root parent in kintree_table

// One entry of a model file: a dense array, a sparse matrix or a string.
struct Entry {
  std::shared_ptr<const NdArray> array;
  std::shared_ptr<const SparseArrays> sparse;
  std::optional<std::string> text;
  std::string description;  // what it is, for errors
};

class Entries {
 public:
  explicit Entries(std::string path) : path_(std::move(path)) {}

  void Add(const std::string& key, Entry e) { entries_[key] = std::move(e); }
  bool Has(const std::string& key) const { return entries_.count(key) > 0; }
  const std::string& path() const { return path_; }

  const Entry& Get(const std::string& key) const {
    const auto it = entries_.find(key);
    if (it == entries_.end())
      throw InputError(path_, key, "this key in the model file", "missing");
    return it->second;
  }

  // A numeric array with the given shape (-1 = any size in that dimension).
  const NdArray& Array(const std::string& key, const std::vector<int64_t>& shape) const {
    const Entry& e = Get(key);
    if (!e.array || !IsNumeric(e.array->dtype)) {
      throw InputError(path_, key, "a numeric array", e.description);
    }
    bool ok = e.array->ndim() == static_cast<int>(shape.size());
    for (size_t k = 0; ok && k < shape.size(); ++k) {
      ok = shape[k] < 0 || e.array->shape[k] == shape[k];
    }
    if (!ok)
      throw InputError(path_, key, "shape " + ShapeText(shape), e.array->ShapeString());
    return *e.array;
  }

  std::vector<double> Doubles(const std::string& key,
                              const std::vector<int64_t>& shape) const {
    const NdArray& a = Array(key, shape);
    std::vector<double> v = a.ToDoubles();
    for (double x : v) {
      if (!std::isfinite(x)) throw InputError(path_, key, "finite values", "NaN or inf");
    }
    return v;
  }

  std::vector<int64_t> Ints(const std::string& key,
                            const std::vector<int64_t>& shape) const {
    const NdArray& a = Array(key, shape);
    if (!(a.dtype != DType::kFloat16 && a.dtype != DType::kFloat32 &&
          a.dtype != DType::kFloat64)) {
      throw InputError(path_, key, "an integer array", std::string(DTypeName(a.dtype)));
    }
    return a.ToInt64s();
  }

  std::string Text(const std::string& key) const {
    const Entry& e = Get(key);
    if (e.text) return *e.text;
    if (e.array && !IsNumeric(e.array->dtype) && e.array->size() == 1)
      return e.array->ToText();
    throw InputError(path_, key, "a string", e.description);
  }

 private:
  static std::string ShapeText(const std::vector<int64_t>& shape) {
    std::string s = "(";
    for (size_t k = 0; k < shape.size(); ++k) {
      s += (k ? ", " : "") + (shape[k] < 0 ? std::string("N") : std::to_string(shape[k]));
    }
    return s + (shape.size() == 1 ? ",)" : ")");
  }

  std::string path_;
  std::map<std::string, Entry> entries_;
};

Entry EntryFromPickle(const PickleValue& v) {
  Entry e;
  e.description = v.Describe();
  if (v.kind == PickleValue::Kind::kArray) e.array = v.array;
  if (v.kind == PickleValue::Kind::kSparse) e.sparse = v.sparse;
  if (v.kind == PickleValue::Kind::kText) e.text = v.text;
  if (v.is_number()) {
    const double x = v.number();
    e.array = std::make_shared<NdArray>(NdArray::FromDoubles({}, &x));
  }
  return e;
}

bool ContainsChumpy(const PickleValue& v) {
  for (const auto& [k, value] : v.entries) {
    if (value.type_name.rfind("chumpy.", 0) == 0) return true;
  }
  return false;
}

// ---- reading the formats into Entries ----------------------------------------------

Entries ReadPickleEntries(const std::string& path, const std::string& bytes,
                          HandModelFormat* format) {
  const PickleValue root = ReadPickle(bytes, path);
  if (root.kind != PickleValue::Kind::kDict) {
    throw InputError(path, "", "a pickled dict of model arrays", root.Describe());
  }
  Entries entries(path);
  for (const auto& [key, value] : root.entries) {
    if (key.kind == PickleValue::Kind::kText)
      entries.Add(key.text, EntryFromPickle(value));
  }
  // The official files are Python 2 protocol-2 pickles holding chumpy objects.
  *format =
      ContainsChumpy(root) ? HandModelFormat::kManoPickle : HandModelFormat::kPickle;
  return entries;
}

Entries ReadNpzEntries(const std::string& path, HandModelFormat* format) {
  const ZipReader zip = ZipReader::OpenFile(path);
  Entries entries(path);
  bool own = false;
  for (const ZipEntry& z : zip.entries()) {
    std::string key = z.name;
    if (key.size() > 4 && key.compare(key.size() - 4, 4, ".npy") == 0)
      key.resize(key.size() - 4);
    const std::string source = path + ":" + z.name;
    const std::string bytes = zip.Read(z);
    const NpyHeader header = ParseNpyHeader(bytes, source);
    Entry e;
    if (header.is_object) {
      // np.savez of a scipy matrix: the payload is a pickle of a 0-d object array.
      const PickleValue v = ReadPickle(bytes.substr(header.data_offset), source);
      e = EntryFromPickle(v);
    } else {
      auto a = std::make_shared<NdArray>(ParseNpy(bytes, source));
      e.description = std::string(DTypeName(a->dtype)) + " array " + a->ShapeString();
      e.array = std::move(a);
    }
    if (key.rfind("handlabel_", 0) == 0) own = true;
    entries.Add(key, std::move(e));
  }
  *format = own ? HandModelFormat::kHandlabelNpz : HandModelFormat::kSmplxNpz;
  return entries;
}

// ---- Entries -> HandModel ------------------------------------------------------------

Eigen::MatrixXd RowMajorMatrix(const std::vector<double>& v, Eigen::Index rows,
                               Eigen::Index cols) {
  return Eigen::Map<
      const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
      v.data(), rows, cols);
}

Eigen::SparseMatrix<double, Eigen::RowMajor> JointRegressor(const Entries& entries,
                                                            int64_t num_vertices) {
  const std::string key = "J_regressor";
  const Entry& e = entries.Get(key);
  std::vector<Eigen::Triplet<double>> triplets;
  if (e.sparse) {
    const SparseArrays& s = *e.sparse;
    if (s.rows != kNumHandJoints || s.cols != num_vertices) {
      throw InputError(
          entries.path(), key, "shape (16, " + std::to_string(num_vertices) + ")",
          "(" + std::to_string(s.rows) + ", " + std::to_string(s.cols) + ")");
    }
    const std::vector<double> data = s.data.ToDoubles();
    const std::vector<int64_t> indices = s.indices.ToInt64s();
    const std::vector<int64_t> indptr = s.indptr.ToInt64s();
    const bool csc = s.format == "csc";
    for (size_t outer = 0; outer + 1 < indptr.size(); ++outer) {
      for (int64_t k = indptr[outer]; k < indptr[outer + 1]; ++k) {
        if (!std::isfinite(data[k]))
          throw InputError(entries.path(), key, "finite values", "NaN or inf");
        const int64_t inner = indices[k];
        triplets.emplace_back(csc ? inner : outer, csc ? outer : inner, data[k]);
      }
    }
  } else {
    const std::vector<double> dense =
        entries.Doubles(key, {kNumHandJoints, num_vertices});
    for (int64_t j = 0; j < kNumHandJoints; ++j) {
      for (int64_t v = 0; v < num_vertices; ++v) {
        const double w = dense[j * num_vertices + v];
        if (w != 0) triplets.emplace_back(j, v, w);
      }
    }
  }
  Eigen::SparseMatrix<double, Eigen::RowMajor> m(kNumHandJoints, num_vertices);
  m.setFromTriplets(triplets.begin(), triplets.end());
  return m;
}

// (V, 3, K) or (3V, K) -> 3V x K with row 3v + c.
Eigen::MatrixXd Blendshapes(const Entries& entries, const std::string& key, int64_t nv,
                            int64_t cols) {
  const Entry& e = entries.Get(key);
  // MANO's (V, 3, K); a flattened (3V, K) is accepted too.
  const bool flat = e.array && e.array->ndim() == 2 && e.array->shape[0] == 3 * nv;
  const std::vector<double> v =
      flat ? entries.Doubles(key, {3 * nv, cols}) : entries.Doubles(key, {nv, 3, cols});
  const int64_t k = flat ? e.array->shape[1] : e.array->shape[2];
  return RowMajorMatrix(v, 3 * nv, k);
}

std::optional<HandSide> SideFromName(const std::string& path) {
  std::string name = path.substr(path.find_last_of('/') + 1);
  std::transform(name.begin(), name.end(), name.begin(), ::tolower);
  const bool left = name.find("left") != std::string::npos;
  const bool right = name.find("right") != std::string::npos;
  if (left != right) return left ? HandSide::kLeft : HandSide::kRight;
  return std::nullopt;
}

std::string Stem(const std::string& path) {
  std::string name = path.substr(path.find_last_of('/') + 1);
  const size_t dot = name.find_last_of('.');
  return dot == std::string::npos || dot == 0 ? name : name.substr(0, dot);
}

// Triangle vertex indices, each checked against the vertex count.
void ReadFaces(const Entries& entries, int64_t nv, HandModel* m) {
  const std::vector<int64_t> faces = entries.Ints("f", {-1, 3});
  m->faces.resize(static_cast<Eigen::Index>(faces.size() / 3), 3);
  for (size_t i = 0; i < faces.size(); ++i) {
    if (faces[i] < 0 || faces[i] >= nv) {
      throw InputError(entries.path(), "f", "vertex indices below " + std::to_string(nv),
                       std::to_string(faces[i]));
    }
    m->faces(static_cast<Eigen::Index>(i / 3), static_cast<Eigen::Index>(i % 3)) =
        static_cast<int>(faces[i]);
  }
}

// Joint parents from MANO's kintree_table (row 0 parents, row 1 the joint ids).
void ReadParents(const Entries& entries, HandModel* m) {
  const std::string& path = entries.path();
  const std::vector<int64_t> kintree = entries.Ints("kintree_table", {2, kNumHandJoints});
  for (int j = 0; j < kNumHandJoints; ++j) {
    if (kintree[kNumHandJoints + j] != j) {
      throw InputError(path, "kintree_table", "joint ids 0..15 in row 1",
                       std::to_string(kintree[kNumHandJoints + j]) + " at column " +
                           std::to_string(j));
    }
    const int64_t parent = kintree[j];
    if (parent == kUint32MinusOne || parent == -1) {
      m->parents[j] = -1;
    } else if (parent >= 0 && parent < kNumHandJoints) {
      m->parents[j] = static_cast<int>(parent);  // order is checked by HandModel::Check
    } else {
      throw InputError(path, "kintree_table", "parent ids in [0, 16) or -1",
                       std::to_string(parent) + " for joint " + std::to_string(j));
    }
  }
}

// The optional pose PCA, and the skinning style, which must be MANO's own.
void ReadPosePcaAndStyle(const Entries& entries, HandModel* m) {
  const std::string& path = entries.path();
  if (entries.Has("hands_components")) {
    const std::vector<double> pca =
        entries.Doubles("hands_components", {-1, kNumPoseParams});
    m->pose_pca_basis = RowMajorMatrix(
        pca, static_cast<Eigen::Index>(pca.size() / kNumPoseParams), kNumPoseParams);
  }
  if (entries.Has("hands_mean")) {
    const std::vector<double> mean = entries.Doubles("hands_mean", {kNumPoseParams});
    m->pose_mean = Eigen::Map<const Eigen::VectorXd>(mean.data(), kNumPoseParams);
  }
  // MANO's own loader supports linear blend skinning with rotation-matrix pose features
  // only; refuse anything else rather than compute a different model.
  if (entries.Has("bs_style") && entries.Text("bs_style") != "lbs") {
    throw InputError(path, "bs_style", "'lbs'", "'" + entries.Text("bs_style") + "'");
  }
  if (entries.Has("bs_type") && entries.Text("bs_type") != "lrotmin") {
    throw InputError(path, "bs_type", "'lrotmin'", "'" + entries.Text("bs_type") + "'");
  }
}

// Version, side, name, tips and keypoint map stored by SaveHandModel.
void ReadHandlabelMetadata(const Entries& entries, HandModel* m) {
  const std::string& path = entries.path();
  const std::vector<int64_t> version = entries.Ints("handlabel_version", {});
  if (version[0] < 1 || version[0] > kHandModelFileVersion) {
    throw InputError(path, "handlabel_version",
                     "a version up to " + std::to_string(kHandModelFileVersion),
                     std::to_string(version[0]));
  }
  m->side = ParseHandSide(entries.Text("handlabel_side"), path, "handlabel_side");
  m->name = entries.Text("handlabel_name");
  const std::vector<int64_t> tips = entries.Ints("handlabel_tip_vertex_ids", {5});
  for (int t = 0; t < 5; ++t) m->tip_vertex_ids[t] = static_cast<int>(tips[t]);
  const std::vector<int64_t> map =
      entries.Ints("handlabel_keypoint_map", {kNumHandKeypoints});
  for (int k = 0; k < kNumHandKeypoints; ++k) {
    if (map[k] != kSnapFromNative[k]) {
      throw InputError(path, "handlabel_keypoint_map",
                       "the SNAP order from native joints + tips "
                       "[0, 13, 14, 15, 16, 1, ...]",
                       "a different map at keypoint " + std::to_string(k));
    }
  }
}

// What a MANO file does not store: name from the file, side from the options or the
// file name, fingertip vertices from the options or manopth's (778-vertex MANO only).
void InferManoMetadata(const std::string& path, int64_t nv,
                       const HandModelLoadOptions& options, HandModel* m) {
  m->name = Stem(path);
  const std::optional<HandSide> side = options.side ? options.side : SideFromName(path);
  if (!side) {
    throw InputError(path, "side",
                     "a file name containing 'left' or 'right' (as MANO_LEFT.pkl) or an "
                     "explicit side option");
  }
  m->side = *side;
  if (options.tip_vertex_ids) {
    m->tip_vertex_ids = *options.tip_vertex_ids;
  } else if (nv == kManoVertexCount) {
    m->tip_vertex_ids = kManopthTipIds;
  } else {
    throw InputError(path, "tip_vertex_ids",
                     "fingertip vertex ids as an option for a model of " +
                         std::to_string(nv) +
                         " vertices (only 778-vertex MANO has defaults)");
  }
}

HandModel ModelFromEntries(const Entries& entries, HandModelFormat format,
                           const HandModelLoadOptions& options) {
  const std::string& path = entries.path();
  HandModel m;
  const std::vector<double> v_template = entries.Doubles("v_template", {-1, 3});
  const int64_t nv = static_cast<int64_t>(v_template.size() / 3);
  m.v_template = RowMajorMatrix(v_template, nv, 3);
  ReadFaces(entries, nv, &m);
  m.shapedirs = Blendshapes(entries, "shapedirs", nv, -1);
  m.posedirs = Blendshapes(entries, "posedirs", nv, 9 * (kNumHandJoints - 1));
  m.joint_regressor = JointRegressor(entries, nv);
  m.skinning_weights = RowMajorMatrix(entries.Doubles("weights", {nv, kNumHandJoints}),
                                      nv, kNumHandJoints);
  ReadParents(entries, &m);
  ReadPosePcaAndStyle(entries, &m);
  if (format == HandModelFormat::kHandlabelNpz) {
    ReadHandlabelMetadata(entries, &m);
  } else {
    InferManoMetadata(path, nv, options, &m);
  }
  m.Check(path);
  return m;
}

NdArray IntArray(const std::vector<int64_t>& shape, const std::vector<int64_t>& values,
                 DType dtype = DType::kInt64) {
  return NdArray::FromInt64s(shape, values.data(), dtype);
}

// 3V x K (row 3v + c) -> (V, 3, K) float64.
NdArray Blendshapes3d(const Eigen::MatrixXd& m) {
  const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> r = m;
  return NdArray::FromDoubles({r.rows() / 3, 3, r.cols()}, r.data());
}

}  // namespace

const char* HandModelFormatName(HandModelFormat format) {
  switch (format) {
    case HandModelFormat::kManoPickle:
      return "MANO pickle (Python 2, chumpy)";
    case HandModelFormat::kPickle:
      return "re-saved MANO pickle";
    case HandModelFormat::kSmplxNpz:
      return "smplx-style npz";
    case HandModelFormat::kHandlabelNpz:
      return "handlabel model npz";
  }
  return "?";
}

LoadedHandModel LoadHandModelFile(const std::string& path,
                                  const HandModelLoadOptions& options) {
  LoadedHandModel out;
  std::string head;
  {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InputError(path, "", "a readable hand model file", "cannot open");
    head.resize(4);
    in.read(head.data(), 4);
    head.resize(static_cast<size_t>(in.gcount()));
  }
  if (head.empty()) {  // else it would be reported as a pickle without opcodes
    throw InputError(path, "", "a hand model file (.npz or MANO .pkl)", "an empty file");
  }
  if (LooksLikeZip(head)) {
    const Entries entries = ReadNpzEntries(path, &out.format);
    out.model = ModelFromEntries(entries, out.format, options);
  } else {
    const Entries entries =
        ReadPickleEntries(path, ReadFileBytes(path, "hand model file"), &out.format);
    out.model = ModelFromEntries(entries, out.format, options);
  }
  return out;
}

void SaveHandModel(const HandModel& model, const std::string& path) {
  model.Check(path);
  NamedArrays arrays;
  arrays.emplace_back("v_template", NdArray::FromMatrix(model.v_template));
  std::vector<int64_t> faces(model.faces.data(), model.faces.data() + model.faces.size());
  arrays.emplace_back("f", IntArray({model.num_faces(), 3}, faces, DType::kUInt32));
  arrays.emplace_back("shapedirs", Blendshapes3d(model.shapedirs));
  arrays.emplace_back("posedirs", Blendshapes3d(model.posedirs));
  const Eigen::MatrixXd regressor = Eigen::MatrixXd(model.joint_regressor);
  arrays.emplace_back("J_regressor", NdArray::FromMatrix(regressor));
  arrays.emplace_back("weights", NdArray::FromMatrix(model.skinning_weights));
  std::vector<int64_t> kintree(2 * kNumHandJoints);
  for (int j = 0; j < kNumHandJoints; ++j) {
    kintree[j] = model.parents[j];
    kintree[kNumHandJoints + j] = j;
  }
  arrays.emplace_back("kintree_table", IntArray({2, kNumHandJoints}, kintree));
  arrays.emplace_back("J", NdArray::FromMatrix(regressor * model.v_template));
  if (model.pose_pca_basis.size() > 0) {
    arrays.emplace_back("hands_components", NdArray::FromMatrix(model.pose_pca_basis));
  }
  if (model.pose_mean.size() > 0) {
    arrays.emplace_back("hands_mean",
                        NdArray::FromDoubles({kNumPoseParams}, model.pose_mean.data()));
  }
  arrays.emplace_back("bs_style", NdArray::FromText("lbs"));
  arrays.emplace_back("bs_type", NdArray::FromText("lrotmin"));
  const int64_t version = kHandModelFileVersion;
  arrays.emplace_back("handlabel_version", IntArray({}, {version}));
  arrays.emplace_back("handlabel_side", NdArray::FromText(HandSideName(model.side)));
  arrays.emplace_back("handlabel_name", NdArray::FromText(model.name));
  arrays.emplace_back("handlabel_tip_vertex_ids",
                      IntArray({5}, std::vector<int64_t>(model.tip_vertex_ids.begin(),
                                                         model.tip_vertex_ids.end())));
  arrays.emplace_back(
      "handlabel_keypoint_map",
      IntArray({kNumHandKeypoints},
               std::vector<int64_t>(kSnapFromNative.begin(), kSnapFromNative.end())));
  WriteNpzFile(path, arrays, ZipMethod::kDeflate);  // atomic
}

}  // namespace handlabel
