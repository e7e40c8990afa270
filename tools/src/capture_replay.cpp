#include "capture_replay.hpp"

#include "trm/encoder_json.hpp"

#include <nlohmann/json.hpp>

#include <condition_variable>
#include <exception>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <thread>

#include <pthread.h>

namespace trm::cli {

namespace {

// Reads a capture one view ahead of the decoder, on a thread of its own: the file reads, the packets' CRCs and the
// receiver's assembly of view t+1 then run while view t is decoded instead of before it.
class ReadAhead {
 public:
  explicit ReadAhead(link::CaptureReplay& replay) : replay_(replay), thread_([this] { run(); }) {}
  ReadAhead(const ReadAhead&) = delete;
  ReadAhead& operator=(const ReadAhead&) = delete;
  ~ReadAhead() {
    {
      std::lock_guard lock(mutex_);
      stopping_ = true;
    }
    changed_.notify_all();
    thread_.join();
  }

  // The next view, nullopt at the end of the capture; rethrows what reading it threw.
  std::optional<link::ReceivedFrame> next() {
    std::unique_lock lock(mutex_);
    changed_.wait(lock, [&] { return ready_; });
    if (failure_) std::rethrow_exception(failure_);
    std::optional<link::ReceivedFrame> view = std::move(view_);
    view_.reset();
    ready_ = false;
    changed_.notify_all();
    return view;
  }

  // The receiver's counters, once next() has returned nullopt.
  link::ReceiverCounters counters() const { return replay_.counters(); }

 private:
  void run() {
    pthread_setname_np(pthread_self(), "trm-read");  // in top -H and perf
    for (;;) {
      std::optional<link::ReceivedFrame> view;
      std::exception_ptr failure;
      try {
        view = replay_.next_frame();
      } catch (...) {
        failure = std::current_exception();
      }
      std::unique_lock lock(mutex_);
      changed_.wait(lock, [&] { return !ready_ || stopping_; });
      if (stopping_) return;
      const bool last = !view || failure;
      view_ = std::move(view);
      failure_ = failure;
      ready_ = true;
      changed_.notify_all();
      if (last) return;
    }
  }

