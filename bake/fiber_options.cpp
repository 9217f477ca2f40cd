#include "fiber_options.h"

#include <fstream>
#include <sstream>

namespace hairis::cli {

void FiberOptions::add_to(CLI::App &cmd, const std::string &default_preset) {
    preset = default_preset;
    cmd.add_option("--preset", preset,
                   "fiber preset: blonde, brunette (Marschner 2003, the seed's), cycles-default "
                   "(Chiang 2016 with the Principled Hair BSDF node's defaults) or cycles-default-huang "
                   "(Huang 2022 with the node's defaults)")
        ->check(CLI::IsMember(fiber_preset_names()))
        ->capture_default_str();
    cmd.add_option("--param-file", param_file,
                   "a parameter file of key = value lines applied over the preset "
                   "(keys: model, parametrization, color, melanin, melanin_redness, tint, absorption, "
                   "roughness, radial_roughness, coat, ior, offset_deg, random_color, random_roughness, "
                   "random; Huang also: aspect_ratio, reflection, transmission, secondary_reflection; "
                   "Marschner: eta, sigma_a, alpha_r_deg, alpha_tt_deg, alpha_trt_deg, beta_r_deg, "
                   "beta_tt_deg, beta_trt_deg, eccentricity, glint_scale, caustic_width_deg, caustic_fade, "
                   "caustic_limit)")
        ->check(CLI::ExistingFile);
    cmd.add_option("--set", settings, "one parameter as key=value, applied last; repeatable (same keys)");
}

Expected<FiberSpec> FiberOptions::resolve() const {
    Expected<FiberSpec> spec = FiberSpec::preset(preset);
    if (!spec) return spec;
    if (!param_file.empty()) {
        std::ifstream file(param_file);
        if (!file) return Error{"cannot read the parameter file \"" + param_file + "\""};
        std::stringstream text;
        text << file.rdbuf();
        Expected<FiberSpec> parsed = parse_fiber_spec(text.str(), spec.value());
        if (!parsed) return Error{param_file + ": " + parsed.error().message};
        spec = parsed;
    }
    for (const std::string &s : settings) {
        const size_t eq = s.find('=');
        if (eq == std::string::npos) return Error{"--set takes key=value (got \"" + s + "\")"};
        if (Status st = spec.value().set(s.substr(0, eq), s.substr(eq + 1)))
            return Error{"--set " + s + ": " + st->message};
    }
    return spec;
}

}  // namespace hairis::cli
