// An Embree device with its errors and allocations observed.
//
// Embree reports failures through a per-device error callback and an error code; this class
// records the first error message so that the adapter can turn it into a Status, and tracks
// the bytes Embree allocates (its memory monitor callback), optionally refusing allocations
// beyond a limit, which makes Embree fail the build with RTC_ERROR_OUT_OF_MEMORY.
#pragma once

#include <embree3/rtcore.h>

#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>

#include "dispex/status.h"

namespace dispex::trace {

class EmbreeDevice {
 public:
  // Creates the device. Error: Embree could not create one (unsupported CPU, bad config).
  static StatusOr<std::unique_ptr<EmbreeDevice>> Create(std::int64_t memory_limit_bytes);

  EmbreeDevice(const EmbreeDevice&) = delete;
  EmbreeDevice& operator=(const EmbreeDevice&) = delete;
  ~EmbreeDevice();

  RTCDevice get() const { return device_; }

  // OK, or the first error Embree reported since the last call (callback message, else the
  // device's error code), as "embree: <what> (<code name>)". Clears the recorded error.
  Status TakeError();
  // Like TakeError but leaves the record in place (for Tracer::status()).
  Status PeekError() const;

  std::int64_t bytes() const { return bytes_.load(std::memory_order_relaxed); }
  std::int64_t peak_bytes() const { return peak_bytes_.load(std::memory_order_relaxed); }
  void ResetPeak() { peak_bytes_.store(bytes(), std::memory_order_relaxed); }

  // Description for reports: "embree 3.13.5 (avx512)", the ISA being the widest one this
  // CPU supports among those Embree is built for (the one Embree dispatches to).
  std::string Describe() const;

 private:
  explicit EmbreeDevice(std::int64_t memory_limit_bytes);
  static void OnError(void* user, RTCError code, const char* message);
  static bool OnMemory(void* user, ssize_t bytes, bool post);

  RTCDevice device_ = nullptr;
  std::int64_t limit_ = 0;
  std::atomic<std::int64_t> bytes_{0};
  std::atomic<std::int64_t> peak_bytes_{0};
  mutable std::mutex mutex_;
  RTCError error_code_ = RTC_ERROR_NONE;
  std::string error_message_;
};

// "RTC_ERROR_OUT_OF_MEMORY" etc.
const char* RtcErrorName(RTCError code);

}  // namespace dispex::trace
