#pragma once
// One-line range checks for option fields, in the manner of Ceres' OPTION_GT: each
// throws InputError(source, field, expected, got) with the offending value in `got`,
// so every option struct reports a bad field in the same words. NaN fails every check:
// the comparisons are written as !(value OP bound), where a plain `if (value < 0)`
// would let NaN through. Rules that are not a plain bound (cross-field rules, lists of
// names) stay written out as `throw InputError(...)`.
//
//   void PckOptions::Check(const std::string& source) const {
//     RequireAtLeast(source, "min_threshold", min_threshold, 0);
//     RequireAtLeast(source, "steps", steps, 2);
//   }
//
// `expected` is generated from the bound ("> 0", ">= 2", "0..45"); pass it only when the
// bare rule would not tell the user enough (units, what 0 means).

#include <string>
#include <type_traits>

#include "core/errors.h"

namespace handlabel {

namespace option_checks_internal {

std::string FloatText(double value);

// Integers and floating point only: a bool or a char as a number is a slip.
template <typename T>
constexpr bool kIsNumber =
    std::is_arithmetic_v<T> && !std::is_same_v<T, bool> && !std::is_same_v<T, char>;

}  // namespace option_checks_internal

// A value as `got` shows it: integers as written, floating point in the shortest form
// that reads back as the same double ("0.25", "1e-06", "nan").
template <typename T>
std::string OptionValueText(T value) {
  static_assert(option_checks_internal::kIsNumber<T>, "an option value is a number");
  if constexpr (std::is_integral_v<T>) {
    return std::to_string(value);
  } else {
    return option_checks_internal::FloatText(static_cast<double>(value));
  }
}

// value > bound.
template <typename T, typename B>
void RequireGreater(const std::string& source, const std::string& field, T value, B bound,
                    const std::string& expected = "") {
  static_assert(option_checks_internal::kIsNumber<B>, "a bound is a number");
  if (!(value > bound)) {
    throw InputError(source, field,
                     expected.empty() ? "> " + OptionValueText(bound) : expected,
                     OptionValueText(value));
  }
}

// value >= bound.
template <typename T, typename B>
void RequireAtLeast(const std::string& source, const std::string& field, T value, B bound,
                    const std::string& expected = "") {
  static_assert(option_checks_internal::kIsNumber<B>, "a bound is a number");
  if (!(value >= bound)) {
    throw InputError(source, field,
                     expected.empty() ? ">= " + OptionValueText(bound) : expected,
                     OptionValueText(value));
  }
}

// value <= bound.
template <typename T, typename B>
void RequireAtMost(const std::string& source, const std::string& field, T value, B bound,
                   const std::string& expected = "") {
  static_assert(option_checks_internal::kIsNumber<B>, "a bound is a number");
  if (!(value <= bound)) {
    throw InputError(source, field,
                     expected.empty() ? "<= " + OptionValueText(bound) : expected,
                     OptionValueText(value));
  }
}

// lo <= value <= hi (closed at both ends).
template <typename T, typename L, typename H>
void RequireInRange(const std::string& source, const std::string& field, T value, L lo,
                    H hi, const std::string& expected = "") {
  static_assert(
      option_checks_internal::kIsNumber<L> && option_checks_internal::kIsNumber<H>,
      "bounds are numbers");
  if (!(value >= lo && value <= hi)) {
    throw InputError(
        source, field,
        expected.empty() ? OptionValueText(lo) + ".." + OptionValueText(hi) : expected,
        OptionValueText(value));
  }
}

}  // namespace handlabel
