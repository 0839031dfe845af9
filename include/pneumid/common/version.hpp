// Library version.
#pragma once

namespace pneumid {
/// "MAJOR.MINOR.PATCH" of the library.
const char* Version();
}  // namespace pneumid
