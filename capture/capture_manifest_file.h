#pragma once
// The manifest file of a native capture folder (capture_format.h), read and written
// whole; writes are atomic, so a reader sees the previous frame list or the new one.

#include <string>

#include "capture/capture_format.h"

namespace handlabel {

// `dir`/capture.json.
std::string CaptureManifestPath(const std::string& dir);

// Throws InputError naming the file when it is missing (with `how_to_make`, e.g. "make
// the capture with `handlabel capture init`"), not JSON, or not a valid manifest.
CaptureManifest ReadCaptureManifest(const std::string& dir,
                                    const std::string& how_to_make);

void WriteCaptureManifest(const std::string& dir, const CaptureManifest& manifest);

}  // namespace handlabel
