// Files for programs built on dispex: outputs that appear whole or not at all, and the check
// that an input is a readable file. The library writes its own outputs (maps, pictures) this
// way; these are for a program's side files (reports) and its argument checks.
#pragma once

#include <cstddef>
#include <string>

#include "dispex/status.h"

namespace dispex {

// Writes `size` bytes to `target` atomically: to a temporary file beside it, renamed onto it
// once complete; on an error, a cancellation or a SIGINT / SIGTERM (with the handlers of
// dispex/cancel.h installed) the target is left as it was and no temporary remains.
Status WriteFileAtomically(const std::string& target, const void* data, std::size_t size);

// Checks that `path` names an existing, readable regular file; the message says which of
// these is not the case.
Status CheckReadableFile(const std::string& path);

// Checks, before any work, that a file can be written at `path`: it is not a folder, and its
// folder exists or can be made (the nearest folder above it that exists is a folder one can
// write in). Missing folders are made when the file is written (WriteFileAtomically; the
// library's maps and pictures alike) and removed again if the write fails.
Status CheckOutputFile(const std::string& path);
// The same for an output folder: `path` is a folder or can be made.
Status CheckOutputFolder(const std::string& path);

}  // namespace dispex
