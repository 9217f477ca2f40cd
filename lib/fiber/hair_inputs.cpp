#include "fiber/hair_inputs.h"

#include <cmath>
#include <type_traits>

namespace hairis {

namespace {

constexpr HairInputInfo kInfo[kHairInputCount] = {
    {"color", 3, 0},           {"melanin", 1, 3},          {"melanin_redness", 1, 4},
    {"tint", 3, 5},            {"absorption", 3, 8},       {"roughness", 1, 11},
    {"radial_roughness", 1, 12}, {"coat", 1, 13},          {"ior", 1, 14},
    {"offset", 1, 15},         {"random_color", 1, 16},    {"random_roughness", 1, 17},
    {"random", 1, 18},
};
static_assert(kInfo[kHairInputCount - 1].slot + 1 == kHairInputSlots);

Rgb rgb(const float *v) { return {v[0], v[1], v[2]}; }

}  // namespace

const HairInputInfo &hair_input_info(HairInput input) { return kInfo[int(input)]; }

std::optional<HairInput> hair_input_named(const std::string &name) {
    for (int i = 0; i < kHairInputCount; ++i)
        if (name == kInfo[i].name) return HairInput(i);
    return std::nullopt;
}

bool reads(HairParametrization parametrization, HairInput input) {
    switch (input) {
        case HairInput::Color: return parametrization == HairParametrization::Color;
        case HairInput::Melanin:
        case HairInput::MelaninRedness:
        case HairInput::Tint:
        case HairInput::RandomColor: return parametrization == HairParametrization::Melanin;
        case HairInput::Absorption: return parametrization == HairParametrization::AbsorptionCoefficient;
        default: return true;
    }
}

Status check_hair_input(HairInput input, const float *v, const std::string &what) {
    const HairInputInfo &info = hair_input_info(input);
    const std::string name = what + info.name;
    switch (input) {
        case HairInput::Color:
        case HairInput::Tint:
        case HairInput::Absorption: {
            const char *suffix[3] = {".r", ".g", ".b"};
            for (int c = 0; c < 3; ++c) {
                const std::string component = name + suffix[c];
                const Status s = input == HairInput::Absorption
                                     ? check::non_negative(component.c_str(), v[c])
                                     : check::greater_than(component.c_str(), v[c], 0.0);
                if (s) return s;
            }
            return std::nullopt;
        }
        case HairInput::Ior: return check::greater_than(name.c_str(), v[0], 1.0);
        case HairInput::Offset: {
            const double max_offset = double(float(kHalfPi));
            return check::in_range(name.c_str(), v[0], -max_offset, max_offset);
        }
        default: return check::in_range(name.c_str(), v[0], 0.0, 1.0);
    }
}

void HairInputValues::set(HairInput input, const float *components) {
    const HairInputInfo &info = hair_input_info(input);
    for (int c = 0; c < info.components; ++c) value[std::size_t(info.slot + c)] = components[c];
    given |= 1u << unsigned(input);
}

PrincipledHairNode with_inputs(PrincipledHairNode node, const HairInputValues &values) {
    if (values.given == 0) return node;
    auto take = [&](HairInput input, auto &field) {
        if (!values.has(input)) return;
        if constexpr (std::is_same_v<std::decay_t<decltype(field)>, Rgb>)
            field = rgb(values.get(input));
        else
            field = *values.get(input);
    };
    take(HairInput::Color, node.color);
    take(HairInput::Melanin, node.melanin);
    take(HairInput::MelaninRedness, node.melanin_redness);
    take(HairInput::Tint, node.tint);
    take(HairInput::Absorption, node.absorption_coefficient);
    take(HairInput::Roughness, node.roughness);
    take(HairInput::RadialRoughness, node.radial_roughness);
    take(HairInput::Coat, node.coat);
    take(HairInput::Ior, node.ior);
    take(HairInput::Offset, node.offset);
    take(HairInput::RandomColor, node.random_color);
    take(HairInput::RandomRoughness, node.random_roughness);
    take(HairInput::Random, node.random);
    return node;
}

}  // namespace hairis
