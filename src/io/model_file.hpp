#pragma once
// Trained models as the files splat tools exchange them: a 3DGS .ply, or a compressed .spz.
#include <filesystem>

#include "io/ply.hpp"

namespace iesrgs {

// True for a name ending in .ply or .spz (any case).
bool is_model_file(const std::filesystem::path& path);

// read_spz for an .spz file, read_ply for anything else.
SplatCloud read_model(const std::filesystem::path& path);

}  // namespace iesrgs
