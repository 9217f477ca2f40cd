// Sampling tables on disk: 32-bit float OpenEXR textures with hairis metadata, one image that
// Blender loads, shows and packs like any other.
//
// One part, scanline, ZIP, channels R, G, B, A, all FLOAT. The image stacks the table's parts
// from the top row down, each padded with zeros to the widest (hairis:parts names them):
//  far   rows y = r·theta_i_count + i for θ_r node r and θ_i cell i (θ_i ascending from −π/2),
//        columns j < phi_count for φ cell j (φ = φ_i − φ_o ascending from −π):
//        R  the direct-scattering density S_direct(θ_i, φ | θ_r) per steradian (cell average);
//        G  the multiple-scattering density S_multiple(θ_i | θ_r, n_h) per steradian: the φ
//           columns are cut into n_h_count equal bands, band k holds n_h_values[k] repeated
//           (Blender's image editor shows one vertical stripe per n_h);
//        B  0;  A  1.
//  near  (Chiang) rows r·4 + p after the far part for θ_o node r (equally spaced over
//        [−π/2, π/2], ends included) and lobe p (R, TT, TRT, TRRT+), columns k ≤ theta_i:
//        R  the mass of θ_i cell k of the lobe's M_p·cos θ_i (0 in the last column);
//        G  M_p at the lower edge of cell k (the last column: the upper edge of the last cell);
//        B  the lobe's integral ∫ M_p cos θ_i dθ_i, along the whole row;
//        A  1 when the lobe draws θ_i from the fiber's cone instead of the row, along the row.
//        This is what the TABLE strategy samples single scattering from (near_field_table.h).
//  huang (huang2022 files, the only part they hold) rows y = (q·theta_o + r)·theta_i + i for
//        φ_o node q, θ_o node r and θ_i cell i, columns j < phi for cell j of φ_i − φ_o
//        (HuangTable::create's values in their order, sampling/huang_table.h):
//        R  the cell's value (∝ luminance(f·cos θ_i) there);  G, B  0;  A  1.
//        This is what the TABLE strategy samples a Huang fiber from.
//  f     (huang2022 files baked with f, after the Huang part) row huang_rows + the Huang
//        part's row, same column:  R, G, B  the expectation of Cycles' f·cos θ_i of TT, TRT and
//        TRRT+ at the cell's midpoint (huang_f_table.h);  A  1. This is what renders shade
//        Huang hair with.
//  absorption (huang2022 files with an f part, after it) ceil(K/4) blocks of huang_rows rows for
//        K absorption nodes: row huang_rows + f_rows + b·huang_rows + the Huang part's row, same
//        column:  R, G, B, A  the cell's values at nodes 4b to 4b + 3 (HuangTableSet::absorption),
//        0 past the last node. This is the f part for strands of other absorption.
//  multiple (huang2022 files baked for dual scattering, after the Huang, f and absorption parts)
//        rows y = huang_rows + f_rows + absorption_rows + r·theta_i_count + i for θ_r node r and
//        θ_i cell i, columns k for n_h_values[k]:  G  S_multiple(θ_i | θ_r, n_h) per steradian;
//        R, B  0;  A  1.
// Metadata (EXR header attributes): hairis:format_version (2), hairis:model (string),
// hairis:source ("exact" or "gaussian"), hairis:parameters ("name=value;..."),
// hairis:theta_r_count, hairis:theta_i_count, hairis:phi_count (the far part), hairis:theta_r_nodes
// (float array, radians), hairis:n_h_values ("1,2,..."), hairis:parts ("far", "far,near",
// "huang", "huang,f", "huang,f,absorption", "huang,multiple", "huang,f,multiple" or
// "huang,f,absorption,multiple"), hairis:near ("row=...;theta_o=...;theta_i=..."), hairis:huang
// ("row=0;theta_o=...;phi_o=...;theta_i=...;phi=..."), hairis:huang_f ("row=..."),
// hairis:huang_absorption ("row=...;nodes=...", the K nodes with 9 significant digits),
// hairis:huang_theta_o_nodes and hairis:huang_phi_o_nodes (float arrays, radians),
// hairis:multiple ("row=...;theta_r=...;theta_i=..."; with it a huang file has
// hairis:theta_r_nodes and hairis:n_h_values, and never the far part's counts),
// hairis:pixel_sha1 (hex SHA-1 of the float pixels in scanline order, RGBA interleaved,
// little-endian). Every pixel outside the parts is 0.
// The image has at most kMaxTableAxisCells + 1 columns and kMaxTableCells pixels.
// Version 1 files (no near part) are refused with a message asking for a re-bake.
#pragma once

#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include "core/expected.h"
#include "sampling/table_set.h"

namespace hairis {

/// The version this build writes and the only one it reads.
inline constexpr int kTableFormatVersion = 2;

/// Encodes a table set as EXR bytes. Refuses an invalid set.
Expected<std::vector<unsigned char>> encode_table_exr(const TableSet &tables);

/// Decodes and validates EXR bytes (a file's contents or a packed Blender image).
Expected<TableSet> decode_table_exr(const void *data, size_t size);

/// A 128-bit fingerprint (hex) of a table file's bytes: the key under which a decoded file may be
/// reused. Not cryptographic: it is fast enough to take on every load of a large file.
std::string table_file_fingerprint(const void *data, size_t size);

/// Reads and validates a table file.
Expected<TableSet> read_table_file(const std::string &path);

/// Writes a table file atomically: a temporary file beside `path`, then a rename, so a
/// failure never leaves a half-written file at `path`.
Status write_table_file(const TableSet &tables, const std::string &path);

}  // namespace hairis
