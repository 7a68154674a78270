#pragma once
// Writes a dict of named numpy arrays as a Python pickle in the form Python 3's
// `pickle.dump(d, f, protocol=2)` writes for such a dict: keys as unicode strings,
// arrays through numpy.core.multiarray._reconstruct with their bytes as
// `_codecs.encode(text, 'latin1')`. Protocol 2 is the newest that Python 2 still
// reads, and this form loads in Python 3 with any `encoding=` (HO3D's loader passes
// 'latin1'), in numpy 1.x and 2.x, and in formats/pickle_reader.h.

#include <string>

#include "formats/npz.h"  // NamedArrays

namespace handlabel {

// The pickle's bytes. Numeric arrays only (bool, integers, float32/64); throws Error
// naming the array for another dtype.
std::string PickleArrayDict(const NamedArrays& arrays);

}  // namespace handlabel
