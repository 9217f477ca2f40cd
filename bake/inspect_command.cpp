// hairis-bake inspect: print a table file's metadata and validate it.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <iostream>

#include "commands.h"
#include "core/math.h"
#include "sampling/huang_table.h"
#include "tables/table_file.h"

namespace hairis::cli {

namespace {

int run_inspect(const std::string &path) {
    Expected<TableSet> t = read_table_file(path);
    if (!t) {
        std::cerr << "hairis-bake inspect: invalid: " << t.error().message << "\n";
        return kExitFailure;
    }
    const TableSet &s = t.value();
    std::printf("file:            %s\n", path.c_str());
    std::printf("format version:  %d\n", kTableFormatVersion);
    std::printf("model:           %s\n", s.model.c_str());
    std::printf("source:          %s\n", s.source.c_str());
    std::printf("parameters:\n");
    for (const auto &[name, value] : s.parameters) std::printf("  %-18s %.9g\n", name.c_str(), value);
    std::error_code size_error;
    const auto bytes = std::filesystem::file_size(path, size_error);
    if (const HuangTableSet *h = s.huang.get()) {
        const int rows = h->phi_o_count() * h->theta_o_count() * h->theta_i_count;
        std::printf("theta_o nodes:   %d (%.2f .. %.2f deg)\n", h->theta_o_count(), degrees(h->theta_o_nodes.front()),
                    degrees(h->theta_o_nodes.back()));
        std::printf("phi_o nodes:     %d (%.2f .. %.2f deg)\n", h->phi_o_count(), degrees(h->phi_o_nodes.front()),
                    degrees(h->phi_o_nodes.back()));
        std::printf("theta_i cells:   %d\n", h->theta_i_count);
        std::printf("phi cells:       %d (of phi_i - phi_o)\n", h->phi_count);
        std::printf("parts:\n");
        std::printf("  huang  rows 0-%d: %d phi_o nodes x %d theta_o nodes x %d theta_i cells, %d phi cells "
                    "(R cell value of luminance(f cos theta_i))\n",
                    rows - 1, h->phi_o_count(), h->theta_o_count(), h->theta_i_count, h->phi_count);
        int width = h->phi_count, height = rows;
        if (h->has_f()) {
            std::printf("  f  rows %d-%d: the same cells (RGB expectation of f cos theta_i of TT, TRT and TRRT+, "
                        "what renders shade with; quadrature refinement %d)\n",
                        rows, 2 * rows - 1, h->f_refinement);
            height += rows;
        } else {
            std::printf("  (no f part: renders shade with Cycles' noisy eval; bake without --no-huang-f)\n");
        }
        const int nodes = h->absorption_count();
        if (h->has_absorption()) {
            const int blocks = (nodes + 3) / 4;
            std::printf("  absorption  rows %d-%d: %d blocks of the same cells, %d absorption nodes (%.6g .. %.6g), "
                        "4 per block in RGBA (one channel of the f part per node, for strands of other absorption)\n",
                        height, height + blocks * rows - 1, blocks, nodes, h->absorption_nodes.front(),
                        h->absorption_nodes.back());
            height += blocks * rows;
        }
        if (s.has_multiple()) {
            const int multiple_rows = s.theta_r_count() * s.theta_i_count, bands = int(s.n_h_values.size());
            std::printf("  multiple  rows %d-%d: %d theta_r nodes (%.2f .. %.2f deg) x %d theta_i cells, columns "
                        "n_h =",
                        height, height + multiple_rows - 1, s.theta_r_count(), degrees(s.theta_r_nodes.front()),
                        degrees(s.theta_r_nodes.back()), s.theta_i_count);
            for (int n : s.n_h_values) std::printf(" %d", n);
            std::printf(" (G multiple-scattering density; integrator=dual_scattering samples it)\n");
            width = std::max(width, bands);
            height += multiple_rows;
        } else {
            std::printf("  (no multiple part: integrator=dual_scattering needs a bake without --no-huang-multiple)\n");
        }
        const std::size_t absorption_cells = nodes > 0 ? h->absorption.size() / std::size_t(nodes) : 0;
        std::printf("cells:           %zu\n", h->values.size() + h->f.size() / 3 + absorption_cells + s.multiple.size());
        std::printf("image:           %d x %d RGBA float (%.1f MB in memory, %.1f MB on disk)\n", width, height,
                    double(width) * height * 16 / 1e6, size_error ? 0.0 : double(bytes) / 1e6);
        std::printf("sampling table:  %.1f MB\n",
                    double(HuangTable::bytes_needed(h->theta_o_count(), h->phi_o_count(), h->theta_i_count,
                                                    h->phi_count)) / 1e6);
        if (h->has_f()) std::printf("baked f:         %.1f MB\n", double(h->f.size() * sizeof(float)) / 1e6);
        if (h->has_absorption())
            std::printf("absorption:      %.1f MB (%d nodes, %.6g .. %.6g)\n",
                        double(h->absorption.size() * sizeof(float)) / 1e6, nodes, h->absorption_nodes.front(),
                        h->absorption_nodes.back());
        std::printf("valid:           yes (metadata, sizes, values and pixel hash checked)\n");
        return 0;
    }
    std::printf("theta_r nodes:   %d (%.2f .. %.2f deg)\n", s.theta_r_count(), degrees(s.theta_r_nodes.front()),
                degrees(s.theta_r_nodes.back()));
    std::printf("theta_i cells:   %d\n", s.theta_i_count);
    std::printf("phi cells:       %d\n", s.phi_count);
    std::printf("n_h values:     ");
    for (int n : s.n_h_values) std::printf(" %d", n);
    std::printf("\nparts:\n");
    const int far_rows = s.theta_r_count() * s.theta_i_count;
    int width = s.phi_count, rows = far_rows;
    std::printf("  far    rows %d-%d: %d theta_r nodes x %d theta_i cells, %d phi cells "
                "(R direct density, G multiple density in %zu n_h bands)\n",
                0, far_rows - 1, s.theta_r_count(), s.theta_i_count, s.phi_count, s.n_h_values.size());
    if (s.near_field) {
        const NearFieldData &n = *s.near_field;
        static const char *const kLobes[4] = {"R", "TT", "TRT", "TRRT+"};
        int cones[4] = {};
        for (int row = 0; row < n.rows(); ++row) cones[row % 4] += n.cone[std::size_t(row)] ? 1 : 0;
        std::printf("  near   rows %d-%d: %d theta_o nodes (-90 .. 90 deg) x 4 lobes, %d theta_i cells "
                    "(R cell mass, G edge value, B lobe integral, A cone flag)\n",
                    rows, rows + n.rows() - 1, n.theta_o_nodes, n.theta_i_cells);
        std::printf("         nodes drawing theta_i from the fiber's cone:");
        for (int p = 0; p < 4; ++p) std::printf(" %s %d", kLobes[p], cones[p]);
        std::printf("\n");
        rows += n.rows();
        width = std::max(width, n.theta_i_cells + 1);
    }
    std::printf("image:           %d x %d RGBA float (%.1f MB in memory, %.1f MB on disk)\n", width, rows,
                double(width) * rows * 16 / 1e6, size_error ? 0.0 : double(bytes) / 1e6);
    std::printf("valid:           yes (metadata, sizes, values and pixel hash checked)\n");
    return 0;
}

}  // namespace

void add_inspect_command(CLI::App &app, int &exit_code) {
    auto path = std::make_shared<std::string>();
    CLI::App *cmd = app.add_subcommand("inspect", "print a table file's metadata and validate it "
                                                  "(exit status 0 when valid)");
    cmd->add_option("file", *path, "the EXR table file")->required();
    cmd->callback([path, &exit_code] { exit_code = run_inspect(*path); });
}

}  // namespace hairis::cli
