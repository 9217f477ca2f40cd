// The Principled Hair BSDF node's inputs that may vary from strand to strand and along a
// strand (what an artist links to Hair Info, attributes or a node chain): their names, sizes
// and ranges, and the values of some of them at one hit.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>

#include "core/expected.h"
#include "fiber/principled_hair.h"

namespace hairis {

/// A node input, in the order the C API lists them (hairis_defaults("curve_inputs")).
enum class HairInput : std::uint8_t {
    Color,
    Melanin,
    MelaninRedness,
    Tint,
    Absorption,
    Roughness,
    RadialRoughness,
    Coat,
    Ior,
    Offset,
    RandomColor,
    RandomRoughness,
    Random,
};
inline constexpr int kHairInputCount = 13;
/// Floats of every input together (three per colour).
inline constexpr int kHairInputSlots = 19;

struct HairInputInfo {
    const char *name;  ///< the C API's name (hairis_fiber_create's option of the same input)
    int components;    ///< 3 for the colours, else 1
    int slot;          ///< its first float in HairInputValues::value
};

/// The input's name, size and slot.
const HairInputInfo &hair_input_info(HairInput input);
/// The input called `name` (C API names), or nullopt.
std::optional<HairInput> hair_input_named(const std::string &name);
/// Whether the node reads `input` under `parametrization` (Blender hides the others): colour
/// for Direct Coloring; melanin, melanin redness, tint and random colour for Melanin
/// Concentration; absorption for Absorption Coefficient; the rest always.
bool reads(HairParametrization parametrization, HairInput input);
/// Refuses a value outside the input's range as to_chiang_params checks it (colour and tint
/// > 0, absorption >= 0, ior > 1, offset in [−π/2, π/2], the others in [0, 1]; every
/// component finite); the message starts with `what`. Each range is an interval, so values
/// interpolated between accepted ones are accepted.
Status check_hair_input(HairInput input, const float *components, const std::string &what);

/// Values of some inputs at one hit; the others are the material's. Trivially destructible.
struct HairInputValues {
    std::uint32_t given = 0;  ///< bit i: HairInput(i) has a value
    std::array<float, kHairInputSlots> value{};

    bool has(HairInput input) const { return (given >> unsigned(input)) & 1u; }
    const float *get(HairInput input) const { return value.data() + hair_input_info(input).slot; }
    void set(HairInput input, const float *components);
};

/// `node` with the given inputs in place of its own.
PrincipledHairNode with_inputs(PrincipledHairNode node, const HairInputValues &values);

/// What a shading model whose inputs may vary per strand (it reads FiberHit::inputs) says
/// about them: the scene refuses curve inputs for any other model, and inputs this one does
/// not read.
class StrandInputReader {
  public:
    virtual ~StrandInputReader() = default;
    /// Whether the model's f depends on `input` (e.g. not on Melanin under Direct Coloring).
    virtual bool reads_input(HairInput input) const = 0;
};

}  // namespace hairis
