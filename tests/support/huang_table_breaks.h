// Test helper: the χ² quadrature breaks of a Huang table's density at one view. The density is
// piecewise constant on the table's cells, so each χ² cell's quadrature is split at the cell
// edges, mapped into the renderer's frame (θ_i edges through each θ_o node's warp).
#pragma once

#include <cmath>

#include "chi2.h"
#include "core/frame.h"
#include "fiber/huang.h"
#include "sampling/huang_table.h"

namespace hairis::testing {

inline void add_huang_table_breaks(Chi2Options &options, const HuangTable &table, const HuangTableQuery &q,
                                   const HuangPoint &point) {
    for (const ThetaWarp &w : q.warp)
        for (int k = 0; k <= table.theta_i_count(); ++k)
            options.theta_breaks.push_back(w.from_node(-kHalfPi + kPi * k / table.theta_i_count()));
    options.theta_breaks.push_back(q.warp[0].anchor);
    for (int k = 0; k <= table.phi_count(); ++k) {
        const double a = std::atan2(q.sin_phi_o, q.cos_phi_o) - kPi + kTwoPi * k / table.phi_count();
        options.phi_breaks.push_back(
            angles_of(point.from_huang({0.0f, q.sign_y * float(std::cos(a)), q.sign_z * float(std::sin(a))})).phi);
    }
}

}  // namespace hairis::testing
