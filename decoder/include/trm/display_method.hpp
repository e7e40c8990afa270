// Display methods (DESIGN §8, paper Sec. 6 Table 1): what the GPU side renders and sends for each view slot (t, eye),
// and what the headset shows in it. TRM is one method; the paper's baselines (full rate, half frame rate, interlace,
// black-frame insertion, NCSFI) are the others, each one file in decoder/src/methods/ plus one line in
// decoder/src/methods/methods.def. Every method goes over the same link (its views are packets like TRM's) and is
// judged by the same panel and metrics.
//
// The two sides are separate objects on purpose: the headset side sees only what crossed the link.
#pragma once

#include "trm/decoder.hpp"
#include "trm/fixed_decoder.hpp"
#include "trm/frame.hpp"
#include "trm/retina.hpp"
#include "trm/scene.hpp"

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace trm {

// What a method is built from: the decoder configuration (its `link` is the encoder's: r, sigma, phase, transfer,
// bits, stereo), the headset decoder implementation for the methods that decode TRM frames (trm, ncsfi), and the
// method's own option, the text after ':' in "NAME:OPTION" (empty when none was given).
struct MethodSetup {
  FixedDecoderConfig decoder;
  std::string impl = "reference";
  std::string option;
  // What a method that morphs frames along the scene's motion (didyk) knows of the scene besides its frames.
  struct SceneMotion {
    // The scene's motion at frame t; empty for a source that reports none (an input: its frames are held still).
    std::function<Motion(std::int64_t t)> at;
    double refresh_hz = 90.0;  // to turn velocities into displacements per frame
    double pixels_per_degree = viewer_preset("vive").pixels_per_degree;  // the viewer's, for the pursuit limit
  } scene;
  // The source the GPU side renders (head poses, motion), for the methods that use it (kim, kim-trm,
  // reprojection); null for a recorded input and wherever only the schedule is asked for. Outlives the sender.
  const FrameSource* source = nullptr;
};

// One view the GPU side sends, with what it cost to render.
struct Transmission {
  LinkFrame frame;
  std::int64_t pixels_rendered = 0;  // pixels the GPU rendered for this view (full size W H, reduced w h, ...)
};

// The GPU side of a method, one per run (both eyes).
class MethodSender {
 public:
  virtual ~MethodSender() = default;
  // Whether view (t, eye) is sent at all. A fixed schedule, so that the headset side and capture replay can tell a
  // view that was never sent from one that was lost.
  virtual bool sends(std::int64_t t, int eye) const = 0;
  // The view sent for (t, eye), called in (t, eye) order for the views sends() names. `linear` is the scene at t
  // (CV_64FC3, full size, linear); a method that does not render at t does not look at it, and says so in
  // pixels_rendered.
  virtual Transmission send(const cv::Mat& linear, std::int64_t t, int eye) = 0;
  // The metadata of the view sent for (t, eye) of a view of size `full`: what capture replay checks arriving views
  // against and describes a lost one by. Only for the views sends() names.
  virtual FrameMeta view_meta(std::int64_t t, int eye, cv::Size full) const = 0;
};

// The headset side of a method: per-eye state across slots, one slot in, the panel drive out. Every slot of every
// eye is shown exactly once, in (t, eye) order, by one of the three calls.
class MethodDisplay {
 public:
  virtual ~MethodDisplay() = default;
  // A view that arrived; line_intact has one entry per line of frame.codes (0 = lost), or is empty when all arrived.
  virtual DecodedFrame show(const LinkFrame& frame, std::span<const std::uint8_t> line_intact) = 0;
  // A view that was sent but none of whose packets arrived. `slot` describes the view as it was sent.
  virtual DecodedFrame show_lost(const FrameMeta& slot) = 0;
  // A slot the method sends nothing for (MethodSender::sends is false). `slot` has the full size and the slot's
  // parity; its width and height are the full size.
  virtual DecodedFrame show_unsent(const FrameMeta& slot) = 0;
  // The TRM decoder inside (trm, ncsfi), for its stage counts, hardware report and the reference beside it; null for
  // a method that decodes no TRM frames.
  virtual HeadsetDecoder* decoder() { return nullptr; }
};

// A method as the registry knows it.
struct DisplayMethod {
  std::string name;
  std::string summary;               // one line for `trm methods`
  std::string option_help;           // what ":OPTION" may be ("" when the method takes none: find_display_method
                                     // then refuses any)
  bool fixed_point = false;          // its headset side decodes TRM frames with any decoder of make_decoder()
  // Each throws std::invalid_argument for an option the method does not know.
  std::function<std::unique_ptr<MethodSender>(const MethodSetup& setup)> make_sender;
  std::function<std::unique_ptr<MethodDisplay>(const MethodSetup& setup)> make_display;
};

// Every method, in the order `trm methods` lists them.
const std::vector<DisplayMethod>& display_methods();
// "NAME" or "NAME:OPTION" -> the method and the option. Throws std::invalid_argument naming the known methods for an
// unknown name, and the method's own message for an option it refuses or an impl it cannot use.
struct MethodChoice {
  const DisplayMethod* method = nullptr;
  std::string option;
};
MethodChoice find_display_method(const std::string& spec);
// The setup for `spec` checked whole (method, option, impl): what `trm run --method` validates up front.
void check_display_method(const std::string& spec, const std::string& impl);

// The metadata of view (t, eye) with the given parity and sent size, of a view of size `full`, on `link`.
FrameMeta view_meta_of(std::int64_t t, int eye, Parity parity, cv::Size sent, cv::Size full, const EncoderConfig& link);
// The slot description the headset gets for view (t, eye) when nothing was sent: full size, TRM parity.
FrameMeta unsent_slot(std::int64_t t, int eye, cv::Size full, const EncoderConfig& link);

}  // namespace trm
