// Files that must survive a crash (learned tables, models) are written
// atomically: to a temporary file in the same folder, flushed to disk, then
// renamed over the target. A reader sees the old or the new content, never a
// mix, whatever moment the writer dies.
#pragma once

#include <string>

namespace iplan::core {

/// Replaces `path` with `content` atomically (write temp, fsync, rename,
/// fsync folder). Throws std::runtime_error with the path and errno text.
void WriteFileAtomically(const std::string& path, const std::string& content);

/// Reads a whole file. Throws std::runtime_error when it cannot be read.
std::string ReadFile(const std::string& path);

}  // namespace iplan::core
