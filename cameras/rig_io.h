#pragma once
// Reading and writing rigs named on the command line as FORMAT:PATH.
//
//   format        read  write  PATH
//   json          yes   yes    the project's rig file (cameras/rig_json.h)
//   colmap        yes   yes    a COLMAP sparse model folder; reads .bin if present,
//                              else .txt; writes binary
//   colmap-text   yes   yes    same, text files only
//   colmap-bin    yes   yes    same, binary files only
//
// Dataset formats (dexycb, ho3d, oakink) register here too (cameras/dataset_calib.h).

#include <string>
#include <vector>

#include "cameras/rig_json.h"
#include "geometry/rig.h"

namespace handlabel {

struct RigSpec {
  std::string format;
  std::string path;
};

// Splits "FORMAT:PATH" at the first ':'; throws InputError naming `flag` for a missing
// or unknown format or an empty path.
RigSpec ParseRigSpec(const std::string& text, const std::string& flag);

// Formats accepted by ReadRig / WriteRig, for help texts.
std::vector<std::string> ReadableRigFormats();
std::vector<std::string> WritableRigFormats();

Rig ReadRig(const RigSpec& spec, RigFileInfo* info = nullptr);
// Creates the folder for COLMAP outputs if needed.
void WriteRig(const Rig& rig, const RigSpec& spec, const RigFileInfo& info = {});

}  // namespace handlabel
