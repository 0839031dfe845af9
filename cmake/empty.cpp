// Placeholder translation unit for an area library that has no sources yet.
namespace pneumid::internal { [[maybe_unused]] static const int kEmptyAreaMarker = 0; }
