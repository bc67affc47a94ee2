// The library's messages name the fields of sim::Options (dt_out,
// max_output_bytes, Options::lcp_solver, ...); the command line's user knows
// them as flags (--dt-out, --max-output, --lcp, ...). with_flag_names is the
// one map from the first to the second, applied where a command prints a
// library message about options it took from flags.
#pragma once

#include <string>

namespace lcsim::cli {

// `message` with each whole field name of sim::Options that `lcsim simulate`
// sets from a flag replaced by that flag ("dt_out must be ..." ->
// "--dt-out must be ..."). Other text is unchanged.
std::string with_flag_names(const std::string& message);

}  // namespace lcsim::cli
