#pragma once
// Calibration boards, given on the command line as
//   charuco:COLSxROWS:SQUARE:MARKER[:DICT]   e.g. charuco:7x5:0.04:0.03:DICT_4X4_50
//   checkerboard:COLSxROWS:SQUARE            e.g. checkerboard:10x7:0.025
// COLS x ROWS count squares (a checkerboard with 9x6 inner corners is 10x7); SQUARE
// and MARKER are side lengths in metres; DICT is an OpenCV ArUco dictionary name
// (default DICT_4X4_50).
//
// Board frame (as OpenCV's CharucoBoard): the board is the plane z = 0; corner id
// i = y * (COLS - 1) + x (x = 0..COLS-2, y = 0..ROWS-2) sits at
// ((x + 1) * SQUARE, (y + 1) * SQUARE, 0). ChArUco corner ids are OpenCV's.

#include <Eigen/Core>
#include <string>
#include <vector>

namespace handlabel {

enum class BoardType { kCharuco, kCheckerboard };

struct BoardSpec {
  BoardType type = BoardType::kCharuco;
  int cols = 7;                            // squares along x
  int rows = 5;                            // squares along y
  double square = 0.04;                    // metres
  double marker = 0.03;                    // metres, ChArUco only
  std::string dictionary = "DICT_4X4_50";  // ChArUco only

  // Throws InputError naming `source` when the numbers cannot make a board.
  void Check(const std::string& source) const;
  int NumCorners() const { return (cols - 1) * (rows - 1); }
  int NumMarkers() const { return cols * rows / 2; }
  Eigen::Vector3d Corner(int id) const;
  std::vector<Eigen::Vector3d> Corners() const;
  double Width() const { return cols * square; }
  double Height() const { return rows * square; }
  std::string ToString() const;
};

// Parses the text form above; throws InputError naming `flag` and the bad part.
BoardSpec ParseBoardSpec(const std::string& text, const std::string& flag = "--board");

// The ArUco dictionaries OpenCV 4.6 predefines: name -> (OpenCV id, number of markers).
struct ArucoDictionaryInfo {
  const char* name;
  int opencv_id;
  int size;
};
const std::vector<ArucoDictionaryInfo>& ArucoDictionaries();

}  // namespace handlabel
