// `trm feed`: decodes a scene or an input and streams the panel drive frames into a test rig over USB
// bulk (libusb), HID (hidapi) or into a file holding exactly the bytes such a device would receive.
// The wire protocol, the HID framing and every error are described in docs/rig_protocol.md.
#include "commands.hpp"
#include "capture_replay.hpp"
#include "pipeline.hpp"
#include "rig/device_list.hpp"
#include "rig/feeder.hpp"
#include "rig/file_transport.hpp"
#include "rig/hid_transport.hpp"
#include "rig/usb_bulk_transport.hpp"

#include "trm/atomic_file.hpp"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <exception>
#include <fstream>
#include <functional>
#include <iostream>
#include <limits>
#include <memory>
#include <mutex>
#include <sstream>
#include <thread>

#include <pthread.h>

namespace trm::cli {
namespace {

struct FeedSettings {
  bool list = false;
  std::string usb, hid, file;
  std::string capture;  // feed the frames decoded from this .trmcap instead of running the pipeline
  // USB bulk
  std::string serial, bus_port;
  int interface_number = -1;
  std::string endpoint_out, endpoint_in;
  int transfer_timeout_ms = 1000;
  bool detach_kernel_driver = false;
  std::size_t bulk_packet_size = 16384;
  // HID
  std::size_t report_size = 64;
  int report_id = 0;
  bool feature_reports = false;
  std::string hid_backend;
  // file
  std::string file_framing = "bulk";
  // pacing and flow control
  double fps = -1.0;  // < 0: the panel refresh
  bool no_drop = false;
  int preroll = 8;  // views sent before the pace starts: the decoder's first views touch its memory for the first time
  bool flow_control = false;
  int answer_timeout_ms = 2000;
  int max_resends = 3;
  // what to feed
  std::string roi;
  int downscale = 1;
  std::string summary_path;
};

int parse_endpoint(const std::string& text, bool in) {
  if (text.empty()) return -1;
  std::size_t used = 0;
  int value = -1;
  try {
    value = std::stoi(text, &used, 0);
  } catch (const std::exception&) {
  }
  if (used != text.size() || value < 0 || value > 0xFF || ((value & 0x80) != 0) != in)
    throw std::invalid_argument("'" + text + "' is not a bulk " + (in ? "IN endpoint (0x81..0x8f)" : "OUT endpoint (0x01..0x0f)"));
  return value;
}

std::optional<rig::Region> parse_roi(const std::string& text) {
  if (text.empty()) return std::nullopt;
  const auto fields = parse_int_list(text, 4, "--roi", "X,Y,W,H in view pixels, e.g. 476,536,128,128");
  const rig::Region r{fields[0], fields[1], fields[2], fields[3]};
  if (r.x < 0 || r.y < 0 || r.width <= 0 || r.height <= 0)
    throw std::invalid_argument("--roi " + text + ": X, Y must be >= 0 and W, H >= 1");
  if (r.x > std::numeric_limits<int>::max() - r.width || r.y > std::numeric_limits<int>::max() - r.height)
    throw std::invalid_argument("--roi " + text + ": the region ends beyond any view");
  return r;
}

std::unique_ptr<rig::RigTransport> open_transport(const FeedSettings& s) {
  if (!s.usb.empty()) {
    rig::UsbBulkOptions o;
    o.id = rig::parse_usb_id(s.usb);
    o.serial = s.serial;
    o.bus_port = s.bus_port;
    o.interface_number = s.interface_number;
    o.endpoint_out = parse_endpoint(s.endpoint_out, false);
    o.endpoint_in = parse_endpoint(s.endpoint_in, true);
    o.timeout = std::chrono::milliseconds(s.transfer_timeout_ms);
    o.detach_kernel_driver = s.detach_kernel_driver;
    o.packet_size = s.bulk_packet_size;
    return std::make_unique<rig::UsbBulkTransport>(o);
  }
  const rig::HidReportFormat format{s.report_size, static_cast<std::uint8_t>(s.report_id), s.feature_reports};
  if (!s.hid.empty()) {
    rig::HidOptions o;
    try {
      o.id = rig::parse_usb_id(s.hid);
    } catch (const std::invalid_argument&) {
      o.path = s.hid;  // not a VID:PID: a hidapi path (/dev/hidrawN, or bus:device:interface for libusb)
    }
    o.serial = s.serial;
    o.format = format;
    o.api = s.hid_backend.empty() ? &rig::linked_hidapi() : &rig::hidapi_backend(s.hid_backend);
    return std::make_unique<rig::HidTransport>(o);
  }
  rig::FileTransportOptions o;
  o.path = s.file;
  if (s.file_framing == "hid") o.framing = rig::FileTransportOptions::Framing::Hid;
  else if (s.file_framing != "bulk") throw std::invalid_argument("--file-framing is bulk or hid, not '" + s.file_framing + "'");
  o.bulk_packet_size = s.bulk_packet_size;
  o.hid = format;
  return std::make_unique<rig::FileTransport>(o);
}

std::string human_seconds(double seconds) {
  char text[64];
  if (seconds < 1.0) std::snprintf(text, sizeof text, "%.1f ms", seconds * 1e3);
  else if (seconds < 120.0) std::snprintf(text, sizeof text, "%.1f s", seconds);
  else std::snprintf(text, sizeof text, "%.1f min", seconds / 60.0);
  return text;
}

// Says up front what the transport can carry, and what to do when a full view does not fit the pace.
void warn_about_throughput(const rig::RigTransport& transport, const rig::RigFrameHeader& frame, double fps, bool cropped) {
  const rig::TransportRate rate = transport.nominal_rate();
  if (rate.bytes_per_second <= 0) return;
  const double per_frame = rig::RigFeeder::seconds_per_frame(transport, frame);
  std::ostringstream out;
  out << "trm feed: " << rate.basis << " (~" << rate.bytes_per_second / 1e3 << " kB/s): one " << frame.width << "x" << frame.height
      << " view of " << frame.payload_size() << " bytes takes ~" << human_seconds(per_frame);
  if (fps > 0 && per_frame > 1.0 / fps) {
    out << ", longer than the " << human_seconds(1.0 / fps) << " slot at " << fps << " Hz: most views will be dropped";
    if (!cropped) {
      int step = 2;
      while (step < 64 && per_frame / (step * step) > 1.0 / fps) step *= 2;
      out << ". Feed a region (--roi X,Y,W,H) or a decimated view (--downscale " << step << " gives "
          << (frame.width + step - 1) / step << "x" << (frame.height + step - 1) / step << ", ~"
          << human_seconds(per_frame / (step * step)) << ")";
    }
    out << "; --fps 0 sends every view as fast as the transport goes";
  }
  std::cerr << out.str() << "\n";
}

rig::RigFrameHeader rig_header(const DecodedFrame& decoded, int bits) {
  const cv::Mat& codes = decoded.drive_codes;
  if (codes.type() != CV_16UC3) throw std::runtime_error("feed: decoder drive codes are not CV_16UC3");
  rig::RigFrameHeader h;
  h.index = decoded.meta.index;
  h.eye = decoded.meta.eye;
  h.width = codes.cols;
  h.height = codes.rows;
  h.bits = bits;
  return h;
}

rig::RigFrame to_rig_frame(const DecodedFrame& decoded, int bits) {
  const cv::Mat& codes = decoded.drive_codes;
  rig::RigFrame f;
  static_cast<rig::RigFrameHeader&>(f) = rig_header(decoded, bits);
  f.samples.reserve(static_cast<std::size_t>(codes.cols) * static_cast<std::size_t>(codes.rows) * 3u);
  for (int y = 0; y < codes.rows; ++y) {
    const auto* row = codes.ptr<std::uint16_t>(y);
    f.samples.insert(f.samples.end(), row, row + codes.cols * 3);
  }
  return f;
}

// Sends each view on a thread of its own while the next one is read and decoded, one view in flight: what the feed
// does per view besides decoding (the rig frame's packing, range check and CRC, the transport's writes) then no
// longer adds to the decoder's time on the main thread, which at 90 Hz leaves no room for it. The view is held by
// reference (its planes are shared, not copied): a decoder never writes into a plane a caller still holds.
class SendingThread {
 public:
  explicit SendingThread(std::function<void(const DecodedFrame&)> send) : send_(std::move(send)), thread_([this] { run(); }) {}
  SendingThread(const SendingThread&) = delete;
  SendingThread& operator=(const SendingThread&) = delete;
  ~SendingThread() { stop(); }

