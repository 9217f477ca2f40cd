#include "fiber/fiber_spec.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <sstream>

namespace hairis {

namespace {

Expected<double> parse_number(const std::string &key, const std::string &text) {
    const char *begin = text.c_str();
    char *end = nullptr;
    const double v = std::strtod(begin, &end);
    while (end && (*end == ' ' || *end == '\t')) ++end;
    if (end == begin || *end != '\0' || !std::isfinite(v))
        return Error{key + " must be a finite number (got \"" + text + "\")"};
    return v;
}

Expected<Rgb> parse_rgb(const std::string &key, std::string text) {
    for (char &c : text)
        if (c == ',') c = ' ';
    std::istringstream in(text);
    double v[3];
    std::string rest;
    if (!(in >> v[0] >> v[1] >> v[2]) || (in >> rest) || !std::isfinite(v[0]) || !std::isfinite(v[1]) ||
        !std::isfinite(v[2]))
        return Error{key + " must be three finite numbers \"r g b\" (got \"" + text + "\")"};
    return Rgb(float(v[0]), float(v[1]), float(v[2]));
}

std::string trim(const std::string &s) {
    const size_t a = s.find_first_not_of(" \t\r");
    if (a == std::string::npos) return "";
    return s.substr(a, s.find_last_not_of(" \t\r") - a + 1);
}

// Scalars: float fields of the node, double fields of Marschner; *_deg in degrees.
struct FloatKey {
    const char *name;
    float *field;
    bool degrees;
};
struct DoubleKey {
    const char *name;
    double *field;
    bool degrees;
};

// The node's scalar inputs a model reads (Chiang: Radial Roughness and Coat; Huang: Aspect
// Ratio and the lobe multipliers), in the order options() writes them.
std::vector<FloatKey> float_keys(FiberSpec &spec, FiberKind kind) {
    PrincipledHairNode &node = spec.node;
    std::vector<FloatKey> keys{{"melanin", &node.melanin, false}, {"melanin_redness", &node.melanin_redness, false},
                               {"roughness", &node.roughness, false}};
    if (kind == FiberKind::Chiang) keys.push_back({"radial_roughness", &node.radial_roughness, false});
    if (kind == FiberKind::Chiang) keys.push_back({"coat", &node.coat, false});
    keys.insert(keys.end(), {{"ior", &node.ior, false},
                             {"offset", &node.offset, false},
                             {"offset_deg", &node.offset, true},
                             {"random_color", &node.random_color, false},
                             {"random_roughness", &node.random_roughness, false},
                             {"random", &node.random, false}});
    if (kind == FiberKind::Huang)
        keys.insert(keys.end(), {{"aspect_ratio", &node.aspect_ratio, false},
                                 {"reflection", &node.reflection, false},
                                 {"transmission", &node.transmission, false},
                                 {"secondary_reflection", &node.secondary_reflection, false}});
    return keys;
}

// Every node key set() reads, whatever the model.
std::vector<FloatKey> all_node_keys(FiberSpec &spec) {
    std::vector<FloatKey> keys = float_keys(spec, FiberKind::Chiang);
    for (const FloatKey &k : float_keys(spec, FiberKind::Huang))
        if (std::none_of(keys.begin(), keys.end(), [&](const FloatKey &c) { return std::string(c.name) == k.name; }))
            keys.push_back(k);
    return keys;
}

std::vector<DoubleKey> double_keys(FiberSpec &spec) {
    MarschnerParams &m = spec.marschner;
    return {{"eta", &m.eta, false},          {"alpha_r_deg", &m.alpha_r, true},
            {"alpha_tt_deg", &m.alpha_tt, true}, {"alpha_trt_deg", &m.alpha_trt, true},
            {"beta_r_deg", &m.beta_r, true},  {"beta_tt_deg", &m.beta_tt, true},
            {"beta_trt_deg", &m.beta_trt, true}, {"eccentricity", &m.eccentricity, false},
            {"glint_scale", &m.glint_scale, false}, {"caustic_width_deg", &m.caustic_width, true},
            {"caustic_fade", &m.caustic_fade, false}, {"caustic_limit", &m.caustic_limit, false}};
}

std::string rgb_text(Rgb c) {
    char text[96];
    std::snprintf(text, sizeof text, "%.9g,%.9g,%.9g", double(c.r), double(c.g), double(c.b));
    return text;
}

std::string number_text(double v) {
    char text[40];
    std::snprintf(text, sizeof text, "%.9g", v);
    return text;
}

}  // namespace

const std::vector<std::string> &fiber_preset_names() {
    static const std::vector<std::string> names = {"blonde", "brunette", "cycles-default", "cycles-default-huang"};
    return names;
}

Expected<FiberSpec> FiberSpec::preset(const std::string &name) {
    FiberSpec spec;
    if (name == "cycles-default") {
        spec.kind = FiberKind::Chiang;
        spec.node = PrincipledHairNode::cycles_default();
    } else if (name == "cycles-default-huang") {
        spec.kind = FiberKind::Huang;
        spec.node = PrincipledHairNode::cycles_default();
    } else if (name == "blonde") {
        spec.kind = FiberKind::Marschner;
        spec.marschner = MarschnerParams::blonde();
    } else if (name == "brunette") {
        spec.kind = FiberKind::Marschner;
        spec.marschner = MarschnerParams::brunette();
    } else {
        return Error{"preset must be one of blonde, brunette, cycles-default, cycles-default-huang (got \"" + name +
                     "\")"};
    }
    return spec;
}

Status FiberSpec::set(const std::string &key, const std::string &value) {
    if (key == "preset") {
        Expected<FiberSpec> p = preset(value);
        if (!p) return p.error();
        *this = p.value();
        return std::nullopt;
    }
    if (key == "model") {
        if (value == "chiang") kind = FiberKind::Chiang;
        else if (value == "huang") kind = FiberKind::Huang;
        else if (value == "marschner") kind = FiberKind::Marschner;
        else return Error{"model must be chiang, huang or marschner (got \"" + value + "\")"};
        return std::nullopt;
    }
    if (key == "cycles") {
        // The Blender version whose Cycles evaluates a Chiang fiber: 3.4 to 4.1 tilt θ_i, 4.2
        // and later θ_o.
        Expected<double> v = parse_number(key, value);
        if (!v || v.value() < 3.4 - 1e-9) return Error{"cycles must be a Blender version >= 3.4, e.g. 3.4 or 4.5 (got \"" + value + "\")"};
        node.tilt = v.value() >= 4.2 - 1e-9 ? ChiangTilt::Outgoing : ChiangTilt::Incident;
        return std::nullopt;
    }
    if (key == "parametrization") {
        if (value == "absorption") node.parametrization = HairParametrization::AbsorptionCoefficient;
        else if (value == "melanin") node.parametrization = HairParametrization::Melanin;
        else if (value == "color") node.parametrization = HairParametrization::Color;
        else return Error{"parametrization must be absorption, melanin or color (got \"" + value + "\")"};
        return std::nullopt;
    }
    // Colours.
    Rgb *rgb = key == "color" ? &node.color : key == "tint" ? &node.tint
             : key == "absorption" ? &node.absorption_coefficient : key == "sigma_a" ? &marschner.sigma_a : nullptr;
    if (rgb) {
        Expected<Rgb> c = parse_rgb(key, value);
        if (!c) return c.error();
        *rgb = c.value();
        return std::nullopt;
    }
    for (const FloatKey &k : all_node_keys(*this))
        if (key == k.name) {
            Expected<double> v = parse_number(key, value);
            if (!v) return v.error();
            *k.field = float(k.degrees ? radians(v.value()) : v.value());
            return std::nullopt;
        }
    for (const DoubleKey &k : double_keys(*this))
        if (key == k.name) {
            Expected<double> v = parse_number(key, value);
            if (!v) return v.error();
            *k.field = k.degrees ? radians(v.value()) : v.value();
            return std::nullopt;
        }
    return Error{"unknown parameter \"" + key + "\" (see hairis-bake bake --help for the keys)"};
}

std::string FiberSpec::options() const {
    FiberSpec copy = *this;
    std::string out = kind == FiberKind::Marschner ? "model=marschner"
                      : kind == FiberKind::Huang   ? "model=huang"
                                                   : "model=chiang";
    if (kind == FiberKind::Marschner) {
        out += ";sigma_a=" + rgb_text(marschner.sigma_a);
        for (const DoubleKey &k : double_keys(copy))
            out += std::string(";") + k.name + "=" + number_text(k.degrees ? degrees(*k.field) : *k.field);
        return out;
    }
    const char *names[] = {"absorption", "melanin", "color"};
    if (kind == FiberKind::Chiang)
        out += std::string(";cycles=") + (node.tilt == ChiangTilt::Outgoing ? "4.2" : "3.4");
    out += std::string(";parametrization=") + names[int(node.parametrization)];
    out += ";color=" + rgb_text(node.color) + ";tint=" + rgb_text(node.tint) +
           ";absorption=" + rgb_text(node.absorption_coefficient);
    for (const FloatKey &k : float_keys(copy, kind))
        if (!k.degrees) out += std::string(";") + k.name + "=" + number_text(double(*k.field));
    return out;
}

Expected<std::unique_ptr<FiberModel>> FiberSpec::create_model(const HuangQuadrature &huang_rule) const {
    if (kind == FiberKind::Marschner) {
        Expected<MarschnerFiber> m = MarschnerFiber::create(marschner);
        if (!m) return m.error();
        return std::unique_ptr<FiberModel>(std::make_unique<MarschnerFiber>(std::move(m).value()));
    }
    if (kind == FiberKind::Huang) {
        Expected<HuangParams> p = to_huang_params(node);
        if (!p) return p.error();
        Expected<HuangFiber> h = HuangFiber::create(p.value(), huang_rule);
        if (!h) return h.error();
        return std::unique_ptr<FiberModel>(std::make_unique<HuangFiber>(std::move(h).value()));
    }
    Expected<ChiangParams> p = to_chiang_params(node);
    if (!p) return p.error();
    Expected<ChiangFiber> c = ChiangFiber::create(p.value());
    if (!c) return c.error();
    return std::unique_ptr<FiberModel>(std::make_unique<ChiangFiber>(std::move(c).value()));
}

Expected<std::vector<std::pair<std::string, double>>> FiberSpec::parameters() const {
    if (kind == FiberKind::Marschner) {
        const MarschnerParams &m = marschner;
        return std::vector<std::pair<std::string, double>>{
            {"eta", m.eta}, {"sigma_a.r", m.sigma_a.r}, {"sigma_a.g", m.sigma_a.g}, {"sigma_a.b", m.sigma_a.b},
            {"alpha_r", m.alpha_r}, {"alpha_tt", m.alpha_tt}, {"alpha_trt", m.alpha_trt},
            {"beta_r", m.beta_r}, {"beta_tt", m.beta_tt}, {"beta_trt", m.beta_trt},
            {"eccentricity", m.eccentricity}, {"glint_scale", m.glint_scale},
            {"caustic_width", m.caustic_width}, {"caustic_fade", m.caustic_fade},
            {"caustic_limit", m.caustic_limit}};
    }
    if (kind == FiberKind::Huang) {
        Expected<HuangParams> p = to_huang_params(node);
        if (!p) return p.error();
        return huang_fiber_parameters(p.value());
    }
    Expected<ChiangParams> p = to_chiang_params(node);
    if (!p) return p.error();
    return chiang_parameters(p.value());
}

std::vector<std::pair<std::string, double>> huang_fiber_parameters(const HuangParams &p) {
    return {{"sigma_a_r", p.sigma_a.r},  {"sigma_a_g", p.sigma_a.g},
            {"sigma_a_b", p.sigma_a.b},  {"roughness", p.roughness},
            {"ior", p.ior},              {"offset", p.offset},
            {"aspect_ratio", p.aspect_ratio}, {"reflection", p.reflection},
            {"transmission", p.transmission}, {"secondary_reflection", p.secondary_reflection}};
}

std::vector<std::pair<std::string, double>> chiang_parameters(const ChiangParams &c) {
    std::vector<std::pair<std::string, double>> out{
        {"sigma_a.r", c.sigma_a.r}, {"sigma_a.g", c.sigma_a.g}, {"sigma_a.b", c.sigma_a.b},
        {"roughness", c.roughness}, {"radial_roughness", c.radial_roughness}, {"coat", c.coat},
        {"ior", c.ior}, {"offset", c.offset}};
    // Cycles 4.2's tilt changes f: such tables say so (3.4's record nothing, as before).
    if (c.tilt == ChiangTilt::Outgoing) out.emplace_back("cycles", 4.2);
    return out;
}

Expected<FiberSpec> parse_fiber_spec(const std::string &text, FiberSpec spec) {
    std::istringstream in(text);
    std::string line;
    int number = 0;
    while (std::getline(in, line)) {
        ++number;
        const size_t hash = line.find('#');
        if (hash != std::string::npos) line.erase(hash);
        line = trim(line);
        if (line.empty()) continue;
        const size_t eq = line.find('=');
        if (eq == std::string::npos)
            return Error{"line " + std::to_string(number) + ": expected key = value (got \"" + line + "\")"};
        const std::string key = trim(line.substr(0, eq)), value = trim(line.substr(eq + 1));
        if (Status s = spec.set(key, value)) return Error{"line " + std::to_string(number) + ": " + s->message};
    }
    return spec;
}

}  // namespace hairis
