// A netlist's text as logical lines of tokens, and SPICE numbers.
#include "circuit/lines.hpp"

#include <cctype>
#include <cmath>
#include <cstdlib>
#include <lcsim/circuit/circuit.hpp>

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

}  // namespace

Lines split_lines(const std::string& text, const std::string& source) {
  Lines r;
  std::size_t pos = 0;
  int number = 0;
  while (pos <= text.size()) {
    const std::size_t end = std::min(text.find('\n', pos), text.size());
    std::string line = text.substr(pos, end - pos);
    pos = end + 1;
    ++number;
    if (number == 1) {  // SPICE: the first line is the title, whatever it holds
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
        throw InputError(source + ":" + std::to_string(number) +
                         ": a continuation line ('+') with no line before it to continue");
      tokenize(body.substr(first + 1), r.lines.back().tokens);
      continue;
    }
    Line l;
    l.number = number;
    tokenize(body, l.tokens);
    if (!l.tokens.empty()) r.lines.push_back(std::move(l));
  }
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
