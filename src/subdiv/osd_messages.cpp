#include "subdiv/osd_messages.h"

#include <opensubdiv/far/error.h>

#include <cstdio>
#include <mutex>

namespace dispex::subdiv {
namespace {

namespace Far = OpenSubdiv::Far;

thread_local OsdMessageCapture* t_capture = nullptr;

void Deliver(const char* message) {
  if (message == nullptr) message = "(no message)";
  if (t_capture != nullptr) {
    t_capture->Append(message);
  } else {
    std::fprintf(stderr, "dispex: OpenSubdiv: %s\n", message);
  }
}

void OnError(Far::ErrorType /*type*/, const char* message) {
  Deliver(message);
}
void OnWarning(const char* message) {
  Deliver(message);
}

// The setters are not thread-safe, so they run once, before any capture is used.
void InstallCallbacks() {
  static std::once_flag once;
  std::call_once(once, [] {
    Far::SetErrorCallback(&OnError);
    Far::SetWarningCallback(&OnWarning);
  });
}

}  // namespace

OsdMessageCapture::OsdMessageCapture() : previous_(t_capture) {
  InstallCallbacks();
  t_capture = this;
}

OsdMessageCapture::~OsdMessageCapture() {
  t_capture = previous_;
}

void OsdMessageCapture::Append(const char* message) {
  std::string line(message);
  while (!line.empty() && (line.back() == '\n' || line.back() == ' ')) line.pop_back();
  for (char& c : line) {
    if (c == '\n') c = ' ';
  }
  if (!messages_.empty()) messages_ += "; ";
  messages_ += line;
}

}  // namespace dispex::subdiv
