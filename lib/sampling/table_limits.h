// Limits on sampling tables, checked before anything is allocated: a file's header, a bake's
// options or a caller's arrays can claim any size.
#pragma once

#include <string>

#include "core/expected.h"

namespace hairis {

inline constexpr int kMaxThetaRNodes = 1024;
inline constexpr int kMaxTableAxisCells = 4096;
inline constexpr long long kMaxTableCells = 64ll * 1024 * 1024;
/// Strand counts one multiple-scattering table may hold.
inline constexpr int kMaxStrandCounts = 64;
/// The most memory one sampling table may allocate (its copy of the values plus CDFs and guides).
inline constexpr long long kMaxSamplingTableBytes = 1ll << 30;

/// The resolution of a baked table set: θ_r nodes × θ_i cells × φ cells.
struct TableResolution {
    int theta_r_count = 0;
    int theta_i_count = 0;
    int phi_count = 0;

    long long cells() const { return (long long)theta_r_count * theta_i_count * phi_count; }
    /// Each axis in range and the product at most kMaxTableCells; names what is out of range.
    Status validate() const {
        if (Status s = first_error(check::count_in_range("theta_r_count", theta_r_count, 1, kMaxThetaRNodes),
                                   check::count_in_range("theta_i_count", theta_i_count, 2, kMaxTableAxisCells),
                                   check::count_in_range("phi_count", phi_count, 1, kMaxTableAxisCells)))
            return s;
        if (cells() > kMaxTableCells)
            return Error{"theta_r_count x theta_i_count x phi_count = " + std::to_string(cells()) + " cells; at most " +
                         std::to_string(kMaxTableCells) + " are allowed"};
        return std::nullopt;
    }
};

/// The image of a table file (table_file.h): as wide as its widest part, as tall as all of
/// them; at most kMaxTableAxisCells + 1 columns (a near part's cells and their upper edge) and
/// kMaxTableCells pixels.
struct TableImageSize {
    long long width = 0;
    long long height = 0;

    Status validate() const {
        constexpr long long kMaxWidth = kMaxTableAxisCells + 1;
        if (width > kMaxWidth || width * height > kMaxTableCells)
            return Error{"the image would be " + std::to_string(width) + "x" + std::to_string(height) +
                         " pixels; a table file holds at most " + std::to_string(kMaxWidth) + " columns and " +
                         std::to_string(kMaxTableCells) + " pixels (bake fewer cells)"};
        return std::nullopt;
    }
};

}  // namespace hairis
