#include "core/atomic_output.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <utility>
#include <vector>

namespace dispex {

namespace {

// An output that cannot be written; path() names it.
Status OutputError(const std::string& message) {
  return Status::Error(StatusCode::kOutput, message);
}

// Temporary paths of live outputs, kept in fixed storage so a signal handler can read them
// without locks or allocation.
constexpr int kMaxLiveOutputs = 256;  // a UV map's tiles are committed together
constexpr std::size_t kMaxPath = 4096;
struct LiveSlot {
  std::atomic<bool> used{false};
  std::atomic<bool> ready{false};
  char path[kMaxPath];
};
std::array<LiveSlot, kMaxLiveOutputs> g_live;

int RegisterLive(const std::string& path) {
  if (path.size() >= kMaxPath) return -1;
  for (int i = 0; i < kMaxLiveOutputs; ++i) {
    bool expected = false;
    if (g_live[i].used.compare_exchange_strong(expected, true)) {
      std::memcpy(g_live[i].path, path.c_str(), path.size() + 1);
      g_live[i].ready.store(true);
      return i;
    }
  }
  return -1;
}

void UnregisterLive(int slot) {
  if (slot < 0) return;
  g_live[slot].ready.store(false);
  g_live[slot].used.store(false);
}

std::string ErrnoText(int err) {
  return std::strerror(err);
}

}  // namespace

void RemoveTemporaryOutputs() noexcept {
  for (auto& slot : g_live) {
    if (slot.ready.load()) ::unlink(slot.path);
  }
}

namespace {

// The folders above `path` that do not exist, the deepest first, and the nearest that does.
std::vector<std::filesystem::path> MissingFolders(const std::filesystem::path& folder,
                                                  std::filesystem::path& existing) {
  namespace fs = std::filesystem;
  std::vector<fs::path> missing;
  std::error_code ec;
  fs::path at = folder.empty() ? fs::path(".") : folder;
  while (!fs::exists(at, ec) && at.has_relative_path()) {
    missing.push_back(at);
    const fs::path up = at.parent_path();
    at = up.empty() ? fs::path(".") : up;
  }
  existing = at;
  return missing;
}

// `folder` is one or can be made: the nearest that exists is a folder one can write in.
Status CheckFolder(const std::string& what, const std::filesystem::path& folder) {
  namespace fs = std::filesystem;
  fs::path existing;
  MissingFolders(folder, existing);
  std::error_code ec;
  if (!fs::is_directory(existing, ec)) {
    return OutputError(what + ": " + existing.string() + " is not a folder");
  }
  if (::access(existing.c_str(), W_OK | X_OK) != 0) {
    return OutputError(what + ": cannot write in " + existing.string() + ": " + ErrnoText(errno));
  }
  return Status::Ok();
}

}  // namespace

Status CheckOutputFile(const std::string& path) {
  namespace fs = std::filesystem;
  if (path.empty()) return OutputError("empty output file name");
  std::error_code ec;
  if (fs::is_directory(path, ec)) return OutputError(path + ": is a folder").WithPath(path);
  return CheckFolder(path, fs::path(path).parent_path()).WithPath(path);
}

Status CheckOutputFolder(const std::string& path) {
  namespace fs = std::filesystem;
  if (path.empty()) return OutputError("empty output folder name");
  std::error_code ec;
  if (fs::exists(path, ec) && !fs::is_directory(path, ec)) {
    return OutputError(path + ": is a file, not a folder").WithPath(path);
  }
  return CheckFolder(path, fs::path(path)).WithPath(path);
}

StatusOr<AtomicOutput> AtomicOutput::Create(const std::string& target) {
  namespace fs = std::filesystem;
  DISPEX_RETURN_IF_ERROR(CheckOutputFile(target));
  fs::path dir = fs::path(target).parent_path();
  fs::path existing;
  std::vector<fs::path> made = MissingFolders(dir, existing);
  for (auto it = made.rbegin(); it != made.rend(); ++it) {
    std::error_code ec;
    if (!fs::create_directory(*it, ec) && ec) {
      for (auto undo = made.rbegin(); undo != it; ++undo) fs::remove(*undo, ec);
      return OutputError(target + ": cannot make folder " + it->string() + ": " + ec.message());
    }
  }
  if (dir.empty()) dir = ".";
  std::string pattern = target + ".tmp.XXXXXX";
  std::string buffer = pattern;
  int fd = ::mkstemp(buffer.data());
  if (fd < 0) {
    const int err = errno;
    std::error_code ec;
    for (const fs::path& folder : made) fs::remove(folder, ec);
    return OutputError(target + ": cannot create output in " + dir.string() + ": " +
                       ErrnoText(err));
  }
  ::fchmod(
      fd, 0644 & ~[] {
        mode_t m = ::umask(0);
        ::umask(m);
        return m;
      }());
  AtomicOutput out;
  out.target_ = target;
  out.temp_ = buffer;
  out.fd_ = fd;
  out.slot_ = RegisterLive(buffer);
  out.made_folders_ = std::move(made);
  return out;
}

AtomicOutput::AtomicOutput(AtomicOutput&& other) noexcept
    : target_(std::move(other.target_)),
      temp_(std::move(other.temp_)),
      fd_(std::exchange(other.fd_, -1)),
      slot_(std::exchange(other.slot_, -1)),
      written_(std::exchange(other.written_, 0)),
      made_folders_(std::move(other.made_folders_)) {}

AtomicOutput& AtomicOutput::operator=(AtomicOutput&& other) noexcept {
  if (this != &other) {
    Abandon();
    target_ = std::move(other.target_);
    temp_ = std::move(other.temp_);
    fd_ = std::exchange(other.fd_, -1);
    slot_ = std::exchange(other.slot_, -1);
    written_ = std::exchange(other.written_, 0);
    made_folders_ = std::move(other.made_folders_);
  }
  return *this;
}

AtomicOutput::~AtomicOutput() {
  Abandon();
}

Status AtomicOutput::Write(const void* data, std::size_t size) {
  if (fd_ < 0) return OutputError(target_ + ": output is closed");
  const char* p = static_cast<const char*>(data);
  while (size > 0) {
    ssize_t n = ::write(fd_, p, size);
    if (n < 0) {
      if (errno == EINTR) continue;
      return OutputError(target_ + ": write failed: " + ErrnoText(errno));
    }
    p += n;
    size -= static_cast<std::size_t>(n);
    written_ += static_cast<std::size_t>(n);
  }
  return Status::Ok();
}

Status AtomicOutput::Close() {
  if (fd_ < 0) return OutputError(target_ + ": output is closed");
  if (::fsync(fd_) != 0 && errno != EINVAL) {
    return OutputError(target_ + ": flush failed: " + ErrnoText(errno));
  }
  if (::close(std::exchange(fd_, -1)) != 0) {
    return OutputError(target_ + ": close failed: " + ErrnoText(errno));
  }
  return Status::Ok();
}

Status AtomicOutput::Commit() {
  if (temp_.empty()) return OutputError(target_ + ": output is closed");
  if (fd_ >= 0) DISPEX_RETURN_IF_ERROR(Close());
  if (::rename(temp_.c_str(), target_.c_str()) != 0) {
    return OutputError(target_ + ": cannot rename temporary file: " + ErrnoText(errno));
  }
  UnregisterLive(std::exchange(slot_, -1));
  temp_.clear();
  made_folders_.clear();
  return Status::Ok();
}

void AtomicOutput::Abandon() {
  if (fd_ >= 0) ::close(std::exchange(fd_, -1));
  if (!temp_.empty()) {
    ::unlink(temp_.c_str());
    temp_.clear();
  }
  UnregisterLive(std::exchange(slot_, -1));
  std::error_code ec;
  for (const std::filesystem::path& folder : made_folders_) std::filesystem::remove(folder, ec);
  made_folders_.clear();
}

Status WriteFileAtomically(const std::string& target, const void* data, std::size_t size) {
  DISPEX_ASSIGN_OR_RETURN(AtomicOutput out, AtomicOutput::Create(target));
  DISPEX_RETURN_IF_ERROR(out.Write(data, size));
  return out.Commit();
}

}  // namespace dispex
