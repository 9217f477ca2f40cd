// Sampling tables on disk: 32-bit float OpenEXR textures with hairis metadata.
//
// Layout (one part, scanline, ZIP compression, channels R, G, B, A, all FLOAT):
//   width  = phi_count, height = theta_r_count × theta_i_count.
//   Row y = r·theta_i_count + i holds θ_r node r and θ_i cell i (θ_i ascending from −π/2);
//   column j is φ cell j (φ ascending from −π).
//   R  the direct-scattering density S_direct(θ_i, φ | θ_r) per steradian (cell average);
//   G  the multiple-scattering density S_multiple(θ_i | θ_r, n_h) per steradian: the φ columns
//      are cut into n_h_count equal bands, band k holds n_h_values[k] repeated over its
//      columns (so Blender's image editor shows one vertical stripe per n_h);
//   B  0;  A  1.
// Metadata (EXR header attributes): hairis:format_version (int), hairis:model (string),
// hairis:source ("exact" or "gaussian"), hairis:parameters (string "name=value;..."),
// hairis:theta_r_count, hairis:theta_i_count, hairis:phi_count (int), hairis:theta_r_nodes
// (float array, radians), hairis:n_h_values (int array), hairis:pixel_sha1 (hex SHA-1 of the
// float pixel data in scanline order, RGBA interleaved, little-endian).
#pragma once

#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include "core/expected.h"
#include "sampling/table_set.h"

namespace hairis {

/// The version this build writes and the only one it reads.
inline constexpr int kTableFormatVersion = 1;

/// Encodes a table set as EXR bytes. Refuses an invalid set.
Expected<std::vector<unsigned char>> encode_table_exr(const TableSet &tables);

/// Decodes and validates EXR bytes (a file's contents or a packed Blender image).
Expected<TableSet> decode_table_exr(const void *data, size_t size);

/// Reads and validates a table file.
Expected<TableSet> read_table_file(const std::string &path);

/// Writes a table file atomically: a temporary file beside `path`, then a rename, so a
/// failure never leaves a half-written file at `path`.
Status write_table_file(const TableSet &tables, const std::string &path);

}  // namespace hairis
