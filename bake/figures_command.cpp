// hairis-bake figures: the seed's Figures 1–4 and fit tables, regenerated from our models.
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <iostream>

#include "commands.h"
#include "fiber_options.h"
#include "fiber/distributions.h"
#include "fiber/dual_scattering.h"
#include "npy.h"
#include "sampling/huang_table.h"
#include "seed_fits.h"
#include "seed_tables.h"
#include "tables/table_file.h"

namespace hairis::cli {

namespace {

struct FiguresFlags {
    std::string output;
    std::string table;  // draw this table file's parts instead of the seed's figures
    FiberOptions fiber;
    int theta_count = 90;
    int phi_count = 180;
    bool data_only = false;
};

// Names each stage of a long run on stderr and how long the one before took.
class Stage {
  public:
    explicit Stage(const std::string &what) { next(what); }
    void next(const std::string &what) {
        const auto now = std::chrono::steady_clock::now();
        if (!what_.empty())
            std::cerr << "hairis-bake figures: " << what_ << " took "
                      << std::lround(std::chrono::duration<double>(now - start_).count()) << " s\n";
        what_ = what;
        start_ = now;
        if (!what_.empty()) std::cerr << "hairis-bake figures: computing " << what_ << "\n";
    }

  private:
    std::string what_;
    std::chrono::steady_clock::time_point start_;
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

// Runs a plotting script on `dir`; `what` names the PNGs for the message.
int plot(const char *script_env_name, const std::string &default_script, const std::string &dir,
         const std::string &label, const std::string &what) {
    const char *script_env = std::getenv(script_env_name);
    const std::string script = script_env ? script_env : default_script;
    if (!std::filesystem::exists(script))
        return fail("the plotting script \"" + script + "\" is missing (set " + script_env_name + ")");
    // Debian's python3 has Debian's matplotlib; a python3 earlier on PATH (pyenv, venv) may not.
    const char *python_env = std::getenv("HAIRIS_PYTHON");
    const std::string python = python_env ? python_env
                               : std::filesystem::exists("/usr/bin/python3") ? "/usr/bin/python3" : "python3";
    const std::string command = quoted(python) + " " + quoted(script) + " " + quoted(dir) + " --model " + quoted(label);
    const int status = std::system(command.c_str());
    if (status != 0)
        return fail("the plotting script failed (exit status " + std::to_string(status) +
                    "); it needs python3 with numpy and matplotlib (scripts/setup installs them)");
    std::cerr << "hairis-bake figures: wrote " << what << " to " << dir << "\n";
    return 0;
}

// The parts of a table file as arrays: far direct [θ_r][θ_i][φ], multiple [θ_r][n_h][θ_i],
// theta_r nodes; near (Chiang) cell densities [θ_o][lobe][θ_i] (mass / cell width, each row
// normalised to integrate to 1) and the cone flags [θ_o][lobe].
// A Huang part (huang2022 files, which hold nothing else): its values [φ_o][θ_o][θ_i][φ] and
// the view nodes.
int run_huang_table_figures(const FiguresFlags &flags, const std::filesystem::path &dir, const TableSet &s) {
    const HuangTableSet &h = *s.huang;
    const std::vector<std::pair<std::string, Status>> writes = {
        {"table_huang.npy", write_npy((dir / "table_huang.npy").string(), h.values,
                                      {h.phi_o_nodes.size(), h.theta_o_nodes.size(), size_t(h.theta_i_count),
                                       size_t(h.phi_count)})},
        {"table_huang_theta_o.npy",
         write_npy((dir / "table_huang_theta_o.npy").string(), h.theta_o_nodes, {h.theta_o_nodes.size()})},
        {"table_huang_phi_o.npy",
         write_npy((dir / "table_huang_phi_o.npy").string(), h.phi_o_nodes, {h.phi_o_nodes.size()})}};
    for (const auto &[name, status] : writes)
        if (status) return fail(status->message);
    if (flags.data_only) return 0;
    return plot("HAIRIS_TABLE_FIGURES_SCRIPT", HAIRIS_TABLE_FIGURES_SCRIPT, flags.output,
                s.model + " table " + std::filesystem::path(flags.table).filename().string(), "the table's part PNGs");
}

int run_table_figures(const FiguresFlags &flags, const std::filesystem::path &dir) {
    Expected<TableSet> t = read_table_file(flags.table);
    if (!t) return fail(t.error().message);
    const TableSet &s = t.value();
    if (s.huang) return run_huang_table_figures(flags, dir, s);
    const size_t nr = size_t(s.theta_r_count()), ni = size_t(s.theta_i_count), np = size_t(s.phi_count);
    std::vector<float> nodes(s.theta_r_nodes.begin(), s.theta_r_nodes.end());
    std::vector<float> n_h(s.n_h_values.begin(), s.n_h_values.end());
    std::vector<std::pair<std::string, Status>> writes = {
        {"table_far.npy", write_npy((dir / "table_far.npy").string(), s.direct, {nr, ni, np})},
        {"table_multiple.npy",
         write_npy((dir / "table_multiple.npy").string(), s.multiple, {nr, s.n_h_values.size(), ni})},
        {"table_theta_r.npy", write_npy((dir / "table_theta_r.npy").string(), nodes, {nr})},
        {"table_n_h.npy", write_npy((dir / "table_n_h.npy").string(), n_h, {n_h.size()})}};
    if (s.near_field) {
        const NearFieldData &n = *s.near_field;
        const size_t cells = size_t(n.theta_i_cells), rows = size_t(n.rows());
        std::vector<float> density(rows * cells), cone(rows);
        const double width = kPi / double(cells);
        for (size_t row = 0; row < rows; ++row) {
            double total = 0;
            for (size_t k = 0; k < cells; ++k) total += n.mass[row * cells + k];
            for (size_t k = 0; k < cells; ++k)
                density[row * cells + k] = total > 0 ? float(n.mass[row * cells + k] / (total * width)) : 0.0f;
            cone[row] = float(n.cone[row]);
        }
        writes.push_back({"table_near.npy", write_npy((dir / "table_near.npy").string(), density,
                                                      {size_t(n.theta_o_nodes), 4, cells})});
        writes.push_back({"table_near_cone.npy",
                          write_npy((dir / "table_near_cone.npy").string(), cone, {size_t(n.theta_o_nodes), 4})});
    }
    for (const auto &[name, status] : writes)
        if (status) return fail(status->message);
    if (flags.data_only) return 0;
    return plot("HAIRIS_TABLE_FIGURES_SCRIPT", HAIRIS_TABLE_FIGURES_SCRIPT, flags.output,
                s.model + " table " + std::filesystem::path(flags.table).filename().string(),
                "the table's part PNGs");
}

int run_figures(const FiguresFlags &flags) {
    std::error_code ec;
    std::filesystem::create_directories(flags.output, ec);
    if (ec) return fail("cannot create \"" + flags.output + "\": " + ec.message());
    const std::filesystem::path dir(flags.output);
    if (!flags.table.empty()) return run_table_figures(flags, dir);
    Expected<FiberSpec> spec = flags.fiber.resolve();
    if (!spec) return fail(spec.error().message);
    std::string label = flags.fiber.preset;
    if (!flags.fiber.param_file.empty()) label += " + " + std::filesystem::path(flags.fiber.param_file).filename().string();
    for (const std::string &setting : flags.fiber.settings) label += " + " + setting;
    Stage stage("the dual-scattering tables of " + label);
    Expected<FigureFiber> fiber = make_figure_fiber(spec.value(), label);
    if (!fiber) return fail(fiber.error().message);
    stage.next("Figure 1 (35 direct distributions)");
    const FiberModel &model = *fiber.value().model;
    const DualScattering &ds = *fiber.value().dual;
    const int n_i = flags.theta_count, n_p = flags.phi_count;

    // Figure 1: S_direct over (θ_i, φ_i) for 5 φ_r rows × 7 θ_r columns.
    std::vector<float> fig1;
    DirectGridSpec direct_spec;
    direct_spec.theta_count = n_i;
    direct_spec.phi_count = n_p;
    direct_spec.quadrature_points = fiber.value().grid_points(n_i, n_p);
    for (double phi_r : kSeedPhiR) {
        for (double theta_r : kSeedThetaR) {
            if (interrupted()) return kExitInterrupted;
            auto g = direct_distribution(model, evaluated_theta_r(theta_r), radians(phi_r), direct_spec);
            if (!g) return fail(g.error().message);
            for (double v : g.value().values) fig1.push_back(float(v));
        }
    }
    stage.next("Figures 2-4");
    // Figures 2 and 3: S_multiple over θ_i (azimuthally uniform).
    ThetaGridSpec theta_spec;
    theta_spec.theta_count = n_i;
    std::vector<float> fig2, fig3;
    for (double theta_r : kSeedThetaR) {
        auto g = multiple_distribution(ds, evaluated_theta_r(theta_r), 2, theta_spec);
        if (!g) return fail(g.error().message);
        for (double v : g.value().values) fig2.push_back(float(v));
    }
    for (int n_h : kSeedStrands) {
        auto g = multiple_distribution(ds, 0.0, n_h, theta_spec);
        if (!g) return fail(g.error().message);
        for (double v : g.value().values) fig3.push_back(float(v));
    }
    // Figure 4: profiles at θ_r ∈ {−60, 0, 60}° for n_h = 1, 2, 4, 8 with the fitted Gaussians.
    auto rows = fit_multiple(ds, {1, 2, 4, 8}, n_i);
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

    stage.next("the fit tables");
    const int fits = write_fit_tables(flags.output, {&fiber.value()}, 2 * n_i, n_p);
    if (fits != 0) return fits;
    stage.next("");
    if (flags.data_only) return 0;

    return plot("HAIRIS_FIGURES_SCRIPT", HAIRIS_FIGURES_SCRIPT, flags.output,
                model.name() + " (" + label + ")", "figure1..4 PNGs and fit tables");
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
    cmd->add_option("--table", flags->table,
                    "draw this table file's parts (far direct and multiple, Chiang's near field) "
                    "instead of the seed's figures")
        ->check(CLI::ExistingFile);
    cmd->callback([flags, &exit_code] { exit_code = run_figures(*flags); });
}

}  // namespace hairis::cli
