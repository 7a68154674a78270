#pragma once
// Counts and sizes that come from flags and files, checked before they are used: whole
// numbers with their range in the message, and counts whose memory the machine must
// hold (core/option_checks.h has the plain bounds of option fields).

#include <string>

namespace handlabel {

// `text` (a flag's or a file's text) as a whole integer in [lo, hi]. Anything else, a
// number too large for any integer type included, throws InputError(source, field,
// "<what> in [lo, hi]", text): "expected an integer" alone did not say that a huge
// value was the problem.
long long ParseIntegerInRange(const std::string& text, const std::string& source,
                              const std::string& field, const std::string& what,
                              long long lo, long long hi);

// This machine's physical memory in bytes (0 if unknown).
double PhysicalMemoryBytes();

// Refuses, before anything is allocated, `count` items of `bytes_each` bytes that would
// take more than half of the machine's memory: InputError(source, field, "at most N
// <what> (B bytes each, M GB of memory)", count). A huge count otherwise ended in a bare
// std::bad_alloc.
void RequireFitsInMemory(const std::string& source, const std::string& field,
                         double count, double bytes_each, const std::string& what);

}  // namespace handlabel
