#pragma once
// Shared by the libFuzzer harnesses of tests/fuzz (docs/fuzzing.md): decoding bytes into
// numbers and a failure report that aborts (libFuzzer then
// saves the input as a crash-* file).

#include <fuzzer/FuzzedDataProvider.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>

namespace hqp::fuzz {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

[[noreturn]] inline void fail(const char* what, double a = 0.0, double b = 0.0) {
  std::fprintf(stderr, "FUZZ FINDING: %s (%.17g, %.17g)\n", what, a, b);
  std::abort();
}
#define HQP_FUZZ_CHECK(cond)                   \
  do {                                         \
    if (!(cond)) ::hqp::fuzz::fail(#cond);     \
  } while (0)
#define HQP_FUZZ_CHECK2(cond, a, b)              \
  do {                                           \
    if (!(cond)) ::hqp::fuzz::fail(#cond, a, b); \
  } while (0)

// A number from the input: mostly exact binary fractions in [-16, 16) (degenerate data:
// equal rows, exact zeros, ties), some real numbers over a few decades, and, when
// `special` is set, ±inf and NaN.
inline double number(FuzzedDataProvider& in, bool special = false, bool infinities_only = false) {
  const int kind = in.ConsumeIntegralInRange<int>(0, 15);
  if (kind < 9) return in.ConsumeIntegralInRange<int>(-128, 127) / 8.0;
  if (kind < 12) return in.ConsumeFloatingPointInRange<double>(-10.0, 10.0);
  if (kind < 14) {
    const double m = in.ConsumeFloatingPointInRange<double>(-1.0, 1.0);
    return m * std::pow(10.0, in.ConsumeIntegralInRange<int>(-4, 4));
  }
  if (kind == 14 || !special) return 0.0;
  switch (in.ConsumeIntegralInRange<int>(0, infinities_only ? 1 : 2)) {
    case 0: return kInf;
    case 1: return -kInf;
    default: return kNaN;
  }
}

}  // namespace hqp::fuzz
