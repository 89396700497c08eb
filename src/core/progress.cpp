#include "core/progress.h"

#include <fmt/format.h>

#include <algorithm>
#include <cstdio>

namespace dispex {

namespace {
std::string FormatDuration(double s) {
  if (s < 60) return fmt::format("{:.0f}s", s);
  if (s < 3600) return fmt::format("{}m{:02}s", static_cast<int>(s) / 60, static_cast<int>(s) % 60);
  return fmt::format("{}h{:02}m", static_cast<int>(s) / 3600, (static_cast<int>(s) / 60) % 60);
}
}  // namespace

std::string Progress::Format(const std::string& label, std::uint64_t done, std::uint64_t total,
                             const std::string& unit, double seconds, int width) {
  double fraction =
      total ? std::min(1.0, static_cast<double>(done) / static_cast<double>(total)) : 1;
  int filled = static_cast<int>(fraction * width + 0.5);
  std::string bar(static_cast<std::size_t>(filled), '#');
  bar.resize(static_cast<std::size_t>(width), ' ');
  double rate = seconds > 0 ? static_cast<double>(done) / seconds : 0;
  std::string eta = "--";
  if (rate > 0 && done < total) eta = FormatDuration(static_cast<double>(total - done) / rate);
  if (done >= total) eta = FormatDuration(seconds);
  return fmt::format("{} [{}] {}/{} {} {:.0f}/s {} {}", label, bar, done, total, unit, rate,
                     done >= total ? "in" : "ETA", eta);
}

Progress::Progress(std::string label, std::uint64_t total, std::string unit, bool enabled,
                   ProgressCounter* counter)
    : label_(std::move(label)),
      total_(total),
      unit_(std::move(unit)),
      enabled_(enabled),
      counter_(counter),
      start_(std::chrono::steady_clock::now()) {
  if (counter_ != nullptr) {
    counter_->done.store(0);
    counter_->total.store(total);
  }
  if (!enabled_) return;
  thread_ = std::thread([this] {
    std::unique_lock lock(mutex_);
    while (!stop_) {
      Draw(false);
      wake_.wait_for(lock, std::chrono::milliseconds(100), [this] { return stop_; });
    }
  });
}

Progress::~Progress() {
  Finish();
}

void Progress::Finish() {
  if (!enabled_ || finished_) return;
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
  Draw(true);
  finished_ = true;
}

void Progress::Draw(bool final_line) {
  double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  std::string line = Format(label_, done(), total_, unit_, seconds);
  std::fprintf(stderr, "\r\033[2K%s%s", line.c_str(), final_line ? "\n" : "");
  std::fflush(stderr);
}

}  // namespace dispex
