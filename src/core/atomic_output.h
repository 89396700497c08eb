// Output files that appear whole or not at all.
//
// AtomicOutput writes to a temporary file beside the target ("<target>.tmp.XXXXXX") and
// renames it over the target on Commit(). Destroying it without Commit(), an error, or a
// signal (see RemoveTemporaryOutputs) removes the temporary file and leaves any existing
// target untouched, so a renderer never reads a half-written map.
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

#include "dispex/files.h"  // WriteFileAtomically
#include "dispex/status.h"

namespace dispex {

class AtomicOutput {
 public:
  // Makes the target's missing folders (removed again by Abandon); fails with a clear message
  // where they cannot be made or written in, or the target is a folder.
  static StatusOr<AtomicOutput> Create(const std::string& target);

  AtomicOutput() = default;
  AtomicOutput(AtomicOutput&& other) noexcept;
  AtomicOutput& operator=(AtomicOutput&& other) noexcept;
  AtomicOutput(const AtomicOutput&) = delete;
  AtomicOutput& operator=(const AtomicOutput&) = delete;
  ~AtomicOutput();

  Status Write(const void* data, std::size_t size);
  // Flushes and closes the temporary file, which stays until Commit() or Abandon(): a set of
  // outputs is closed one by one, then committed together once every one was complete.
  Status Close();
  // Closes the temporary file (when still open) and renames it onto the target.
  Status Commit();
  // Closes and removes the temporary file (also done by the destructor).
  void Abandon();

  const std::string& target() const { return target_; }
  const std::string& temp_path() const { return temp_; }
  std::size_t bytes_written() const { return written_; }

 private:
  std::string target_;
  std::string temp_;
  int fd_ = -1;
  int slot_ = -1;
  std::size_t written_ = 0;
  // Folders Create made for the target, the deepest first: removed (when empty) by Abandon.
  std::vector<std::filesystem::path> made_folders_;
};

// Unlinks every temporary file of live AtomicOutputs. Async-signal-safe: a SIGINT/SIGTERM
// handler calls it before exiting.
void RemoveTemporaryOutputs() noexcept;

}  // namespace dispex
