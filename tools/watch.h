// dispex extract --watch: re-run a command each time one of its input files is saved.
//
// The folders of the files are watched (inotify), not the files themselves: most tools save by
// writing a temporary file and renaming it onto the target, which replaces the file a watch on
// it would follow. A file counts as saved once it is complete:
//  - renamed onto its name: complete at once (after `rename_quiet_ms` without another event);
//  - written in place: once its size, modification time and inode have stayed the same for
//    `settle_ms` and no writer holds it open (modified and not closed again: inotify's
//    IN_MODIFY without IN_CLOSE_WRITE). A file held open that has not changed for
//    `held_open_ms` is taken anyway.
// Files saved together (base and sculpt) are waited for together. A save that leaves the file
// as the last round read it (same inode, size, times) starts no round. Cancellation
// (dispex/cancel.h: Ctrl-C) is noticed within `poll_ms`, at once on a signal.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "dispex/extract.h"
#include "dispex/status.h"

namespace dispex::cli {

struct WatchSettings {
  int settle_ms = 300;
  int rename_quiet_ms = 50;
  int held_open_ms = 5000;
  int poll_ms = 100;
};

class FileWatcher {
 public:
  // Watches the folders of `paths` (duplicates merged), each path also through the folder of
  // the file it names when it is a symbolic link. Fails when a folder cannot be watched.
  static StatusOr<std::unique_ptr<FileWatcher>> Create(const std::vector<std::string>& paths,
                                                       const WatchSettings& settings);
  ~FileWatcher();
  FileWatcher(const FileWatcher&) = delete;
  FileWatcher& operator=(const FileWatcher&) = delete;

  // Blocks until files were saved (as above) and differ from the last time they were returned
  // (from Create's time at first); returns them, as given to Create. Empty: cancellation was
  // requested. An error: a watched folder was removed or moved, or inotify failed.
  StatusOr<std::vector<std::string>> WaitForSaves();

 private:
  struct Impl;
  explicit FileWatcher(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

// Runs `round({})` at once, then `round(changed)` after each save of some of `paths` (the files
// saved, as given), until cancelled: returns 128 + the signal (130 for Ctrl-C, 143 for SIGTERM)
// after printing "dispex: interrupted: stopped watching", or 1 when the folders cannot be
// watched. A round prints its own outcome; a failed round does not end the watch. Unless
// `quiet`, says once which files it watches.
int RunWatch(const std::vector<std::string>& paths, const WatchSettings& settings, bool quiet,
             const std::function<void(const std::vector<std::string>& changed)>& round);

// "a.obj", "a.obj and b.obj": the files a round line names.
std::string JoinFileNames(const std::vector<std::string>& paths);

// What an extraction round of `dispex extract --watch` prints (`changed`: the files saved, empty
// for the round at start), one line:
//   dispex: sculpt.obj changed: 12 of 252 faces extracted again (sculpt), map.ptx written in 0.41 s
//   dispex: sculpt.obj changed: map.ptx is up to date (made from the same inputs and options)
// then the report's warnings that the round before did not give (`warned`: those it gave).
std::string WatchRoundLines(const std::vector<std::string>& changed, const ExtractReport& report,
                            std::vector<std::string>& warned);
// A round that failed: the map at `map` is left as it was (or there is none yet).
//   dispex: sculpt.obj changed: not extracted, map.ptx left as it was: sculpt.obj:12: ...
std::string WatchFailureLine(const std::vector<std::string>& changed, const std::string& map,
                             const std::string& message);

}  // namespace dispex::cli
