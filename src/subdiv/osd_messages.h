// Turns OpenSubdiv's global error and warning callbacks (Far::SetErrorCallback,
// Far::SetWarningCallback) into messages collected by the calling thread, so that a failed
// OpenSubdiv call becomes a Status at the adapter instead of text on stdout.
#pragma once

#include <string>

namespace dispex::subdiv {

// While an OsdMessageCapture lives, every Far::Error / Far::Warning raised on this thread is
// appended to it (one message per line). Captures nest; the innermost one receives. Messages
// raised on a thread without a capture go to stderr prefixed "dispex: OpenSubdiv: ".
class OsdMessageCapture {
 public:
  OsdMessageCapture();
  ~OsdMessageCapture();
  OsdMessageCapture(const OsdMessageCapture&) = delete;
  OsdMessageCapture& operator=(const OsdMessageCapture&) = delete;

  bool empty() const { return messages_.empty(); }
  // All messages joined with "; " (a Status message is one line).
  const std::string& messages() const { return messages_; }

  void Append(const char* message);

 private:
  std::string messages_;
  OsdMessageCapture* previous_;
};

}  // namespace dispex::subdiv
