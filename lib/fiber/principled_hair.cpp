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

// The closure's σ_a under the node's parametrization; `colour_roughness` is the randomized,
// unclamped roughness the colour inversion uses (Chiang: Radial Roughness, Huang: Roughness).
Expected<Rgb> absorption(const PrincipledHairNode &node, double colour_roughness) {
    switch (node.parametrization) {
        case HairParametrization::AbsorptionCoefficient:
            if (Status error = non_negative_colour("absorption_coefficient", node.absorption_coefficient)) {
                return *error;
            }
            return node.absorption_coefficient;
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
            return principled_hair::sigma_from_concentration(eumelanin, pheomelanin) +
                   principled_hair::sigma_from_reflectance(node.tint, colour_roughness);
        }
        case HairParametrization::Color:
            if (Status error = positive_colour("color", node.color)) return *error;
            return principled_hair::sigma_from_reflectance(node.color, colour_roughness);
    }
    return Error{"parametrization must be AbsorptionCoefficient, Melanin or Color"};
}

// Random factor range [1 − r, 1 + r]: the per-strand value in [0, 1] recentred.
double roughness_factor(const PrincipledHairNode &node) {
    return 1.0 + 2.0 * (double(node.random) - 0.5) * node.random_roughness;
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

    const double factor = roughness_factor(node);
    const double roughness = node.roughness * factor;
    const double radial_roughness = node.radial_roughness * factor;

    ChiangParams params;
    // Cycles clamps these to [0.001, 1] in the closure setup; ChiangFiber does the same.
    params.roughness = float(std::clamp(roughness, 0.0, 1.0));
    params.radial_roughness = float(std::clamp(radial_roughness, 0.0, 1.0));
    params.coat = node.coat;
    params.ior = node.ior;
    params.offset = node.offset;
    params.tilt = node.tilt;
    // The tint and the colour use the randomized, unclamped radial roughness, as Cycles does.
    Expected<Rgb> sigma = absorption(node, radial_roughness);
    if (!sigma) return sigma.error();
    params.sigma_a = sigma.value();
    return params;
}

Expected<HuangParams> to_huang_params(const PrincipledHairNode &node) {
    const double max_offset = double(float(kHalfPi));
    if (Status error = first_error(
            check::in_range("roughness", node.roughness, 0.0, 1.0),
            check::greater_than("ior", node.ior, 1.0),
            check::in_range("offset", node.offset, -max_offset, max_offset),
            check::in_range("random_roughness", node.random_roughness, 0.0, 1.0),
            check::in_range("random", node.random, 0.0, 1.0),
            check::finite("aspect_ratio", node.aspect_ratio),
            check::finite("reflection", node.reflection),
            check::finite("transmission", node.transmission),
            check::finite("secondary_reflection", node.secondary_reflection))) {
        return *error;
    }
    if (!(node.aspect_ratio > 0.0f && node.aspect_ratio <= 1000.0f))
        return Error{"aspect_ratio must be in (0, 1000] (got " + std::to_string(node.aspect_ratio) +
                     "); values above 1 are rendered as their inverse, as Cycles does"};
    if (!(node.reflection > 0.0f || node.transmission > 0.0f || node.secondary_reflection > 0.0f))
        return Error{"reflection, transmission and secondary_reflection are all <= 0: Cycles allocates no "
                     "closure then (the strands neither scatter nor let light through); at least one must be > 0"};

    const double roughness = node.roughness * roughness_factor(node);
    HuangParams params;
    params.roughness = float(std::clamp(roughness, 0.0, 1.0));
    params.ior = node.ior;
    params.offset = node.offset;
    params.aspect_ratio = node.aspect_ratio;
    params.reflection = std::max(0.0f, node.reflection);
    params.transmission = std::max(0.0f, node.transmission);
    params.secondary_reflection = std::max(0.0f, node.secondary_reflection);
    // Huang inverts the colour with the randomized, unclamped Roughness.
    Expected<Rgb> sigma = absorption(node, roughness);
    if (!sigma) return sigma.error();
    params.sigma_a = sigma.value();
    return params;
}

}  // namespace hairis