  // Waits until the view before has been sent, rethrowing what sending it threw, then hands this one over.
  void submit(const DecodedFrame& view) {
    std::unique_lock lock(mutex_);
    idle_.wait(lock, [&] { return !pending_; });
    rethrow_failure(lock);
    pending_ = view;
    ready_.notify_one();
  }

  // Waits until the last view has been sent; rethrows what sending it threw.
  void finish() {
    std::unique_lock lock(mutex_);
    idle_.wait(lock, [&] { return !pending_; });
    rethrow_failure(lock);
  }

 private:
  void run() {
    pthread_setname_np(pthread_self(), "trm-send");  // in top -H and perf
    std::unique_lock lock(mutex_);
    for (;;) {
      ready_.wait(lock, [&] { return pending_.has_value() || stopping_; });
      if (!pending_) return;
      lock.unlock();
      // pending_ stays set while it is sent: submit() waits for it and nothing else writes it.
      std::exception_ptr failure;
      try {
        send_(*pending_);
      } catch (...) {
        failure = std::current_exception();
      }
      lock.lock();
      pending_.reset();  // before the decoder is let go, so that it finds the view's planes free to reuse
      if (failure && !failure_) failure_ = failure;
      idle_.notify_all();
    }
  }

  void rethrow_failure(std::unique_lock<std::mutex>&) {
    if (!failure_) return;
    std::exception_ptr failure = std::exchange(failure_, nullptr);
    std::rethrow_exception(failure);
  }

