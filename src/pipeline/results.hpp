#pragma once
// A run's table: its rows' scores, training times and rendering speeds, written as results.json,
// .csv and .md, and each scored row's own result.json, from which a later run keeps it.
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "eval/metrics.hpp"
#include "pipeline/rows.hpp"

namespace iesrgs::pipeline {

struct RowResult {
  std::string id, label;
  eval::ViewMetrics mean;  // over the test views; evaluated only with ground truth
  bool evaluated = false;
  double train_seconds = 0;       // the row's own HR training (internal only: the LR model's)
  double fps = 0;                 // test-view rendering at HR
  bool from_earlier_run = false;  // read from its result.json, not run by this command
};

struct RunResult {
  std::vector<RowResult> rows;
  nlohmann::json stages;      // seconds per stage
  nlohmann::json evaluation;  // what the rows were scored against: test views' digest, LPIPS net
};
// Where a scored row keeps its entry of the table and what it was scored against, in its folder:
// a later run with other rows finds it there.
inline constexpr char kRowResultFile[] = "result.json";

// Writes <row_dir>/result.json atomically: {"evaluation": evaluation, "row": the row's entry}.
void write_row_result(const std::filesystem::path& row_dir, const RowResult& row,
                      const nlohmann::json& evaluation);

// A folder written before rows kept their own scores holds them in <output>/results.json alone:
// gives each row whose folder is still there, and has no result.json, its entry from the table.
void keep_table_scores_in_rows(const std::filesystem::path& output);

// The row of an earlier run's entry; kept only under the current settings, so its label is the
// one they give.
RowResult earlier_row(const RowSpec& spec, std::string label, const nlohmann::json& entry);

// The table as Markdown, then the time per stage; rows without ground truth show "-".
std::string results_markdown(const RunResult& result);

// Writes <dir>/results.{json,csv,md}, each atomically.
void write_results(const std::filesystem::path& dir, const RunResult& result);

}  // namespace iesrgs::pipeline
