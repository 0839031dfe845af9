#include "pneumid/common/version.hpp"

namespace pneumid {
const char* Version() { return "0.1.0"; }
}  // namespace pneumid
