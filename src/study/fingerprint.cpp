// fingerprint() (detail.hpp): FNV-1a 64 (Fowler, Noll, Vo), offset basis
// 0xcbf29ce484222325, prime 0x100000001b3.
#include <cstdio>

#include "study/detail.hpp"

namespace lcsim::study {

std::string fingerprint(std::string_view text) {
  std::uint64_t h = 0xcbf29ce484222325ULL;
  for (const char c : text) {
    h ^= static_cast<unsigned char>(c);
    h *= 0x100000001b3ULL;
  }
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
  return buf;
}

}  // namespace lcsim::study
