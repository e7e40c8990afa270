// `import trm`: the scenes, the TRM encoder, the headset decoders, the panel models and the metrics on numpy arrays
// (README "Python"). Configurations are dicts in the JSON form the reports write (trm/encoder_json.hpp,
// trm/decoder_json.hpp), read by the same readers and validated by them; fields left out keep their defaults.
// Every C++ exception reaches Python as ValueError with its message (MemoryError for an allocation failure).
#include "arrays.hpp"

#include "trm/decoder.hpp"
#include "trm/decoder_json.hpp"
#include "trm/encoder.hpp"
#include "trm/encoder_json.hpp"
#include "trm/fixed_decoder.hpp"
#include "trm/media.hpp"
#include "trm/metrics.hpp"
#include "trm/mtcd.hpp"
#include "trm/panel.hpp"
#include "trm/scene.hpp"
#include "trm/visual_difference.hpp"

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>  // the IMREAD_* flags; the calls go through trm/media.hpp
#include <opencv2/imgproc.hpp>
#include <pybind11/stl.h>

#include <chrono>
#include <memory>
#include <mutex>
#include <new>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#ifndef TRM_VERSION
#error "TRM_VERSION is set by tools/python/CMakeLists.txt from project(trm VERSION ...)"
#endif

namespace trm::python {
namespace {

using Json = nlohmann::json;

// ---- configurations as dicts ----

Json json_of(const py::handle& value, const std::string& what) {
  try {
    const std::string text =
        py::module_::import("json").attr("dumps")(value, py::arg("allow_nan") = false).cast<std::string>();
    return Json::parse(text);
  } catch (const py::error_already_set& e) {
    throw std::invalid_argument(what + ": not representable as JSON (" + std::string(e.what()) +
                                "; an infinite sensitivity is the string \"inf\")");
  }
}

py::object python_of(const nlohmann::ordered_json& json) {
  return py::module_::import("json").attr("loads")(json.dump());
}

// A field of `patch` that `defaults` does not have is a typo, not a wish: reject it by its path.
void check_known_fields(const Json& patch, const Json& defaults, const std::string& path) {
  if (!patch.is_object() || !defaults.is_object()) return;
  for (auto it = patch.begin(); it != patch.end(); ++it) {
    const auto known = defaults.find(it.key());
    if (known == defaults.end()) {
      std::string fields;
      for (auto d = defaults.begin(); d != defaults.end(); ++d) fields += (fields.empty() ? "" : ", ") + d.key();
      throw std::invalid_argument(path + ": unknown field '" + it.key() + "' (fields: " + fields + ")");
    }
    check_known_fields(it.value(), *known, path + "." + it.key());
  }
}

// The encoder block `patch` over `defaults` (both encoder_json form). A patch that sets the reduction but not sigma
// means the default sigma of that reduction (1.25 / r), not the default reduction's sigma.
Json patched_encoder(const Json& defaults, const Json& patch, const std::string& path) {
  if (!patch.is_object()) throw std::invalid_argument(path + ": expected a dict");
  check_known_fields(patch, defaults, path);
  Json merged = defaults;
  merged.merge_patch(patch);
  if (patch.contains("reduction") && !patch.contains("sigma") && merged["reduction"].is_number()) {
    EncoderConfig c;
    c.reduction = merged["reduction"].get<double>();
    merged["sigma"] = c.reduction > 0.0 ? c.effective_sigma() : 0.0;
  }
  return merged;
}

// The command line's defaults: FixedDecoderConfig's, on the vive panel as `--panel vive` parses it (a default Panel
// carries the name but gamma 2.2 on every channel).
FixedDecoderConfig default_config() {
  FixedDecoderConfig config;
  config.decoder.panel = parse_panel("vive");
  return config;
}

// A decoder configuration: None (the defaults), a dict in fixed_decoder_json form (it has "decoder") or one in
// decoder_json form (the algorithm parameters only; the fixed-point formats keep their defaults).
FixedDecoderConfig fixed_config_of(const py::object& value) {
  if (value.is_none()) return default_config();
  if (!py::isinstance<py::dict>(value)) throw std::invalid_argument("decoder config: expected a dict or None");
  Json patch = json_of(value, "decoder config");
  Json merged = fixed_decoder_json(default_config());
  if (!patch.contains("decoder")) patch = Json{{"decoder", patch}};
  Json& decoder_patch = patch["decoder"];
  if (decoder_patch.is_object() && decoder_patch.contains("encoder")) {
    merged["decoder"]["encoder"] =
        patched_encoder(merged["decoder"]["encoder"], decoder_patch["encoder"], "decoder config: decoder.encoder");
    decoder_patch.erase("encoder");
  }
  // A panel is replaced whole (another kind has other fields), and may be given by its spec string.
  std::optional<Json> panel;
  if (decoder_patch.is_object() && decoder_patch.contains("panel")) {
    panel = decoder_patch["panel"];
    if (panel->is_string()) {
      nlohmann::json spec;
      to_json(spec, parse_panel(panel->get<std::string>()));
      panel = spec;
    }
    decoder_patch.erase("panel");
  }
  check_known_fields(patch, merged, "decoder config");
  merged.merge_patch(patch);
  if (panel) merged["decoder"]["panel"] = *panel;
  return fixed_decoder_config_from_json(merged);
}

// An encoder configuration: None, the encoder block itself, or any decoder configuration holding one (a report's
// parameters.decoder), whose encoder block is taken.
EncoderConfig encoder_config_of(const py::object& value) {
  if (value.is_none()) return EncoderConfig{};
  if (!py::isinstance<py::dict>(value)) throw std::invalid_argument("encoder config: expected a dict or None");
  Json patch = json_of(value, "encoder config");
  if (patch.contains("decoder")) return fixed_config_of(value).decoder.link;
  if (patch.contains("encoder")) patch = patch["encoder"];
  return encoder_config_from_json(
      patched_encoder(Json::parse(encoder_json(EncoderConfig{}).dump()), patch, "encoder config"));
}

Parity parity_of_name(const std::string& name) {
  if (name == "full") return Parity::Full;
  if (name == "reduced") return Parity::Reduced;
  throw std::invalid_argument("parity must be 'full' or 'reduced', got '" + name + "'");
}

// ---- value types ----

struct View {
  LinkFrame frame;
};

struct Decoded {
  DecodedFrame frame;
};

py::dict stats_of(const FrameStats& s) {
  py::dict d;
  d["clipped_fraction"] = s.clipped_fraction;
  d["residual_mean_abs"] = s.residual_mean_abs;
  d["residual_max_abs"] = s.residual_max_abs;
  d["dropped_sum"] = s.dropped_sum;
  d["mean_motion_weight"] = s.mean_motion_weight;
  d["residual_applied"] = s.residual_applied;
  d["lcd_unreachable_fraction"] = s.lcd_unreachable_fraction;
  d["concealed_lines"] = s.concealed_lines;
  d["frame_lost"] = s.frame_lost;
  return d;
}

py::dict counts_of(const FixedStageCounts& c) {
  py::dict d;
  d["beta_clipped"] = c.beta_clipped;
  d["residual_saturated"] = c.residual_saturated;
  d["residual_rounded"] = c.residual_rounded;
  d["alpha_clipped"] = c.alpha_clipped;
  d["weight_underflow"] = c.weight_underflow;
  d["lcd_unreachable"] = c.lcd_unreachable;
  d["motion_test_lines_skipped"] = c.motion_test_lines_skipped;
  d["residual_read_lines_skipped"] = c.residual_read_lines_skipped;
  d["residual_write_lines_skipped"] = c.residual_write_lines_skipped;
  d["grey_lines"] = c.grey_lines;
  d["grey_reduced_rows"] = c.grey_reduced_rows;
  return d;
}

// A view built in Python: its codes copied into a matrix of its own, since a decoder may keep a view's codes (its
// d_t frame store) after the call.
View make_view(const py::handle& codes, std::int64_t t, const std::string& parity, int full_width, int full_height,
               int eye, int bits, const std::string& transfer) {
  py::object keep;
  const cv::Mat borrowed = borrow_image(codes, Element::Uint16, 3, "View codes", keep);
  View view;
  view.frame.codes = borrowed.clone();
  FrameMeta& m = view.frame.meta;
  m.index = t;
  m.eye = eye;
  m.parity = parity_of_name(parity);
  m.width = borrowed.cols;
  m.height = borrowed.rows;
  m.full_width = full_width;
  m.full_height = full_height;
  m.bits = bits;
  m.transfer = parse_transfer(transfer);
  check_view_meta(m, "View");
  return view;
}

// A report plane of a decoded view, or None where the decoder was made without them.
py::object report_plane(const cv::Mat& plane) {
  return plane.empty() ? py::object(py::none()) : py::object(share_image(plane));
}

FixedDecoderConfig with_report_planes(FixedDecoderConfig config, bool report_planes) {
  config.decoder.report_planes = report_planes;
  return config;
}

// The GIL is released while a decoder runs (other Python threads, other decoders, go on); the lock keeps two threads
// from running one decoder, whose per-eye state is not for concurrent use, at once.
class Decoder {
 public:
  Decoder(const std::string& name, const py::object& config, bool report_planes)
      : config_(with_report_planes(fixed_config_of(config), report_planes)), decoder_(make_decoder(name, config_)) {}

