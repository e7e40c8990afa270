// The reports of `trm sweep` over a SweepResult: sweep.csv, sweep.md, report.json, the per-knob plots and the table
// printed to stdout.
#pragma once

#include "sweep.hpp"

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include <filesystem>
#include <string>
#include <vector>

namespace trm::cli {

// sweep.csv: a header and one row per knob x value (value_label: an index knob's value by name, else the number).
std::string sweep_csv(const SweepResult& result);
// sweep.md: parameters, a summary per knob, then one table per knob (the base value marked).
std::string sweep_markdown(const SweepResult& result);
// report.json: parameters, base configuration and every point.
Json sweep_json(const SweepResult& result);
// Its "parameters" block: the sequence and configuration every point was decoded with.
Json sweep_parameters_json(const SweepResult& result);
// sweep_<knob>.png: error against knob value, against memory and against decode time (eye-model knobs: the visual
// difference against the eye-model time).
void write_sweep_plot(const std::filesystem::path& path, const SweepResult& result, const SweepKnobResult& knob);
// sweep_pareto.png: the decoder knobs' mean code error against decode time and against memory, the eye-model knobs'
// visual difference against eye-model time, and when it was swept the LC model's against eye-model time (a chart of
// its own: its reference is the second-order overdriven LC, not the exact eye); each chart marks its Pareto front
// and the default point.
void write_pareto_plot(const std::filesystem::path& path, const SweepResult& result);
// The indices of the points on the Pareto front of (cost, error), both minimised: those no other point beats with
// cost <= and error <= and one of them <. Ascending cost; equal points are all on it. Throws std::invalid_argument
// when the two differ in length.
std::vector<std::size_t> pareto_front(const std::vector<double>& cost, const std::vector<double>& error);
// The short table printed to stdout: per knob, the base point and the cheapest point meeting the criterion.
std::string sweep_summary(const SweepResult& result);

}  // namespace trm::cli
