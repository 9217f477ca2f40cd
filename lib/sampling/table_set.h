// A baked table set as plain data: what a table file holds and what the samplers are built
// from (table_file.h reads and writes it as EXR).
#pragma once

#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include <memory>

#include "core/expected.h"
#include "sampling/near_field_table.h"
#include "sampling/table_limits.h"

namespace hairis {

struct HuangTableSet;  // sampling/huang_table.h

/// Everything a table file holds, as plain data. A huang2022 set holds its Huang table (`huang`)
/// and, when baked for dual scattering, the multiple table (theta_r_nodes, theta_i_count,
/// n_h_values, multiple); never a direct table (phi_count 0, direct empty) or a near-field part.
struct TableSet {
    std::string model;   ///< "chiang2016", "marschner2003" or "huang2022"
    std::string source;  ///< "exact" (our distributions) or "gaussian" (the seed's PDFs)
    std::vector<std::pair<std::string, double>> parameters;  ///< every model parameter
    std::vector<float> theta_r_nodes;  ///< radians, strictly increasing, in [−π/2, π/2]
    int theta_i_count = 0;             ///< θ_i cells over [−π/2, π/2]
    int phi_count = 0;                 ///< φ cells over [−π, π]
    std::vector<int> n_h_values;       ///< strands for the multiple tables, increasing
    std::vector<float> direct;    ///< [r][i][j]: theta_r_count × theta_i_count × phi_count
    std::vector<float> multiple;  ///< [r][k][i]: theta_r_count × n_h count × theta_i_count
    /// Chiang's near-field tables (what TABLE samples single scattering from for a fiber); null
    /// for other models.
    std::shared_ptr<const NearFieldData> near_field;
    /// The Huang table (huang2022 sets only; its parameters are `parameters`), else null.
    std::shared_ptr<const HuangTableSet> huang;

    int theta_r_count() const { return int(theta_r_nodes.size()); }
    /// True when the set has the far-field part (every model but huang2022).
    bool has_far_field() const { return !theta_r_nodes.empty() && !huang; }
    /// True when the set has multiple-scattering tables (every far field; huang2022 sets baked
    /// for dual scattering, TableSet::multiple over theta_r_nodes × n_h_values × theta_i_count).
    bool has_multiple() const { return !theta_r_nodes.empty(); }
    TableResolution resolution() const { return {theta_r_count(), theta_i_count, phi_count}; }
    float direct_at(int r, int i, int j) const {
        return direct[(size_t(r) * theta_i_count + i) * phi_count + j];
    }
    float multiple_at(int r, int k, int i) const {
        return multiple[(size_t(r) * n_h_values.size() + k) * theta_i_count + i];
    }

    /// Checks sizes, ordering, ranges and values; names the first problem found.
    Status validate() const;

  private:
    Status validate_huang() const;
    Status validate_axes() const;      // θ_r nodes and n_h values
    Status validate_multiple() const;  // the multiple table's size and values
};

/// "name=value;..." with values printed to 9 significant digits, in the order given.
std::string canonical_parameters(const std::vector<std::pair<std::string, double>> &params);

}  // namespace hairis
