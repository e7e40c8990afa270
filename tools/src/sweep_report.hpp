// The reports of `trm sweep` over a SweepResult: sweep.csv, sweep.md, report.json, the per-knob plots and the table
// printed to stdout.
#pragma once

#include "sweep.hpp"

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include <filesystem>
#include <string>

namespace trm::cli {

// sweep.csv: a header and one row per knob x value.
std::string sweep_csv(const SweepResult& result);
// sweep.md: parameters, a summary per knob, then one table per knob (the base value marked).
std::string sweep_markdown(const SweepResult& result);
// report.json: parameters, base configuration and every point.
Json sweep_json(const SweepResult& result);
// Its "parameters" block: the sequence and configuration every point was decoded with.
Json sweep_parameters_json(const SweepResult& result);
// sweep_<knob>.png: error against knob value, against memory and against decode time.
void write_sweep_plot(const std::filesystem::path& path, const SweepResult& result, const SweepKnobResult& knob);
// The short table printed to stdout: per knob, the base point and the cheapest point meeting the criterion.
std::string sweep_summary(const SweepResult& result);

}  // namespace trm::cli
