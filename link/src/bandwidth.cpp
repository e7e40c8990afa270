#include "trm/bandwidth.hpp"

#include "trm/atomic_file.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <stdexcept>

namespace trm::link {

void LinkBudget::validate() const {
  if (!(refresh_hz > 0.0) || !std::isfinite(refresh_hz))
    throw std::invalid_argument("link budget: refresh rate must be > 0 Hz");
  if (!(preset.data_gbps() > 0.0) || !std::isfinite(preset.data_gbps()))
    throw std::invalid_argument("link budget: link data rate must be > 0 Gbit/s");
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
  frames_.push_back(std::move(u));
  return frames_.back();
}

BandwidthSummary BandwidthMeter::summary() const {
  BandwidthSummary s;
  s.link_frames = static_cast<std::int64_t>(frames_.size());
  double wire_sum = 0.0, payload_sum = 0.0, utilisation_sum = 0.0;
  for (const LinkFrameUsage& u : frames_) {
    s.peak_wire_bits = std::max(s.peak_wire_bits, u.bits.wire_bits());
    s.peak_payload_bits = std::max(s.peak_payload_bits, u.bits.payload_bits);
    s.peak_utilisation = std::max(s.peak_utilisation, u.utilisation);
    s.total_pixel_bits += u.bits.pixel_bits;
    s.total_payload_bits += u.bits.payload_bits;
    s.total_overhead_bits += u.bits.overhead_bits;
    wire_sum += static_cast<double>(u.bits.wire_bits());
    payload_sum += static_cast<double>(u.bits.payload_bits);
    utilisation_sum += u.utilisation;
    if (!u.fits) ++s.frames_not_fitting;
  }
  if (!frames_.empty()) {
    const double n = static_cast<double>(frames_.size());
    s.average_wire_bits = wire_sum / n;
    s.average_payload_bits = payload_sum / n;
    s.average_utilisation = utilisation_sum / n;
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

void write_frames_csv(const std::filesystem::path& path, std::span<const LinkFrameUsage> frames, double refresh_hz) {
  std::ostringstream out;
  out << "link_frame,time_s,views,parities,pixel_bits,payload_bits,overhead_bits,wire_bits,packets,"
         "wire_time_s,available_time_s,utilisation,fits\n";
  out << std::setprecision(9);
  for (const LinkFrameUsage& u : frames) {
    out << u.index << ',' << static_cast<double>(u.index) / refresh_hz << ',' << u.views << ',' << u.parities << ','
        << u.bits.pixel_bits << ',' << u.bits.payload_bits << ',' << u.bits.overhead_bits << ','
        << u.bits.wire_bits() << ',' << u.bits.packets << ',' << u.wire_seconds << ',' << u.available_seconds << ','
        << u.utilisation << ',' << (u.fits ? 1 : 0) << '\n';
  }
  const std::string text = out.str();
  io::write_file_atomically(path, text);
}

}  // namespace trm::link
