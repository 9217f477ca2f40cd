// Writes float arrays as NumPy .npy files (format 1.0) for the plotting script.
#pragma once

#include <string>
#include <vector>

#include "core/expected.h"

namespace hairis::cli {

/// Writes `values` (row-major, C order) with the given shape as little-endian float32.
Status write_npy(const std::string &path, const std::vector<float> &values, const std::vector<size_t> &shape);

}  // namespace hairis::cli
