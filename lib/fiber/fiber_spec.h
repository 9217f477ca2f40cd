// A fiber described by its model and parameters, as the CLI, the C API and table metadata
// see it: built from presets, key = value text or code, turned into a FiberModel.
#pragma once

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "fiber/chiang.h"
#include "fiber/huang.h"
#include "core/expected.h"
#include "fiber/marschner.h"
#include "fiber/principled_hair.h"

namespace hairis {

enum class FiberKind { Chiang, Marschner, Huang };

/// A fiber model and its parameters. For Chiang and Huang the Principled Hair node's inputs
/// are kept (so every parametrization is available); they map to ChiangParams or HuangParams
/// as Cycles does.
struct FiberSpec {
    FiberKind kind = FiberKind::Chiang;
    PrincipledHairNode node;    ///< kind == Chiang or Huang
    MarschnerParams marschner;  ///< kind == Marschner

    /// "blonde", "brunette" (Marschner, the seed's presets), "cycles-default" (Chiang, the
    /// Principled Hair BSDF node's defaults) or "cycles-default-huang" (the node's defaults
    /// with the Huang model).
    static Expected<FiberSpec> preset(const std::string &name);

    /// Applies one `key = value` setting (see parse_fiber_spec for the keys).
    Status set(const std::string &key, const std::string &value);

    /// Every key of the spec's model with its value, as "key=value;..." that set() reads back.
    std::string options() const;
    /// The model, validated; a Huang fiber evaluates its far field with `huang_rule`.
    Expected<std::unique_ptr<FiberModel>> create_model(const HuangQuadrature &huang_rule = {}) const;

    /// The parameters that determine the model's scattering, as name/value pairs in a fixed
    /// order (Chiang and Huang: the mapped closure parameters, so two nodes that scatter alike
    /// match).
    Expected<std::vector<std::pair<std::string, double>>> parameters() const;
};

/// The parameters of a Chiang fiber that determine its scattering, in a fixed order (what
/// table metadata records and a table's match with a fiber compares).
std::vector<std::pair<std::string, double>> chiang_parameters(const ChiangParams &params);

/// The parameters of a Huang fiber that determine its scattering, in HuangParams' order.
std::vector<std::pair<std::string, double>> huang_fiber_parameters(const HuangParams &params);

/// The preset names.
const std::vector<std::string> &fiber_preset_names();

/// Parses a small parameter file: one `key = value` per line, `#` starts a comment.
/// Keys: `preset`, `model` (chiang | huang | marschner); Chiang: `cycles` (the Blender version
/// whose Cycles evaluates it, 3.4 by default: 4.2 and later tilt θ_o), `parametrization`
/// (absorption | melanin | color), `color`, `melanin`, `melanin_redness`, `tint`,
/// `absorption`, `roughness`, `radial_roughness`, `coat`, `ior`, `offset_deg`,
/// `random_color`, `random_roughness`, `random`; Huang (as Cycles 4.5 and 5.0 evaluate it):
/// the same without `cycles`, `radial_roughness` and `coat`, plus `aspect_ratio`,
/// `reflection`, `transmission`, `secondary_reflection`; Marschner: `eta`, `sigma_a`, `alpha_r_deg`, `alpha_tt_deg`,
/// `alpha_trt_deg`, `beta_r_deg`, `beta_tt_deg`, `beta_trt_deg`, `eccentricity`,
/// `glint_scale`, `caustic_width_deg`, `caustic_fade`, `caustic_limit`. Colours are three
/// numbers separated by spaces or commas. Errors name the line and the key.
Expected<FiberSpec> parse_fiber_spec(const std::string &text, FiberSpec start = {});

}  // namespace hairis
