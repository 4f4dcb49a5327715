#include "pipeline/results.hpp"

#include <fmt/core.h>

#include <utility>

#include "core/progress.hpp"
#include "io/atomic_file.hpp"
#include "pipeline/stage_record.hpp"

namespace iesrgs::pipeline {

namespace {

nlohmann::json row_json(const RowResult& row) {
  nlohmann::json entry = {{"row", row.id},
                          {"label", row.label},
                          {"train_seconds", row.train_seconds},
                          {"fps", row.fps}};
  if (row.from_earlier_run) entry["from_earlier_run"] = true;
  if (row.evaluated) {
    entry["psnr"] = row.mean.psnr;
    entry["ssim"] = row.mean.ssim;
    if (row.mean.lpips) entry["lpips"] = *row.mean.lpips;
  }
  return entry;
}

std::string format_metric(const RowResult& row, double value, int decimals) {
  return row.evaluated ? fmt::format("{:.{}f}", value, decimals) : "-";
}

// The time of each stage, from `stages` (results.json's), in pipeline order: what the paper's
// Table 5 reports. A stage reused from the cache counts the time it took when it ran; rows kept
// from an earlier run have none.
std::string stages_markdown(const RunResult& result) {
  const nlohmann::json& stages = result.stages;
  std::string md = "| stage | time |\n|---|---|\n";
  const auto add = [&](const std::string& stage, const nlohmann::json& seconds) {
    if (seconds.is_number())
      md += fmt::format("| {} | {} |\n", stage, format_duration(seconds.get<double>()));
  };
  // A missing entry is null, which `add` skips.
  const auto entry = [](const nlohmann::json& object, const std::string& key) {
    return object.is_object() ? object.value(key, nlohmann::json()) : nlohmann::json();
  };
  add("external knowledge (E_image, E_depth)", entry(stages, "external_seconds"));
  add("internal model (LR Mip-Splatting)", entry(stages, "internal_training_seconds"));
  add("SR-splatting (I_image, I_depth at HR)", entry(stages, "sr_splatting_seconds"));
  for (const RowResult& row : result.rows)
    add("HR training, " + row.id, entry(entry(stages, "fusion_seconds"), row.id));
  for (const RowResult& row : result.rows)
    add("rendering and scoring, " + row.id, entry(entry(stages, "evaluation_seconds"), row.id));
  add("this run in all", entry(stages, "total_seconds_this_run"));
  return md;
}

void write_row_record(const std::filesystem::path& row_dir, const nlohmann::json& entry,
                      const nlohmann::json& evaluation) {
  const nlohmann::json record = {{"evaluation", evaluation}, {"row", entry}};
  write_file_atomically(row_dir / kRowResultFile, record.dump(2) + "\n");
}

}  // namespace

void write_row_result(const std::filesystem::path& row_dir, const RowResult& row,
                      const nlohmann::json& evaluation) {
  write_row_record(row_dir, row_json(row), evaluation);
}

void keep_table_scores_in_rows(const std::filesystem::path& output) {
  const nlohmann::json table = read_stage_record(output / "results.json");
  const nlohmann::json rows = table.value("rows", nlohmann::json());
  if (!rows.is_array()) return;
  for (const nlohmann::json& entry : rows) {
    if (!entry.is_object() || !entry.value("row", nlohmann::json()).is_string()) continue;
    const std::string id = entry["row"].get<std::string>();
    const std::filesystem::path dir = output / "rows" / id;
    std::error_code ec;
    if (!find_row(id) || !std::filesystem::is_directory(dir, ec) ||
        std::filesystem::exists(dir / kRowResultFile, ec))
      continue;
    write_row_record(dir, entry, table.value("evaluation", nlohmann::json()));
  }
}

RowResult earlier_row(const RowSpec& spec, std::string label, const nlohmann::json& entry) {
  RowResult row;
  row.id = spec.id;
  row.label = std::move(label);
  row.from_earlier_run = true;
  row.train_seconds = entry.value("train_seconds", 0.0);
  row.fps = entry.value("fps", 0.0);
  row.evaluated = entry.contains("psnr") && entry.contains("ssim");
  if (row.evaluated) {
    row.mean.psnr = entry.value("psnr", 0.0);
    row.mean.ssim = entry.value("ssim", 0.0);
    if (entry.contains("lpips")) row.mean.lpips = entry.value("lpips", 0.0);
  }
  return row;
}

std::string results_markdown(const RunResult& result) {
  std::string md =
      "| row | PSNR | SSIM | LPIPS | HR training | FPS at HR |\n|---|---|---|---|---|---|\n";
  bool earlier = false;
  for (const RowResult& row : result.rows) {
    earlier = earlier || row.from_earlier_run;
    md += fmt::format("| {}{} | {} | {} | {} | {} | {} |\n", row.label,
                      row.from_earlier_run ? " *" : "", format_metric(row, row.mean.psnr, 2),
                      format_metric(row, row.mean.ssim, 4),
                      row.mean.lpips ? fmt::format("{:.4f}", *row.mean.lpips) : "-",
                      format_duration(row.train_seconds),
                      row.fps > 0 ? fmt::format("{:.1f}", row.fps) : "-");  // none rendered
  }
  if (earlier) md += "\n\\* from an earlier run in this folder with the same settings\n";
  return md + "\n" + stages_markdown(result);
}

void write_results(const std::filesystem::path& dir, const RunResult& result) {
  nlohmann::json json = {{"stages", result.stages},
                         {"evaluation", result.evaluation},
                         {"rows", nlohmann::json::array()}};
  std::string csv = "row,label,psnr,ssim,lpips,train_seconds,fps,from_earlier_run\n";
  for (const RowResult& row : result.rows) {
    json["rows"].push_back(row_json(row));
    csv +=
        fmt::format("{},\"{}\",{},{},{},{},{},{}\n", row.id, row.label,
                    format_metric(row, row.mean.psnr, 4), format_metric(row, row.mean.ssim, 5),
                    row.mean.lpips ? fmt::format("{:.5f}", *row.mean.lpips) : "", row.train_seconds,
                    row.fps > 0 ? fmt::format("{}", row.fps) : "", row.from_earlier_run);
  }
  write_files_atomically({{dir / "results.json", json.dump(2) + "\n"},
                          {dir / "results.csv", csv},
                          {dir / "results.md", results_markdown(result)}});
}

}  // namespace iesrgs::pipeline
