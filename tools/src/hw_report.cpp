#include "hw_report.hpp"

#include "trm/panel.hpp"

#include <iomanip>
#include <sstream>
#include <stdexcept>

namespace trm::cli {

namespace {

std::string bits_text(std::int64_t bits) {
  std::ostringstream s;
  s << bits << " bits (" << std::fixed << std::setprecision(1) << static_cast<double>(bits) / 8.0 / 1024.0 << " KiB)";
  return s.str();
}

}  // namespace

std::string hardware_summary(const Json& hw) {
  std::ostringstream s;
  s << "view " << hw["full_size"][0] << "x" << hw["full_size"][1] << ", reduced " << hw["reduced_size"][0] << "x"
    << hw["reduced_size"][1] << "; latency " << hw["full_frame_latency_lines"] << " lines (full frames), "
    << hw["reduced_frame_latency_lines"] << " reduced lines (reduced frames)\n";
  s << "line buffers and frame stores (lines x samples x bits):\n";
  for (const auto& b : hw["buffers"]) {
    s << "  " << std::left << std::setw(62) << b["name"].get<std::string>() << std::right << std::setw(6)
      << b["lines"].get<int>() << " x " << std::setw(5) << b["samples"].get<int>() << " x " << std::setw(2)
      << b["bits"].get<int>() << " = " << b["total_bits"].get<std::int64_t>() << "\n";
  }
  s << "ROMs (copies x entries x bits):\n";
  for (const auto& rom : hw["roms"]) {
    s << "  " << std::left << std::setw(62) << rom["name"].get<std::string>() << std::right << std::setw(6)
      << rom["count"].get<int>() << " x " << std::setw(5) << rom["entries"].get<int>() << " x " << std::setw(2)
      << rom["word_bits"].get<int>() << " = " << rom["total_bits"].get<std::int64_t>() << "\n";
  }
  s << "arithmetic per evaluation (adders / multipliers / comparators / ROM reads; per output pixel):\n";
  for (const auto& a : hw["arithmetic"]) {
    s << "  " << std::left << std::setw(46) << a["stage"].get<std::string>() << std::setw(8)
      << a["frame"].get<std::string>() << std::right << std::setw(4) << a["adders"].get<int>() << std::setw(4)
      << a["multipliers"].get<int>() << std::setw(4) << a["comparators"].get<int>() << std::setw(4)
      << a["rom_reads"].get<int>() << "   per pixel " << std::fixed << std::setprecision(2)
      << a["adders_per_pixel"].get<double>() << " / " << a["multipliers_per_pixel"].get<double>() << " / "
      << a["comparators_per_pixel"].get<double>() << "  (" << a["evaluated_per"].get<std::string>() << ")\n";
  }
  for (const char* kind : {"full", "reduced"}) {
    const auto& p = hw["arithmetic_per_output_pixel"][kind];
    s << "  total per output pixel, " << kind << " frames: " << std::fixed << std::setprecision(2)
      << p["adders"].get<double>() << " adders, " << p["multipliers"].get<double>() << " multipliers, "
      << p["comparators"].get<double>() << " comparators\n";
  }
  const auto& t = hw["totals"];
  s << "on chip:  line buffers " << bits_text(t["line_buffer_bits"].get<std::int64_t>()) << " + ROMs "
    << bits_text(t["rom_bits"].get<std::int64_t>()) << " = " << bits_text(t["on_chip_bits"].get<std::int64_t>())
    << "\n";
  s << "off chip: frame stores " << bits_text(t["off_chip_bits"].get<std::int64_t>()) << "\n";
  const auto& p = hw["paper_comparison"];
  s << "paper's previous frame + residual: " << bits_text(p["paper_frame_store_bits"].get<std::int64_t>())
    << "; reduced d_t + residual: " << bits_text(p["model_frame_store_bits"].get<std::int64_t>()) << "; saves "
    << bits_text(p["saved_bits"].get<std::int64_t>()) << " = " << std::fixed << std::setprecision(1)
    << p["saved_percent"].get<double>() << " %\n";
  if (hw.contains("concealment")) s << "concealment: " << hw["concealment"].get<std::string>() << "\n";
  return s.str();
}

}  // namespace trm::cli
