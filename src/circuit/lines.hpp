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
  std::string file;  // the file of an `.include`d line; empty for the netlist's own
};

// The title (line 1) and the logical lines after it, comments removed:
// lines whose first non-blank is '*', and the rest of a line from ';' or
// from a '$' at its start or after a blank. A line starting with '+'
// continues the one before. InputError for a '+' with nothing to continue.
// `.include file` (or `.inc`; the file's name as the rest of the line, quotes
// removed, relative to the directory of the file holding the line) is
// replaced by that file's lines (no title line; a `.end` there ends that file
// only), nested up to 16 deep; InputError naming the line for a file it
// cannot read.
struct Lines {
  std::string title;
  std::vector<Line> lines;
};
Lines split_lines(const std::string& text, const std::string& source);

std::string lower(std::string s);

// .param (src/circuit/params.cpp): removes the `.param` lines, evaluating
// them in order, and replaces each `{expr}` on the other lines by its value.
// InputError naming the line for an unknown parameter, an expression it
// cannot read, or .param inside .subckt.
void apply_params(Lines& lines, const std::string& source);

}  // namespace lcsim::circuit::detail
