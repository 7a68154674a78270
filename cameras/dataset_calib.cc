#include "cameras/dataset_calib.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

#include "core/errors.h"
#include "core/text.h"
#include "formats/pickle_reader.h"

namespace handlabel {
namespace {

namespace fs = std::filesystem;

YAML::Node LoadYaml(const fs::path& path) {
  if (!fs::is_regular_file(path)) {
    throw InputError(path.string(), "(file)", "an existing YAML file", "not found");
  }
  try {
    return YAML::LoadFile(path.string());
  } catch (const YAML::Exception& e) {
    throw InputError(path.string(), "(YAML syntax)", "valid YAML", e.what());
  }
}

double YamlNumber(const YAML::Node& node, const std::string& path,
                  const std::string& field) {
  if (!node || !node.IsScalar()) throw InputError(path, field, "a number", "missing");
  try {
    return node.as<double>();
  } catch (const YAML::Exception&) {
    throw InputError(path, field, "a number", "'" + node.as<std::string>() + "'");
  }
}

Rigid3 CamFromCommon(const std::vector<double>& v, const std::string& path,
                     const std::string& field) {
  Matrix3x4d m;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 4; ++c) m(r, c) = v[4 * r + c];
  }
  if (std::abs(m.leftCols<3>().determinant() - 1) > 1e-3) {
    throw InputError(path, field, "a rotation (determinant 1) in the left 3x3",
                     "determinant " + std::to_string(m.leftCols<3>().determinant()));
  }
  return Rigid3::FromMatrix(m).Inverse();
}

// ---------------------------------------------------------------------------- DexYCB

constexpr char kDexYcbTagKey[] = "apriltag";

struct SizedIntrinsicsFile {
  fs::path file;
  int width = 0;
  int height = 0;
};

// <serial>_<W>x<H>.yml; the size comes from the name. DexYCB's toolkit always reads
// <serial>_640x480.yml (its images are 640x480), so that file wins when several sizes
// sit side by side; a single other size is taken as it is; several without 640x480
// are ambiguous and an error. `chosen` is set to the file read.
Camera DexYcbIntrinsics(const fs::path& folder, const std::string& serial,
                        std::string* chosen) {
  static const std::regex size_suffix("_([0-9]+)x([0-9]+)\\.yml");
  std::vector<SizedIntrinsicsFile> found;
  if (fs::is_directory(folder)) {
    for (const auto& e : fs::directory_iterator(folder)) {
      const std::string filename = e.path().filename().string();
      if (filename.rfind(serial, 0) != 0) continue;
      const std::string rest = filename.substr(serial.size());
      std::smatch m;
      if (!std::regex_match(rest, m, size_suffix)) continue;
      found.push_back({e.path(), std::stoi(m[1]), std::stoi(m[2])});
    }
  }
  std::sort(found.begin(), found.end(),
            [](const auto& a, const auto& b) { return a.file < b.file; });
  if (found.empty()) {
    throw InputError(folder.string(), serial + "_<W>x<H>.yml",
                     "an intrinsics file for camera " + serial, "not found");
  }
  size_t pick = 0;
  if (found.size() > 1) {
    std::vector<std::string> files;
    pick = found.size();
    for (size_t i = 0; i < found.size(); ++i) {
      files.push_back(found[i].file.filename().string());
      if (found[i].width == 640 && found[i].height == 480) pick = i;
    }
    if (pick == found.size()) {
      throw InputError(folder.string(), serial + "_<W>x<H>.yml",
                       "one intrinsics size, or " + serial +
                           "_640x480.yml (the size DexYCB's toolkit reads)",
                       Join(files));
    }
  }
  const fs::path& file = found[pick].file;
  *chosen = file.string();
  const int width = found[pick].width;
  const int height = found[pick].height;
  const YAML::Node color = LoadYaml(file)["color"];
  const std::string p = file.string();
  if (!color) throw InputError(p, "color", "a map with fx, fy, ppx, ppy", "missing");
  return Camera(
      CameraModelId::kPinhole, width, height,
      {YamlNumber(color["fx"], p, "color.fx"), YamlNumber(color["fy"], p, "color.fy"),
       YamlNumber(color["ppx"], p, "color.ppx"),
       YamlNumber(color["ppy"], p, "color.ppy")},
      p);
}

