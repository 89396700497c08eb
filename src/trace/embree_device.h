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
#include <string_view>

#include "dispex/status.h"
#include "dispex/trace.h"

namespace dispex::trace {

// The Embree kernel sets dispex can ask for (Embree 3.13's `isa=` names), narrowest first.
inline constexpr std::string_view kEmbreeIsas[] = {"sse2", "sse4.2", "avx", "avx2", "avx512"};

// Whether this CPU has the features Embree requires for kernel set `isa` (its AVX2 set also
// needs FMA and BMI1/2).
bool CpuHasIsa(std::string_view isa);

// The ISA to force: `requested` (TracerOptions::isa) when not empty, else the environment
// variable DISPEX_EMBREE_ISA when set and not empty, else "" (Embree's own choice). The one
// place that reads DISPEX_EMBREE_ISA. `source` says where the name came from, for messages.
std::string ChosenIsa(const std::string& requested, std::string* source);

class EmbreeDevice {
 public:
  // Creates the device with Embree's kernels for `isa` ("" = Embree's choice for this CPU;
  // `isa_source` names where `isa` came from, for messages). Errors: an unknown ISA name, an
  // ISA this CPU lacks, Embree could not create a device.
  static StatusOr<std::unique_ptr<EmbreeDevice>> Create(std::int64_t memory_limit_bytes,
                                                        const std::string& isa = "",
                                                        const std::string& isa_source = "isa");

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

  // The ISA whose kernels Embree runs: the forced one, else Embree's pick (see isa()).
  const std::string& isa() const { return isa_; }
  bool isa_forced() const { return isa_forced_; }

  // Description for reports: "embree 3.13.5 (avx2)", or "(sse4.2, forced)" when forced.
  std::string Describe() const;

 private:
  explicit EmbreeDevice(std::int64_t memory_limit_bytes);
  static void OnError(void* user, RTCError code, const char* message);
  static bool OnMemory(void* user, ssize_t bytes, bool post);

  RTCDevice device_ = nullptr;
  std::string isa_;
  bool isa_forced_ = false;
  std::int64_t limit_ = 0;
  std::atomic<std::int64_t> bytes_{0};
  std::atomic<std::int64_t> peak_bytes_{0};
  mutable std::mutex mutex_;
  RTCError error_code_ = RTC_ERROR_NONE;
  std::string error_message_;
};

// "RTC_ERROR_OUT_OF_MEMORY" etc.
std::string_view RtcErrorName(RTCError code);

}  // namespace dispex::trace
