// The core layer's homes (issue #25, item 5): number formatting gives the
// same text as the helpers it replaced (an ostream at precision 6, printf's
// %.17g, std::to_chars' shortest form), the outcome type's defaults, and the
// registry's one mechanism.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <lcsim/core/format.hpp>
#include <lcsim/core/outcome.hpp>
#include <lcsim/core/registry.hpp>
#include <limits>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

namespace lcsim {
namespace {

// Values whose text is easy to get wrong: signed zeros, the ends of the range,
// subnormals, ties of rounding at 6 digits, the switch between fixed and
// exponent notation (1e-5 / 1e-4, 1e5 / 1e6 at 6 digits), non-finite ones;
// then random doubles over the whole exponent range.
std::vector<double> samples() {
  constexpr double inf = std::numeric_limits<double>::infinity();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::vector<double> v = {0.0,
                           -0.0,
                           1.0,
                           -1.0,
                           0.1,
                           1.0 / 3.0,
                           2.5e-7,
                           1e-5,
                           9.99999e-5,
                           1e-4,
                           0.5,
                           123456.5,
                           999999.5,
                           1e6,
                           1234567.0,
                           1e300,
                           -1e-300,
                           std::numeric_limits<double>::max(),
                           std::numeric_limits<double>::min(),
                           std::numeric_limits<double>::denorm_min(),
                           inf,
                           -inf,
                           nan,
                           -nan};
  std::mt19937_64 rng(25);
  std::uniform_int_distribution<std::uint64_t> bits;
  for (int i = 0; i < 20000; ++i) {
    const std::uint64_t b = bits(rng);
    double x;
    std::memcpy(&x, &b, sizeof x);
    if (std::isfinite(x)) v.push_back(x);
  }
  std::uniform_real_distribution<double> unit(-10.0, 10.0);
  for (int i = 0; i < 20000; ++i) v.push_back(unit(rng));  // the numbers messages usually show
  return v;
}

std::string ostream_text(double x) {  // what sim::short_number printed before
  std::ostringstream s;
  s.precision(6);
  s << x;
  return s.str();
}

std::string printf_text(const char* format, double x) {  // the %.6g / %.17g helpers
  char buf[64];
  std::snprintf(buf, sizeof buf, format, x);
  return buf;
}

TEST(Format, SixDigitsIsTheOstreamAndPrintfText) {
  for (const double x : samples()) {
    ASSERT_EQ(short_number(x), ostream_text(x)) << printf_text("%a", x);
    ASSERT_EQ(format_number(x, 6), printf_text("%.6g", x)) << printf_text("%a", x);
  }
}

TEST(Format, SeventeenDigitsIsPrintfsAndReadsBack) {
  for (const double x : samples()) {
    std::string s = "a,";
    append_number(s, x, 17);
    ASSERT_EQ(s, "a," + printf_text("%.17g", x)) << printf_text("%a", x);
    if (std::isfinite(x)) {
      ASSERT_EQ(std::strtod(s.c_str() + 2, nullptr), x);
    }
  }
  EXPECT_EQ(format_number(0.1, 17), "0.10000000000000001");
  EXPECT_EQ(format_number(1.0 / 3.0, 3), "0.333");
}

TEST(Format, ShortestReadsBack) {
  EXPECT_EQ(format_number(2.0), "2");
  EXPECT_EQ(format_number(0.1), "0.1");
  EXPECT_EQ(format_number(-1e-300), "-1e-300");
  EXPECT_EQ(format_number(std::numeric_limits<double>::infinity()), "inf");
  for (const double x : samples())
    if (std::isfinite(x)) {
      ASSERT_EQ(std::strtod(format_number(x).c_str(), nullptr), x);
    }
}

TEST(Format, TextIsTheOstreamTextOfItsParts) {
  const long i = 3;
  const int j = -12;
  const double x = 2.0 / 3.0, y = 1e-7;
  const std::string s = "q";
  std::ostringstream os;
  os << "M(" << i << "," << j << ") = " << x << ", " << s << ' ' << y << " " << 17u;
  EXPECT_EQ(text("M(", i, ",", j, ") = ", x, ", ", s, ' ', y, " ", 17u), os.str());
  EXPECT_EQ(os.str(), "M(3,-12) = 0.666667, q 1e-07 17");  // independent of both
  // A bool reads as a word (an ostream would print 1), and a C string is
  // text, not the bool its pointer converts to.
  EXPECT_EQ(text(true, " ", false, " ", "abc"), "true false abc");
}

struct Solved : Outcome {
  int n = 0;
};
struct Failing : OutcomeStartingAs<Status::kNumericalFailure> {
  int n = 0;
};

TEST(Outcome, DefaultsAndAggregates) {
  static_assert(std::is_aggregate_v<Solved> && std::is_aggregate_v<Failing>);
  const Solved a;
  EXPECT_TRUE(a.ok());
  EXPECT_EQ(a.status, Status::kOk);
  const Failing b{};
  EXPECT_FALSE(b.ok());
  EXPECT_EQ(b.status, Status::kNumericalFailure);
  EXPECT_EQ(b.message, "");
  Failing c;
  c.status = Status::kOk;
  const Outcome& o = c;  // every result reports through the one type
  EXPECT_TRUE(o.ok());
}

struct Method {
  virtual ~Method() = default;
  virtual int id() const = 0;
};
struct One : Method {
  int id() const override { return 1; }
};
int fills = 0;
Registry<Method>& methods() {
  return Registry<Method>::instance("method", [](Registry<Method>& r) {
    ++fills;
    r.add("one", [] { return std::make_unique<One>(); });
    r.add_alias("uno", "one", "'uno' is 'one'");
  });
}

TEST(Registry, OneInstanceFilledOnceAndMakeOrThrow) {
  Registry<Method>& r = methods();
  EXPECT_EQ(&r, &methods());
  EXPECT_EQ(fills, 1);
  EXPECT_EQ(r.kind(), "method");
  EXPECT_EQ(r.make_or_throw("uno")->id(), 1);
  try {
    r.make_or_throw("two", "two is elsewhere");
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "unknown method 'two' (known: one; alias uno); two is elsewhere");
  }
}

}  // namespace
}  // namespace lcsim
