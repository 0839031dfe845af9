#include "pneumid/common/check.hpp"

namespace pneumid::internal {

void ThrowInvalidArgument(const char* /*condition*/, const char* /*file*/, int /*line*/,
                          const std::string& message) {
  throw InvalidArgument(message);
}

}  // namespace pneumid::internal
