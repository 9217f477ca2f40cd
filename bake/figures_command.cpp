// hairis-bake figures: the seed's Figures 1–4 and fit tables, regenerated from our models.
#include <cstdlib>
#include <filesystem>
#include <iostream>

#include "commands.h"
#include "fiber_options.h"
#include "fiber/distributions.h"
#include "fiber/dual_scattering.h"
#include "npy.h"
#include "seed_fits.h"
#include "seed_tables.h"

namespace hairis::cli {

namespace {

struct FiguresFlags {
    std::string output;
    FiberOptions fiber;
    int theta_count = 90;
    int phi_count = 180;
    bool data_only = false;
};

int fail(const std::string &message) {
    std::cerr << "hairis-bake figures: " << message << "\n";
    return kExitFailure;
}

std::string quoted(const std::string &s) {
    std::string out = "'";
    for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return out + "'";
}

int run_figures(const FiguresFlags &flags) {
    std::error_code ec;
    std::filesystem::create_directories(flags.output, ec);
    if (ec) return fail("cannot create \"" + flags.output + "\": " + ec.message());
    const std::filesystem::path dir(flags.output);
    Expected<FiberSpec> spec = flags.fiber.resolve();
    if (!spec) return fail(spec.error().message);
    auto model = spec.value().create_model();
    if (!model) return fail(model.error().message);
    auto ds = DualScattering::create(*model.value(), DualScatteringParams{});
    if (!ds) return fail(ds.error().message);
    const int n_i = flags.theta_count, n_p = flags.phi_count;

    // Figure 1: S_direct over (θ_i, φ_i) for 5 φ_r rows × 7 θ_r columns.
    std::vector<float> fig1;
    DirectGridSpec direct_spec;
    direct_spec.theta_count = n_i;
    direct_spec.phi_count = n_p;
    for (double phi_r : kSeedPhiR) {
        for (double theta_r : kSeedThetaR) {
            if (interrupted()) return kExitInterrupted;
            auto g = direct_distribution(*model.value(), evaluated_theta_r(theta_r), radians(phi_r), direct_spec);
            if (!g) return fail(g.error().message);
            for (double v : g.value().values) fig1.push_back(float(v));
        }
    }
    // Figures 2 and 3: S_multiple over θ_i (azimuthally uniform).
    ThetaGridSpec theta_spec;
    theta_spec.theta_count = n_i;
    std::vector<float> fig2, fig3;
    for (double theta_r : kSeedThetaR) {
        auto g = multiple_distribution(ds.value(), evaluated_theta_r(theta_r), 2, theta_spec);
        if (!g) return fail(g.error().message);
        for (double v : g.value().values) fig2.push_back(float(v));
    }
    for (int n_h : kSeedStrands) {
        auto g = multiple_distribution(ds.value(), 0.0, n_h, theta_spec);
        if (!g) return fail(g.error().message);
        for (double v : g.value().values) fig3.push_back(float(v));
    }
    // Figure 4: profiles at θ_r ∈ {−60, 0, 60}° for n_h = 1, 2, 4, 8 with the fitted Gaussians.
    auto rows = fit_multiple(ds.value(), {1, 2, 4, 8}, n_i);
    if (!rows) return fail(rows.error().message);
    std::vector<float> fig4_profiles, fig4_fits;
    for (const MultipleFitRow &r : rows.value()) {
        if (r.theta_r_deg != -60 && r.theta_r_deg != 0 && r.theta_r_deg != 60) continue;
        for (double v : r.profile) fig4_profiles.push_back(float(v));
        fig4_fits.insert(fig4_fits.end(), {float(r.fit.scale), float(r.fit.sigma), float(r.fit.mean)});
    }
    const std::vector<std::pair<std::string, Status>> writes = {
        {"figure1.npy", write_npy((dir / "figure1.npy").string(), fig1, {5, 7, size_t(n_i), size_t(n_p)})},
        {"figure2.npy", write_npy((dir / "figure2.npy").string(), fig2, {7, size_t(n_i)})},
        {"figure3.npy", write_npy((dir / "figure3.npy").string(), fig3, {5, size_t(n_i)})},
        {"figure4_profiles.npy", write_npy((dir / "figure4_profiles.npy").string(), fig4_profiles, {4, 3, size_t(n_i)})},
        {"figure4_fits.npy", write_npy((dir / "figure4_fits.npy").string(), fig4_fits, {4, 3, 3})}};
    for (const auto &[name, status] : writes)
        if (status) return fail(status->message);

    const int fits = write_fit_tables(flags.output, {flags.fiber.preset}, 2 * n_i, n_p);
    if (fits != 0) return fits;
    if (flags.data_only) return 0;

    const char *script_env = std::getenv("HAIRIS_FIGURES_SCRIPT");
    const std::string script = script_env ? script_env : HAIRIS_FIGURES_SCRIPT;
    if (!std::filesystem::exists(script))
        return fail("the plotting script \"" + script + "\" is missing (set HAIRIS_FIGURES_SCRIPT)");
    // Debian's python3 has Debian's matplotlib; a python3 earlier on PATH (pyenv, venv) may not.
    const char *python_env = std::getenv("HAIRIS_PYTHON");
    const std::string python = python_env ? python_env
                               : std::filesystem::exists("/usr/bin/python3") ? "/usr/bin/python3" : "python3";
    const std::string command = quoted(python) + " " + quoted(script) + " " + quoted(flags.output) + " --model " +
                                quoted(model.value()->name() + " (" + flags.fiber.preset + ")");
    const int status = std::system(command.c_str());
    if (status != 0)
        return fail("the plotting script failed (exit status " + std::to_string(status) +
                    "); it needs python3 with numpy and matplotlib (scripts/setup installs them)");
    std::cerr << "hairis-bake figures: wrote figure1..4 PNGs and fit tables to " << flags.output << "\n";
    return 0;
}

}  // namespace

void add_figures_command(CLI::App &app, int &exit_code) {
    auto flags = std::make_shared<FiguresFlags>();
    CLI::App *cmd = app.add_subcommand("figures", "regenerate the seed's Figures 1-4 and fit tables as PNG, "
                                                  "NumPy and markdown files");
    cmd->add_option("--output,-o", flags->output, "the folder to write into")->required();
    flags->fiber.add_to(*cmd, "blonde");
    cmd->add_option("--theta-i", flags->theta_count, "theta_i cells per panel")
        ->check(CLI::Range(8, 1024))->capture_default_str();
    cmd->add_option("--phi", flags->phi_count, "phi cells per panel")
        ->check(CLI::Range(8, 2048))->capture_default_str();
    cmd->add_flag("--data-only", flags->data_only, "write the .npy data and fit tables but no PNGs");
    cmd->callback([flags, &exit_code] { exit_code = run_figures(*flags); });
}

}  // namespace hairis::cli
