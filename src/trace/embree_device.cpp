#include "trace/embree_device.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cstdlib>
#include <iterator>
#include <vector>

namespace dispex::trace {

std::string_view RtcErrorName(RTCError code) {
  switch (code) {
    case RTC_ERROR_NONE:
      return "RTC_ERROR_NONE";
    case RTC_ERROR_UNKNOWN:
      return "RTC_ERROR_UNKNOWN";
    case RTC_ERROR_INVALID_ARGUMENT:
      return "RTC_ERROR_INVALID_ARGUMENT";
    case RTC_ERROR_INVALID_OPERATION:
      return "RTC_ERROR_INVALID_OPERATION";
    case RTC_ERROR_OUT_OF_MEMORY:
      return "RTC_ERROR_OUT_OF_MEMORY";
    case RTC_ERROR_UNSUPPORTED_CPU:
      return "RTC_ERROR_UNSUPPORTED_CPU";
    case RTC_ERROR_CANCELLED:
      return "RTC_ERROR_CANCELLED";
  }
  return "RTC_ERROR_(unknown code)";
}

bool CpuHasIsa(std::string_view isa) {
#if defined(__x86_64__) || defined(__i386__)
  __builtin_cpu_init();
  if (isa == "sse2") return __builtin_cpu_supports("sse2");
  if (isa == "sse4.2") return __builtin_cpu_supports("sse4.2") && __builtin_cpu_supports("popcnt");
  if (isa == "avx") return __builtin_cpu_supports("avx");
  if (isa == "avx2") {
    return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") &&
           __builtin_cpu_supports("bmi") && __builtin_cpu_supports("bmi2");
  }
  if (isa == "avx512") {
    return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") &&
           __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512dq") &&
           __builtin_cpu_supports("avx512cd");
  }
#endif
  return false;
}

namespace {

// Embree's own pick: the 16- and 8-wide native packet properties are the device's answer
// to "AVX-512 kernels?" and "AVX kernels?"; AVX against AVX2, and SSE4.2 against SSE2, is
// told by the CPU features Embree requires for them.
std::string AutoIsa(RTCDevice device) {
  if (rtcGetDeviceProperty(device, RTC_DEVICE_PROPERTY_NATIVE_RAY16_SUPPORTED) != 0) {
    return "avx512";
  }
  if (rtcGetDeviceProperty(device, RTC_DEVICE_PROPERTY_NATIVE_RAY8_SUPPORTED) != 0) {
    return CpuHasIsa("avx2") ? "avx2" : "avx";
  }
  return CpuHasIsa("sse4.2") ? "sse4.2" : "sse2";
}

Status ErrorStatus(RTCError code, const std::string& message) {
  if (code == RTC_ERROR_OUT_OF_MEMORY) {
    return Status::Error(fmt::format("embree: out of memory building the sculpt's BVH ({}{}{})",
                                     message, message.empty() ? "" : ", ", RtcErrorName(code)));
  }
  return Status::Error(
      fmt::format("embree: {} ({})", message.empty() ? "error" : message, RtcErrorName(code)));
}

}  // namespace

EmbreeDevice::EmbreeDevice(std::int64_t memory_limit_bytes) : limit_(memory_limit_bytes) {}

std::string ChosenIsa(const std::string& requested, std::string* source) {
  if (!requested.empty()) {
    *source = "isa";
    return requested;
  }
  const char* env = std::getenv("DISPEX_EMBREE_ISA");
  if (env != nullptr && *env != '\0') {
    *source = "DISPEX_EMBREE_ISA";
    return env;
  }
  *source = "isa";
  return "";
}

StatusOr<std::unique_ptr<EmbreeDevice>> EmbreeDevice::Create(std::int64_t memory_limit_bytes,
                                                             const std::string& isa,
                                                             const std::string& isa_source) {
  // Embree reads an unknown name as sse2 without a word: check it here.
  if (!isa.empty() &&
      std::find(std::begin(kEmbreeIsas), std::end(kEmbreeIsas), isa) == std::end(kEmbreeIsas)) {
    return Status::Error(fmt::format("{} '{}': unknown Embree ISA (valid: {})", isa_source, isa,
                                     fmt::join(kEmbreeIsas, ", ")));
  }
  std::unique_ptr<EmbreeDevice> device(new EmbreeDevice(memory_limit_bytes));
  const std::string config = isa.empty() ? std::string() : "isa=" + isa;
  device->device_ = rtcNewDevice(config.empty() ? nullptr : config.c_str());
  if (device->device_ == nullptr) {
    const RTCError code = rtcGetDeviceError(nullptr);
    if (code == RTC_ERROR_UNSUPPORTED_CPU && !isa.empty()) {
      return Status::Error(fmt::format(
          "{} '{}': this CPU lacks the instructions of these Embree "
          "kernels (it supports: {}) ({})",
          isa_source, isa, fmt::join(dispex::SupportedEmbreeIsas(), ", "), RtcErrorName(code)));
    }
    return Status::Error(fmt::format("embree: could not create a device ({})", RtcErrorName(code)));
  }
  device->isa_forced_ = !isa.empty();
  device->isa_ = isa.empty() ? AutoIsa(device->device_) : isa;
  rtcSetDeviceErrorFunction(device->device_, &EmbreeDevice::OnError, device.get());
  rtcSetDeviceMemoryMonitorFunction(device->device_, &EmbreeDevice::OnMemory, device.get());
  return device;
}

EmbreeDevice::~EmbreeDevice() {
  if (device_ != nullptr) rtcReleaseDevice(device_);
}

void EmbreeDevice::OnError(void* user, RTCError code, const char* message) {
  auto* self = static_cast<EmbreeDevice*>(user);
  std::lock_guard lock(self->mutex_);
  if (self->error_code_ != RTC_ERROR_NONE) return;  // keep the first, the cause
  self->error_code_ = code;
  self->error_message_ = message != nullptr ? message : "";
}

bool EmbreeDevice::OnMemory(void* user, ssize_t bytes, bool post) {
  auto* self = static_cast<EmbreeDevice*>(user);
  // Refusing an allocation (only possible before it happens, post == false) makes Embree
  // throw RTC_ERROR_OUT_OF_MEMORY without allocating, so refused bytes are not counted.
  if (bytes > 0 && !post && self->limit_ > 0 &&
      self->bytes_.load(std::memory_order_relaxed) + bytes > self->limit_) {
    return false;
  }
  const std::int64_t now = self->bytes_.fetch_add(bytes, std::memory_order_relaxed) + bytes;
  std::int64_t peak = self->peak_bytes_.load(std::memory_order_relaxed);
  while (now > peak &&
         !self->peak_bytes_.compare_exchange_weak(peak, now, std::memory_order_relaxed)) {
  }
  return true;
}

Status EmbreeDevice::TakeError() {
  RTCError code = rtcGetDeviceError(device_);
  std::string message;
  {
    std::lock_guard lock(mutex_);
    if (error_code_ != RTC_ERROR_NONE) {
      code = error_code_;
      message = std::move(error_message_);
    }
    error_code_ = RTC_ERROR_NONE;
    error_message_.clear();
  }
  if (code == RTC_ERROR_NONE) return Status::Ok();
  return ErrorStatus(code, message);
}

Status EmbreeDevice::PeekError() const {
  std::lock_guard lock(mutex_);
  if (error_code_ == RTC_ERROR_NONE) return Status::Ok();
  return ErrorStatus(error_code_, error_message_);
}

std::string EmbreeDevice::Describe() const {
  return fmt::format("embree {}.{}.{} ({}{})",
                     rtcGetDeviceProperty(device_, RTC_DEVICE_PROPERTY_VERSION_MAJOR),
                     rtcGetDeviceProperty(device_, RTC_DEVICE_PROPERTY_VERSION_MINOR),
                     rtcGetDeviceProperty(device_, RTC_DEVICE_PROPERTY_VERSION_PATCH), isa_,
                     isa_forced_ ? ", forced" : "");
}

}  // namespace dispex::trace

namespace dispex {

std::span<const std::string_view> EmbreeIsaNames() {
  return trace::kEmbreeIsas;
}

std::vector<std::string_view> SupportedEmbreeIsas() {
  std::vector<std::string_view> names;
  for (const std::string_view isa : trace::kEmbreeIsas) {
    if (trace::CpuHasIsa(isa)) names.push_back(isa);
  }
  return names;
}

}  // namespace dispex
