// `interlace`: odd and even rows in alternate frames (Table 1 "Interlace": combing, 50 % of the pixels). Each slot
// renders and sends one field, the rows of TRM's parity (even rows where TRM sends its full frame, odd rows where it
// sends its reduced one); the headset shows the missing rows black, as in the paper, or with the option "double"
// repeats the field row next to them (line doubling: full peak luminance, half the vertical resolution).
#include "method_support.hpp"

#include <stdexcept>

namespace trm::methods {

namespace {

// The rows of view (t, eye)'s field start at this row.
int first_row(std::int64_t t, int eye, const EncoderConfig& link) { return parity_of(t, eye, link) == Parity::Full ? 0 : 1; }
int rows_of_field(int full_height, int first) { return (full_height - first + 1) / 2; }

bool line_doubling(const MethodSetup& setup) {
  if (setup.option.empty()) return false;
  if (setup.option == "double") return true;
  throw std::invalid_argument("method 'interlace': unknown option '" + setup.option +
                              "' (interlace shows missing rows black; interlace:double repeats the field's rows)");
}

class InterlaceSender : public MethodSender {
 public:
  explicit InterlaceSender(const EncoderConfig& link) : encoder_(link) {}
  bool sends(std::int64_t, int) const override { return true; }
  FrameMeta view_meta(std::int64_t t, int eye, cv::Size full) const override {
    const int rows = rows_of_field(full.height, first_row(t, eye, encoder_.config()));
    return view_meta_of(t, eye, Parity::Reduced, cv::Size(full.width, rows), full, encoder_.config());
  }
  Transmission send(const cv::Mat& linear, std::int64_t t, int eye) override {
    const int first = first_row(t, eye, encoder_.config());
    if (linear.rows < 2) throw std::invalid_argument("interlace: the view must be at least 2 rows high");
    // Only the field's rows are rendered and encoded.
    cv::Mat field_linear(rows_of_field(linear.rows, first), linear.cols, CV_64FC3);
    for (int k = 0; k < field_linear.rows; ++k) linear.row(first + 2 * k).copyTo(field_linear.row(k));
    LinkFrame field = encoder_.encode_as(Parity::Full, field_linear, t, eye);
    field.meta.parity = Parity::Reduced;  // on the link: a view smaller than the full raster
    field.meta.full_width = linear.cols;
    field.meta.full_height = linear.rows;
    Transmission out;
    out.frame = std::move(field);
    out.pixels_rendered = static_cast<std::int64_t>(out.frame.codes.total());
    return out;
  }

 private:
  TrmEncoder encoder_;
};

class InterlaceDisplay : public MethodDisplay {
 public:
  explicit InterlaceDisplay(const MethodSetup& setup)
      : panel_(setup.decoder.decoder), link_(setup.decoder.decoder.link), doubling_(line_doubling(setup)) {}
  DecodedFrame show(const LinkFrame& frame, std::span<const std::uint8_t> line_intact) override {
    check_received(frame, panel_.config(), "interlace");
    const FrameMeta& meta = frame.meta;
    const int first = first_row(meta.index, meta.eye, link_);
    if (meta.width != meta.full_width || meta.height != rows_of_field(meta.full_height, first)) {
      throw std::invalid_argument("interlace: view t=" + std::to_string(meta.index) + " is " +
                                  std::to_string(meta.width) + "x" + std::to_string(meta.height) +
                                  ", not the field of a " + std::to_string(meta.full_width) + "x" +
                                  std::to_string(meta.full_height) + " view");
    }
    cv::Mat codes = frame.codes;
    int concealed = 0;
    if (!line_intact.empty()) {
      codes = frame.codes.clone();
      concealed = conceal_lost_rows(codes, line_intact);
    }
    const cv::Mat field = linear_of_codes(codes, meta);
    cv::Mat shown = cv::Mat::zeros(meta.full_height, meta.full_width, CV_64FC3);
    for (int k = 0; k < field.rows; ++k) {
      const int y = first + 2 * k;
      field.row(k).copyTo(shown.row(y));
      // Line doubling: the missing row next to this field row (the row above for an odd field's first row).
      const int other = first == 0 ? y + 1 : y - 1;
      if (doubling_ && other >= 0 && other < shown.rows) field.row(k).copyTo(shown.row(other));
    }
    // An odd field of an odd-height view leaves the last row without a neighbour below: it takes the row above.
    if (doubling_ && first == 1 && shown.rows % 2 == 1) shown.row(shown.rows - 2).copyTo(shown.row(shown.rows - 1));
    DecodedFrame out = panel_.show(meta, shown);
    out.stats.concealed_lines = concealed;
    return out;
  }
  DecodedFrame show_lost(const FrameMeta& slot) override { return panel_.lost(slot); }
  DecodedFrame show_unsent(const FrameMeta&) override { throw std::logic_error("interlace: every field is sent"); }

 private:
  PanelShow panel_;
  EncoderConfig link_;
  bool doubling_;
};

}  // namespace

DisplayMethod interlace_method() {
  DisplayMethod m;
  m.name = "interlace";
  m.summary = "odd and even rows in alternate frames, missing rows black (50 % pixels rendered and sent)";
  m.option_help = "double: line doubling, each field row shown twice instead of black rows";
  m.make_sender = [](const MethodSetup& setup) -> std::unique_ptr<MethodSender> {
    (void)line_doubling(setup);
    return std::make_unique<InterlaceSender>(setup.decoder.decoder.link);
  };
  m.make_display = [](const MethodSetup& setup) -> std::unique_ptr<MethodDisplay> {
    return std::make_unique<InterlaceDisplay>(setup);
  };
  return m;
}

}  // namespace trm::methods
