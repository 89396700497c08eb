// --progress-lines: progress for programs that drive the command line (the Blender add-on)
// rather than for a person at a terminal. A thread reads the library's ProgressCounter
// (dispex/progress.h) ten times a second and prints one line on stderr each time it moved,
//
//   progress extract 1234/5678
//
// (the phase, then Ptex faces done of the phase's total), and the final state once the work
// ends, whether stderr is a terminal or a pipe. Nothing before a phase starts (a run that
// fails first, or an --incremental run that extracts no face).
#pragma once

#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <string>
#include <thread>

#include "dispex/progress.h"

namespace dispex::cli {

class ProgressLines {
 public:
  // Prints nothing and counts nothing unless `enabled`.
  ProgressLines(std::string phase, bool enabled);
  ~ProgressLines();
  ProgressLines(const ProgressLines&) = delete;
  ProgressLines& operator=(const ProgressLines&) = delete;

  // What the library counts into (ExtractOptions::progress_counter); null when not enabled.
  ProgressCounter* counter() { return enabled_ ? &counter_ : nullptr; }

  // Stops the thread and prints the final state (unless that was the last line printed); the
  // destructor does it too, and only the first call does anything.
  void Finish();

  // "progress PHASE DONE/TOTAL" with a newline.
  static std::string Format(const std::string& phase, std::uint64_t done, std::uint64_t total);

 private:
  // Prints the counter when it moved since the last line, once a phase has started.
  void PrintIfMoved();

  std::string phase_;
  bool enabled_;
  ProgressCounter counter_;
  std::uint64_t printed_done_ = 0, printed_total_ = 0;
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stop_ = false;
  bool finished_ = false;
  std::thread thread_;
};

}  // namespace dispex::cli
