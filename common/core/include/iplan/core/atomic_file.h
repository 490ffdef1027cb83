// Files that must survive a crash (learned tables, models) are written
// atomically: to a temporary file in the same folder, flushed to disk, then
// renamed over the target. A reader sees the old or the new content, never a
// mix, whatever moment the writer dies.
#pragma once

#include <string>
#include <vector>

namespace iplan::core {

/// Replaces `path` with `content` atomically (write temp, fsync, rename,
/// fsync folder). `mode` is the new file's permission bits (less the
/// umask): 0600 for secrets. Throws std::runtime_error with the path and
/// errno text.
void WriteFileAtomically(const std::string& path, const std::string& content, unsigned mode = 0644);

/// Removes the temporaries `path.tmp.<pid>` that WriteFileAtomically left
/// behind when its process died between creating and renaming them (kill -9,
/// power loss): those whose <pid> is no running process (a folder built the
/// same way, e.g. a keystore, with all it holds). Kept: this
/// process's own (its next write of `path` truncates and renames it), those
/// of running processes (a write in progress) and names that are not ours
/// (a suffix that is not a pid). A pid reused by an unrelated process keeps
/// its file until that process ends. Best effort: a file that cannot be
/// removed is skipped, a missing folder is no error. Returns the paths
/// removed. Never throws; allocates; thread-safe.
std::vector<std::string> RemoveStaleTempFiles(const std::string& path);

/// Reads a whole file. Throws std::runtime_error when it cannot be read.
std::string ReadFile(const std::string& path);

}  // namespace iplan::core
