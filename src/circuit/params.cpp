// .param (docs/circuits.md): global parameters, and `{expr}` in place of a
// value on any line. The subset read: `.param name=value ...` at the top
// level (not inside .subckt), each value a number with SPICE's suffixes, a
// parameter defined before it, or an expression; an expression (inside
// braces on element and control lines, with or without them on .param
// lines) of numbers, parameter names, + - * / and parentheses. Each brace
// group is replaced by its value, written with 17 significant digits (read
// back to the same double).
#include <cctype>
#include <cmath>
#include <cstdio>
#include <lcsim/circuit/circuit.hpp>
#include <lcsim/core/format.hpp>
#include <map>

#include "circuit/lines.hpp"

namespace lcsim::circuit::detail {
namespace {

// Recursive descent over an expression's text; throws a message (the
// caller names the line).
struct Expression {
  const std::string& s;
  const std::map<std::string, double>& params;
  std::size_t i = 0;

  void blanks() {
    while (i < s.size() && std::isspace(static_cast<unsigned char>(s[i]))) ++i;
  }
  [[noreturn]] void fail(const std::string& what) const {
    throw std::runtime_error(what + " in '" + s + "'");
  }
  double sum() {
    double v = product();
    for (blanks(); i < s.size() && (s[i] == '+' || s[i] == '-'); blanks()) {
      const char op = s[i++];
      const double w = product();
      v = op == '+' ? v + w : v - w;
    }
    return v;
  }
  double product() {
    double v = factor();
    for (blanks(); i < s.size() && (s[i] == '*' || s[i] == '/'); blanks()) {
      const char op = s[i++];
      const double w = factor();
      if (op == '/' && w == 0.0) fail("division by zero");
      v = op == '*' ? v * w : v / w;
    }
    return v;
  }
  double factor() {
    blanks();
    if (i >= s.size()) fail("a value is missing");
    const char c = s[i];
    if (c == '+' || c == '-') {
      ++i;
      return c == '-' ? -factor() : factor();
    }
    if (c == '(') {
      ++i;
      const double v = sum();
      blanks();
      if (i >= s.size() || s[i] != ')') fail("')' is missing");
      ++i;
      return v;
    }
    const std::size_t start = i;
    if (std::isdigit(static_cast<unsigned char>(c)) || c == '.') {  // a SPICE number
      while (i < s.size() &&
             (std::isalnum(static_cast<unsigned char>(s[i])) || s[i] == '.' ||
              ((s[i] == '+' || s[i] == '-') && (s[i - 1] == 'e' || s[i - 1] == 'E') &&
               std::isdigit(static_cast<unsigned char>(s[start])))))
        ++i;
      const std::optional<double> v = spice_number(s.substr(start, i - start));
      if (!v) fail("non-numeric value '" + s.substr(start, i - start) + "'");
      return *v;
    }
    if (std::isalpha(static_cast<unsigned char>(c)) || c == '_') {
      while (i < s.size() && (std::isalnum(static_cast<unsigned char>(s[i])) || s[i] == '_')) ++i;
      const std::string name = s.substr(start, i - start);
      const auto it = params.find(lower(name));
      if (it == params.end()) fail("unknown parameter '" + name + "'");
      return it->second;
    }
    fail(std::string("unexpected '") + c + "'");
  }
};

double evaluate(const std::string& text, const std::map<std::string, double>& params) {
  Expression e{text, params};
  const double v = e.sum();
  e.blanks();
  if (e.i < text.size()) e.fail(std::string("unexpected '") + text[e.i] + "'");
  if (!std::isfinite(v)) e.fail("a value that is not finite");
  return v;
}

std::string where(const Line& l, const std::string& source) {
  return (l.file.empty() ? source : l.file) + ":" + std::to_string(l.number);
}

std::string exact_text(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

// The tokens from `i` to the one that closes the brace opened at tokens[i],
// joined (the tokenizer splits "(", ")" and "=" out of an expression).
std::string brace_group(const Line& l, std::size_t& i, const std::string& source) {
  std::string text;
  for (; i < l.tokens.size(); ++i) {
    text += (text.empty() ? "" : " ") + l.tokens[i];
    if (l.tokens[i].find('}') != std::string::npos) break;
  }
  if (i == l.tokens.size() || text.back() != '}' || text.find('{', 1) != std::string::npos)
    throw InputError(where(l, source) + ": " + l.tokens[0] + ": a '{' without its '}' (or " +
                     "text after it) in '" + text + "'");
  return text.substr(1, text.size() - 2);
}

// .param name=value ...: into `params`, in order.
void define(const Line& l, const std::string& source, std::map<std::string, double>& params) {
  const auto& t = l.tokens;
  for (std::size_t i = 1; i < t.size();) {
    if (i + 2 >= t.size() || t[i + 1] != "=")
      throw InputError(where(l, source) + ": .param: expected name=value (at '" + t[i] + "')");
    const std::string name = t[i];
    i += 2;
    std::string text;  // the value: up to the next `name =`
    while (i < t.size() && !(i + 1 < t.size() && t[i + 1] == "="))
      text += (text.empty() ? "" : " ") + t[i++];
    if (text.size() >= 2 && text.front() == '{' && text.back() == '}')
      text = text.substr(1, text.size() - 2);
    try {
      params[lower(name)] = evaluate(text, params);
    } catch (const std::runtime_error& e) {
      throw InputError(where(l, source) + ": .param " + name + ": " + e.what());
    }
  }
}

}  // namespace

void apply_params(Lines& lines, const std::string& source) {
  std::map<std::string, double> params;
  std::vector<Line> kept;
  int subckt = 0;
  for (const Line& l : lines.lines) {
    const std::string k = lower(l.tokens[0]);
    subckt += k == ".subckt" ? 1 : k == ".ends" ? -1 : 0;
    if (k != ".param") {
      kept.push_back(l);
      continue;
    }
    if (subckt > 0)
      throw InputError(where(l, source) +
                       ": .param inside .subckt is not supported (lcsim reads global .param)");
    define(l, source, params);
  }
  for (Line& l : kept) {
    std::vector<std::string> out;
    for (std::size_t i = 0; i < l.tokens.size(); ++i) {
      if (l.tokens[i].empty() || l.tokens[i][0] != '{') {
        out.push_back(l.tokens[i]);
        continue;
      }
      const std::string text = brace_group(l, i, source);
      try {
        out.push_back(exact_text(evaluate(text, params)));
      } catch (const std::runtime_error& e) {
        throw InputError(where(l, source) + ": " + l.tokens[0] + ": " + e.what());
      }
    }
    l.tokens = std::move(out);
  }
  lines.lines = std::move(kept);
}

}  // namespace lcsim::circuit::detail
