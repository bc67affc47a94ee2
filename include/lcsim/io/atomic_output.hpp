// Output files that appear whole or not at all, even on SIGINT or SIGTERM.
#pragma once

#include <filesystem>
#include <lcsim/io/input_error.hpp>
#include <string>

namespace lcsim::io {

// Writes text to a temporary file beside `path` and renames it into place, so
// a failure never leaves a half-written file. InputError if not writable.
void write_file_atomic(const std::filesystem::path& path, const std::string& content);

// The temporary files of the writers above (and of any caller that tracks
// its own) are kept in a fixed table, so that a signal handler can remove
// them: remove_temporary_files() is async-signal-safe (unlink(2) over a
// table of char buffers; at most 32 files, paths under 4096 bytes).
void track_temporary_file(const std::string& path);
void untrack_temporary_file(const std::string& path);
void remove_temporary_files() noexcept;

}  // namespace lcsim::io
