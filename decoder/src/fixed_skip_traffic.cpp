// The off-chip traffic the DESIGN §7 skips avoid, from their counters and the stores' formats (the widths of
// FixedStreamingDecoder::report()'s frame stores).
#include "trm/fixed_decoder.hpp"
#include "trm/resample.hpp"

#include <stdexcept>

namespace trm {

FixedSkipTraffic skip_traffic_saved(const FixedDecoderConfig& config, cv::Size full, const FixedStageCounts& counts,
                                    std::int64_t views) {
  if (full.width < 1 || full.height < 1) throw std::invalid_argument("skip_traffic_saved: `full` must be at least 1x1");
  if (views < 0) throw std::invalid_argument("skip_traffic_saved: `views` must be >= 0");
  const auto lines = [](std::uint64_t n) { return static_cast<std::int64_t>(n); };
  const std::int64_t residual_line = 3 * static_cast<std::int64_t>(full.width) * config.residual.width();
  const std::int64_t reduced_width = reduced_size(full.width, config.decoder.link.reduction);
  const std::int64_t low_row = 3 * reduced_width * config.decoder.link.bits;
  FixedSkipTraffic t;
  t.residual_write_bits = lines(counts.residual_write_lines_skipped) * residual_line;
  t.residual_read_bits = lines(counts.residual_read_lines_skipped) * residual_line;
  t.previous_low_read_bits = lines(counts.motion_test_lines_skipped) * 2 * low_row;
  if (!config.decoder.panel.has_history()) {
    // Per sample an LCD reads v_{t-1} and x_{t-1} and writes both; the OLED's held-output store takes the v write.
    const std::int64_t samples = 3 * static_cast<std::int64_t>(full.width) * full.height;
    t.lcd_store_bits = views * samples * (config.decoder.output_bits + 2 * (3 + config.linear_frac_bits));
  }
  return t;
}

}  // namespace trm
