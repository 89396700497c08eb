#include "trace/embree_device.h"

#include <fmt/format.h>

namespace dispex::trace {

const char* RtcErrorName(RTCError code) {
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

namespace {

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

StatusOr<std::unique_ptr<EmbreeDevice>> EmbreeDevice::Create(std::int64_t memory_limit_bytes) {
  std::unique_ptr<EmbreeDevice> device(new EmbreeDevice(memory_limit_bytes));
  device->device_ = rtcNewDevice(nullptr);
  if (device->device_ == nullptr) {
    const RTCError code = rtcGetDeviceError(nullptr);
    return Status::Error(fmt::format("embree: could not create a device ({})", RtcErrorName(code)));
  }
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
  const char* isa = "sse2";
#if defined(__x86_64__) || defined(__i386__)
  __builtin_cpu_init();
  if (__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") &&
      __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512dq") &&
      __builtin_cpu_supports("avx512cd")) {
    isa = "avx512";
  } else if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") &&
             __builtin_cpu_supports("bmi2")) {
    isa = "avx2";
  } else if (__builtin_cpu_supports("avx")) {
    isa = "avx";
  } else if (__builtin_cpu_supports("sse4.2")) {
    isa = "sse4.2";
  }
#else
  isa = "native";
#endif
  return fmt::format("embree {}.{}.{} ({})",
                     rtcGetDeviceProperty(device_, RTC_DEVICE_PROPERTY_VERSION_MAJOR),
                     rtcGetDeviceProperty(device_, RTC_DEVICE_PROPERTY_VERSION_MINOR),
                     rtcGetDeviceProperty(device_, RTC_DEVICE_PROPERTY_VERSION_PATCH), isa);
}

}  // namespace dispex::trace
