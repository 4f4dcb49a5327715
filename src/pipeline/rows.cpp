#include "pipeline/rows.hpp"

#include <fmt/core.h>

#include <iterator>

#include "core/error.hpp"

namespace iesrgs::pipeline {

namespace {

using loss::TextureGuidance;

constexpr RowSpec kRows[] = {
    {"bicubic", "bicubic-3DGS", Source::Bicubic, TextureGuidance::External, false, false, false},
    {"internal", "internal only (LR Mip-Splatting at HR)", Source::Internal,
     TextureGuidance::External, false, false, false},
    {"external", "external only (2D SR -> 3DGS)", Source::SuperResolved, TextureGuidance::External,
     false, false, false},
    {"external-depth", "+ E_depth", Source::SuperResolved, TextureGuidance::External, false, true,
     false},
    {"joint", "+ I_image (averaged, no mask)", Source::SuperResolved, TextureGuidance::Average,
     false, true, false},
    {"joint-depth", "+ I_depth", Source::SuperResolved, TextureGuidance::Average, true, true,
     false},
    {"ie-srgs", "IE-SRGS (+ mask)", Source::SuperResolved, TextureGuidance::Masked, true, true,
     false},
    {"mask-oracle", "IE-SRGS with the oracle mask (from the HR truth)", Source::SuperResolved,
     TextureGuidance::Masked, true, true, true},
    {"hr", "HR upper bound", Source::HighRes, TextureGuidance::External, false, false, false},
};

}  // namespace

const RowSpec* find_row(const std::string& id) {
  for (const RowSpec& row : kRows)
    if (id == row.id) return &row;
  return nullptr;
}

const RowSpec& row_spec(const std::string& id) {
  if (const RowSpec* row = find_row(id)) return *row;
  fail("unknown row '{}'; rows: {}", id, describe_rows());
}

size_t table_position(const std::string& id) {
  return size_t(find_row(id) - std::begin(kRows));
}

std::vector<std::string> expand_rows(const std::vector<std::string>& names) {
  std::vector<bool> wanted(std::size(kRows), false);
  for (const std::string& name : names) {
    for (size_t i = 0; i < std::size(kRows); ++i) {
      const std::string id = kRows[i].id;
      const bool ablation = id != "bicubic" && id != "hr" && id != "mask-oracle";
      const bool demo = id == "bicubic" || id == "internal" || id == "external" || id == "ie-srgs";
      if (name == id || name == "all" || (name == "ablation" && ablation) ||
          (name == "demo" && demo))
        wanted[i] = true;
    }
    if (name != "all" && name != "ablation" && name != "demo") row_spec(name);  // validates
  }
  std::vector<std::string> rows;
  for (size_t i = 0; i < std::size(kRows); ++i)
    if (wanted[i]) rows.push_back(kRows[i].id);
  if (rows.empty()) fail("--rows: no row selected");
  return rows;
}

std::string describe_rows() {
  std::string text;
  for (const RowSpec& row : kRows)
    text += fmt::format("{}{} ({})", text.empty() ? "" : ", ", row.id, row.label);
  return text + "; groups: demo, ablation, all";
}

}  // namespace iesrgs::pipeline