  std::string name() const { return decoder_->name(); }
  py::object config() const { return python_of(fixed_decoder_json(config_)); }

  Decoded decode(const View& view, const py::object& line_intact) {
    if (line_intact.is_none()) {
      py::gil_scoped_release unlocked;
      const std::lock_guard<std::mutex> lock(mutex_);
      const auto start = std::chrono::steady_clock::now();
      Decoded out{decoder_->decode(view.frame)};
      last_decode_seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      return out;
    }
    if (!py::isinstance<py::array>(line_intact) ||
        !py::reinterpret_borrow<py::array>(line_intact).dtype().is(py::dtype::of<std::uint8_t>()) ||
        py::reinterpret_borrow<py::array>(line_intact).ndim() != 1) {
      throw std::invalid_argument("line_intact: expected a one-dimensional uint8 array (0 = line lost), one entry per "
                                  "line of the view");
    }
    const auto mask = py::array_t<std::uint8_t, py::array::c_style>::ensure(line_intact);
    const std::span<const std::uint8_t> lines(mask.data(), static_cast<std::size_t>(mask.size()));
    py::gil_scoped_release unlocked;
    const std::lock_guard<std::mutex> lock(mutex_);
    return Decoded{decoder_->decode(view.frame, lines)};
  }

  Decoded decode_lost(const View& view) {
    py::gil_scoped_release unlocked;
    const std::lock_guard<std::mutex> lock(mutex_);
    return Decoded{decoder_->decode_lost(view.frame.meta)};
  }

