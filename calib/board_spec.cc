#include "calib/board_spec.h"

#include <cmath>
#include <sstream>

#include "core/errors.h"

namespace handlabel {
namespace {

std::vector<std::string> Split(const std::string& text, char sep) {
  std::vector<std::string> parts;
  std::string part;
  std::istringstream in(text);
  while (std::getline(in, part, sep)) parts.push_back(part);
  if (!text.empty() && text.back() == sep) parts.push_back("");
  return parts;
}

double ParseLength(const std::string& text, const std::string& flag, const char* field) {
  size_t used = 0;
  double value = 0;
  try {
    value = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != text.size() || !(value > 0) || !std::isfinite(value)) {
    throw InputError(flag, field, "a positive length in metres", "'" + text + "'");
  }
  return value;
}

const char* kUsage =
    "charuco:COLSxROWS:SQUARE:MARKER[:DICT] or checkerboard:COLSxROWS:SQUARE";

}  // namespace

const std::vector<ArucoDictionaryInfo>& ArucoDictionaries() {
  static const std::vector<ArucoDictionaryInfo> dictionaries = {
      {"DICT_4X4_50", 0, 50},
      {"DICT_4X4_100", 1, 100},
      {"DICT_4X4_250", 2, 250},
      {"DICT_4X4_1000", 3, 1000},
      {"DICT_5X5_50", 4, 50},
      {"DICT_5X5_100", 5, 100},
      {"DICT_5X5_250", 6, 250},
      {"DICT_5X5_1000", 7, 1000},
      {"DICT_6X6_50", 8, 50},
      {"DICT_6X6_100", 9, 100},
      {"DICT_6X6_250", 10, 250},
      {"DICT_6X6_1000", 11, 1000},
      {"DICT_7X7_50", 12, 50},
      {"DICT_7X7_100", 13, 100},
      {"DICT_7X7_250", 14, 250},
      {"DICT_7X7_1000", 15, 1000},
      {"DICT_ARUCO_ORIGINAL", 16, 1024},
      {"DICT_APRILTAG_16h5", 17, 30},
      {"DICT_APRILTAG_25h9", 18, 35},
      {"DICT_APRILTAG_36h10", 19, 2320},
      {"DICT_APRILTAG_36h11", 20, 587},
  };
  return dictionaries;
}

void BoardSpec::Check(const std::string& source) const {
  if (cols < 2 || rows < 2 || cols > 1000 || rows > 1000) {
    throw InputError(source, "COLSxROWS", "2 to 1000 squares each way",
                     std::to_string(cols) + "x" + std::to_string(rows));
  }
  if (!(square > 0) || !std::isfinite(square)) {
    throw InputError(source, "SQUARE", "a positive length in metres");
  }
  if (type != BoardType::kCharuco) return;
  if (!(marker > 0) || !(marker < square)) {
    throw InputError(source, "MARKER",
                     "a marker side below the square side " + std::to_string(square),
                     std::to_string(marker));
  }
  const ArucoDictionaryInfo* info = nullptr;
  std::string known;
  for (const ArucoDictionaryInfo& d : ArucoDictionaries()) {
    if (dictionary == d.name) info = &d;
    known += (known.empty() ? "" : ", ") + std::string(d.name);
  }
  if (!info) throw InputError(source, "DICT", "one of " + known, "'" + dictionary + "'");
  if (NumMarkers() > info->size) {
    throw InputError(source, "DICT",
                     "a dictionary with at least " + std::to_string(NumMarkers()) +
                         " markers for a " + std::to_string(cols) + "x" +
                         std::to_string(rows) + " board",
                     dictionary + " (" + std::to_string(info->size) + ")");
  }
}

Eigen::Vector3d BoardSpec::Corner(int id) const {
  const int x = id % (cols - 1), y = id / (cols - 1);
  return Eigen::Vector3d((x + 1) * square, (y + 1) * square, 0.0);
}

std::vector<Eigen::Vector3d> BoardSpec::Corners() const {
  std::vector<Eigen::Vector3d> corners;
  for (int i = 0; i < NumCorners(); ++i) corners.push_back(Corner(i));
  return corners;
}

std::string BoardSpec::ToString() const {
  std::ostringstream s;
  s << (type == BoardType::kCharuco ? "charuco:" : "checkerboard:") << cols << "x" << rows
    << ":" << square;
  if (type == BoardType::kCharuco) s << ":" << marker << ":" << dictionary;
  return s.str();
}

BoardSpec ParseBoardSpec(const std::string& text, const std::string& flag) {
  const std::vector<std::string> parts = Split(text, ':');
  if (parts.empty() || (parts[0] != "charuco" && parts[0] != "checkerboard")) {
    throw InputError(flag, "type", kUsage, "'" + text + "'");
  }
  BoardSpec spec;
  spec.type = parts[0] == "charuco" ? BoardType::kCharuco : BoardType::kCheckerboard;
  const size_t min_parts = spec.type == BoardType::kCharuco ? 4 : 3;
  const size_t max_parts = spec.type == BoardType::kCharuco ? 5 : 3;
  if (parts.size() < min_parts || parts.size() > max_parts) {
    throw InputError(flag, "fields", kUsage, "'" + text + "'");
  }
  const std::vector<std::string> size = Split(parts[1], 'x');
  try {
    size_t a = 0, b = 0;
    if (size.size() != 2) throw std::invalid_argument("size");
    spec.cols = std::stoi(size[0], &a);
    spec.rows = std::stoi(size[1], &b);
    if (a != size[0].size() || b != size[1].size()) throw std::invalid_argument("size");
  } catch (const std::exception&) {
    throw InputError(flag, "COLSxROWS", "two integers like 7x5 (squares)",
                     "'" + parts[1] + "'");
  }
  spec.square = ParseLength(parts[2], flag, "SQUARE");
  if (spec.type == BoardType::kCharuco) {
    spec.marker = ParseLength(parts[3], flag, "MARKER");
    if (parts.size() == 5) spec.dictionary = parts[4];
  }
  spec.Check(flag);
  return spec;
}

}  // namespace handlabel
