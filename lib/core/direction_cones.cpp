#include "core/direction_cones.h"

#include <algorithm>
#include <cmath>

namespace hairis {

namespace {

// Far above the rounding of a dot product of near-unit vectors, far below any angle that
// matters: a cone this close to the threshold is tested member by member.
constexpr double kMargin = 1e-9;

}  // namespace

DirectionCones::DirectionCones(const std::vector<Vec3d> &directions, int bands) {
    bands = std::max(1, bands);
    const int sectors = 2 * bands;
    auto cell_of = [&](Vec3d d) {
        if (!(std::isfinite(d.x) && std::isfinite(d.y) && std::isfinite(d.z))) return 0;
        const int band = std::clamp(int((std::clamp(d.z, -1.0, 1.0) + 1.0) * 0.5 * bands), 0, bands - 1);
        const double longitude = std::atan2(d.y, d.x);  // (−π, π]
        const int sector = std::clamp(int((longitude + kPi) / kTwoPi * sectors), 0, sectors - 1);
        return band * sectors + sector;
    };
    // A counting sort by cell keeps the input order within a cell.
    const std::size_t cells = std::size_t(bands) * std::size_t(sectors);
    std::vector<std::uint32_t> cell(directions.size()), start(cells + 1, 0);
    for (std::size_t k = 0; k < directions.size(); ++k) {
        cell[k] = std::uint32_t(cell_of(directions[k]));
        ++start[cell[k] + 1];
    }
    for (std::size_t c = 0; c < cells; ++c) start[c + 1] += start[c];
    order_.resize(directions.size());
    std::vector<std::uint32_t> next(start.begin(), start.end() - 1);
    for (std::size_t k = 0; k < directions.size(); ++k) order_[next[cell[k]]++] = std::uint32_t(k);

    for (std::size_t c = 0; c < cells; ++c) {
        if (start[c] == start[c + 1]) continue;
        Cone cone;
        cone.begin = start[c];
        cone.end = start[c + 1];
        Vec3d sum;
        for (std::uint32_t k = cone.begin; k < cone.end; ++k) sum = sum + directions[order_[k]];
        const double len = length(sum);
        cone.axis = len > 0.0 ? sum / len : directions[order_[cone.begin]];
        double cos_radius = 1.0;
        for (std::uint32_t k = cone.begin; k < cone.end; ++k) {
            const double cos_member = dot(directions[order_[k]], cone.axis);
            if (!std::isfinite(cos_member)) cone.decidable = false;
            cos_radius = std::min(cos_radius, cos_member);
        }
        cone.cos_radius = std::clamp(cos_radius - kMargin, -1.0, 1.0);
        cone.sin_radius = std::sqrt(1.0 - cone.cos_radius * cone.cos_radius);
        cones_.push_back(cone);
    }
}

DirectionCones::Threshold::Threshold(Vec3d l, double c) : l_(l), c_(c), len_(length(l)) {
    usable_ = len_ > 0.0 && std::isfinite(len_);
    // The margin scales with |l|, as the rounding of dot(d, l) does.
    margin_ = kMargin * std::max(1.0, len_);
}

}  // namespace hairis
