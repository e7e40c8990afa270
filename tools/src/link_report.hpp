// The link part of a run's outputs: frames.csv, the bits-per-frame plot, the report.json block and the summary
// lines (does it fit, and on what link would it).
#pragma once

#include "output_dir.hpp"
#include "pipeline.hpp"
#include "run_report.hpp"

#include <string>

namespace trm::cli {

// Streams frames.csv (a row per link frame as it is carried) and keeps the plot's trace of this run bounded, so
// that a long run's memory stays flat.
class LinkRecorder {
 public:
  LinkRecorder(const OutputDir& dir, const PipelineOptions& options);
  void add(const link::LinkFrameUsage& usage);
  // Closes frames.csv, draws link_bits.png; returns the report.json "link" block.
  Json finish(const LinkOutcome& outcome, int full_width, int full_height);

 private:
  const OutputDir& dir_;
  const PipelineOptions& options_;
  link::FramesCsvWriter csv_;
  link::PlotTrace measured_;
};
std::string link_summary_lines(const LinkOutcome& outcome);
// The receiver's counters as report.json holds them (run --link and decode --capture).
Json receiver_json(const link::ReceiverCounters& counters);

}  // namespace trm::cli
