#include "core/mapped_file.h"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <utility>

namespace dispex {

namespace {
std::string ErrnoText(int err) {
  return std::strerror(err);
}
}  // namespace

Status CheckReadableFile(const std::string& path) {
  auto error = [&](const std::string& message) {
    return Status::Error(StatusCode::kBadInput, message).WithPath(path);
  };
  struct stat st {};
  if (path.empty()) return error("empty file name");
  if (::stat(path.c_str(), &st) != 0) {
    if (errno == ENOENT) return error(path + ": no such file");
    return error(path + ": " + ErrnoText(errno));
  }
  if (S_ISDIR(st.st_mode)) return error(path + ": is a directory, not a file");
  if (!S_ISREG(st.st_mode)) return error(path + ": not a regular file");
  if (::access(path.c_str(), R_OK) != 0) return error(path + ": " + ErrnoText(errno));
  return Status::Ok();
}

StatusOr<MappedFile> MappedFile::Open(const std::string& path) {
  DISPEX_RETURN_IF_ERROR(CheckReadableFile(path));
  int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return Status::Error(path + ": cannot open: " + ErrnoText(errno));
  struct stat st {};
  if (::fstat(fd, &st) != 0) {
    int err = errno;
    ::close(fd);
    return Status::Error(path + ": cannot stat: " + ErrnoText(err));
  }
  MappedFile file;
  file.path_ = path;
  file.size_ = static_cast<std::size_t>(st.st_size);
  if (file.size_ > 0) {
    void* p = ::mmap(nullptr, file.size_, PROT_READ, MAP_PRIVATE, fd, 0);
    if (p == MAP_FAILED) {
      int err = errno;
      ::close(fd);
      return Status::Error(path + ": cannot map: " + ErrnoText(err));
    }
    ::madvise(p, file.size_, MADV_SEQUENTIAL);
    file.data_ = static_cast<const char*>(p);
  }
  file.fd_ = fd;
  return file;
}

MappedFile::MappedFile(MappedFile&& other) noexcept
    : path_(std::move(other.path_)),
      data_(std::exchange(other.data_, nullptr)),
      size_(std::exchange(other.size_, 0)),
      fd_(std::exchange(other.fd_, -1)) {}

MappedFile& MappedFile::operator=(MappedFile&& other) noexcept {
  if (this != &other) {
    if (data_) ::munmap(const_cast<char*>(data_), size_);
    if (fd_ >= 0) ::close(fd_);
    path_ = std::move(other.path_);
    data_ = std::exchange(other.data_, nullptr);
    size_ = std::exchange(other.size_, 0);
    fd_ = std::exchange(other.fd_, -1);
  }
  return *this;
}

MappedFile::~MappedFile() {
  if (data_) ::munmap(const_cast<char*>(data_), size_);
  if (fd_ >= 0) ::close(fd_);
}

}  // namespace dispex
