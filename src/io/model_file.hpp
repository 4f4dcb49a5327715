#pragma once
// Trained models as the files splat tools exchange them: a 3DGS .ply, a compressed .spz or the
// web viewers' .splat.
#include <filesystem>

#include "io/ply.hpp"

namespace iesrgs {

// True for a name ending in .ply, .spz or .splat (any case).
bool is_model_file(const std::filesystem::path& path);

// read_spz for an .spz file, read_splat for a .splat file, read_ply for anything else.
SplatCloud read_model(const std::filesystem::path& path);

}  // namespace iesrgs
