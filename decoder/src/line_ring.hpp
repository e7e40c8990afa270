// The line buffer of the streaming decoder (DESIGN §5): a fixed number of circular lines with a rotating index, as a
// hardware line buffer is built.
#pragma once

#include <algorithm>
#include <cstddef>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace trm::fixed_detail {

// `depth` circular lines of `samples` values; input line n >= 0 lives in slot n mod depth. Reading a line that was
// overwritten (or never written) is a scheduling bug and throws. The lines are not initialised, and a copy copies only
// the lines written: a buffer that holds none (a view's whole-view template, FixedStreamingDecoder::decode_in_bands)
// touches no memory until its lines are written. The sanitizer build (TRM_POISON_LINE_BUFFERS) fills them with a
// pattern instead, so that a read of memory no line wrote would change the bits the tests compare.
//
// A line can also be held where it already is (refer): a whole view's input lines, which outlive the view, are then
// read in place instead of copied in. The slot is taken as by write (the line it held is gone), so the schedule's
// reads are checked the same way and the buffer's depth means what it means in hardware.
template <typename T>
class LineRing {
 public:
  LineRing(std::string name, int depth, int samples)
      : name_(std::move(name)),
        samples_(static_cast<std::size_t>(samples)),
        data_(std::make_unique_for_overwrite<T[]>(static_cast<std::size_t>(depth) * samples_)),
        tags_(static_cast<std::size_t>(depth), kUnwritten),
        external_(static_cast<std::size_t>(depth), nullptr) {
    poison();
  }
  LineRing(const LineRing& other)
      : name_(other.name_),
        samples_(other.samples_),
        data_(std::make_unique_for_overwrite<T[]>(other.tags_.size() * other.samples_)),
        tags_(other.tags_),
        external_(other.external_) {
    poison();
    for (std::size_t slot = 0; slot < tags_.size(); ++slot) {
      if (tags_[slot] == kUnwritten || external_[slot] != nullptr) continue;
      const T* line = other.data_.get() + slot * samples_;
      std::copy(line, line + samples_, data_.get() + slot * samples_);
    }
  }
  LineRing& operator=(const LineRing& other) {
    if (this != &other) *this = LineRing(other);
    return *this;
  }
  LineRing(LineRing&&) noexcept = default;
  LineRing& operator=(LineRing&&) noexcept = default;
  ~LineRing() = default;

  T* write(int line) {
    const std::size_t slot = take(line);
    external_[slot] = nullptr;
    return data_.get() + slot * samples_;
  }
  // Holds line `line` at `where` (samples values that outlive every read of it) instead of a copy in its slot.
  void refer(int line, const T* where) { external_[take(line)] = where; }
  const T* read(int line) const {
    const std::size_t slot = static_cast<std::size_t>(line) % tags_.size();
    if (line < 0 || tags_[slot] != line) {
      throw std::logic_error("line buffer '" + name_ + "': line " + std::to_string(line) + " is not held");
    }
    return external_[slot] != nullptr ? external_[slot] : data_.get() + slot * samples_;
  }

 private:
  static constexpr int kUnwritten = -1;  // no line: line numbers are >= 0

  std::size_t take(int line) {
    if (line < 0) throw std::logic_error("line buffer '" + name_ + "': line " + std::to_string(line) + " written");
    const std::size_t slot = static_cast<std::size_t>(line) % tags_.size();
    tags_[slot] = line;
    return slot;
  }

  void poison() {
#ifdef TRM_POISON_LINE_BUFFERS
    std::fill(data_.get(), data_.get() + tags_.size() * samples_, static_cast<T>(0x5A5A5A5A5A5A5A5AULL));
#endif
  }
  std::string name_;
  std::size_t samples_;
  std::unique_ptr<T[]> data_;
  std::vector<int> tags_;
  std::vector<const T*> external_;  // per slot: where a referred line is; null: the slot's own storage
};

}  // namespace trm::fixed_detail
