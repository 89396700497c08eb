#include "watch.h"

#include <fmt/format.h>
#include <poll.h>
#include <signal.h>
#include <sys/inotify.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <optional>
#include <utility>

#include "command.h"
#include "dispex/cancel.h"

namespace dispex::cli {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

// What says a file was written again: a new inode (a rename onto it), another size or time.
struct Stamp {
  dev_t dev = 0;
  ino_t ino = 0;
  off_t size = 0;
  std::int64_t mtime_ns = 0, ctime_ns = 0;
  bool operator==(const Stamp&) const = default;
};

std::optional<Stamp> StatFile(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) return std::nullopt;
  Stamp s;
  s.dev = st.st_dev;
  s.ino = st.st_ino;
  s.size = st.st_size;
  s.mtime_ns = std::int64_t{st.st_mtim.tv_sec} * 1'000'000'000 + st.st_mtim.tv_nsec;
  s.ctime_ns = std::int64_t{st.st_ctim.tv_sec} * 1'000'000'000 + st.st_ctim.tv_nsec;
  return s;
}

std::string Errno(const std::string& what) {
  return fmt::format("{}: {}", what, std::strerror(errno));
}

struct Folder {
  int wd = -1;
  std::string path;
};

struct WatchedFile {
  std::string path;                                // as given
  std::vector<std::pair<int, std::string>> names;  // (folder's watch, name in it)
  bool pending = false;                            // an event since the last round
  bool writing = false;                            // modified and not closed again
  bool renamed = false;                            // renamed onto its name: complete
  Clock::time_point last_change;
  std::optional<Stamp> stamp;        // as last seen
  std::optional<Stamp> round_stamp;  // as the last round read it
  bool reported_missing = false;
};

}  // namespace

struct FileWatcher::Impl {
  WatchSettings settings;
  int fd = -1;
  std::vector<Folder> folders;
  std::vector<WatchedFile> files;

  ~Impl() {
    if (fd >= 0) ::close(fd);
  }

  Status Watch(const fs::path& file, WatchedFile& watched) {
    fs::path folder = file.parent_path();
    if (folder.empty()) folder = ".";
    const std::uint32_t mask = IN_CREATE | IN_MODIFY | IN_CLOSE_WRITE | IN_MOVED_TO |
                               IN_MOVED_FROM | IN_DELETE | IN_DELETE_SELF | IN_MOVE_SELF;
    const int wd = ::inotify_add_watch(fd, folder.c_str(), mask);
    if (wd < 0) {
      return Status::Error(Errno(fmt::format("{}: cannot watch the folder", folder.string())))
          .WithPath(folder.string());
    }
    if (std::none_of(folders.begin(), folders.end(), [&](const Folder& f) { return f.wd == wd; })) {
      folders.push_back({wd, folder.string()});
    }
    watched.names.emplace_back(wd, file.filename().string());
    return Status::Ok();
  }

  std::chrono::milliseconds Needed(const WatchedFile& f) const {
    const int ms = f.writing   ? std::max(settings.held_open_ms, settings.settle_ms)
                   : f.renamed ? std::min(settings.rename_quiet_ms, settings.settle_ms)
                               : settings.settle_ms;
    return std::chrono::milliseconds(ms);
  }

  void Touch(WatchedFile& f, std::uint32_t mask) {
    f.pending = true;
    f.last_change = Clock::now();
    if (mask & (IN_MODIFY | IN_CREATE)) {
      f.writing = true;
      f.renamed = false;
    }
    if (mask & IN_CLOSE_WRITE) {
      f.writing = false;
      f.renamed = false;
    }
    if (mask & IN_MOVED_TO) {
      f.writing = false;
      f.renamed = true;
    }
    if (mask & (IN_DELETE | IN_MOVED_FROM)) f.writing = f.renamed = false;
  }

