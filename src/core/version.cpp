#include "dispex/version.h"

namespace dispex {

const char* Version() noexcept {
  return DISPEX_VERSION_STRING;
}

}  // namespace dispex
