// A read-only memory map of a whole file, with the errors a user can cause (missing file,
// a directory, no permission) turned into Status messages that name the path.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

#include "dispex/files.h"  // CheckReadableFile
#include "dispex/status.h"

namespace dispex {

class MappedFile {
 public:
  static StatusOr<MappedFile> Open(const std::string& path);

  MappedFile() = default;
  MappedFile(MappedFile&& other) noexcept;
  MappedFile& operator=(MappedFile&& other) noexcept;
  MappedFile(const MappedFile&) = delete;
  MappedFile& operator=(const MappedFile&) = delete;
  ~MappedFile();

  const char* data() const { return data_; }
  std::size_t size() const { return size_; }
  std::string_view view() const { return {data_, size_}; }
  const std::string& path() const { return path_; }
  // The open file the map was made from, kept open while the map lives: reads of it see that
  // file whatever later happens to the path (a new file renamed over it).
  int fd() const { return fd_; }

 private:
  std::string path_;
  const char* data_ = nullptr;
  std::size_t size_ = 0;
  int fd_ = -1;
};

}  // namespace dispex