Rig ReadDexYcb(const fs::path& path, RigFileInfo* info) {
  fs::path extrinsics_file = path;
  std::vector<std::string> serials;  // from meta.yml, if given
  if (path.filename() == "meta.yml") {
    const YAML::Node meta = LoadYaml(path);
    const std::string p = path.string();
    if (!meta["extrinsics"])
      throw InputError(p, "extrinsics", "a calibration id", "missing");
    if (meta["serials"] && meta["serials"].IsSequence()) {
      for (const YAML::Node& s : meta["serials"]) serials.push_back(s.as<std::string>());
    }
    // <root>/<subject>/<sequence>/meta.yml -> <root>/calibration/extrinsics_<id>/
    const fs::path root = fs::absolute(path).parent_path().parent_path().parent_path();
    extrinsics_file = root / "calibration" /
                      ("extrinsics_" + meta["extrinsics"].as<std::string>()) /
                      "extrinsics.yml";
  } else if (fs::is_directory(path)) {
    extrinsics_file = path / "extrinsics.yml";
  }
  const YAML::Node extr = LoadYaml(extrinsics_file);
  const std::string p = extrinsics_file.string();
  const YAML::Node map = extr["extrinsics"];
  if (!map || !map.IsMap())
    throw InputError(p, "extrinsics", "a map serial -> 12 numbers", "missing");
  std::string master;
  if (extr["master"]) master = extr["master"].as<std::string>();
  if (serials.empty()) {
    // Every entry is a camera serial except `apriltag`: the calibration tag's pose in
    // the common frame (world_from_tag, 3x4), which is no camera.
    for (const auto& kv : map) {
      const std::string key = kv.first.as<std::string>();
      if (key != kDexYcbTagKey) serials.push_back(key);
    }
  }
  const fs::path intrinsics_folder =
      fs::absolute(extrinsics_file).parent_path().parent_path() / "intrinsics";
  Rig rig;
  std::vector<std::string> intrinsics_files;
  for (const std::string& serial : serials) {
    const YAML::Node values = map[serial];
    const std::string field = "extrinsics." + serial;
    if (!values || !values.IsSequence() || values.size() != 12) {
      throw InputError(p, field, "12 numbers (3x4 camera -> common, row-major)",
                       values ? std::to_string(values.size()) + " values" : "missing");
    }
    std::vector<double> v;
    for (const YAML::Node& x : values) v.push_back(YamlNumber(x, p, field));
    intrinsics_files.emplace_back();
    rig.Add({serial,
             DexYcbIntrinsics(intrinsics_folder, serial, &intrinsics_files.back()),
             CamFromCommon(v, p, field)});
  }
  if (info) {
    info->world = "DexYCB common frame (master camera " + master + ")";
    info->intrinsics_files = intrinsics_files;
  }
  return rig;
}

// ---------------------------------------------------------------------------- HO3D

// Whitespace-separated numbers (np.savetxt's output).
std::vector<double> ReadNumbers(const fs::path& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path.string(), "(file)", "a readable text file", "not found");
  std::stringstream buffer;
  buffer << in.rdbuf();
  std::istringstream parse(buffer.str());
  std::vector<double> out;
  std::string token;
  while (parse >> token) {
    try {
      size_t used = 0;
      out.push_back(std::stod(token, &used));
      if (used != token.size()) throw std::invalid_argument(token);
    } catch (const std::exception&) {
      throw InputError(path.string(), "(numbers)", "numbers", "'" + token + "'");
    }
  }
  return out;
}

