#include "train/config.hpp"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <type_traits>

#include "core/error.hpp"

namespace iesrgs::train {

namespace {

// One list of every field and its JSON name, shared by writing, reading and overriding.
template <typename Config, typename Visit>
void visit_fields(Config& c, Visit&& visit) {
  visit("preset", c.preset);
  visit("iterations", c.iterations);
  visit("views_per_iteration", c.views_per_iteration);
  visit("seed", c.seed);
  visit("dssim_weight", c.dssim_weight);
  visit("max_sh_degree", c.max_sh_degree);
  visit("sh_increase_every", c.sh_increase_every);
  visit("densify_from", c.densify_from);
  visit("densify_until", c.densify_until);
  visit("densify_every", c.densify_every);
  visit("opacity_reset_every", c.opacity_reset_every);
  visit("grad_threshold", c.grad_threshold);
  visit("absolute_gradients", c.absolute_gradients);
  visit("percent_dense", c.percent_dense);
  visit("min_opacity", c.min_opacity);
  visit("max_screen_size", c.max_screen_size);
  visit("max_world_size", c.max_world_size);
  visit("filter_update_every", c.filter_update_every);
  visit("max_gaussians", c.max_gaussians);
  visit("lr_position_initial", c.learning_rates.position_initial);
  visit("lr_position_final", c.learning_rates.position_final);
  visit("lr_position_max_steps", c.learning_rates.position_max_steps);
  visit("lr_sh_dc", c.learning_rates.sh_dc);
  visit("lr_sh_rest", c.learning_rates.sh_rest);
  visit("lr_opacity", c.learning_rates.opacity);
  visit("lr_scaling", c.learning_rates.scaling);
  visit("lr_rotation", c.learning_rates.rotation);
  visit("init", c.init);
  visit("random_points", c.random_points);
  visit("random_extent", c.random_extent);
  visit("checkpoint_every", c.checkpoint_every);
  visit("test_every", c.test_every);
  visit("test_views", c.test_views);
  visit("log_every", c.log_every);
}

template <typename T>
void read_field(const nlohmann::json& value, T& field, const std::string& key,
                const std::string& origin) {
  const bool ok = std::is_same_v<T, bool>          ? value.is_boolean()
                  : std::is_same_v<T, std::string> ? value.is_string()
                  : std::is_floating_point_v<T>    ? value.is_number()
                  : std::is_unsigned_v<T>          ? value.is_number_unsigned()
                                                   : value.is_number_integer();
  if (!ok) fail("{}: \"{}\" has the wrong type ({})", origin, key, value.dump());
  if constexpr (std::is_integral_v<T> && !std::is_same_v<T, bool>) {
    // JSON integers are 64-bit: a larger one than the field holds would wrap around.
    const bool fits = value.is_number_unsigned()
                          ? value.get<uint64_t>() <= uint64_t(std::numeric_limits<T>::max())
                          : value.get<int64_t>() >= int64_t(std::numeric_limits<T>::min()) &&
                                value.get<int64_t>() <= int64_t(std::numeric_limits<T>::max());
    if (!fits) fail("{}: \"{}\" is out of range ({})", origin, key, value.dump());
  }
  if constexpr (std::is_floating_point_v<T>) {
    // Beyond the field's range it would hold an infinity, which config.json cannot store.
    if (!(std::abs(value.get<double>()) <= double(std::numeric_limits<T>::max())))
      fail("{}: \"{}\" is out of range ({})", origin, key, value.dump());
  }
  field = value.get<T>();
}

int64_t scaled(int64_t steps, double ratio) {
  return std::max<int64_t>(1, std::llround(steps * ratio));
}

}  // namespace

TrainConfig make_preset(const std::string& name, int64_t iterations) {
  TrainConfig config;
  config.preset = name;
  if (name == "cpu") {
    // A third of the paper's schedule keeps densification's rhythm and reaches most of the
    // quality on two cores.
    rescale_schedule(config, 10000);
  } else if (name == "fast") {
    rescale_schedule(config, 3000);
    config.test_every = 500;
    config.checkpoint_every = 500;
  } else if (name != "paper") {
    fail("unknown preset \"{}\" (known: paper, cpu, fast)", name);
  }
  // 3DGS prunes large Gaussians from its first opacity reset on, when 25 densification steps
  // have split the model into small splats. A shortened schedule resets after a few steps, when
  // the model is still made of large splats (a 20-pixel rule deleted 84 % of lego's at 800x800),
  // so short presets leave that pruning off, as 3DGS does before its first reset.
  if (name != "paper") config.max_world_size = 0;
  if (iterations > 0) rescale_schedule(config, iterations);
  return config;
}

void rescale_schedule(TrainConfig& config, int64_t iterations) {
  if (iterations <= 0) fail("iterations must be positive, not {}", iterations);
  const double ratio = double(iterations) / double(config.iterations);
  config.densify_from = scaled(config.densify_from, ratio);
  config.densify_until = scaled(config.densify_until, ratio);
  // A reset undoes the opacities that densification's clones and splits start from; without a
  // densification step since the last one it only throws training away (3DGS has 30 between two).
  config.opacity_reset_every =
      std::max(scaled(config.opacity_reset_every, ratio), config.densify_every);
  config.sh_increase_every = scaled(config.sh_increase_every, ratio);
  config.learning_rates.position_max_steps = iterations;
  config.iterations = iterations;
}

nlohmann::json to_json(const TrainConfig& config) {
  nlohmann::json json = nlohmann::json::object();
  visit_fields(config, [&](const char* key, const auto& field) { json[key] = field; });
  return json;
}

std::vector<std::string> config_changes(const TrainConfig& from, const TrainConfig& to) {
  const nlohmann::json before = to_json(from), after = to_json(to);
  std::vector<std::string> changes;
  for (const auto& item : before.items())
    if (after[item.key()] != item.value() &&
        std::find(kReportingFields.begin(), kReportingFields.end(), item.key()) ==
            kReportingFields.end())
      changes.push_back(fmt::format("{} {} instead of {}", item.key(), after[item.key()].dump(),
                                    item.value().dump()));
  return changes;
}

void apply_json(TrainConfig& config, const nlohmann::json& json, const std::string& origin) {
  if (!json.is_object()) fail("{}: a training config must be a JSON object", origin);
  for (const auto& item : json.items()) {
    // Named references, not structured bindings: clang 14 cannot capture those in the lambda.
    const std::string& key = item.key();
    const nlohmann::json& value = item.value();
    bool known = false;
    visit_fields(config, [&](const char* name, auto& field) {
      if (key != name) return;
      read_field(value, field, key, origin);
      known = true;
    });
    if (!known) fail("{}: unknown training parameter \"{}\"", origin, key);
  }
}

void apply_assignment(TrainConfig& config, const std::string& assignment,
                      const std::string& option_prefix) {
  const std::string flag = option_prefix + "set";
  const size_t eq = assignment.find('=');
  if (eq == std::string::npos || eq == 0) fail("{} \"{}\": expected key=value", flag, assignment);
  const std::string key = assignment.substr(0, eq), text = assignment.substr(eq + 1);
  // The preset names where the schedule came from; setting the name alone would mislabel it.
  if (key == "preset")
    fail("{} \"{}\": the preset is chosen with {}, which also sets its schedule", flag, assignment,
         option_prefix + "preset");
  nlohmann::json value = nlohmann::json::parse(text, nullptr, false);
  if (value.is_discarded()) value = text;
  apply_json(config, nlohmann::json{{key, value}}, flag + " " + assignment);
}

void validate(const TrainConfig& c) {
  auto require = [](bool ok, const char* what) {
    if (!ok) fail("invalid training config: {}", what);
  };
  require(c.iterations > 0, "iterations must be positive");
  require(c.views_per_iteration >= 1, "views_per_iteration must be at least 1");
  require(c.dssim_weight >= 0 && c.dssim_weight <= 1, "dssim_weight must be in [0, 1]");
  require(c.max_sh_degree >= 0 && c.max_sh_degree <= 3, "max_sh_degree must be 0..3");
  require(c.sh_increase_every > 0, "sh_increase_every must be positive");
  require(c.densify_every > 0, "densify_every must be positive");
  require(c.opacity_reset_every > 0, "opacity_reset_every must be positive");
  require(c.filter_update_every > 0, "filter_update_every must be positive");
  require(c.log_every > 0, "log_every must be positive");
  require(c.checkpoint_every >= 0 && c.test_every >= 0 && c.test_views >= 0,
          "checkpoint_every, test_every and test_views must not be negative");
  require(c.densify_from >= 0 && c.densify_until >= 0,
          "densify_from and densify_until must not be negative");
  require(c.grad_threshold > 0, "grad_threshold must be positive");
  require(c.percent_dense >= 0, "percent_dense must not be negative");
  require(c.min_opacity >= 0 && c.min_opacity < 1, "min_opacity must be in [0, 1)");
  require(c.max_screen_size >= 0 && c.max_world_size >= 0,
          "max_screen_size and max_world_size must be 0 (off) or positive");
  require(c.max_gaussians >= 0, "max_gaussians must be 0 (no cap) or positive");
  require(c.init == "auto" || c.init == "random", "init must be \"auto\" or \"random\"");
  require(c.random_points > 0, "random_points must be positive");
  require(c.random_extent >= 0, "random_extent must be 0 (from the scene) or positive");
  const gs::LearningRates& lr = c.learning_rates;
  require(lr.position_max_steps > 0, "lr_position_max_steps must be positive");
  // The position rate decays log-linearly between the two: a zero at one end is zero throughout.
  require((lr.position_initial > 0 && lr.position_final > 0) ||
              (lr.position_initial == 0 && lr.position_final == 0),
          "lr_position_initial and lr_position_final must both be positive, or both 0 (positions "
          "held fixed)");
  require(
      lr.sh_dc >= 0 && lr.sh_rest >= 0 && lr.opacity >= 0 && lr.scaling >= 0 && lr.rotation >= 0,
      "learning rates must not be negative (0 holds a parameter fixed)");
}

}  // namespace iesrgs::train
