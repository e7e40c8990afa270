#include "hw_report.hpp"

#include "trm/panel.hpp"

#include <iomanip>
#include <sstream>
#include <stdexcept>

namespace trm::cli {

namespace {

bool on_chip(const FixedBufferReport& b) { return b.name.rfind("line:", 0) == 0; }

std::string bits_text(std::int64_t bits) {
  std::ostringstream s;
  s << bits << " bits (" << std::fixed << std::setprecision(1) << static_cast<double>(bits) / 8.0 / 1024.0 << " KiB)";
  return s.str();
}

}  // namespace

Json hardware_json(const FixedStreamingReport& r) {
  Json hw;
  hw["full_size"] = {r.full.width, r.full.height};
  hw["reduced_size"] = {r.reduced.width, r.reduced.height};
  hw["full_frame_latency_lines"] = r.full_latency_lines;
  hw["reduced_frame_latency_lines"] = r.reduced_latency_lines;
  Json buffers = Json::array();
  std::int64_t total_bits = 0;
  std::int64_t line_bits = 0;
  std::int64_t frame_bits = 0;
  for (const auto& b : r.buffers) {
    buffers.push_back({{"name", b.name}, {"kind", on_chip(b) ? "line buffer" : "frame store"}, {"lines", b.lines},
                       {"samples", b.samples}, {"bits", b.bits}, {"total_bits", b.total_bits()}});
    total_bits += b.total_bits();
    (on_chip(b) ? line_bits : frame_bits) += b.total_bits();
  }
  hw["buffers"] = buffers;
  hw["total_bits"] = total_bits;  // line buffers + frame stores
  Json roms = Json::array();
  std::int64_t rom_bits = 0;
  for (const auto& rom : r.roms) {
    roms.push_back({{"name", rom.name}, {"entries", rom.entries}, {"word_bits", rom.word_bits}, {"count", rom.count},
                    {"total_bits", rom.total_bits()}});
    rom_bits += rom.total_bits();
  }
  hw["roms"] = roms;
  // Not cv::Size::area(): an int, which overflows from 2^31 pixels.
  const double pixels = static_cast<double>(r.full.width) * r.full.height;
  Json arithmetic = Json::array();
  Json per_pixel;
  for (const char* kind : {"full", "reduced"}) per_pixel[kind] = {{"adders", 0.0}, {"multipliers", 0.0}, {"comparators", 0.0}};
  for (const auto& a : r.arithmetic) {
    const double scale = pixels > 0 ? static_cast<double>(a.evaluations) / pixels : 0.0;
    arithmetic.push_back({{"stage", a.stage}, {"frame", a.frame}, {"evaluated_per", a.evaluated_per},
                          {"evaluations", a.evaluations}, {"adders", a.adders}, {"multipliers", a.multipliers},
                          {"comparators", a.comparators}, {"rom_reads", a.rom_reads},
                          {"adders_per_pixel", a.adders * scale}, {"multipliers_per_pixel", a.multipliers * scale},
                          {"comparators_per_pixel", a.comparators * scale}});
    for (const char* kind : {"full", "reduced"}) {
      if (a.frame != kind && a.frame != "both") continue;
      per_pixel[kind]["adders"] = per_pixel[kind]["adders"].get<double>() + a.adders * scale;
      per_pixel[kind]["multipliers"] = per_pixel[kind]["multipliers"].get<double>() + a.multipliers * scale;
      per_pixel[kind]["comparators"] = per_pixel[kind]["comparators"].get<double>() + a.comparators * scale;
    }
  }
  hw["arithmetic"] = arithmetic;
  hw["arithmetic_per_output_pixel"] = per_pixel;
  hw["totals"] = {{"line_buffer_bits", line_bits},
                  {"rom_bits", rom_bits},
                  {"on_chip_bits", line_bits + rom_bits},
                  {"frame_store_bits", frame_bits},
                  {"off_chip_bits", frame_bits}};
  const std::int64_t saved = r.paper_frame_store_bits - r.model_frame_store_bits;
  hw["concealment"] = r.concealment;
  hw["paper_comparison"] = {
      {"description", "paper Sec. 9: full-size previous frame (link codes) + full-size residual; this model: "
                      "reduced-size d_t (link codes) + full-size residual (LCD stores and the held output for "
                      "lost views excluded from both)"},
      {"paper_frame_store_bits", r.paper_frame_store_bits},
      {"model_frame_store_bits", r.model_frame_store_bits},
      {"saved_bits", saved},
      {"saved_percent", r.paper_frame_store_bits > 0 ? 100.0 * static_cast<double>(saved) /
                                                           static_cast<double>(r.paper_frame_store_bits)
                                                     : 0.0}};
  return hw;
}

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
