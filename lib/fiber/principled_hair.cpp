#include "fiber/principled_hair.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

namespace hairis {

namespace principled_hair {

double albedo_roughness_scale(double radial_roughness) {
    const double x = radial_roughness;
    return (((((0.245 * x) + 5.574) * x - 10.73) * x + 2.532) * x - 0.215) * x + 5.969;
}

Rgb sigma_from_reflectance(Rgb color, double radial_roughness) {
    const double scale = albedo_roughness_scale(radial_roughness);
    auto channel = [&](float c) { return float(sqr(std::log(double(c)) / scale)); };
    return {channel(color.r), channel(color.g), channel(color.b)};
}

Rgb sigma_from_concentration(double eumelanin, double pheomelanin) {
    auto channel = [&](double eu, double pheo) { return float(eumelanin * eu + pheomelanin * pheo); };
    return {channel(0.506, 0.343), channel(0.841, 0.733), channel(1.653, 1.924)};
}

}  // namespace principled_hair

namespace {

// A colour fed through log(): zero would give infinite absorption and negatives NaN.
// Components above 1 are accepted and, as in Cycles, absorb like their reciprocals.
Status positive_colour(const std::string &name, Rgb c) {
    const char *suffix[3] = {".r", ".g", ".b"};
    for (int i = 0; i < 3; ++i) {
        if (!(std::isfinite(c[i]) && c[i] > 0.0f)) {
            std::ostringstream message;
            message.precision(9);
            message << name << suffix[i] << " must be finite and greater than 0 (got " << c[i]
                    << "); 0 would mean infinite absorption";
            return Error{message.str()};
        }
    }
    return std::nullopt;
}

Status non_negative_colour(const std::string &name, Rgb c) {
    const std::string names[3] = {name + ".r", name + ".g", name + ".b"};
    return first_error(check::non_negative(names[0].c_str(), c.r),
                       check::non_negative(names[1].c_str(), c.g),
                       check::non_negative(names[2].c_str(), c.b));
}

}  // namespace

Expected<ChiangParams> to_chiang_params(const PrincipledHairNode &node) {
    const double max_offset = double(float(kHalfPi));
    if (Status error = first_error(
            check::in_range("roughness", node.roughness, 0.0, 1.0),
            check::in_range("radial_roughness", node.radial_roughness, 0.0, 1.0),
            check::in_range("coat", node.coat, 0.0, 1.0),
            check::greater_than("ior", node.ior, 1.0),
            check::in_range("offset", node.offset, -max_offset, max_offset),
            check::in_range("random_roughness", node.random_roughness, 0.0, 1.0),
            check::in_range("random", node.random, 0.0, 1.0))) {
        return *error;
    }

    // Random factor range [1 − r, 1 + r]: the per-strand value in [0, 1] recentred.
    const double roughness_factor = 1.0 + 2.0 * (double(node.random) - 0.5) * node.random_roughness;
    const double roughness = node.roughness * roughness_factor;
    const double radial_roughness = node.radial_roughness * roughness_factor;

    ChiangParams params;
    // Cycles clamps these to [0.001, 1] in the closure setup; ChiangFiber does the same.
    params.roughness = float(std::clamp(roughness, 0.0, 1.0));
    params.radial_roughness = float(std::clamp(radial_roughness, 0.0, 1.0));
    params.coat = node.coat;
    params.ior = node.ior;
    params.offset = node.offset;
    params.tilt = node.tilt;

    switch (node.parametrization) {
        case HairParametrization::AbsorptionCoefficient: {
            if (Status error = non_negative_colour("absorption_coefficient", node.absorption_coefficient)) {
                return *error;
            }
            params.sigma_a = node.absorption_coefficient;
            break;
        }
        case HairParametrization::Melanin: {
            if (Status error = first_error(
                    check::in_range("melanin", node.melanin, 0.0, 1.0),
                    check::in_range("melanin_redness", node.melanin_redness, 0.0, 1.0),
                    check::in_range("random_color", node.random_color, 0.0, 1.0),
                    positive_colour("tint", node.tint))) {
                return *error;
            }
            const double color_factor = 1.0 + 2.0 * (double(node.random) - 0.5) * node.random_color;
            // The perceptually linear [0, 1] amount to a concentration in [0, ~9.2].
            const double melanin = -std::log(std::max(1.0 - node.melanin * color_factor, 1e-4));
            const double eumelanin = melanin * (1.0 - node.melanin_redness);
            const double pheomelanin = melanin * node.melanin_redness;
            // The tint uses the randomized, unclamped radial roughness, as Cycles does.
            params.sigma_a = principled_hair::sigma_from_concentration(eumelanin, pheomelanin) +
                             principled_hair::sigma_from_reflectance(node.tint, radial_roughness);
            break;
        }
        case HairParametrization::Color: {
            if (Status error = positive_colour("color", node.color)) return *error;
            params.sigma_a = principled_hair::sigma_from_reflectance(node.color, radial_roughness);
            break;
        }
        default:
            return Error{"parametrization must be AbsorptionCoefficient, Melanin or Color"};
    }
    return params;
}

}  // namespace hairis
