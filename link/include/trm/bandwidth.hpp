// Bandwidth accounting per link frame: bits on the wire, time on the wire, fit in the frame period.
#pragma once

#include "trm/link.hpp"
#include "trm/presets.hpp"
#include "trm/atomic_file.hpp"

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace trm::link {

// What a link frame may use: the preset's data rate for one frame period at the refresh rate, less the
// blanking time of the panel's video timing when one is given (CVT-RB v2, option).
struct LinkBudget {
  LinkPreset preset;
  double refresh_hz = 90.0;
  std::optional<VideoTiming> blanking;  // nullopt: the whole period carries data

  void validate() const;  // throws std::invalid_argument (refresh <= 0, data rate <= 0)
  double frame_period_seconds() const { return 1.0 / refresh_hz; }
  double available_seconds() const;       // period * active fraction
  double capacity_bits_per_frame() const;  // data rate * available time
};

struct LinkFrameUsage {
  std::int64_t index = 0;       // link frame t
  int views = 0;                // 1 mono, 2 stereo
  std::string parities;         // per view in stream order: "F", "R", "FR", "RF"
  ViewBits bits;                // summed over the views
  double wire_seconds = 0.0;    // (payload + overhead) bits / data rate
  double available_seconds = 0.0;
  double utilisation = 0.0;     // wire / available
  bool fits = false;
};

struct BandwidthSummary {
  std::int64_t link_frames = 0;
  std::uint64_t peak_wire_bits = 0;
  double average_wire_bits = 0.0;
  std::uint64_t peak_payload_bits = 0;
  double average_payload_bits = 0.0;
  std::uint64_t total_pixel_bits = 0;
  std::uint64_t total_payload_bits = 0;
  std::uint64_t total_overhead_bits = 0;
  double peak_utilisation = 0.0;
  double average_utilisation = 0.0;
  std::int64_t frames_not_fitting = 0;
  bool fits = true;
  // The data rate (after coding) the peak link frame needs, Gbit/s: peak wire bits / available time.
  double required_data_gbps = 0.0;
  // The slowest built-in preset the peak link frame fits, or nullopt if none does.
  std::optional<LinkPreset> minimum_preset;
};

// Keeps running statistics only, so that its memory does not grow with the run; each frame's usage (what
// add() returns) is streamed by the caller, e.g. into a FramesCsvWriter.
class BandwidthMeter {
 public:
  explicit BandwidthMeter(LinkBudget budget);
  const LinkBudget& budget() const { return budget_; }

  // Accounts link frame `index` made of these views (one per stream, in stream order).
  const LinkFrameUsage& add(std::int64_t index, std::span<const SentView> views);
  // The same from bit counts alone (e.g. predicted full-rate views).
  const LinkFrameUsage& add(std::int64_t index, const std::string& parities, const ViewBits& bits, int views);

  const LinkFrameUsage& last() const { return last_; }  // the most recently added link frame
  BandwidthSummary summary() const;

 private:
  LinkBudget budget_;
  LinkFrameUsage last_;
  BandwidthSummary running_;  // counts, peaks and totals; summary() adds the averages
  double wire_sum_ = 0.0, payload_sum_ = 0.0, utilisation_sum_ = 0.0;
};

// The slowest built-in preset on which `wire_bits` fit in one frame period (less blanking, if given).
std::optional<LinkPreset> minimum_fitting_preset(std::uint64_t wire_bits, double refresh_hz,
                                                 const std::optional<VideoTiming>& blanking);

// OUT/frames.csv: one row per link frame. Columns:
// link_frame,time_s,views,parities,pixel_bits,payload_bits,overhead_bits,wire_bits,packets,
// wire_time_s,available_time_s,utilisation,fits,method
// `method` names the display method whose views the link frame carried, so that files of several methods' runs can
// be read together.
// Rows are streamed to a temporary name in the same directory and renamed on close(), so a reader never
// sees half a file. Throws std::runtime_error naming the path on an I/O failure; a writer destroyed
// unclosed removes its temporary file.
class FramesCsvWriter {
 public:
  FramesCsvWriter(const std::filesystem::path& path, double refresh_hz, std::string method);
  void add(const LinkFrameUsage& usage);
  void close();

 private:
  io::AtomicFile file_;
  double refresh_hz_;
  std::string method_;
  bool closed_ = false;
};
void write_frames_csv(const std::filesystem::path& path, std::span<const LinkFrameUsage> frames, double refresh_hz,
                      const std::string& method);

// A series of bits per link frame of any length in bounded memory, for plotting: consecutive values are folded into at most max_buckets
// buckets of a power-of-two width. Up to max_buckets values each bucket holds one value and the plot is
// exactly that of the whole series; beyond, a bucket is well under a pixel column wide and its min..max span
// draws what the whole series would.
class PlotTrace {
 public:
  struct Bucket {
    double first, last;
    double min, max;  // over the finite values; min > max when there are none
  };
  explicit PlotTrace(std::string label, std::size_t max_buckets = 4096);  // max_buckets: even, >= 2
  void add(double bits);

  const std::string& label() const { return label_; }
  std::int64_t count() const { return count_; }
  std::int64_t bucket_width() const { return width_; }
  const std::vector<Bucket>& buckets() const { return buckets_; }

 private:
  std::string label_;
  std::size_t max_buckets_;
  std::int64_t count_ = 0, width_ = 1;
  std::vector<Bucket> buckets_;
};

}  // namespace trm::link
