#pragma once
// The offline default super-resolution prior: the pre-trained ESRGAN generators (RDN and RRDN
// trained on DIV2K) that UpscalerJS publishes on npm under the MIT license as TensorFlow.js
// layers models, @upscalerjs/esrgan-slim, -medium and -thick, each for x2, x3, x4 and x8.
#include <filesystem>
#include <memory>
#include <string>

#include "priors/sr/sr_net.hpp"

namespace iesrgs::priors::sr {

// The variants scripts/setup.sh installs, best first ("--sr-model auto" takes the first present):
// thick is the default prior, slim's outputs are checked against TensorFlow.js'.
inline constexpr const char* kSetupEsrganVariants[] = {"thick", "slim"};

// @upscalerjs/esrgan-<variant> ("slim", "medium" or "thick") at `scale` (2, 3, 4 or 8), read from
// `package_dir`, the package's folder (holding models/x<scale>/model.json); an empty path selects
// default_esrgan_package_dir(variant). Throws Error naming the model or file and the problem.
std::unique_ptr<SrNet> make_esrgan(const std::string& variant, int scale,
                                   const std::filesystem::path& package_dir);

// The package's folder holding the model for `scale` (models/x<scale>, with model.json and its
// weight shards); an empty `package_dir` selects default_esrgan_package_dir(variant).
std::filesystem::path esrgan_model_dir(const std::string& variant, int scale,
                                       const std::filesystem::path& package_dir);

// <npm dir>/node_modules/@upscalerjs/esrgan-<variant>, where <npm dir> is $IESRGS_NPM_DIR or, when
// that is unset, third_party/npm in the source tree (where scripts/setup.sh installs
// kSetupEsrganVariants).
std::filesystem::path default_esrgan_package_dir(const std::string& variant);

}  // namespace iesrgs::priors::sr