Camera Ho3dIntrinsics(const fs::path& path) {
  std::ifstream in(path);
  if (!in)
    throw InputError(path.string(), "(file)", "fx:..., fy:..., ppx:..., ppy:...",
                     "not found");
  std::string line;
  std::getline(in, line);
  double values[4];
  const char* keys[4] = {"fx", "fy", "ppx", "ppy"};
  for (int k = 0; k < 4; ++k) {
    const std::regex re(std::string("(^|[ ,])") + keys[k] + "\\s*:\\s*([-+0-9.eE]+)");
    std::smatch m;
    if (!std::regex_search(line, m, re)) {
      throw InputError(path.string(), keys[k], "fx:..., fy:..., ppx:..., ppy:...",
                       "'" + line + "'");
    }
    values[k] = std::stod(m[2]);
  }
  return Camera(CameraModelId::kPinhole, 640, 480,
                {values[0], values[1], values[2], values[3]}, path.string());
}

// cam_orders.txt as np.loadtxt reads it: whitespace-separated numbers, '#' comments;
// each a camera folder index, no index twice.
std::vector<int> Ho3dCameraOrder(const fs::path& file) {
  std::ifstream in(file);
  if (!in) throw InputError(file.string(), "(file)", "a readable text file", "not found");
  std::vector<int> order;
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream tokens(line.substr(0, line.find('#')));
    std::string token;
    while (tokens >> token) {
      double value = 0;
      size_t used = 0;
      try {
        value = std::stod(token, &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (used != token.size() || value < 0 || value > 1000 ||
          value != std::floor(value)) {
        throw InputError(file.string(), "(camera order)",
                         "whitespace-separated camera indices (as np.loadtxt reads them)",
                         "'" + token + "'");
      }
      const int index = static_cast<int>(value);
      if (std::find(order.begin(), order.end(), index) != order.end()) {
        throw InputError(file.string(), "(camera order)", "each camera index once",
                         std::to_string(index) + " twice");
      }
      order.push_back(index);
    }
  }
  return order;
}

// Pairing, as HO3D's multi-camera viewer reads it: the files with index i
// (trans_<i>.txt, cam_<i>_intrinsics.txt) belong to the camera folder
// <SEQ><cams_order[i]>, where cams_order[i] is the i-th entry of cam_orders.txt. The
// rig lists the cameras in that file order. Without cam_orders.txt the order is the
// identity.
Rig ReadHo3d(const fs::path& folder, RigFileInfo* info) {
  if (!fs::is_directory(folder)) {
    throw InputError(folder.string(), "(folder)", "calibration/<SEQ>/calibration",
                     "not a folder");
  }
  // calibration/<SEQ>/calibration: cameras are named <SEQ><i> like the image folders.
  const fs::path abs = fs::absolute(folder).lexically_normal();
  const fs::path dir = abs.filename().empty() ? abs.parent_path() : abs;
  const std::string seq = dir.parent_path().filename().string();
  int transforms = 0;  // trans_0.txt, trans_1.txt, ...: one per camera
  while (fs::exists(dir / ("trans_" + std::to_string(transforms) + ".txt"))) ++transforms;
  std::vector<int> order;
  if (fs::exists(dir / "cam_orders.txt")) {
    order = Ho3dCameraOrder(dir / "cam_orders.txt");
    // A list shorter than the cameras made a smaller rig without a word.
    if (static_cast<int>(order.size()) != transforms) {
      throw InputError((dir / "cam_orders.txt").string(), "(camera order)",
                       "one camera index per trans_<i>.txt beside it (" +
                           std::to_string(transforms) + ")",
                       std::to_string(order.size()) + " indices");
    }
  } else {
    for (int i = 0; i < transforms; ++i) order.push_back(i);
  }
  if (order.empty()) {
    throw InputError(dir.string(), "cam_orders.txt / trans_<i>.txt", "HO3D camera files",
                     "none");
  }
  Rig rig;
  for (size_t i = 0; i < order.size(); ++i) {
    const std::string index = std::to_string(i);
    const fs::path trans = dir / ("trans_" + index + ".txt");
    const std::vector<double> v = ReadNumbers(trans);
    if (v.size() != 16) {
      throw InputError(trans.string(), "(matrix)", "16 numbers (4x4 camera -> common)",
                       std::to_string(v.size()));
    }
    rig.Add({seq + std::to_string(order[i]),
             Ho3dIntrinsics(dir / ("cam_" + index + "_intrinsics.txt")),
             CamFromCommon(std::vector<double>(v.begin(), v.begin() + 12), trans.string(),
                           "(matrix)")});
  }
  if (info) info->world = "HO3D common frame of sequence " + seq;
  return rig;
}

// ---------------------------------------------------------------------------- OakInk

std::vector<double> PickleMatrix(const PickleValue& root, const char* key, int rows,
                                 int cols, const std::string& path) {
  const PickleValue* v = root.Find(key);
  if (!v) throw InputError(path, key, "an array", "missing");
  if (v->kind != PickleValue::Kind::kArray ||
      v->array->shape != std::vector<int64_t>{rows, cols}) {
    throw InputError(path, key,
                     "a " + std::to_string(rows) + "x" + std::to_string(cols) + " array",
                     v->Describe());
  }
  return v->array->ToDoubles();
}

Rig ReadOakInk(const fs::path& path, RigFileInfo* info) {
  // <seq>__<ts>__<sbj>__<frame>__<cam>.pkl: the group is everything before <cam>.
  const auto split = [](const std::string& stem, std::string* group, std::string* cam) {
    const size_t last = stem.rfind("__");
    if (last == std::string::npos) return false;
    *group = stem.substr(0, last);
    *cam = stem.substr(last + 2);
    return !cam->empty();
  };
  std::string group, cam;
  fs::path folder = path;
  if (fs::is_regular_file(path)) {
    folder = path.parent_path();
    if (!split(path.stem().string(), &group, &cam)) {
      throw InputError(path.string(), "(file name)",
                       "<seq>__<ts>__<sbj>__<frame>__<cam>.pkl",
                       path.filename().string());
    }
  } else if (!fs::is_directory(path)) {
    throw InputError(path.string(), "(path)", "an OakInk general_info folder or pickle",
                     "not found");
  }
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(folder.empty() ? "." : folder)) {
    if (e.path().extension() == ".pkl") files.push_back(e.path());
  }
  std::sort(files.begin(), files.end());
  if (group.empty()) {  // a folder: the first frame in name order
    for (const fs::path& f : files) {
      if (split(f.stem().string(), &group, &cam)) break;
    }
  }
  Rig rig;
  for (const fs::path& f : files) {
    std::string g, c;
    if (!split(f.stem().string(), &g, &c) || g != group) continue;
    rig.Add(ReadOakInkCamera(f.string(), c));
  }
  if (rig.empty()) {
    throw InputError(path.string(), "(pickles)", "OakInk general_info pickles",
                     "none found");
  }
  if (info) info->world = "OakInk world frame of " + group;
  return rig;
}

}  // namespace

