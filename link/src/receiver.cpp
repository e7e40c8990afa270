#include "trm/link.hpp"
#include "trm/jpegls.hpp"

#include "bit_packing.hpp"

#include <algorithm>
#include <cstring>
#include <exception>

namespace trm::link {

namespace {

bool same_view(const FrameMeta& a, const FrameMeta& b) {
  return a.index == b.index && a.eye == b.eye && a.parity == b.parity && a.width == b.width &&
         a.height == b.height && a.full_width == b.full_width && a.full_height == b.full_height &&
         a.bits == b.bits && a.transfer == b.transfer;
}

}  // namespace

const char* to_string(PushResult result) {
  switch (result) {
    case PushResult::Accepted: return "accepted";
    case PushResult::Damaged: return "damaged";
    case PushResult::Malformed: return "malformed";
    case PushResult::Inconsistent: return "inconsistent";
    case PushResult::Duplicate: return "duplicate";
    case PushResult::Stale: return "stale";
  }
  return "?";
}

int ReceivedFrame::intact_lines() const {
  return static_cast<int>(std::count(line_intact.begin(), line_intact.end(), std::uint8_t{1}));
}

Receiver::Receiver(ReceiverLimits limits) : limits_(limits) {}

PushResult Receiver::push(std::span<const std::uint8_t> bytes) {
  ++counters_.packets_received;
  const std::optional<ParsedPacket> parsed = parse_packet(bytes, limits_, &last_error_);
  if (!parsed) {
    if (last_error_ == PacketError::CrcMismatch || last_error_ == PacketError::TooShort) {
      ++counters_.crc_failures;
      return PushResult::Damaged;
    }
    ++counters_.malformed;
    return PushResult::Malformed;
  }
  const PacketHeader& h = parsed->header;

  // Frame boundaries: link frames are sent in order, so a later index ends every view of earlier ones.
  if (have_handed_out_ && h.frame_index <= handed_out_through_) {
    ++counters_.stale;
    return PushResult::Stale;
  }
  if (have_index_ && h.frame_index < current_index_) {
    ++counters_.stale;
    return PushResult::Stale;
  }
  if (!have_index_ || h.frame_index > current_index_) {
    if (have_index_) {
      hand_out_all();
      if (h.frame_index > current_index_ + 1)
        counters_.frame_index_gaps += static_cast<std::uint64_t>(h.frame_index - current_index_ - 1);
    } else if (have_handed_out_ && h.frame_index > handed_out_through_ + 1) {
      counters_.frame_index_gaps += static_cast<std::uint64_t>(h.frame_index - handed_out_through_ - 1);
    }
    have_index_ = true;
    current_index_ = h.frame_index;
  }

  Assembly& a = assembly_[h.stream];
  const FrameMeta meta = h.frame_meta();
  if (a.active && !same_view(a.meta, meta)) {
    ++counters_.inconsistent;
    return PushResult::Inconsistent;
  }
  const cv::Rect rect(h.first_column, h.first_line, h.column_count, h.line_count);
  if (a.active && cv::countNonZero(a.coverage(rect)) != 0) {
    ++counters_.duplicates;
    return PushResult::Duplicate;
  }

  // A bad payload must leave the view untouched (and start none): a raw one is checked before it is unpacked into
  // the view, a JPEG-LS one is decoded into scratch first.
  const cv::Rect whole(0, 0, h.column_count, h.line_count);
  const bool raw = h.coding == PayloadCoding::Raw;
  if (raw) {
    if (!detail::raw_padding_is_zero(parsed->payload, h.bits, whole)) {
      ++counters_.malformed;
      return PushResult::Malformed;
    }
  } else {
    try {
      scratch_ = jpegls_decode(parsed->payload, h.column_count, h.line_count, h.bits);
    } catch (const std::exception&) {
      ++counters_.malformed;
      return PushResult::Malformed;
    }
  }

  if (!a.active) {
    // Sizes were checked against the receiver's limits by parse_packet before this allocation.
    a.active = true;
    a.meta = meta;
    // Not cleared: every line is either covered whole by accepted packets or zeroed when handed out.
    a.codes.create(h.height, h.width, CV_16UC3);
    a.coverage = cv::Mat::zeros(h.height, h.width, CV_8U);
  }
  if (raw) detail::unpack_codes(parsed->payload, h.bits, a.codes, rect);
  else scratch_.copyTo(a.codes(rect));
  for (int y = rect.y; y < rect.y + rect.height; ++y) {  // row by row: cv::Mat::setTo costs more than the copy
    std::memset(a.coverage.ptr<std::uint8_t>(y) + rect.x, 1, static_cast<std::size_t>(rect.width));
  }

  if (have_sequence_[h.stream] && h.sequence != expected_sequence_[h.stream]) {
    // Unsigned difference: correct across the 2^32 wrap. A sequence that went backwards is a resent or
    // reordered packet, not a gap.
    const std::uint32_t gap = h.sequence - expected_sequence_[h.stream];
    if (gap < (1u << 31)) counters_.sequence_gaps += gap;
  }
  have_sequence_[h.stream] = true;
  expected_sequence_[h.stream] = h.sequence + 1u;

  ++counters_.packets_accepted;
  return PushResult::Accepted;
}

void Receiver::hand_out_all() {
  for (Assembly& a : assembly_) {  // stream order
    if (!a.active) continue;
    ReceivedFrame f;
    f.meta = a.meta;
    f.codes = std::move(a.codes);
    f.line_intact.resize(static_cast<std::size_t>(a.meta.height));
    for (int y = 0; y < a.meta.height; ++y) {
      const bool intact = cv::countNonZero(a.coverage.row(y)) == a.meta.width;
      f.line_intact[static_cast<std::size_t>(y)] = intact ? 1 : 0;
      if (!intact) {
        f.codes.row(y).setTo(cv::Scalar::all(0));  // never hand out half a line
        ++counters_.lines_lost;
      }
    }
    ++counters_.frames_out;
    if (f.complete()) ++counters_.frames_complete; else ++counters_.frames_partial;
    ready_.push_back(std::move(f));
    a = Assembly{};
  }
  if (have_index_) {
    have_handed_out_ = true;
    handed_out_through_ = current_index_;
    have_index_ = false;
  }
}

void Receiver::flush() { hand_out_all(); }

std::vector<ReceivedFrame> Receiver::take_frames() {
  std::vector<ReceivedFrame> out;
  out.swap(ready_);
  return out;
}

}  // namespace trm::link
