#include "core/size_checks.h"

#include <unistd.h>

#include <charconv>
#include <cmath>
#include <cstdio>
#include <system_error>

#include "core/errors.h"
#include "core/option_checks.h"

namespace handlabel {

long long ParseIntegerInRange(const std::string& text, const std::string& source,
                              const std::string& field, const std::string& what,
                              long long lo, long long hi) {
  long long value = 0;
  const char* end = text.data() + text.size();
  const std::from_chars_result r = std::from_chars(text.data(), end, value);
  if (text.empty() || r.ec != std::errc() || r.ptr != end || value < lo || value > hi) {
    throw InputError(
        source, field,
        what + " in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]", text);
  }
  return value;
}

double PhysicalMemoryBytes() {
  const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
  return pages > 0 && page > 0 ? static_cast<double>(pages) * page : 0.0;
}

void RequireFitsInMemory(const std::string& source, const std::string& field,
                         double count, double bytes_each, const std::string& what) {
  const double memory = PhysicalMemoryBytes();
  if (memory <= 0 || bytes_each <= 0) return;
  const double most = std::floor(0.5 * memory / bytes_each);
  if (!(count > most)) return;
  char detail[160];
  std::snprintf(detail, sizeof(detail),
                "at most %.0f %s (%.0f bytes each; half of %.1f GB of memory)", most,
                what.c_str(), bytes_each, memory / 1e9);
  throw InputError(source, field, detail, OptionValueText(count));
}

}  // namespace handlabel
