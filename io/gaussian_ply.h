// The standard 3DGS PLY (the Inria layout that viewers and trainers read): per vertex
// x y z nx ny nz f_dc_0..2 f_rest_0..(3(K-1)-1) opacity scale_0..2 rot_0..3, binary little-endian floats,
// raw values: opacity logit, log-scales, unnormalized quaternion (w first). f_rest is channel-major
// (all coefficients of channel 0, then channel 1, then 2), as 3DGS writes it.
//
// A one-channel (thermal) model is written with its channel in all three colour slots, so common viewers
// show it as gray, and a header line "comment litgs_channels 1" that makes the reader return one channel.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "kernels/splat/splat_types.h"

namespace litgs::io {

// IoError naming the file (and line or byte) on: a missing or truncated file, a non-PLY file, a missing
// property, an f_rest count that is not 3 * (K - 1) for K in {1, 4, 9, 16}, a one-channel comment on a
// file whose colour slots differ.
kernels::GaussianModel read_gaussian_ply(const std::filesystem::path& path);
// The header's comment lines, without "comment " (litgs_channels included), in order; IoError naming the file
// if it cannot be opened or is not a PLY.
std::vector<std::string> read_gaussian_ply_comments(const std::filesystem::path& path);

// Writes atomically (temporary file, then rename). Models with 1 or 3 channels. `comments` become header
// lines "comment TEXT" (one line each: std::invalid_argument on a line break).
void write_gaussian_ply(const std::filesystem::path& path, const kernels::GaussianModel& model,
                        const std::vector<std::string>& comments = {});

}  // namespace litgs::io
