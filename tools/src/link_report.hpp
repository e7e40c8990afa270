// The link part of a run's outputs: frames.csv, the bits-per-frame plot, the report.json block and the summary
// lines (does it fit, and on what link would it).
#pragma once

#include "output_dir.hpp"
#include "pipeline.hpp"
#include "run_report.hpp"

#include <string>

namespace trm::cli {

// Writes frames.csv and link_bits.png into dir; returns the report.json "link" block.
Json write_link_outputs(const OutputDir& dir, const PipelineOptions& options, const LinkOutcome& outcome,
                        int full_width, int full_height);
std::string link_summary_lines(const LinkOutcome& outcome);
// The receiver's counters as report.json holds them (run --link and decode --capture).
Json receiver_json(const link::ReceiverCounters& counters);

}  // namespace trm::cli
