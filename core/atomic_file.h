#pragma once
// Crash-safe file writes: the content goes to a temporary file in the same directory,
// is flushed to disk, then renamed over the target. A reader (or a resumed job after
// `kill -9`) sees either the old file or the complete new one, never half of it.

#include <string>

namespace handlabel {

// Throws Error naming the path if any step fails (a full disk: "cannot write 'PATH':
// No space left on device"); the temporary is removed. Creates missing parent folders.
void WriteFileAtomically(const std::string& path, const std::string& content);

// Appends one line (a '\n' is added) and flushes it to disk before returning, so a
// line reported as written survives a crash. A crash mid-append can leave a partial
// last line; readers of append-only logs must ignore a last line without '\n'.
void AppendLineDurably(const std::string& path, const std::string& line);

// Removes leftovers of interrupted atomic writes (files named "*.tmp.<pid>") in `dir`.
// Returns how many were removed.
int RemoveStaleTemporaries(const std::string& dir);

}  // namespace handlabel
