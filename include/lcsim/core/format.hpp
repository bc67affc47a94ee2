// Numbers as text, one home for every layer: the shortest text that reads
// back (files, input errors), a number with N significant digits (messages,
// the CSV), and a message built from its parts. Locale-independent
// (std::to_chars): a program that sets LC_NUMERIC still writes "0.5".
#pragma once

#include <charconv>
#include <string>
#include <string_view>
#include <type_traits>

namespace lcsim {

// Appends x with `digits` (1..17) significant digits, the text of printf's
// "%.<digits>g" in the C locale ("0.333333", "1e-07", "inf", "-nan"); 17
// digits read back as the same double.
inline void append_number(std::string& out, double x, int digits) {
  char buf[64];  // "%.17g" needs at most 24
  const auto [end, ec] =
      std::to_chars(buf, buf + sizeof buf, x, std::chars_format::general, digits);
  if (ec == std::errc())
    out.append(buf, end);
  else
    out += '?';
}

// The shortest text that reads back as the same double ("2", "0.1",
// "-1e-300"): what files and input-error messages print, so that a user can
// paste the value back.
inline std::string format_number(double x) {
  char buf[64];
  const auto [end, ec] = std::to_chars(buf, buf + sizeof buf, x);
  return ec == std::errc() ? std::string(buf, end) : std::string("?");
}

// x with `digits` significant digits, as append_number.
inline std::string format_number(double x, int digits) {
  std::string s;
  append_number(s, x, digits);
  return s;
}

// A number in a message meant for reading: six significant digits, as an
// ostream prints it by default ("0.001", "3.16228e+04").
inline std::string short_number(double x) { return format_number(x, 6); }

// The entries of a vector (anything with size() and [i]: Eigen, std::vector)
// with `digits` significant digits, joined by ", ": "1, 0.5, -2".
template <class V>
std::string number_list(const V& v, int digits) {
  std::string s;
  for (decltype(v.size()) i = 0; i < v.size(); ++i) {
    if (i) s += ", ";
    append_number(s, static_cast<double>(v[i]), digits);
  }
  return s;
}

// One part of a message: a string as it is, a character as itself, a bool
// as "true" / "false", an integer in full, a floating-point number by
// short_number (so numbers read as an ostream prints them by default).
inline std::string to_text(std::string_view s) { return std::string(s); }
inline std::string to_text(const char* s) { return s; }  // not the bool overload
inline std::string to_text(char c) { return std::string(1, c); }
inline std::string to_text(bool b) { return b ? "true" : "false"; }
template <class T>
requires(std::is_integral_v<T> && !std::is_same_v<T, bool> && !std::is_same_v<T, char>) std::string
    to_text(T i) {
  return std::to_string(i);
}
template <class T>
requires std::is_floating_point_v<T> std::string to_text(T x) {
  return short_number(static_cast<double>(x));
}

// A message from its parts, each by to_text:
//   text("M(", i, ",", j, ") = ", M(i, j), " is not finite")
// Built only where it is needed (no ostream on a path that runs per step).
template <class... T>
std::string text(const T&... parts) {
  std::string s;
  ((s += to_text(parts)), ...);
  return s;
}

}  // namespace lcsim
