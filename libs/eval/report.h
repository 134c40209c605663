// Reports of an evaluation: the JSON body of metrics.json (schemas/metrics.schema.json), a text
// table for the terminal, Markdown, and the data the plotting script draws. Pure formatting.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "eval/evaluate.h"

namespace jvl::eval {

nlohmann::json OptionsToJson(const EvalOptions& options);
nlohmann::json StatsToJson(const ErrorStats& stats);
nlohmann::json SequenceToJson(const SequenceEval& sequence, const EvalOptions& options);
nlohmann::json EstimateToJson(const EstimateEval& estimate, const EvalOptions& options);
// {"options": ..., "estimates": [...]}: the body of a metrics report.
nlohmann::json ReportToJson(const std::vector<EstimateEval>& estimates, const EvalOptions& options);

// Fixed-width comparison table (one row per estimate, plus per-sequence rows for several).
std::string FormatTable(const std::vector<EstimateEval>& estimates, const EvalOptions& options);
// The same as Markdown, with the KITTI per-length table of each estimate.
std::string FormatMarkdown(const std::vector<EstimateEval>& estimates, const EvalOptions& options);

// Positions, per-frame APE and per-length KITTI errors for scripts/plot_eval.py.
nlohmann::json PlotData(const std::vector<EstimateEval>& estimates, const EvalOptions& options);

}  // namespace jvl::eval