  Status Handle(const inotify_event& e) {
    if (e.mask & IN_Q_OVERFLOW) {  // events were lost: look at every file again
      for (WatchedFile& f : files) Touch(f, IN_CLOSE_WRITE);
      return Status::Ok();
    }
    if (e.mask & (IN_DELETE_SELF | IN_MOVE_SELF | IN_IGNORED | IN_UNMOUNT)) {
      std::string folder = "a watched folder";
      for (const Folder& f : folders) {
        if (f.wd == e.wd) folder = f.path;
      }
      return Status::Error(
                 fmt::format("{}: the folder was removed or moved: stopped watching", folder))
          .WithPath(folder);
    }
    if (e.len == 0) return Status::Ok();
    const std::string_view name(e.name);
    for (WatchedFile& f : files) {
      for (const auto& [wd, file_name] : f.names) {
        if (wd == e.wd && file_name == name) Touch(f, e.mask);
      }
    }
    return Status::Ok();
  }

  Status ReadEvents() {
    alignas(inotify_event) char buffer[64 * 1024];
    for (;;) {
      const ssize_t length = ::read(fd, buffer, sizeof buffer);
      if (length < 0) {
        if (errno == EAGAIN || errno == EWOULDBLOCK) return Status::Ok();
        if (errno == EINTR) continue;
        return Status::Error(Errno("inotify: read"));
      }
      if (length == 0) return Status::Ok();
      for (const char* p = buffer; p < buffer + length;) {
        const auto* event = reinterpret_cast<const inotify_event*>(p);
        DISPEX_RETURN_IF_ERROR(Handle(*event));
        p += sizeof(inotify_event) + event->len;
      }
    }
  }
};

