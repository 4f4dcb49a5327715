#pragma once
// The super-resolution backends: which exist, how to build one, and where they find their
// checkpoints (below priors::default_weights_dir).
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "priors/sr/sr_net.hpp"

namespace iesrgs::priors::sr {

// Builds the backend `model` (bicubic, safmn, imdn, pan, swinir, esrgan-slim,
// esrgan-medium, esrgan-thick) for `scale`, loading `weights` when the model
// has any (an empty path selects the model's default location, if it has one).
// Throws iesrgs::Error naming the model or file and the problem.
std::unique_ptr<SrNet> make_sr_net(const std::string& model, const std::filesystem::path& weights,
                                   int scale);

// The official file of `model` at `scale`: <weights dir>/sr/<MODEL>_x<scale>.pth, e.g.
// SAFMN_x4.pth.
std::filesystem::path default_sr_weights(const std::string& model, int scale);

// The best prior at hand for `scale`, for "--sr-model auto": SAFMN when its checkpoint is at
// the default location, else the best installed ESRGAN package (thick, then slim), else bicubic.
std::string auto_sr_model(int scale);

// The scale a checkpoint's file name states, as the authors name them (PANx2_DF2K.pth,
// IMDN_x4.pth: a lowercase "x" and one digit, neither after a lowercase letter or a digit nor
// before another digit), or 0 when it states none or several different ones.
int scale_in_file_name(const std::filesystem::path& file);

// The names make_sr_net accepts.
const std::vector<std::string>& sr_model_names();

}  // namespace iesrgs::priors::sr