  // The same views decoded in one call: what the per-call cost of the Python loop is measured against.
  std::vector<Decoded> decode_all(const std::vector<const View*>& views) {
    std::vector<Decoded> out;
    out.reserve(views.size());
    py::gil_scoped_release unlocked;
    const std::lock_guard<std::mutex> lock(mutex_);
    for (const View* view : views) out.push_back(Decoded{decoder_->decode(view->frame)});
    return out;
  }

  // The time the C++ decoder took in the last decode() of a whole view: a Python caller's time minus this is what
  // the call through the module cost (tools/python/bench_bindings.py).
  double last_decode_seconds() const {
    const std::lock_guard<std::mutex> lock(mutex_);
    return last_decode_seconds_;
  }

  py::object stage_counts() const {
    const std::lock_guard<std::mutex> lock(mutex_);
    const FixedStageCounts* counts = decoder_->stage_counts();
    if (counts == nullptr) return py::none();
    return counts_of(*counts);
  }

 private:
  FixedDecoderConfig config_;
  std::unique_ptr<HeadsetDecoder> decoder_;
  double last_decode_seconds_ = 0.0;
  mutable std::mutex mutex_;
};

Panel panel_of(const py::object& spec) {
  if (py::isinstance<py::str>(spec)) return parse_panel(spec.cast<std::string>());
  if (py::isinstance<py::dict>(spec)) {
    Panel panel;
    from_json(json_of(spec, "panel"), panel);
    return panel;
  }
  throw std::invalid_argument("panel: expected a spec string ('vive', 'lcd', 'gamma:2.2', ...) or a panel dict");
}

void require_same_shape(const cv::Mat& a, const cv::Mat& b, const std::string& what) {
  if (a.size() != b.size() || a.type() != b.type()) {
    throw std::invalid_argument(what + ": the two images differ in shape (" + std::to_string(a.rows) + "x" +
                                std::to_string(a.cols) + " against " + std::to_string(b.rows) + "x" +
                                std::to_string(b.cols) + ")");
  }
}

// Light emitted for a drive image (values in [0, 1]) after `previous` (LCD; ignored by OLED, which has no history).
cv::Mat emitted_light(const Panel& panel, const cv::Mat& drive, const cv::Mat* previous) {
  cv::Mat out(drive.size(), CV_64FC3);
  for (int y = 0; y < drive.rows; ++y) {
    const auto* v = drive.ptr<cv::Vec3d>(y);
    const auto* p = previous ? previous->ptr<cv::Vec3d>(y) : v;
    auto* o = out.ptr<cv::Vec3d>(y);
    for (int x = 0; x < drive.cols; ++x) {
      for (int c = 0; c < 3; ++c) {
        if (!(v[x][c] >= 0.0 && v[x][c] <= 1.0) || !(p[x][c] >= 0.0 && p[x][c] <= 1.0)) {
          throw std::invalid_argument("emitted: drive values must lie in [0, 1]; row " + std::to_string(y) +
                                      ", column " + std::to_string(x) + " has " + std::to_string(v[x][c]) +
                                      (previous ? " (or its previous drive " + std::to_string(p[x][c]) + ")" : ""));
        }
        o[x][c] = panel.emitted(v[x][c], p[x][c], c);
      }
    }
  }
  return out;
}

void translate_exceptions() {
  py::register_exception_translator([](std::exception_ptr thrown) {
    try {
      if (thrown) std::rethrow_exception(thrown);
    } catch (const py::error_already_set&) {
      throw;
    } catch (const py::builtin_exception&) {
      throw;
    } catch (const std::bad_alloc&) {
      PyErr_SetString(PyExc_MemoryError, "trm: out of memory");
    } catch (const std::exception& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    }
  });
}

}  // namespace
}  // namespace trm::python

