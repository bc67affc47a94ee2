// The library's messages name fields (sim::Options::dt_out, the state x0,
// the analysis report's option `full`); the command line's user knows them as
// flags (--dt-out, --x0, --full). with_flag_names is the one map from the
// first to the second, applied where a command prints a library message about
// options it took from flags; each command has its table.
#pragma once

#include <span>
#include <string>
#include <string_view>

namespace lcsim::cli {

struct FieldFlag {
  std::string_view field, flag;
};
using FieldFlags = std::span<const FieldFlag>;

// `lcsim simulate`: the fields of sim::Options it sets from a flag.
FieldFlags simulate_flags();
// `lcsim analyze`: app::AnalysisOptions::full as the report's text names it.
FieldFlags analyze_flags();
// `lcsim impacts`: the fields of app::ImpactsRequest.
FieldFlags impacts_flags();
// `lcsim study`: the fields of study::ExecOptions.
FieldFlags study_flags();

// `message` with each whole field name of `flags` replaced by its flag
// ("dt_out must be ..." -> "--dt-out must be ...", "x0: ..." -> "--x0: ...").
// A name is whole when no letter, digit, '_' or ':' comes before it, nor a
// '.' (a member of something else: "mechanical.restitution" is not the field
// "restitution"), and no letter, digit, '_' or "::" after it. Other text is
// unchanged.
std::string with_flag_names(const std::string& message, FieldFlags flags = simulate_flags());

}  // namespace lcsim::cli
