// Internal helpers of src/study (not part of the public face).
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

namespace lcsim::study {

// FNV-1a 64 of `text` as 16 hex digits: the journal's line check and the
// study's fingerprint (a check against torn or foreign lines, not a
// cryptographic hash).
std::string fingerprint(std::string_view text);

}  // namespace lcsim::study