FileWatcher::FileWatcher(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
FileWatcher::~FileWatcher() = default;

StatusOr<std::unique_ptr<FileWatcher>> FileWatcher::Create(const std::vector<std::string>& paths,
                                                           const WatchSettings& settings) {
  auto impl = std::make_unique<Impl>();
  impl->settings = settings;
  impl->fd = ::inotify_init1(IN_NONBLOCK | IN_CLOEXEC);
  if (impl->fd < 0) return Status::Error(Errno("inotify"));
  for (const std::string& path : paths) {
    if (std::any_of(impl->files.begin(), impl->files.end(),
                    [&](const WatchedFile& f) { return f.path == path; })) {
      continue;
    }
    WatchedFile watched;
    watched.path = path;
    DISPEX_RETURN_IF_ERROR(impl->Watch(path, watched));
    // A symbolic link: also where it points, which a save through another path changes.
    std::error_code error;
    if (fs::is_symlink(path, error)) {
      const fs::path target = fs::canonical(path, error);
      if (!error) DISPEX_RETURN_IF_ERROR(impl->Watch(target, watched));
    }
    watched.stamp = watched.round_stamp = StatFile(path);
    impl->files.push_back(std::move(watched));
  }
  return std::unique_ptr<FileWatcher>(new FileWatcher(std::move(impl)));
}

StatusOr<std::vector<std::string>> FileWatcher::WaitForSaves() {
  Impl& s = *impl_;
  for (;;) {
    if (CancelRequested()) return std::vector<std::string>{};
    // Sleep until an event, the next file's settling time, or the next look at cancellation.
    auto timeout = std::chrono::milliseconds(std::max(1, s.settings.poll_ms));
    for (const WatchedFile& f : s.files) {
      if (!f.pending) continue;
      const auto left =
          std::chrono::ceil<std::chrono::milliseconds>(f.last_change + s.Needed(f) - Clock::now());
      timeout = std::clamp(left, std::chrono::milliseconds(0), timeout);
    }
    pollfd p{s.fd, POLLIN, 0};
    const int n = ::poll(&p, 1, static_cast<int>(timeout.count()));
    if (n < 0) {
      if (errno == EINTR) continue;  // a signal: cancellation is looked at first
      return Status::Error(Errno("inotify: poll"));
    }
    if (n > 0) DISPEX_RETURN_IF_ERROR(s.ReadEvents());

    const auto now = Clock::now();
    bool any = false, settled = true;
    for (WatchedFile& f : s.files) {
      if (!f.pending) continue;
      any = true;
      const std::optional<Stamp> stamp = StatFile(f.path);
      if (stamp != f.stamp) {
        f.stamp = stamp;
        f.last_change = now;
      }
      settled &= now - f.last_change >= s.Needed(f);
    }
    if (!any || !settled) continue;
    std::vector<std::string> saved;
    for (WatchedFile& f : s.files) {
      if (!f.pending) continue;
      f.pending = false;
      if (!f.stamp) {
        if (!f.reported_missing) {
          std::fprintf(stderr, "dispex: %s is gone: waiting for it to be saved again\n",
                       f.path.c_str());
        }
        f.reported_missing = true;
        continue;
      }
      f.reported_missing = false;
      if (f.stamp != f.round_stamp) {
        f.round_stamp = f.stamp;
        saved.push_back(f.path);
      }
    }
    if (!saved.empty()) return saved;
  }
}

std::string JoinFileNames(const std::vector<std::string>& paths) {
  std::string out;
  for (std::size_t i = 0; i < paths.size(); ++i) {
    out += i == 0 ? "" : i + 1 == paths.size() ? " and " : ", ";
    out += paths[i];
  }
  return out;
}

std::string WatchRoundLines(const std::vector<std::string>& changed, const ExtractReport& r,
                            std::vector<std::string>& warned) {
  const std::string saved = changed.empty() ? "" : JoinFileNames(changed) + " changed: ";
  std::string out;
  if (r.incremental.unchanged) {
    out = fmt::format("dispex: {}{} is up to date (made from the same inputs and options)\n", saved,
                      r.output.path);
  } else {
    const std::string& reason = r.incremental.redo_reason;
    const std::string tiles =
        r.uv.paths.empty() ? "" : fmt::format(" and {} UV tiles", r.uv.paths.size());
    out = fmt::format("dispex: {}{} of {} faces extracted{} ({}), {}{} written in {:.2f} s\n",
                      saved, r.incremental.faces_extracted,
                      r.incremental.faces_extracted + r.incremental.faces_copied,
                      changed.empty() ? "" : " again", reason, r.output.path, tiles, r.times.total);
  }
  for (const std::string& warning : r.warnings) {
    if (std::find(warned.begin(), warned.end(), warning) == warned.end()) {
      out += "  warning: " + warning + "\n";
    }
  }
  warned = r.warnings;
  return out;
}

std::string WatchFailureLine(const std::vector<std::string>& changed, const std::string& map,
                             const std::string& message) {
  std::error_code error;
  return fmt::format("dispex: {}not extracted, {}: {}\n",
                     changed.empty() ? "" : JoinFileNames(changed) + " changed: ",
                     fs::exists(map, error) ? map + " left as it was" : "no map written yet",
                     message);
}

int RunWatch(const std::vector<std::string>& paths, const WatchSettings& settings, bool quiet,
             const std::function<void(const std::vector<std::string>& changed)>& round) {
  auto watcher = FileWatcher::Create(paths, settings);
  if (!watcher.ok()) return ReportFailure(watcher.status());
  round({});
  if (!CancelRequested() && !quiet) {
    std::vector<std::string> names;
    for (const std::string& path : paths) {
      if (std::find(names.begin(), names.end(), path) == names.end()) names.push_back(path);
    }
    std::fprintf(stderr, "dispex: watching %s for saves (Ctrl-C to stop)\n",
                 JoinFileNames(names).c_str());
  }
  while (!CancelRequested()) {
    auto saved = (*watcher)->WaitForSaves();
    if (!saved.ok()) return ReportFailure(saved.status());
    if (saved->empty()) break;  // cancelled
    round(*saved);
  }
  std::fputs("dispex: interrupted: stopped watching\n", stderr);
  const int sig = CancelSignal();
  return 128 + (sig != 0 ? sig : SIGINT);
}

}  // namespace dispex::cli
