// How a parallel stage of an extraction stops: with the error of the lowest face id (so the
// message does not depend on scheduling), or because cancellation was requested.
#pragma once

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include "core/first_error.h"
#include "core/progress.h"
#include "dispex/cancel.h"
#include "dispex/ids.h"
#include "dispex/status.h"

namespace dispex::extract {

inline Status Cancelled() {
  int sig = CancelSignal();
  return Status::Error(StatusCode::kCancelled,
                       sig ? fmt::format("interrupted by signal {}", sig) : "interrupted");
}

// In parallel over `count` items, item k being face face_of(k), each thread with its own
// scratch; stops at the first error or a cancellation and returns the lowest face's error.
template <class Scratch, class FaceOf, class Work>
Status ForEachFace(int count, FaceOf face_of, tbb::enumerable_thread_specific<Scratch>& scratches,
                   Progress* bar, Work work) {
  FirstError error;
  tbb::parallel_for(tbb::blocked_range<int>(0, count, 1),
                    [&](const tbb::blocked_range<int>& range) {
                      Scratch& w = scratches.local();
                      for (int k = range.begin(); k != range.end(); ++k) {
                        const int f = face_of(k);
                        if (error.failed()) return;
                        if (CancelRequested()) return error.Record(-1, Cancelled());
                        Status s = work(PtexFaceId(f), w);
                        if (!s.ok()) return error.Record(f, s);
                        if (bar) bar->Advance();
                      }
                    });
  return error.failed() ? error.status() : Status::Ok();
}

}  // namespace dispex::extract
