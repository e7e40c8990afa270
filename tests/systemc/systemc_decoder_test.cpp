// trm::sc::DecoderModule in a SystemC simulation against the command line: a golden scene's link codes (`trm vectors`
// output) streamed line by line through the module's FIFOs, every drive row compared code for code with the CLI's
// drive files and hashed against tests/golden/vectors.txt, and the module's throughput (one row per N clocks) read
// off the simulation clock.
//
// A program of its own rather than a GoogleTest suite: SystemC elaborates once per process (no module can be built
// after sc_start), so each ctest run is one simulation, chosen by its mode:
//   golden VECTORS_DIR GOLDEN_FILE SCENE PANEL CLOCKS_PER_ROW
//   bad-config VECTORS_DIR   (an invalid configuration is refused with the C API's message, nothing simulated)
//   bad-line VECTORS_DIR     (a line of the wrong length stops the simulation with an error report, no crash)
#include "trm/systemc_decoder.hpp"

#include "vectors.hpp"  // fnv1a64, the hash of the checked-in golden vectors

#include <nlohmann/json.hpp>
#include <systemc>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

using trm::sc::Line;
constexpr int kClockNs = 10;

int failures = 0;
void fail(const std::string& message) {
  std::cerr << "FAIL: " << message << "\n";
  ++failures;
}

std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read " + path);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

struct HexFile {
  std::string text;
  std::vector<std::vector<std::uint16_t>> rows;
  int digits = 0;  // hex digits per word
};

HexFile read_hex(const std::string& path) {
  HexFile file;
  file.text = read_text(path);
  std::istringstream lines(file.text);
  std::string line;
  while (std::getline(lines, line)) {
    std::istringstream words(line);
    std::string word;
    std::vector<std::uint16_t> row;
    while (words >> word) {
      file.digits = static_cast<int>(word.size());
      row.push_back(static_cast<std::uint16_t>(std::stoul(word, nullptr, 16)));
    }
    file.rows.push_back(std::move(row));
  }
  if (file.rows.empty()) throw std::runtime_error(path + " is empty");
  return file;
}

// The drive file's text for rows of codes, as `trm vectors` writes it.
std::string hex_text(const std::vector<std::vector<std::uint16_t>>& rows, int digits) {
  std::string text;
  char word[8];
  for (const auto& row : rows)
    for (std::size_t i = 0; i < row.size(); ++i) {
      std::snprintf(word, sizeof word, "%0*x", digits, static_cast<unsigned>(row[i]));
      text += word;
      text += i + 1 == row.size() ? '\n' : ' ';
    }
  return text;
}

