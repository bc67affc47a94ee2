// Field names of the library to the flags of the commands (flag_names.hpp).
#include "cli/flag_names.hpp"

#include <cctype>

namespace lcsim::cli {
namespace {

// Longer names first, so "Options::dt_out" is replaced whole, not as
// "Options::" followed by "dt_out". t_end is absent: a horizon comes from
// --t-end or from the model file's t_end, and the message cannot tell which.
constexpr FieldFlag kSimulateFlags[] = {
    {"Options::max_output_bytes", "--max-output"},
    {"Options::sensitivity", "--sensitivity"},
    {"sensitivity", "--sensitivity"},
    {"Options::lcp_solver", "--lcp"},
    {"Options::dt_out", "--dt-out"},
    {"Options::impact", "--impact"},
    {"Options::theta", "--theta"},
    {"Options::force", "--force"},
    {"Options::h", "--h"},
    {"max_output_bytes", "--max-output"},
    {"linearisation_threshold", "--linearisation-threshold"},
    {"dt_out", "--dt-out"},
};

// The report's text says "full = true prints it" (app/analysis.hpp).
constexpr FieldFlag kAnalyzeFlags[] = {
    {"full = true", "--full"},
    {"linearisation_threshold", "--linearisation-threshold"},
};

// app::ImpactsRequest's fields, as its messages name them.
constexpr FieldFlag kImpactsFlags[] = {
    {"restitution", "--restitution"},
    {"rules", "--rules"},
    {"x0", "--x0"},
};

// study::ExecOptions's fields, as its messages name them.
constexpr FieldFlag kStudyFlags[] = {
    {"resume = true continues", "--resume continues"},
    {"jobs", "--jobs"},
    {"out", "--out"},
};

bool word_char(char c) {
  return std::isalnum(static_cast<unsigned char>(c)) != 0 || c == '_' || c == ':';
}

// A name ending at `end` is whole: what follows is no letter, digit or '_',
// nor "::" (it would go on as "Options::dt_out" does); one ':' ends it ("x0: ...").
bool ends_word(const std::string& message, size_t end) {
  if (end == message.size() || !word_char(message[end])) return true;
  return message[end] == ':' && (end + 1 == message.size() || message[end + 1] != ':');
}

}  // namespace

FieldFlags simulate_flags() { return kSimulateFlags; }
FieldFlags analyze_flags() { return kAnalyzeFlags; }
FieldFlags impacts_flags() { return kImpactsFlags; }
FieldFlags study_flags() { return kStudyFlags; }

std::string with_flag_names(const std::string& message, FieldFlags flags) {
  std::string out;
  for (size_t i = 0; i < message.size();) {
    bool replaced = false;
    if (i == 0 || !(word_char(message[i - 1]) || message[i - 1] == '.'))
      for (const auto& [field, flag] : flags) {
        const size_t end = i + field.size();
        if (message.compare(i, field.size(), field) == 0 && ends_word(message, end)) {
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
