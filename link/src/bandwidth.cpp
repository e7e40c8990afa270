#include "trm/bandwidth.hpp"

#include "trm/atomic_file.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <system_error>

namespace trm::link {

void LinkBudget::validate() const {
  validate_refresh_hz(refresh_hz, "link budget: the refresh");
  if (!(preset.data_gbps() > 0.0 && preset.data_gbps() <= kMaxLinkGbps))
    throw std::invalid_argument("link budget: link data rate must be > 0 and <= " + std::to_string(static_cast<int>(kMaxLinkGbps)) +
                                " Gbit/s");
}

double LinkBudget::available_seconds() const {
  return frame_period_seconds() * (blanking ? blanking->active_fraction() : 1.0);
}

double LinkBudget::capacity_bits_per_frame() const { return preset.data_bits_per_second() * available_seconds(); }

BandwidthMeter::BandwidthMeter(LinkBudget budget) : budget_(std::move(budget)) { budget_.validate(); }

const LinkFrameUsage& BandwidthMeter::add(std::int64_t index, std::span<const SentView> views) {
  ViewBits bits;
  std::string parities;
  for (const SentView& v : views) {
    bits += v.bits;
    parities += v.meta.parity == Parity::Full ? 'F' : 'R';
  }
  return add(index, parities, bits, static_cast<int>(views.size()));
}

const LinkFrameUsage& BandwidthMeter::add(std::int64_t index, const std::string& parities, const ViewBits& bits,
                                          int views) {
  LinkFrameUsage u;
  u.index = index;
  u.views = views;
  u.parities = parities;
  u.bits = bits;
  u.wire_seconds = static_cast<double>(bits.wire_bits()) / budget_.preset.data_bits_per_second();
  u.available_seconds = budget_.available_seconds();
  u.utilisation = u.wire_seconds / u.available_seconds;
  u.fits = u.wire_seconds <= u.available_seconds;
  BandwidthSummary& s = running_;
  ++s.link_frames;
  s.peak_wire_bits = std::max(s.peak_wire_bits, bits.wire_bits());
  s.peak_payload_bits = std::max(s.peak_payload_bits, bits.payload_bits);
  s.peak_utilisation = std::max(s.peak_utilisation, u.utilisation);
  s.total_pixel_bits += bits.pixel_bits;
  s.total_payload_bits += bits.payload_bits;
  s.total_overhead_bits += bits.overhead_bits;
  wire_sum_ += static_cast<double>(bits.wire_bits());
  payload_sum_ += static_cast<double>(bits.payload_bits);
  utilisation_sum_ += u.utilisation;
  if (!u.fits) ++s.frames_not_fitting;
  last_ = std::move(u);
  return last_;
}

BandwidthSummary BandwidthMeter::summary() const {
  BandwidthSummary s = running_;
  if (s.link_frames > 0) {
    const double n = static_cast<double>(s.link_frames);
    s.average_wire_bits = wire_sum_ / n;
    s.average_payload_bits = payload_sum_ / n;
    s.average_utilisation = utilisation_sum_ / n;
  }
  s.fits = s.frames_not_fitting == 0;
  s.required_data_gbps = static_cast<double>(s.peak_wire_bits) / budget_.available_seconds() / 1e9;
  s.minimum_preset = minimum_fitting_preset(s.peak_wire_bits, budget_.refresh_hz, budget_.blanking);
  return s;
}

std::optional<LinkPreset> minimum_fitting_preset(std::uint64_t wire_bits, double refresh_hz,
                                                 const std::optional<VideoTiming>& blanking) {
  for (const LinkPreset& p : builtin_link_presets()) {  // slowest first
    LinkBudget budget{p, refresh_hz, blanking};
    if (static_cast<double>(wire_bits) <= budget.capacity_bits_per_frame()) return p;
  }
  return std::nullopt;
}

FramesCsvWriter::FramesCsvWriter(const std::filesystem::path& path, double refresh_hz, std::string method)
    : file_(path), refresh_hz_(refresh_hz), method_(std::move(method)) {
  if (method_.find_first_of(",\"\n") != std::string::npos) {
    throw std::invalid_argument("frames.csv: method name '" + method_ + "' cannot be a CSV field");
  }
  file_.write("link_frame,time_s,views,parities,pixel_bits,payload_bits,overhead_bits,wire_bits,packets,"
              "wire_time_s,available_time_s,utilisation,fits,method\n");
}

void FramesCsvWriter::add(const LinkFrameUsage& u) {
  std::ostringstream row;
  row << std::setprecision(9) << u.index << ',' << static_cast<double>(u.index) / refresh_hz_ << ',' << u.views << ','
      << u.parities << ',' << u.bits.pixel_bits << ',' << u.bits.payload_bits << ',' << u.bits.overhead_bits << ','
      << u.bits.wire_bits() << ',' << u.bits.packets << ',' << u.wire_seconds << ',' << u.available_seconds << ','
      << u.utilisation << ',' << (u.fits ? 1 : 0) << ',' << method_ << '\n';
  file_.write(row.str());
}

void FramesCsvWriter::close() {
  if (closed_) return;
  file_.commit();
  closed_ = true;
}

void write_frames_csv(const std::filesystem::path& path, std::span<const LinkFrameUsage> frames, double refresh_hz,
                      const std::string& method) {
  FramesCsvWriter writer(path, refresh_hz, method);
  for (const LinkFrameUsage& u : frames) writer.add(u);
  writer.close();
}

PlotTrace::PlotTrace(std::string label, std::size_t max_buckets) : label_(std::move(label)), max_buckets_(max_buckets) {
  if (max_buckets_ < 2 || max_buckets_ % 2 != 0) {
    throw std::invalid_argument("plot trace: max_buckets must be even, >= 2");
  }
  buckets_.reserve(max_buckets_);
}

void PlotTrace::add(double bits) {
  const bool finite = std::isfinite(bits);
  if (count_ % width_ == 0) {
    if (buckets_.size() == max_buckets_) {
      // Full: pairs of buckets become one of twice the width, which leaves count_ on a bucket boundary.
      for (std::size_t i = 0; i < max_buckets_ / 2; ++i) {
        const Bucket& a = buckets_[2 * i];
        const Bucket& b = buckets_[2 * i + 1];
        buckets_[i] = {a.first, b.last, std::min(a.min, b.min), std::max(a.max, b.max)};
      }
      buckets_.resize(max_buckets_ / 2);
      width_ *= 2;
    }
    const double inf = std::numeric_limits<double>::infinity();
    buckets_.push_back({bits, bits, finite ? bits : inf, finite ? bits : -inf});
  } else {
    Bucket& b = buckets_.back();
    b.last = bits;
    if (finite) {
      b.min = std::min(b.min, bits);
      b.max = std::max(b.max, bits);
    }
  }
  ++count_;
}

}  // namespace trm::link
