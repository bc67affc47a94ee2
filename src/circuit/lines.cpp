// A netlist's text as logical lines of tokens, and SPICE numbers.
#include "circuit/lines.hpp"

#include <cctype>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <lcsim/circuit/circuit.hpp>
#include <lcsim/io/yaml.hpp>

namespace lcsim::circuit {

namespace detail {

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

namespace {

bool blank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v'; }

// The line without its comment: from ';', or from '$' at the start or after
// a blank (ngspice's inline comments).
std::string strip_comment(const std::string& line) {
  for (std::size_t i = 0; i < line.size(); ++i) {
    if (line[i] == ';') return line.substr(0, i);
    if (line[i] == '$' && (i == 0 || blank(line[i - 1]))) return line.substr(0, i);
  }
  return line;
}

void tokenize(const std::string& text, std::vector<std::string>& out) {
  std::string cur;
  const auto flush = [&] {
    if (!cur.empty()) out.push_back(cur);
    cur.clear();
  };
  for (char c : text) {
    if (blank(c) || c == ',') {
      flush();
    } else if (c == '(' || c == ')' || c == '=') {
      flush();
      out.emplace_back(1, c);
    } else {
      cur += c;
    }
  }
  flush();
}

// The file named by an `.include` line's body (after the keyword at
// `first`): the rest of the line, trimmed, without quotes.
std::string include_name(const std::string& body, std::size_t first) {
  std::size_t i = first;
  while (i < body.size() && !blank(body[i])) ++i;  // the keyword
  std::string name = body.substr(i);
  while (!name.empty() && blank(name.front())) name.erase(name.begin());
  while (!name.empty() && blank(name.back())) name.pop_back();
  if (name.size() >= 2 && (name.front() == '"' || name.front() == '\'') &&
      name.back() == name.front())
    name = name.substr(1, name.size() - 2);
  return name;
}

constexpr int kMaxIncludeDepth = 16;

void append_lines(const std::string& text, const std::string& source, const std::string& file,
                  int depth, Lines& r);

// `.include name` at line `number` of `source` (its own file, `file`): the
// named file's lines, appended.
void include(const std::string& name, const std::string& source, const std::string& file,
             int number, int depth, Lines& r) {
  const std::string here = (file.empty() ? source : file) + ":" + std::to_string(number);
  if (name.empty()) throw InputError(here + ": .include: expected a file name");
  if (depth >= kMaxIncludeDepth)
    throw InputError(here + ": .include nested more than " + std::to_string(kMaxIncludeDepth) +
                     " deep (a file that includes itself?)");
  const std::filesystem::path base =
      std::filesystem::path(file.empty() ? source : file).parent_path();
  const std::filesystem::path path = base / name;  // an absolute name replaces base
  std::string text;
  try {
    text = io::read_file(path);
  } catch (const InputError& e) {
    throw InputError(here + ": .include: " + e.what());
  }
  append_lines(text, source, path.string(), depth + 1, r);
}

// The logical lines of one file: the netlist (file empty; its first line the
// title) or an included one.
void append_lines(const std::string& text, const std::string& source, const std::string& file,
                  int depth, Lines& r) {
  std::size_t pos = 0;
  int number = 0;
  const std::string& where = file.empty() ? source : file;
  while (pos <= text.size()) {
    const std::size_t end = std::min(text.find('\n', pos), text.size());
    std::string line = text.substr(pos, end - pos);
    pos = end + 1;
    ++number;
    if (number == 1 && file.empty()) {  // SPICE: the first line is the title, whatever it holds
      while (!line.empty() && (line.back() == '\r' || blank(line.back()))) line.pop_back();
      r.title = line;
      continue;
    }
    std::size_t first = 0;
    while (first < line.size() && blank(line[first])) ++first;
    if (first == line.size() || line[first] == '*') continue;
    const std::string body = strip_comment(line);
    if (line[first] == '+') {
      if (r.lines.empty())
        throw InputError(where + ":" + std::to_string(number) +
                         ": a continuation line ('+') with no line before it to continue");
      tokenize(body.substr(first + 1), r.lines.back().tokens);
      continue;
    }
    Line l;
    l.number = number;
    l.file = file;
    tokenize(body, l.tokens);
    if (l.tokens.empty()) continue;
    const std::string key = lower(l.tokens[0]);
    if (key == ".include" || key == ".inc") {
      include(include_name(body, first), source, file, number, depth, r);
      continue;
    }
    if (key == ".end" && !file.empty()) return;  // ends the included file only
    r.lines.push_back(std::move(l));
  }
}

}  // namespace

Lines split_lines(const std::string& text, const std::string& source) {
  Lines r;
  append_lines(text, source, "", 0, r);
  return r;
}

}  // namespace detail

std::optional<double> spice_number(const std::string& text) {
  // The number: [sign] digits [. digits] [e [sign] digits], at least one digit.
  std::size_t i = 0;
  const std::size_t n = text.size();
  if (i < n && (text[i] == '+' || text[i] == '-')) ++i;
  const std::size_t mantissa = i;
  while (i < n && std::isdigit(static_cast<unsigned char>(text[i]))) ++i;
  if (i < n && text[i] == '.') ++i;
  while (i < n && std::isdigit(static_cast<unsigned char>(text[i]))) ++i;
  if (i == mantissa || (i == mantissa + 1 && text[mantissa] == '.')) return std::nullopt;
  const std::string digits = text.substr(0, i);
  long exponent = 0;
  if (i < n && (text[i] == 'e' || text[i] == 'E')) {
    std::size_t j = i + 1;
    if (j < n && (text[j] == '+' || text[j] == '-')) ++j;
    const std::size_t first = j;
    while (j < n && std::isdigit(static_cast<unsigned char>(text[j]))) ++j;
    if (j > first && j - first < 6) {  // else the 'e' is a unit letter (rare)
      exponent = std::strtol(text.substr(i + 1, j - i - 1).c_str(), nullptr, 10);
      i = j;
    }
  }
  // The suffix: letters only; its start may be a scale factor.
  const std::string suffix = detail::lower(text.substr(i));
  for (char c : suffix)
    if (!std::isalpha(static_cast<unsigned char>(c))) return std::nullopt;
  double factor = 1.0;  // "mil" only: not a power of ten
  if (suffix.rfind("meg", 0) == 0) {
    exponent += 6;
  } else if (suffix.rfind("mil", 0) == 0) {
    factor = 25.4e-6;
  } else if (!suffix.empty()) {
    switch (suffix[0]) {
      case 'f':
        exponent -= 15;
        break;
      case 'p':
        exponent -= 12;
        break;
      case 'n':
        exponent -= 9;
        break;
      case 'u':
        exponent -= 6;
        break;
      case 'm':
        exponent -= 3;
        break;
      case 'k':
        exponent += 3;
        break;
      case 'g':
        exponent += 9;
        break;
      case 't':
        exponent += 12;
        break;
      default:
        break;  // a unit letter (V, A, s, F, ohm, Hz): ignored
    }
  }
  // One correctly rounded conversion of the decimal value ("10u" is 1e-5
  // exactly as the literal 1e-5 is, not 10 * 1e-6).
  const double v = std::strtod((digits + "e" + std::to_string(exponent)).c_str(), nullptr) * factor;
  if (!std::isfinite(v)) return std::nullopt;
  return v;
}

}  // namespace lcsim::circuit
