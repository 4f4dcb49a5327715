#pragma once
// The rows of a run's table: what supervises each row's HR model and which of the fusion loss's
// terms it uses, so that the paper's baselines, ablation steps and IE-SRGS are settings of one
// training.
#include <string>
#include <vector>

#include "loss/fusion.hpp"

namespace iesrgs::pipeline {

// What supervises a row's HR model.
enum class Source {
  Internal,       // no HR model: the internal LR model itself, rendered at HR
  SuperResolved,  // the external (and internal) knowledge
  Bicubic,        // bicubic-upsampled LR views
  HighRes,        // the HR ground truth (upper bound)
};

struct RowSpec {
  const char* id;
  const char* label;
  Source source;
  loss::TextureGuidance texture;
  bool internal_depth, external_depth;
  // The mask from the HR truth instead of D: the internal image wherever it is the closer
  // reference. What IE-SRGS would reach with a perfect mask; benchmarks only.
  bool oracle_mask;

  static bool needs_truth(const RowSpec& row) {
    return row.source == Source::HighRes || row.oracle_mask;
  }
};

// The row named `id`, or null.
const RowSpec* find_row(const std::string& id);
// The same; throws Error naming the rows for an unknown one.
const RowSpec& row_spec(const std::string& id);
// Where the row stands in the table.
size_t table_position(const std::string& id);

// Row names in table order, with the groups "demo" (bicubic, internal, external, ie-srgs),
// "ablation" and "all" expanded. Throws Error for an unknown name.
std::vector<std::string> expand_rows(const std::vector<std::string>& names);
// "name (what it is)" for every row, and the groups, for --help.
std::string describe_rows();

}  // namespace iesrgs::pipeline
