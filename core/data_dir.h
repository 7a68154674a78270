#pragma once
// Where the binary finds its shipped data (models/): never through a path compiled
// into it, so that an installed copy works without the source tree.
//   1. $HANDLABEL_DATA_DIR, if set: a folder holding models/ (used as given);
//   2. <folder of the running executable>/../share/handlabel: the install layout
//      (P/bin/handlabel beside P/share/handlabel/models). The build tree mirrors it:
//      CMake links build/share/handlabel/models to the checkout's models/, so
//      build/apps/handlabel, build/tests/* and build/bench/* find them the same way.

#include <string>

namespace handlabel {

// The data folder by the rules above, without checking that it exists; "" only if
// the running executable cannot be found (no /proc/self/exe) and the variable is unset.
std::string DataDir();

// DataDir() + "/models/" + name, whether or not the file exists; "" if DataDir() is.
std::string ShippedModelPath(const std::string& name);

}  // namespace handlabel
