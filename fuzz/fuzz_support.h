// Shared set-up of the libFuzzer targets: one TBB thread (deterministic, and libFuzzer
// measures one process) and a loud abort when a reader breaks its contract.
#pragma once

#include <tbb/global_control.h>

#include <cstdio>
#include <cstdlib>
#include <string>

namespace dispex::fuzz {

// Limits TBB to the calling thread for the life of the process (ValidateMesh and the
// readers' parallel loops would otherwise start a worker per core).
inline void UseOneThread() {
  static tbb::global_control one_thread(tbb::global_control::max_allowed_parallelism, 1);
}

// Aborts (a crash libFuzzer records) when `why` names a contract violation.
inline void RequireContract(const char* target, const std::string& why) {
  if (why.empty()) return;
  std::fprintf(stderr, "%s: reader contract broken: %s\n", target, why.c_str());
  std::fflush(stderr);
  std::abort();
}

}  // namespace dispex::fuzz
