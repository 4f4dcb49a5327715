#include "priors/sr/registry.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <functional>
#include <map>
#include <regex>

#include "core/error.hpp"
#include "priors/sr/bicubic.hpp"
#include "priors/sr/esrgan.hpp"
#include "priors/sr/imdn.hpp"
#include "priors/sr/network_sr.hpp"
#include "priors/sr/pan.hpp"
#include "priors/sr/safmn.hpp"
#include "priors/sr/sr_net.hpp"
#include "priors/sr/swinir.hpp"
#include "priors/state_dict.hpp"

namespace iesrgs::priors::sr {

namespace fs = std::filesystem;
namespace F = torch::nn::functional;

namespace {

// Pads by edge replication up to `min_side` pixels a side (SAFMN's smallest input).
InputPad replicate_to(int64_t min_side) {
  return [min_side](const torch::Tensor& rgb) {
    const int64_t pad_y = std::max<int64_t>(0, min_side - rgb.size(2));
    const int64_t pad_x = std::max<int64_t>(0, min_side - rgb.size(3));
    if (pad_x == 0 && pad_y == 0) return rgb;
    return F::pad(rgb, F::PadFuncOptions({0, pad_x, 0, pad_y}).mode(torch::kReplicate));
  };
}

// `weights`, or when empty the model's default checkpoint, which must then exist.
fs::path checkpoint_file(const std::string& model, int scale, const fs::path& weights) {
  if (!weights.empty()) return weights;
  const fs::path file = default_sr_weights(model, scale);
  if (!fs::exists(file))
    fail_file(file, fmt::format("not found, and {} was given no other checkpoint (pass one, or "
                                "set IESRGS_WEIGHTS_DIR to the folder above sr/)",
                                model));
  return file;
}

using Factory = std::function<std::unique_ptr<SrNet>(const fs::path& weights, int scale)>;
// Refuses, naming the file, checkpoints of a release the network does not build.
using ReleaseCheck = void (*)(const StateDict& weights, const fs::path& file);

// Refuses a checkpoint whose name states another scale than `scale`. The layout cannot always
// tell: PAN's x2 and x3 files have the same names and shapes, and either would run at the other's
// scale without a word.
void check_scale_in_name(const fs::path& file, int scale) {
  const int stated = scale_in_file_name(file);
  if (stated != 0 && stated != scale)
    fail_file(file, fmt::format("its name says x{}, but x{} was requested (rename the file if it "
                                "really is a x{} checkpoint)",
                                stated, scale, scale));
}

// A network whose configuration is the released one at any scale.
template <class Net, class Options>
Factory network(const std::string& model, ReleaseCheck check_release = nullptr) {
  return [model, check_release](const fs::path& weights, int scale) {
    const fs::path file = checkpoint_file(model, scale, weights);
    check_scale_in_name(file, scale);
    const StateDict state = read_state_dict(file);
    if (check_release) check_release(state, file);
    Options options;
    options.scale = scale;
    Net net(options);
    load_state_dict(*net, state, file);
    return std::make_unique<NetworkSr<Net>>(model, std::move(net), scale);
  };
}

// SAFMN in whichever released layout and size the checkpoint has.
std::unique_ptr<SrNet> make_safmn(const fs::path& weights, int scale) {
  const fs::path file = checkpoint_file("safmn", scale, weights);
  const StateDict state = read_state_dict(file);
  const SafmnOptions options = infer_safmn_options(state, file);
  if (options.scale != scale)
    fail_file(file,
              fmt::format("a x{} SAFMN checkpoint, but x{} was requested", options.scale, scale));
  Safmn net(options);
  load_state_dict(*net, state, file);
  return std::make_unique<NetworkSr<Safmn>>("safmn", std::move(net), scale,
                                            replicate_to(safmn_min_side(options.release)));
}

const std::map<std::string, Factory>& factories() {
  static const std::map<std::string, Factory> table = [] {
    std::map<std::string, Factory> models = {
        {"bicubic", [](const fs::path&, int scale) { return make_bicubic(scale); }},
        {"safmn", make_safmn},
        {"imdn", network<Imdn, ImdnOptions>("imdn", check_imdn_release)},
        {"pan", network<Pan, PanOptions>("pan")},
        {"swinir", [](const fs::path& weights, int scale) { return make_swinir(weights, scale); }},
    };
    for (const std::string variant : {"slim", "medium", "thick"})
      models["esrgan-" + variant] = [variant](const fs::path& package, int scale) {
        return make_esrgan(variant, scale, package);
      };
    return models;
  }();
  return table;
}

}  // namespace

fs::path default_sr_weights(const std::string& model, int scale) {
  std::string upper = model;
  std::transform(upper.begin(), upper.end(), upper.begin(),
                 [](unsigned char c) { return char(std::toupper(c)); });
  return default_weights_dir() / "sr" / fmt::format("{}_x{}.pth", upper, scale);
}

int scale_in_file_name(const fs::path& file) {
  static const std::regex token("(^|[^a-z0-9])x([1-9])(?![0-9])");
  const std::string stem = file.stem().string();
  int stated = 0;
  for (auto it = std::sregex_iterator(stem.begin(), stem.end(), token);
       it != std::sregex_iterator(); ++it) {
    const int scale = std::stoi((*it)[2].str());
    if (stated != 0 && scale != stated) return 0;
    stated = scale;
  }
  return stated;
}

const std::vector<std::string>& sr_model_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> keys;
    for (const auto& entry : factories()) keys.push_back(entry.first);
    return keys;
  }();
  return names;
}

std::unique_ptr<SrNet> make_sr_net(const std::string& model, const fs::path& weights, int scale) {
  const auto found = factories().find(model);
  if (found == factories().end())
    fail("unknown super-resolution model '{}' (known: {})", model,
         fmt::join(sr_model_names(), ", "));
  if (scale < 1) fail("{}: invalid scale {}", model, scale);
  return found->second(weights, scale);
}

std::string auto_sr_model(int scale) {
  if (fs::exists(default_sr_weights("safmn", scale))) return "safmn";
  for (const char* variant : kSetupEsrganVariants)
    if (fs::exists(esrgan_model_dir(variant, scale, {}) / "model.json"))
      return std::string("esrgan-") + variant;
  return "bicubic";
}

}  // namespace iesrgs::priors::sr
