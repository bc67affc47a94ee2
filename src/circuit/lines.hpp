// The circuit layer's private parts: a netlist's logical lines and tokens.
#pragma once

#include <string>
#include <vector>

namespace lcsim::circuit::detail {

// A logical line (continuation lines joined): its first physical line's
// number (1-based) and its tokens as written. Separators are blanks and
// commas; '(', ')' and '=' are tokens of their own.
struct Line {
  int number = 0;
  std::vector<std::string> tokens;
};

// The title (line 1) and the logical lines after it, comments removed:
// lines whose first non-blank is '*', and the rest of a line from ';' or
// from a '$' at its start or after a blank. A line starting with '+'
// continues the one before. InputError for a '+' with nothing to continue.
struct Lines {
  std::string title;
  std::vector<Line> lines;
};
Lines split_lines(const std::string& text, const std::string& source);

std::string lower(std::string s);

}  // namespace lcsim::circuit::detail