  void stop() {
    {
      std::lock_guard lock(mutex_);
      stopping_ = true;
    }
    ready_.notify_one();
    if (thread_.joinable()) thread_.join();
  }

  std::function<void(const DecodedFrame&)> send_;
  std::mutex mutex_;
  std::condition_variable ready_, idle_;
  std::optional<DecodedFrame> pending_;
  std::exception_ptr failure_;
  bool stopping_ = false;
  std::thread thread_;  // last: started once everything it reads exists
};

int run_feed(const FeedSettings& s, const PipelineOptions& options_given) {
  PipelineOptions pipeline = options_given;
  pipeline.report_planes = false;  // the rig is sent the drive codes alone
  pipeline.motion_weight_statistics = false;
  if (s.list) {
    const rig::HidApi& api = s.hid_backend.empty() ? rig::linked_hidapi() : rig::hidapi_backend(s.hid_backend);
    std::cout << rig::format_listing(rig::list_devices(api));
    return 0;
  }
  if (s.usb.empty() + s.hid.empty() + s.file.empty() != 2)
    throw std::invalid_argument("feed: give exactly one of --usb VID:PID, --hid VID:PID|PATH or --file OUT (or --list)");
  if (s.downscale < 1) throw std::invalid_argument("--downscale must be >= 1");
  const std::optional<rig::Region> roi = parse_roi(s.roi);
  pipeline.validate();

  nlohmann::json summary;
  summary["protocol_version"] = rig::kProtocolVersion;
  // Before anything is sent or created: a feed whose outputs cannot be written must not start.
  if (!s.file.empty()) io::check_file_target(s.file);
  if (!s.summary_path.empty()) io::check_file_target(s.summary_path);
  auto finish = [&](int exit_code) {
    const std::string text = summary.dump(2);
    std::cout << text << "\n";
    if (s.summary_path.empty()) return exit_code;
    try {
      io::write_file_atomically(s.summary_path, text + "\n");
    } catch (const std::runtime_error& e) {
      std::cerr << "trm: error: --summary: " << e.what() << "\n";
      return exit_code != 0 ? exit_code : 1;
    }
    return exit_code;
  };
  auto record_error = [&](const rig::RigError& e) {
    summary["status"] = "error";
    summary["error"] = {{"kind", rig::to_string(e.kind())}, {"message", e.what()}, {"exit_code", e.exit_code()}};
    std::cerr << "\ntrm: error: " << e.what() << "\n";
    return e.exit_code();
  };

  std::unique_ptr<rig::RigTransport> transport;
  try {
    transport = open_transport(s);
  } catch (const rig::RigError& e) {
    summary["stats"] = rig::FeedStats{}.to_json();
    return finish(record_error(e));
  }
  summary["transport"] = transport->description();
  summary["nominal_bytes_per_second"] = transport->nominal_rate().bytes_per_second;

  rig::FeedOptions options;
  options.fps = s.fps < 0 ? pipeline.refresh_hz : s.fps;
  options.drop_late = !s.no_drop;
  options.preroll_frames = s.preroll;
  options.flow_control = s.flow_control;
  options.answer_timeout = std::chrono::milliseconds(s.answer_timeout_ms);
  options.max_resends_per_frame = s.max_resends;
  const bool live = ::isatty(STDERR_FILENO) != 0;
  if (live) options.on_progress = [](const rig::FeedStats& st) { std::cerr << "\r" << st.progress_line() << "   " << std::flush; };
  rig::RigFeeder feeder(*transport, options);
  summary["fps"] = options.fps;

  bool warned = false;
  int exit_code = 0;
  try {
    const bool whole_views = !roi && s.downscale == 1;
    const auto send_view = [&](const DecodedFrame& decoded) {
      const cv::Mat& codes = decoded.drive_codes;
      const bool in_place = whole_views && codes.isContinuous();  // packed straight from the decoder's output plane
      rig::RigFrame copied;
      if (!in_place) {
        copied = to_rig_frame(decoded, pipeline.output_bits);
        if (!whole_views)
          copied = rig::crop_and_decimate(copied, roi.value_or(rig::Region{0, 0, copied.width, copied.height}), s.downscale);
      }
      const rig::RigFrameHeader header = in_place ? rig_header(decoded, pipeline.output_bits) : copied;
      const std::span<const std::uint16_t> samples =
          in_place ? std::span<const std::uint16_t>(codes.ptr<std::uint16_t>(), codes.total() * 3u) : copied.samples;
      if (!warned) {
        warn_about_throughput(*transport, header, options.fps, !whole_views);
        warned = true;
      }
      feeder.feed(header, samples);
    };
    SendingThread sender(send_view);
    if (!s.capture.empty()) {
      decode_capture_stream(pipeline, s.capture,
                            [&](const FrameMeta&, SlotOutcome, const link::ReceivedFrame*, const DecodedFrame& decoded) {
                              sender.submit(decoded);
                            });
    } else {
      run_pipeline(pipeline, [&](const DecodedView& view) { sender.submit(*view.decoded); });
    }
    sender.finish();
    transport->finish();
    summary["status"] = "ok";
  } catch (const rig::RigError& e) {
    exit_code = record_error(e);
  }
  if (live) std::cerr << "\n";
  summary["stats"] = feeder.stats().to_json();
  return finish(exit_code);
}

}  // namespace

void register_feed(CLI::App& app, Action& action) {
  auto* cmd = app.add_subcommand("feed", "Stream decoded panel drive frames into a USB bulk or HID test rig, or a file "
                                         "(protocol: docs/rig_protocol.md)");
  auto settings = std::make_shared<FeedSettings>();
  auto pipeline = std::make_shared<PipelineOptions>();
  // A rig is fed what the hardware would show, at the panel's pace: the hardware model on every core by default.
  pipeline->impl = "fixed";
  pipeline->threads = std::clamp(static_cast<int>(std::thread::hardware_concurrency()), 1, kMaxDecoderThreads);
  pipeline->add_options(*cmd);
  pipeline->add_method_option(*cmd);
  FeedSettings& s = *settings;

  cmd->add_option("--capture", s.capture, "Feed the frames decoded from a recorded packet stream (.trmcap)")
      ->excludes(cmd->get_option("--input"));
  cmd->add_flag("--list", s.list, "List candidate USB and HID devices (VID:PID, strings, endpoints) and exit");
  auto* usb = cmd->add_option("--usb", s.usb, "USB bulk rig, VID:PID in hex (e.g. 1234:5678)");
  auto* hid = cmd->add_option("--hid", s.hid, "HID rig, VID:PID in hex or a hidapi path (/dev/hidrawN)");
  auto* file = cmd->add_option("--file", s.file, "Write the bytes a device would receive to this file");
  usb->excludes(hid)->excludes(file);
  hid->excludes(file);

  cmd->add_option("--serial", s.serial, "Pick the device with this serial number");
  cmd->add_option("--bus-port", s.bus_port, "USB: pick the device at this bus-port (e.g. 1-4.2, see --list)");
  cmd->add_option("--interface", s.interface_number, "USB: interface number (default: the first with a bulk OUT endpoint)");
  cmd->add_option("--ep", s.endpoint_out, "USB: bulk OUT endpoint (default: the interface's first, e.g. 0x01)");
  cmd->add_option("--ep-in", s.endpoint_in, "USB: bulk IN endpoint for the rig's answers (default: the interface's first)");
  cmd->add_option("--timeout", s.transfer_timeout_ms, "USB: per-transfer timeout in ms")->capture_default_str()->check(CLI::Range(1, 600000));
  cmd->add_flag("--detach-kernel-driver", s.detach_kernel_driver, "USB: take the interface from a bound kernel driver (given back on exit)");
  cmd->add_option("--chunk", s.bulk_packet_size, "USB / bulk file: packet size in bytes (64..65543)")->capture_default_str();
  cmd->add_option("--report-size", s.report_size, "HID: report size in bytes (64 full speed, up to 1024 high speed)")->capture_default_str();
  cmd->add_option("--report-id", s.report_id, "HID: report ID (0: unnumbered reports)")->capture_default_str()->check(CLI::Range(0, 255));
  cmd->add_flag("--feature", s.feature_reports, "HID: send feature reports instead of output reports");
  cmd->add_option("--hid-backend", s.hid_backend, "HID: hidapi backend, hidraw (linked) or libusb (loaded at run time)")
      ->check(CLI::IsMember({"hidraw", "libusb"}));
  cmd->add_option("--file-framing", s.file_framing, "File: bulk (a USB stream) or hid (reports, with --report-size/--report-id)")
      ->capture_default_str()->check(CLI::IsMember({"bulk", "hid"}));
  cmd->add_option("--fps", s.fps, "Views per second (default: the panel refresh, --refresh; 0: as fast as possible)")
      ->check(finite_non_negative(" (0: as fast as possible; leave --fps out for the panel refresh)"));
  cmd->add_flag("--no-drop", s.no_drop, "Paced: send late views anyway instead of dropping them");
  cmd->add_option("--preroll", s.preroll,
                  "Paced: views sent as soon as they are decoded before the pace starts (the decoder's first views "
                  "touch its frame stores for the first time)")
      ->capture_default_str()->check(CLI::Range(0, 1000000));
  cmd->add_flag("--flow-control", s.flow_control, "Wait for the rig's READY / RESEND / ERROR after every view");
  cmd->add_option("--answer-timeout", s.answer_timeout_ms, "Flow control: ms to wait for an answer")->capture_default_str()->check(CLI::Range(1, 600000));
  cmd->add_option("--max-resends", s.max_resends, "Flow control: RESEND answers honoured per view")->capture_default_str()->check(CLI::Range(0, 1000));
  cmd->add_option("--roi", s.roi, "Feed only this region of each view: X,Y,W,H in view pixels");
  cmd->add_option("--downscale", s.downscale, "Feed every N-th pixel in both directions (codes unchanged)")->check(CLI::Range(1, 4096));
  cmd->add_option("--summary", s.summary_path, "Also write the final JSON summary to this file");

  cmd->callback([&action, settings, pipeline] { action = [settings, pipeline] { return run_feed(*settings, *pipeline); }; });
}

}  // namespace trm::cli