  link::CaptureReplay& replay_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::optional<link::ReceivedFrame> view_;
  std::exception_ptr failure_;
  bool ready_ = false;     // view_ / failure_ hold the next result, not yet taken
  bool stopping_ = false;
  std::thread thread_;     // last: started once everything it reads exists
};

}  // namespace

std::string capture_metadata(const PipelineOptions& options, std::int64_t frames) {
  nlohmann::ordered_json meta = encoder_json(options.encoder);
  meta["method"] = options.method;
  meta["refresh_hz"] = options.refresh_hz;
  meta["frames"] = frames;  // link frames the run sends: views lost at the end of a capture are known too
  return meta.dump();
}

CaptureDecodeResult decode_capture_stream(const PipelineOptions& options, const std::string& capture_path,
                                          const CaptureSink& sink) {
  link::CaptureReplay replay(capture_path);
  const std::string where = "capture '" + capture_path + "': ";
  nlohmann::json meta;
  try {
    meta = nlohmann::json::parse(replay.metadata());
  } catch (const nlohmann::json::exception& e) {
    throw std::runtime_error(where + "no readable configuration in its header: " + e.what());
  }
  // The link configuration comes from the header, checked as strictly as the command line that wrote it; panel,
  // sensitivity, output bits and fixed-point formats come from the options.
  PipelineOptions capture_options = options;
  EncoderConfig& link = capture_options.encoder;
  std::optional<std::int64_t> frames_sent;
  try {
    link = encoder_config_from_json(meta);
    validate_refresh_hz(meta.at("refresh_hz").get<double>(), "refresh_hz");
    if (meta.contains("frames")) {
      frames_sent = meta.at("frames").get<std::int64_t>();
      if (*frames_sent < 1) throw std::invalid_argument("frames must be >= 1");
    }
  } catch (const nlohmann::json::exception& e) {
    throw std::runtime_error(where + "incomplete configuration in its header: " + e.what());
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(where + "invalid configuration in its header: " + e.what());
  }
  // Captures written before display methods existed carry TRM frames.
  capture_options.method = meta.value("method", std::string("trm"));
  try {
    check_display_method(capture_options.method, capture_options.impl_given ? capture_options.impl
                                                                            : capture_options.method_impl());
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(where + "its method: " + e.what());
  }
  const MethodSetup setup = capture_options.method_setup();
  const MethodChoice method = find_display_method(capture_options.method);
  // The sender is built only for its schedule: which views were sent at all, and what each looked like.
  const std::unique_ptr<MethodSender> schedule = method.method->make_sender(setup);
  const std::unique_ptr<MethodDisplay> display = method.method->make_display(setup);

  // Views in link order: (t, eye) as t * eyes + eye. A view that lost every packet never comes out of the receiver;
  // the panel holds its previous output for it, and it is decoded and handed on as lost. A slot the method sends
  // nothing for is shown as the method shows it and handed on as not sent.
  const int eyes = link.stereo ? 2 : 1;
  std::int64_t next_view = 0;
  cv::Size full_size;
  bool right_eye_arrived = false;
  CaptureDecodeResult result;
  result.link_configuration = meta.dump();
  result.method = capture_options.method;
  result.impl = setup.impl;
  const auto hand_on_views_before = [&](std::int64_t view_number) {
    for (; next_view < view_number; ++next_view) {
      const std::int64_t t = next_view / eyes;
      const int eye = static_cast<int>(next_view % eyes);
      ++result.views;
      if (!schedule->sends(t, eye)) {
        const FrameMeta slot = unsent_slot(t, eye, full_size, link);
        sink(slot, SlotOutcome::NotSent, nullptr, display->show_unsent(slot));
        continue;
      }
      const FrameMeta lost = schedule->view_meta(t, eye, full_size);
      ++result.lost_views;
      sink(lost, SlotOutcome::Lost, nullptr, display->show_lost(lost));
    }
  };
  ReadAhead reader(replay);
  while (auto received = reader.next()) {
    const FrameMeta& m = received->meta;
    const std::string view = "view t=" + std::to_string(m.index) + " eye " + std::to_string(m.eye);
    if (m.eye >= eyes) {
      throw std::runtime_error(where + "holds a view of eye " + std::to_string(m.eye) + " (stream " +
                               std::to_string(m.eye) + ") but its header says " + (eyes == 1 ? "mono" : "stereo"));
    }
    if (!schedule->sends(m.index, m.eye)) {
      throw std::runtime_error(where + view + " arrived, but method '" + capture_options.method +
                               "' sends nothing there");
    }
    const FrameMeta expected = schedule->view_meta(m.index, m.eye, cv::Size(m.full_width, m.full_height));
    if (m.parity != expected.parity || m.width != expected.width || m.height != expected.height) {
      throw std::runtime_error(where + view + " is sent " + to_string(m.parity) + " " + std::to_string(m.width) + "x" +
                               std::to_string(m.height) + ", but the header's method '" + capture_options.method +
                               "' and phase " + std::to_string(link.phase) + " make it " + to_string(expected.parity) +
                               " " + std::to_string(expected.width) + "x" + std::to_string(expected.height));
    }
    const std::int64_t view_number = m.index * eyes + m.eye;
    if (view_number < next_view) throw std::runtime_error(where + view + " arrives after a later one");
    if (frames_sent && m.index >= *frames_sent) {
      throw std::runtime_error(where + view + " lies beyond the " + std::to_string(*frames_sent) +
                               " frames its header says were sent");
    }
    if (full_size.empty()) full_size = cv::Size(m.full_width, m.full_height);
    if (m.eye == 1) right_eye_arrived = true;
    hand_on_views_before(view_number);
    const DecodedFrame decoded = display->show(LinkFrame{m, received->codes}, received->line_intact);
    result.concealed_lines += decoded.stats.concealed_lines;
    ++result.views;
    ++next_view;
    sink(m, SlotOutcome::Arrived, &*received, decoded);
  }
  if (full_size.empty()) throw std::runtime_error(where + "holds no frame that arrived");
  if (eyes == 2 && !right_eye_arrived) {
    throw std::runtime_error(where + "its header says stereo, but no view of eye 1 (stream 1) arrived: a mono stream");
  }
  if (frames_sent) hand_on_views_before(*frames_sent * eyes);
  result.receiver = reader.counters();
  return result;
}

}  // namespace trm::cli
