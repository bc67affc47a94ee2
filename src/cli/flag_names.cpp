// Field names of sim::Options to the flags of `lcsim simulate` (flag_names.hpp).
#include "cli/flag_names.hpp"

#include <cctype>
#include <string_view>

namespace lcsim::cli {
namespace {

struct FieldFlag {
  std::string_view field, flag;
};

// Longer names first, so "Options::dt_out" is replaced whole, not as
// "Options::" followed by "dt_out". t_end is absent: a horizon comes from
// --t-end or from the model file's t_end, and the message cannot tell which.
constexpr FieldFlag kFieldFlags[] = {
    {"Options::max_output_bytes", "--max-output"},
    {"Options::lcp_solver", "--lcp"},
    {"Options::dt_out", "--dt-out"},
    {"Options::impact", "--impact"},
    {"Options::theta", "--theta"},
    {"Options::force", "--force"},
    {"Options::h", "--h"},
    {"max_output_bytes", "--max-output"},
    {"dt_out", "--dt-out"},
};

bool word_char(char c) {
  return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '_' || c == ':';
}

}  // namespace

std::string with_flag_names(const std::string& message) {
  std::string out;
  for (size_t i = 0; i < message.size();) {
    bool replaced = false;
    if (i == 0 || !word_char(message[i - 1]))
      for (const auto& [field, flag] : kFieldFlags) {
        const size_t end = i + field.size();
        if (message.compare(i, field.size(), field) == 0 &&
            (end == message.size() || !word_char(message[end]))) {
          out += flag;
          i = end;
          replaced = true;
          break;
        }
      }
    if (!replaced) out += message[i++];
  }
  return out;
}

}  // namespace lcsim::cli