// <scene> <panel> <file> <hash> lines of the golden file, for one scene and panel.
std::map<std::string, std::uint64_t> read_golden(const std::string& path, const std::string& scene,
                                                 const std::string& panel) {
  std::map<std::string, std::uint64_t> golden;
  std::istringstream lines(read_text(path));
  std::string line;
  while (std::getline(lines, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    std::string s, p, name, hash;
    if (!(fields >> s >> p >> name >> hash)) throw std::runtime_error(path + ": malformed line '" + line + "'");
    if (s == scene && p == panel) golden[name] = std::stoull(hash, nullptr, 16);
  }
  return golden;
}

struct View {
  int kind = TRM_FRAME_FULL;
  std::string name;  // frame_NNN_<full|reduced>
  HexFile codes, drive;
};

// Feeds the views' lines into the module and collects the rows it gives, with the time each arrived.
SC_MODULE(Harness) {
  sc_core::sc_in<bool> clk;
  sc_core::sc_fifo_out<Line> lines_out;
  sc_core::sc_fifo_in<Line> rows_in;

  const std::vector<View>* views = nullptr;
  bool short_line = false;  // bad-line mode: the first line is one sample short
  std::vector<std::vector<Line>> rows;  // per view
  std::vector<std::vector<sc_core::sc_time>> times;

  SC_CTOR(Harness) {
    SC_THREAD(feed);
    SC_THREAD(collect);
  }

  void feed() {
    for (std::size_t v = 0; v < views->size(); ++v) {
      const View& view = (*views)[v];
      for (std::size_t y = 0; y < view.codes.rows.size(); ++y) {
        Line line;
        line.first = y == 0;
        line.kind = view.kind;
        line.index = static_cast<std::int64_t>(v);
        line.full_width = static_cast<int>(view.drive.rows[0].size() / 3);
        line.full_height = static_cast<int>(view.drive.rows.size());
        line.samples = view.codes.rows[y];
        if (short_line) line.samples.pop_back();
        lines_out.write(line);
      }
    }
  }

  void collect() {
    rows.resize(views->size());
    times.resize(views->size());
    for (std::size_t v = 0; v < views->size(); ++v) {
      for (;;) {
        Line row = rows_in.read();
        times[v].push_back(sc_core::sc_time_stamp());
        const bool last = row.last;
        rows[v].push_back(std::move(row));
        if (last) break;
      }
    }
    sc_core::sc_stop();
  }
};

std::vector<View> read_views(const std::string& dir, const std::map<std::string, std::uint64_t>& golden) {
  std::vector<View> views;
  for (int t = 0;; ++t) {
    char prefix[32];
    View view;
    std::snprintf(prefix, sizeof prefix, "frame_%03d_full", t);
    view.name = prefix;
    if (golden.count(view.name + "_drive.hex") == 0) {
      std::snprintf(prefix, sizeof prefix, "frame_%03d_reduced", t);
      view.name = prefix;
      view.kind = TRM_FRAME_REDUCED;
      if (golden.count(view.name + "_drive.hex") == 0) break;
    }
    view.codes = read_hex(dir + "/" + view.name + "_codes.hex");
    view.drive = read_hex(dir + "/" + view.name + "_drive.hex");
    // The CLI's files are the golden scene's: else a match below would prove nothing about the checked-in set.
    for (const HexFile* file : {&view.codes, &view.drive}) {
      const std::string name = view.name + (file == &view.codes ? "_codes.hex" : "_drive.hex");
      if (golden.count(name) == 0 || trm::cli::fnv1a64(file->text) != golden.at(name))
        throw std::runtime_error(dir + "/" + name + " does not hash to its golden hash");
    }
    views.push_back(std::move(view));
  }
  if (views.empty()) throw std::runtime_error("no views of this scene and panel in the golden file");
  return views;
}

int run_golden(const std::string& dir, const std::string& golden_path, const std::string& scene,
               const std::string& panel, int clocks_per_row) {
  const auto golden = read_golden(golden_path, scene, panel);
  const std::vector<View> views = read_views(dir, golden);

  sc_core::sc_clock clk("clk", kClockNs, sc_core::SC_NS);
  sc_core::sc_fifo<Line> lines("lines", 2);
  sc_core::sc_fifo<Line> rows("rows", 2);
  trm::sc::DecoderModule decoder("decoder", read_text(dir + "/report.json"), clocks_per_row);
  Harness harness("harness");
  decoder.clk(clk);
  decoder.lines_in(lines);
  decoder.rows_out(rows);
  harness.clk(clk);
  harness.lines_out(lines);
  harness.rows_in(rows);
  harness.views = &views;
  sc_core::sc_start(sc_core::sc_time(10, sc_core::SC_MS));

  std::int64_t total_rows = 0;
  for (std::size_t v = 0; v < views.size(); ++v) {
    const View& view = views[v];
    const auto& got = harness.rows[v];
    if (got.size() != view.drive.rows.size()) {
      fail(view.name + ": " + std::to_string(got.size()) + " rows, the CLI's drive file has " +
           std::to_string(view.drive.rows.size()));
      continue;
    }
    std::vector<std::vector<std::uint16_t>> codes;
    for (std::size_t y = 0; y < got.size(); ++y) {
      if (got[y].row != static_cast<int>(y)) fail(view.name + ": row " + std::to_string(got[y].row) + " came as row " +
                                                  std::to_string(y) + " (raster order)");
      if (got[y].samples != view.drive.rows[y])
        fail(view.name + ": row " + std::to_string(y) + " differs from the CLI's");
      // The module's throughput: rows of a view leave at least clocks_per_row clocks apart.
      if (y > 0 && harness.times[v][y] - harness.times[v][y - 1] <
                       sc_core::sc_time(kClockNs * clocks_per_row, sc_core::SC_NS))
        fail(view.name + ": rows " + std::to_string(y - 1) + " and " + std::to_string(y) + " only " +
             (harness.times[v][y] - harness.times[v][y - 1]).to_string() + " apart");
      codes.push_back(got[y].samples);
    }
    const std::uint64_t hash = trm::cli::fnv1a64(hex_text(codes, view.drive.digits));
    if (hash != golden.at(view.name + "_drive.hex")) fail(view.name + ": the rows' hash is not the golden hash");
    total_rows += static_cast<std::int64_t>(got.size());
  }
  if (decoder.rows_given() != total_rows) fail("the module counted " + std::to_string(decoder.rows_given()) + " rows");
  const sc_core::sc_time last = harness.times.back().back();
  if (last < sc_core::sc_time(static_cast<double>(kClockNs) * clocks_per_row * static_cast<double>(total_rows - 1),
                              sc_core::SC_NS))
    fail("all rows were out at " + last.to_string() + ", faster than one per " + std::to_string(clocks_per_row) +
         " clocks");
  std::cout << scene << " " << panel << ": " << views.size() << " views, " << total_rows << " rows through the "
            << "SystemC module, identical to `trm vectors` and the golden hashes; last row at " << last.to_string()
            << " (" << clocks_per_row << " clocks of " << kClockNs << " ns per row)\n";
  return failures == 0 ? 0 : 1;
}

// The scene's own configuration with one field the decoder rejects: the refusal must name the field.
int run_bad_config(const std::string& dir) {
  nlohmann::json report = nlohmann::json::parse(read_text(dir + "/report.json"));
  report["parameters"]["decoder"]["decoder"]["output_bits"] = 9;
  try {
    trm::sc::DecoderModule decoder("decoder", report.dump(), 1);
    fail("a configuration with 9-bit drive codes was accepted");
  } catch (const std::invalid_argument& e) {
    const std::string message = e.what();
    std::cout << "refused: " << message << "\n";
    if (message.find("trm::sc::DecoderModule: ") != 0 || message.find("output_bits") == std::string::npos)
      fail("the message does not name the module and output_bits");
  }
  try {
    trm::sc::DecoderModule decoder("decoder", report.dump(), 0);
    fail("clocks_per_row 0 was accepted");
  } catch (const std::invalid_argument& e) {
    std::cout << "refused: " << e.what() << "\n";
  }
  return failures == 0 ? 0 : 1;
}

int run_bad_line(const std::string& dir) {
  const std::string text = read_text(dir + "/report.json");
  View view;
  view.codes = read_hex(dir + "/frame_000_full_codes.hex");
  view.drive = read_hex(dir + "/frame_000_full_drive.hex");
  const std::vector<View> views{view};
  sc_core::sc_clock clk("clk", kClockNs, sc_core::SC_NS);
  sc_core::sc_fifo<Line> lines("lines", 2);
  sc_core::sc_fifo<Line> rows("rows", 2);
  trm::sc::DecoderModule decoder("decoder", text, 1);
  Harness harness("harness");
  decoder.clk(clk);
  decoder.lines_in(lines);
  decoder.rows_out(rows);
  harness.clk(clk);
  harness.lines_out(lines);
  harness.rows_in(rows);
  harness.views = &views;
  harness.short_line = true;
  sc_core::sc_report_handler::set_actions(sc_core::SC_ERROR, sc_core::SC_THROW);
  try {
    sc_core::sc_start(sc_core::sc_time(1, sc_core::SC_MS));
    fail("a line one sample short was taken");
  } catch (const sc_core::sc_report& report) {
    const std::string message = report.what();
    std::cout << "stopped: " << message << "\n";
    if (message.find("trm_decoder_push_line") == std::string::npos ||
        message.find("(" + std::to_string(TRM_ERROR_LINE_LENGTH) + ")") == std::string::npos)
      fail("the report does not name push_line and TRM_ERROR_LINE_LENGTH");
  }
  if (decoder.lines_taken() != 0) fail("the short line was counted as taken");
  return failures == 0 ? 0 : 1;
}

}  // namespace

int sc_main(int argc, char* argv[]) {
  try {
    const std::vector<std::string> args(argv + 1, argv + argc);
    if (args.size() == 6 && args[0] == "golden")
      return run_golden(args[1], args[2], args[3], args[4], std::stoi(args[5]));
    if (args.size() == 2 && args[0] == "bad-config") return run_bad_config(args[1]);
    if (args.size() == 2 && args[0] == "bad-line") return run_bad_line(args[1]);
    std::cerr << "usage: systemc_decoder_test golden VECTORS_DIR GOLDEN_FILE SCENE PANEL CLOCKS_PER_ROW\n"
                 "       systemc_decoder_test bad-config|bad-line VECTORS_DIR\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "FAIL: " << e.what() << "\n";
    return 1;
  }
}
