// shadesim report, the outputs made from report.json: report.csv, report.md, the columns that do
// not apply, the contact sheet, and the plots by scripts/plot_report.py. report.csv and
// report.md are formatted from the JSON's values only, so that no figure is copied by hand.
#pragma once

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli/report_measure.h"
#include "image/image.h"

namespace shd::cli {

// The columns that do not apply, where and why: [{"columns", "where", "why"}], from the rows
// and options of a report (before its "not_applicable" member is set).
nlohmann::json notApplicable(const nlohmann::json& report);

// One line per row of report["rows"]; an empty cell where the JSON has null or nothing.
std::string reportCsv(const nlohmann::json& report);

// The readable report: a table per lobe, the units and their area, what does not apply, what was
// skipped, the contact sheet by position, the plots, the checks.
std::string reportMarkdown(const nlohmann::json& report);

// The contact sheet: one row per lobe with images, one column per method, each cell the image
// above its heat map; an empty cell light grey. `json` describes it (report.json's
// "contact_sheet").
struct ContactSheet {
  Image image;
  nlohmann::json json;
};
ContactSheet contactSheet(const Measured& m);

// The files scripts/plot_report.py may write.
extern const std::vector<std::string> kPlotFiles;

// scripts/plot_report.py run on the report (written into `tmp`, which is made and left for the
// caller to remove): its files (name, bytes) if a python3 that runs and gnuplot were found and it
// succeeded, else why not. `json` is report.json's "plots".
struct Plots {
  std::vector<std::pair<std::string, std::string>> files;
  nlohmann::json json;
};
Plots makePlots(const nlohmann::json& report, const std::filesystem::path& tmp);

}  // namespace shd::cli