RigCamera ReadOakInkCamera(const std::string& path, const std::string& name) {
  const PickleValue root = ReadPickleFile(path);
  if (root.kind != PickleValue::Kind::kDict) {
    throw InputError(path, "(pickle)", "a dict with cam_intr and cam_extr",
                     root.Describe());
  }
  const std::vector<double> k = PickleMatrix(root, "cam_intr", 3, 3, path);
  const std::vector<double> e = PickleMatrix(root, "cam_extr", 4, 4, path);
  Matrix3x4d m;
  for (int r = 0; r < 3; ++r) {
    for (int col = 0; col < 4; ++col) m(r, col) = e[4 * r + col];
  }
  return {name, Camera(CameraModelId::kPinhole, 848, 480, {k[0], k[4], k[2], k[5]}, path),
          Rigid3::FromMatrix(m)};
}

std::vector<std::string> DatasetRigFormats() { return {"dexycb", "ho3d", "oakink"}; }

Rig ReadDatasetRig(const std::string& format, const std::string& path,
                   RigFileInfo* info) {
  if (format == "dexycb") return ReadDexYcb(path, info);
  if (format == "ho3d") return ReadHo3d(path, info);
  if (format == "oakink") return ReadOakInk(path, info);
  throw InputError(path, "FORMAT", "dexycb, ho3d or oakink", "'" + format + "'");
}

}  // namespace handlabel