PYBIND11_MODULE(trm, m) {
  using namespace trm;
  using namespace trm::python;
  translate_exceptions();
  m.doc() = "Temporal Resolution Multiplexing: scenes, the TRM encoder, the headset decoders (reference and "
            "fixed-point), panel models and metrics on numpy arrays (HxWx3, RGB). Linear light is float64 in [0, 1], "
            "link and drive codes uint16.";
  m.attr("__version__") = TRM_VERSION;

  m.def("scene_names", &scene_names, "The built-in scenes.");
  m.def("decoder_names", &decoder_names, "The decoders Decoder() builds by name.");
  m.def("default_decoder_config", [] { return python_of(fixed_decoder_json(default_config())); },
        "The default decoder configuration as a dict (fixed_decoder_json form, as report.json's parameters.decoder).");
  m.def("default_encoder_config", [] { return python_of(encoder_json(EncoderConfig{})); },
        "The default encoder configuration as a dict (encoder_json form).");

  py::class_<FrameSource, std::unique_ptr<FrameSource>>(m, "FrameSource", "Linear-light frames of a scene or input.")
      .def_property_readonly("name", &FrameSource::name)
      .def_property_readonly("width", &FrameSource::width)
      .def_property_readonly("height", &FrameSource::height)
      .def_property_readonly("frame_count", &FrameSource::frame_count, "Frames available; None for a scene.")
      .def("frame", [](FrameSource& s, std::int64_t t) {
             if (t < 0) throw std::invalid_argument("frame: t must be >= 0, got " + std::to_string(t));
             if (const auto n = s.frame_count(); n && t >= *n) {
               throw std::invalid_argument("frame: t = " + std::to_string(t) + " but the input has " +
                                           std::to_string(*n) + " frames");
             }
             return share_image(s.linear_frame(t));  // with the GIL held: a source is not for concurrent use
           }, py::arg("t"), "Frame t: HxWx3 float64 linear RGB in [0, 1] (read-only, no copy).");
  m.def("scene", [](const std::string& name, int width, int height, double refresh_hz, std::uint64_t seed,
                    const std::string& image, int supersample) {
          if (width < 1 || height < 1 || width > kMaxViewSide || height > kMaxViewSide) {
            throw std::invalid_argument("scene: width and height must be 1 .. " + std::to_string(kMaxViewSide));
          }
          if (supersample < 1 || supersample > 16) throw std::invalid_argument("scene: supersample must be 1 .. 16");
          validate_refresh_hz(refresh_hz, "scene: refresh_hz");
          SceneParams p;
          p.width = width;
          p.height = height;
          p.refresh_hz = refresh_hz;
          p.seed = seed;
          p.image_path = image;
          p.supersample = supersample;
          return make_scene(name, p);
        },
        py::arg("name"), py::arg("width") = 1080, py::arg("height") = 1200, py::arg("refresh_hz") = 90.0,
        py::arg("seed") = 1, py::arg("image") = "", py::arg("supersample") = 4, "A built-in scene (scene_names()).");
  m.def("image_sequence", &open_image_sequence, py::arg("pattern"),
        "An image sequence as `trm run --input` reads it: a glob such as 'DIR/frame_*.png', sorted by name, sRGB.");

  py::class_<View>(m, "View", "One view the link carries: link codes and their metadata.")
      .def(py::init(&make_view), py::arg("codes"), py::arg("t"), py::arg("parity"), py::arg("full_width"),
           py::arg("full_height"), py::arg("eye") = 0, py::arg("bits") = 8, py::arg("transfer") = "srgb",
           "A view from HxWx3 uint16 codes (copied once: a decoder may keep them).")
      .def_property_readonly("codes", [](const View& v) { return share_image(v.frame.codes); },
                             "HxWx3 uint16 link codes (read-only, no copy).")
      .def_property_readonly("t", [](const View& v) { return v.frame.meta.index; })
      .def_property_readonly("eye", [](const View& v) { return v.frame.meta.eye; })
      .def_property_readonly("parity", [](const View& v) { return std::string(to_string(v.frame.meta.parity)); })
      .def_property_readonly("full_width", [](const View& v) { return v.frame.meta.full_width; })
      .def_property_readonly("full_height", [](const View& v) { return v.frame.meta.full_height; })
      .def_property_readonly("bits", [](const View& v) { return v.frame.meta.bits; })
      .def_property_readonly("transfer", [](const View& v) { return std::string(to_string(v.frame.meta.transfer)); })
      .def("__repr__", [](const View& v) {
        return "<trm.View t=" + std::to_string(v.frame.meta.index) + " eye=" + std::to_string(v.frame.meta.eye) + " " +
               to_string(v.frame.meta.parity) + " " + std::to_string(v.frame.codes.cols) + "x" +
               std::to_string(v.frame.codes.rows) + ">";
      });

  py::class_<TrmEncoder>(m, "Encoder", "The GPU-side TRM encoder.")
      .def(py::init([](const py::object& config) { return TrmEncoder(encoder_config_of(config)); }),
           py::arg("config") = py::none(),
           "config: None (defaults), an encoder dict (default_encoder_config() form, fields left out keep their "
           "defaults) or a decoder configuration holding one.")
      .def_property_readonly("config", [](const TrmEncoder& e) { return python_of(encoder_json(e.config())); })
      .def("encode", [](const TrmEncoder& e, const py::handle& linear, std::int64_t t, int eye,
                        const py::object& parity) {
             py::object keep;
             const cv::Mat frame = borrow_image(linear, Element::Float64, 3, "encode: linear", keep);
             if (!parity.is_none() && !py::isinstance<py::str>(parity)) {
               throw std::invalid_argument("encode: parity must be None, 'full' or 'reduced'");
             }
             const std::optional<Parity> forced =
                 parity.is_none() ? std::nullopt : std::optional(parity_of_name(parity.cast<std::string>()));
             py::gil_scoped_release unlocked;
             return View{forced ? e.encode_as(*forced, frame, t, eye) : e.encode(frame, t, eye)};
           },
           py::arg("linear"), py::arg("t"), py::arg("eye") = 0, py::arg("parity") = py::none(),
           "Frame t of one eye (HxWx3 float64 linear RGB in [0, 1], read in place when C-contiguous) as the view the "
           "link carries: full or reduced by TRM's parity rule, or as `parity` says ('full' / 'reduced').");

  py::class_<Decoded>(m, "Decoded", "One decoded view: what the panel is driven with and emits.")
      .def_property_readonly("drive_codes", [](const Decoded& d) { return share_image(d.frame.drive_codes); },
                             "HxWx3 uint16 panel drive codes (output_bits).")
      .def_property_readonly("drive", [](const Decoded& d) { return report_plane(d.frame.drive); },
                             "HxWx3 float64 drive values v in [0, 1] before output quantisation (None without "
                             "report planes).")
      .def_property_readonly("wanted_linear", [](const Decoded& d) { return report_plane(d.frame.wanted_linear); },
                             "HxWx3 float64: clamp(beta) for a full view, alpha' for a reduced one (None without "
                             "report planes).")
      .def_property_readonly("emitted_linear", [](const Decoded& d) { return report_plane(d.frame.emitted_linear); },
                             "HxWx3 float64 light the panel emits from the quantised drive (None without report "
                             "planes).")
      .def_property_readonly("stats", [](const Decoded& d) { return stats_of(d.frame.stats); })
      .def_property_readonly("t", [](const Decoded& d) { return d.frame.meta.index; })
      .def_property_readonly("eye", [](const Decoded& d) { return d.frame.meta.eye; })
      .def_property_readonly("parity", [](const Decoded& d) { return std::string(to_string(d.frame.meta.parity)); });

  py::class_<Decoder>(m, "Decoder", "A headset decoder with per-eye state across calls.")
      .def(py::init<const std::string&, const py::object&, bool>(), py::arg("name"), py::arg("config") = py::none(),
           py::kw_only(), py::arg("report_planes") = true,
           "name: 'reference', 'fixed' (streaming, the hardware model) or 'fixed-frame'. config: None, a dict in "
           "default_decoder_config() form (as report.json's parameters.decoder) or in its 'decoder' block's form; "
           "fields left out keep their defaults. report_planes=False: drive codes and statistics only (drive, "
           "wanted_linear and emitted_linear are None), the same codes in less time and memory.")
      .def_property_readonly("name", &Decoder::name)
      .def_property_readonly("config", &Decoder::config, "The whole configuration (default_decoder_config() form).")
      .def("decode", &Decoder::decode, py::arg("view"), py::arg("line_intact") = py::none(),
           "Decodes a view that arrived; line_intact (uint8, one per line of the view, 0 = lost) conceals lost lines.")
      .def("decode_lost", &Decoder::decode_lost, py::arg("view"),
           "The view never arrived: the panel holds this eye's previous output (black if none).")
      .def("decode_all", &Decoder::decode_all, py::arg("views"), "decode() of every view, in one call.")
      .def_property_readonly("last_decode_seconds", &Decoder::last_decode_seconds,
                             "Seconds the C++ decoder spent in the last decode(view) without a line mask.")
      .def_property_readonly("stage_counts", &Decoder::stage_counts,
                             "Fixed-point stage events of the last view as a dict; None for the reference.");

  py::class_<Panel>(m, "Panel", "A panel model (OLED gamma per channel, or the LCD temporal merge).")
      .def(py::init(&panel_of), py::arg("spec"),
           "spec: 'vive', 'rift', 'generic', 'gamma:G', 'gamma:GR,GG,GB', 'lcd', 'lcd:p1,p2,p3,p4,gamma', or the "
           "panel's dict (Panel.config).")
      .def_property_readonly("config", [](const Panel& p) {
        nlohmann::ordered_json j;
        to_json(j, p);
        return python_of(j);
      })
      .def_property_readonly("has_history", &Panel::has_history, "The LCD's emission depends on the previous drive.")
      .def("emitted", [](const Panel& p, const py::handle& drive, const py::object& previous) {
             py::object keep_drive, keep_previous;
             const cv::Mat v = borrow_image(drive, Element::Float64, 3, "emitted: drive", keep_drive);
             cv::Mat v_prev;
             if (!previous.is_none()) {
               v_prev = borrow_image(previous, Element::Float64, 3, "emitted: previous", keep_previous);
               require_same_shape(v, v_prev, "emitted");
             }
             cv::Mat out;
             {
               py::gil_scoped_release unlocked;
               out = emitted_light(p, v, previous.is_none() ? nullptr : &v_prev);
             }
             return share_image(out);
           },
           py::arg("drive"), py::arg("previous") = py::none(),
           "Linear light emitted for HxWx3 float64 drive values in [0, 1]; LCD: after `previous` (the same frame held "
           "when None).");

  m.def("psnr_srgb", [](const py::handle& a, const py::handle& b) {
          py::object ka, kb;
          const cv::Mat ma = borrow_image(a, Element::Float64, 3, "psnr_srgb: a", ka);
          const cv::Mat mb = borrow_image(b, Element::Float64, 3, "psnr_srgb: b", kb);
          require_same_shape(ma, mb, "psnr_srgb");
          return psnr_srgb(ma, mb);
        }, py::arg("a"), py::arg("b"), "PSNR (dB) of two linear images on their sRGB encodings; inf when identical.");
  m.def("ssim_srgb", [](const py::handle& a, const py::handle& b) {
          py::object ka, kb;
          const cv::Mat ma = borrow_image(a, Element::Float64, 3, "ssim_srgb: a", ka);
          const cv::Mat mb = borrow_image(b, Element::Float64, 3, "ssim_srgb: b", kb);
          require_same_shape(ma, mb, "ssim_srgb");
          return ssim_srgb(ma, mb);
        }, py::arg("a"), py::arg("b"), "SSIM of two linear images on their 8-bit sRGB encodings, mean over channels.");
  m.def("perceived_pair", [](const py::handle& a, const py::handle& b) {
          py::object ka, kb;
          const cv::Mat ma = borrow_image(a, Element::Float64, 3, "perceived_pair: a", ka);
          const cv::Mat mb = borrow_image(b, Element::Float64, 3, "perceived_pair: b", kb);
          require_same_shape(ma, mb, "perceived_pair");
          return share_image(perceived_pair(ma, mb));
        }, py::arg("a"), py::arg("b"), "Talbot-Plateau: the mean of two frames' linear light.");
  m.def("mtcd", [](const std::vector<py::object>& frames) {
          std::vector<py::object> keep(frames.size());
          std::vector<cv::Mat> mats;
          for (std::size_t k = 0; k < frames.size(); ++k) {
            const std::string what = "mtcd: frame " + std::to_string(k);
            const py::array a = py::isinstance<py::array>(frames[k]) ? py::reinterpret_borrow<py::array>(frames[k])
                                                                      : py::array();
            if (a && a.dtype().is(py::dtype::of<double>())) {
              mats.push_back(borrow_image(frames[k], Element::Float64, 3, what, keep[k]));
            } else {
              mats.push_back(borrow_codes_image(frames[k], what, keep[k]));
            }
          }
          return mtcd(mats);
        }, py::arg("frames"),
        "Mean temporal colour difference (Kim et al. Eq. 6) over HxWx3 frames (float64, uint8 or uint16), in their "
        "own units.");
  m.def("visual_difference_energy", [](const py::handle& a, const py::handle& b, double ppd, double fps, double vr) {
          py::object ka, kb;
          const cv::Mat ma = borrow_image(a, Element::Float64, 1, "visual_difference_energy: l_a", ka);
          const cv::Mat mb = borrow_image(b, Element::Float64, 1, "visual_difference_energy: l_b", kb);
          return visual_difference_energy(ma, mb, ppd, fps, vr);
        }, py::arg("l_a"), py::arg("l_b"), py::arg("pixels_per_degree"), py::arg("samples_per_second"),
        py::arg("retinal_velocity_deg_s") = 0.0,
        "The supplement's visual difference energy (Eqs. 1, 2, 4) between two x-t luminance images (K x N float64: "
        "one row per time sample, one column per pixel of the line).");

  m.def("read_png", [](const std::string& path) {
          cv::Mat image = media::read_image(path, cv::IMREAD_UNCHANGED);
          if (image.empty()) throw std::invalid_argument("read_png: cannot read an image from '" + path + "'");
          if (image.channels() != 3) {
            throw std::invalid_argument("read_png: '" + path + "' has " + std::to_string(image.channels()) +
                                        " channels; RGB images only");
          }
          cv::cvtColor(image, image, cv::COLOR_BGR2RGB);
          return share_image(image);
        }, py::arg("path"), "An 8- or 16-bit RGB PNG as HxWx3 uint8 or uint16 (as trm writes codes).");
  m.def("write_png", [](const std::string& path, const py::handle& codes) {
          py::object keep;
          const cv::Mat rgb = borrow_codes_image(codes, "write_png: codes", keep);
          cv::Mat bgr;
          cv::cvtColor(rgb, bgr, cv::COLOR_RGB2BGR);
          bool written = false;
          try {
            written = media::write_image(path, bgr);
          } catch (const cv::Exception& e) {
            throw std::invalid_argument("write_png: cannot write '" + path + "': " + e.what());
          }
          if (!written) throw std::invalid_argument("write_png: cannot write '" + path + "'");
        }, py::arg("path"), py::arg("codes"), "HxWx3 uint8 or uint16 RGB codes as a PNG.");
}
