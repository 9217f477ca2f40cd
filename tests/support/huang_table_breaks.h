// Test helper: the χ² quadrature breaks of a Huang table's density at one view. The density is
// piecewise constant on the table's cells, so each χ² cell's quadrature is split at the cell
// edges, mapped into the renderer's frame (θ_i edges through each θ_o node's warp). Also the
// χ² test of a TABLE sampler of Huang hair at a renderer hit, with those breaks.
#pragma once

#include <cmath>

#include "chi2.h"
#include "core/scratch.h"
#include "huang_fixtures.h"
#include "core/frame.h"
#include "fiber/huang.h"
#include "sampling/huang_table.h"
#include "sampling/sampler.h"

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

/// The χ² test of TABLE sampler `s` of Huang hair, which samples `table`, at huang_hit(θ_o, ψ),
/// one of `test_count` tests of its family.
inline Chi2Result chi2_huang_table_sampler(const Sampler &s, const HuangTable &table, double theta_o_deg,
                                           double psi, int test_count) {
    const FiberHit hit = huang_hit(theta_o_deg, psi);
    ScratchBuffer scratch;
    const HuangPoint &point = static_cast<const HuangPoint &>(s.model()->prepare(hit, scratch));
    const SamplerPoint &at = s.at(hit, &point, scratch);
    Chi2Options options;
    options.test_count = test_count;
    add_huang_table_breaks(options, table, table.locate(point.to_huang(hit.wo)), point);
    return chi2_sampler_test(at, options);
}

}  // namespace hairis::testing
