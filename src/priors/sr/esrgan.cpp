#include "priors/sr/esrgan.hpp"

#include <fmt/format.h>
#include <fmt/ostream.h>

#include <algorithm>
#include <cstdlib>
#include <iterator>
#include <vector>

#include "core/error.hpp"
#include "core/paths.hpp"
#include "io/image_tensor.hpp"
#include "priors/keras_model.hpp"

namespace iesrgs::priors::sr {

namespace {

namespace fs = std::filesystem;

struct Variant {
  const char* name;
  // UpscalerJS feeds its RDN models (slim, medium) pixels in 0..255 and its RRDN model (thick)
  // pixels in 0..1, and clips their outputs to the same range.
  float pixel_range;
};

constexpr Variant kVariants[] = {{"slim", 255.f}, {"medium", 255.f}, {"thick", 1.f}};
constexpr int kScales[] = {2, 3, 4, 8};

const Variant& find_variant(const std::string& name) {
  for (const Variant& variant : kVariants)
    if (name == variant.name) return variant;
  fail("unknown ESRGAN variant '{}' (known: slim, medium, thick)", name);
}

class Esrgan final : public SrNet {
 public:
  Esrgan(std::string name, int scale, float pixel_range, keras::LayersModel model)
      : name_(std::move(name)), scale_(scale), range_(pixel_range), model_(std::move(model)) {}

  std::string name() const override { return name_; }
  int scale() const override { return scale_; }

  torch::Tensor upscale(const torch::Tensor& rgb) override {
    check_rgb_batch(rgb, name_);
    const torch::NoGradGuard no_grad;
    const torch::Tensor output = model_.forward(rgb * range_);
    const std::vector<int64_t> expected{1, 3, rgb.size(2) * scale_, rgb.size(3) * scale_};
    if (output.sizes() != torch::IntArrayRef(expected))
      fail("{}: the model returned shape {}, expected {}", name_, fmt::streamed(output.sizes()),
           fmt::streamed(torch::IntArrayRef(expected)));
    return output.div(range_).clamp_(0, 1);
  }

 private:
  std::string name_;
  int scale_;
  float range_;
  keras::LayersModel model_;
};

fs::path npm_dir() {
  return env_path("IESRGS_NPM_DIR").value_or(IESRGS_DEFAULT_NPM_DIR);
}

// The npm command spelled out, as setup runs it (which installs only kSetupEsrganVariants); the
// loader was checked against the 1.0.0 packages. npm removes the unsaved packages that an install
// does not name, so it names setup's and those already installed too.
std::string install_hint(const std::string& variant, bool default_location) {
  const std::string name = "esrgan-" + variant;
  if (!default_location) return fmt::format("the folder is not an @upscalerjs/{} package", name);
  const auto by_setup = [](const std::string& v) {
    return std::find(std::begin(kSetupEsrganVariants), std::end(kSetupEsrganVariants), v) !=
           std::end(kSetupEsrganVariants);
  };
  std::vector<std::string> packages;
  for (const Variant& known : kVariants)
    if (by_setup(known.name) || known.name == variant ||
        fs::exists(default_esrgan_package_dir(known.name)))
      packages.push_back(fmt::format("@upscalerjs/esrgan-{}@1.0.0", known.name));
  return fmt::format("npm install --prefix {} --no-save --omit=peer {} installs it{}",
                     npm_dir().string(), fmt::join(packages, " "),
                     by_setup(variant) ? ", and so does scripts/setup.sh" : "");
}

}  // namespace

fs::path default_esrgan_package_dir(const std::string& variant) {
  return npm_dir() / "node_modules" / "@upscalerjs" / ("esrgan-" + variant);
}

fs::path esrgan_model_dir(const std::string& variant, int scale, const fs::path& package_dir) {
  const fs::path folder = package_dir.empty() ? default_esrgan_package_dir(variant) : package_dir;
  return folder / "models" / fmt::format("x{}", scale);
}

std::unique_ptr<SrNet> make_esrgan(const std::string& variant, int scale,
                                   const fs::path& package_dir) {
  const Variant& found = find_variant(variant);
  const std::string name = "esrgan-" + variant;
  if (std::find(std::begin(kScales), std::end(kScales), scale) == std::end(kScales))
    fail("{}: no model for scale {} (available: 2, 3, 4, 8)", name, scale);
  const fs::path model_json = esrgan_model_dir(variant, scale, package_dir) / "model.json";
  if (!fs::exists(model_json))
    fail_file(model_json, fmt::format("{} is not installed ({})", name,
                                      install_hint(variant, package_dir.empty())));
  keras::LayersModel model = keras::LayersModel::load(model_json);
  if (model.input_channels() != 3) fail_file(model_json, "the model does not take RGB input");
  return std::make_unique<Esrgan>(name, scale, found.pixel_range, std::move(model));
}

}  // namespace iesrgs::priors::sr
