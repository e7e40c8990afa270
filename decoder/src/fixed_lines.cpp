// The line kernels of fixed_lines.hpp, compiled once per x86 instruction set by Highway's foreach_target and chosen
// at run time. Every product is formed from operands that fit 32 bits (MulEven), which is what the plans' format
// checks guarantee; the tails shorter than a vector run the same arithmetic on scalars.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "fixed_lines.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include <hwy/highway.h>

#include "fixed_kernels.hpp"
#include "fixed_lines.hpp"

#include <algorithm>
#include <bit>
#include <cstdint>
#include <iterator>
#include <type_traits>

HWY_BEFORE_NAMESPACE();
namespace trm::fixed_detail::lines {
namespace HWY_NAMESPACE {

// (phase + step) mod 3 for phase < 3 and step < 3, without the division the modulo compiles to.
inline std::size_t next_phase(std::size_t phase, std::size_t step) {
  const std::size_t next = phase + step;
  return next >= 3 ? next - 3 : next;
}

// The kernels whose chain runs through a table lookup work a chunk of samples (pixels, in the motion test) at a time
// in passes: the places of the table words, then the words by look_up, then the rest. A gather inside one long vector
// loop stalled the loop's whole chain; scalar loads that do not wait on each other overlap.
constexpr std::size_t kPassChunk = 256;

// The next chunk of a kernel's passes: whole vectors of the `remaining` samples, at most kPassChunk.
inline std::size_t pass_chunk(std::size_t remaining, std::size_t lanes) {
  return std::min(kPassChunk, remaining / lanes * lanes);
}

// Fetches a table into the caches ahead of its lookups: in a full frame D's line buffers (17 rows of a reduced line at
// r = 1/2) pass through the first and second level caches between two output lines and push the tables out, and a
// lookup pass would then wait on each table line in turn. (For the OLED drive search's larger table it measured
// slower: only U's nodes take it.)
// A table larger than a first-level data cache (32 KiB) is not fetched whole.
template <typename Word>
inline void prefetch_table(const std::vector<Word>& table) {
  constexpr std::size_t kWordsPerLine = 64 / sizeof(Word);
  constexpr std::size_t kMaxWords = (std::size_t{32} << 10) / sizeof(Word);
  if (table.size() > kMaxWords) return;
  for (std::size_t i = 0; i < table.size(); i += kWordsPerLine) __builtin_prefetch(table.data() + i);
}

// out[i] = table[places[i]] for i < n (out may be places: the lookup pass in place). Four scalar loads ahead of their
// four stores; the empty asm keeps each index in a general register, so that the compiler neither vectorises the
// loop (GCC 12 built the indices as vectors and moved each lane out through the stack, which ran a line at up to
// twice the time, depending on the kernel and the build) nor interleaves each load with a store it may take as a
// dependency.
template <typename Word, typename Place, typename Out>
inline void look_up_into(const Word* table, const Place* places, std::size_t n, Out* out) {
  std::size_t i = 0;
  for (; i + 4 <= n; i += 4) {
    auto p0 = static_cast<std::size_t>(places[i]), p1 = static_cast<std::size_t>(places[i + 1]),
         p2 = static_cast<std::size_t>(places[i + 2]), p3 = static_cast<std::size_t>(places[i + 3]);
    asm("" : "+r"(p0), "+r"(p1), "+r"(p2), "+r"(p3));
    const Word v0 = table[p0], v1 = table[p1], v2 = table[p2], v3 = table[p3];
    out[i] = static_cast<Out>(v0);
    out[i + 1] = static_cast<Out>(v1);
    out[i + 2] = static_cast<Out>(v2);
    out[i + 3] = static_cast<Out>(v3);
  }
  for (; i < n; ++i) out[i] = static_cast<Out>(table[places[i]]);
}
template <typename Word, typename Place>
inline void look_up(const Word* table, Place* places, std::size_t n) {
  look_up_into(table, places, n, places);
}
namespace hn = hwy::HWY_NAMESPACE;

#if HWY_TARGET != HWY_SCALAR
// On four 64-bit lanes (AVX2): the words table[at[i]] and table[at[i] + 1] of each lane i by four 128-bit loads, as
// the 128-bit blocks of `low` (lanes 0 and 2) and `high` (lanes 1 and 3); InterleaveLower / InterleaveUpper of the
// two give the first / second words in lane order. On the CPUs measured (Zen 3) a gather of four words costs several
// times as much.
template <class D>
HWY_INLINE void LoadWordPairs(D d, const std::int64_t* table, hn::Vec<D> at, hn::Vec<D>& low, hn::Vec<D>& high) {
  static_assert(hn::MaxLanes(D()) == 4);
  HWY_ALIGN std::int64_t offset[4];
  hn::Store(at, d, offset);
  const hn::Half<D> dh;
  low = hn::Combine(d, hn::LoadU(dh, table + offset[2]), hn::LoadU(dh, table + offset[0]));
  high = hn::Combine(d, hn::LoadU(dh, table + offset[3]), hn::LoadU(dh, table + offset[1]));
}

// table[index] of each 64-bit lane (the tables LookupWords reads carry one word more, read with the last).
template <class D>
HWY_INLINE hn::Vec<D> LookupWords(D d, const std::int64_t* table, hn::Vec<D> index) {
  if constexpr (hn::MaxLanes(d) == 4) {
    hn::Vec<D> low, high;
    LoadWordPairs(d, table, index, low, high);
    return hn::InterleaveLower(d, low, high);
  } else {
    return hn::GatherIndex(d, table, index);
  }
}

// A count of true mask lanes kept per lane (one subtraction of the all-ones lanes per mask, where moving the mask to a
// scalar and counting its bits is a longer chain), and its total.
template <class D>
HWY_INLINE hn::Vec<D> CountInto(D d, hn::Vec<D> counts, hn::Mask<D> mask) {
  return hn::Sub(counts, hn::VecFromMask(d, mask));
}
template <class D>
HWY_INLINE std::uint64_t Total(D d, hn::Vec<D> counts) {
  return static_cast<std::uint64_t>(hn::GetLane(hn::SumOfLanes(d, counts)));
}

// A ROM word's interpolation, rounded half up: (node 2^j + step w + 2^(j-1)) >> j of word = node << 32 | step
// (packed_rom) and weight w in [0, 2^j). In unsigned lanes, exact because packed_rom takes only ROMs whose every node
// and node + step are non-negative, so the sum (a weighted mean of the two times 2^j) is; AVX2 has no 64-bit
// arithmetic shift. j is one count for all lanes or a vector of counts.
template <class D, class Shift>
HWY_INLINE hn::Vec<D> InterpolateWord(D d, hn::Vec<D> word, hn::Vec<D> weight, Shift j) {
  const hn::RebindToUnsigned<D> du;
  const hn::Repartition<std::int32_t, D> di32;
  const auto node = hn::ShiftRight<32>(hn::BitCast(du, word));
  const auto step_times_weight = hn::BitCast(du, hn::MulEven(hn::BitCast(di32, word), hn::BitCast(di32, weight)));
  if constexpr (std::is_same_v<Shift, int>) {
    const auto exact = hn::Add(hn::ShiftLeftSame(node, j), step_times_weight);
    return hn::BitCast(d, hn::ShiftRightSame(hn::Add(exact, hn::Set(du, std::uint64_t{1} << (j - 1))), j));
  } else {
    const auto shift = hn::BitCast(du, j);
    const auto one = hn::Set(du, std::uint64_t{1});
    const auto exact = hn::Add(hn::Shl(node, shift), step_times_weight);
    return hn::BitCast(d, hn::Shr(hn::Add(exact, hn::Shl(one, hn::Sub(shift, one))), shift));
  }
}

// The place of input code `code` (below 2^53) in an octave-segmented ROM, as InterpolatedLut::evaluate_raw finds it:
// the region by the code's leading one (read from its double's exponent; the bottom region holds the codes below
// 2^bottom_bits), the node and the weight over 2^scale_bits, for InterpolateWord.
template <class D>
struct OctavePlace {
  hn::Vec<D> node, weight, scale_bits;
};
template <class D>
HWY_INLINE OctavePlace<D> OctaveRomPlace(D d, hn::Vec<D> code, hn::Vec<D> bottom_bits, int segments_log2) {
  const hn::RebindToUnsigned<D> du;
  const hn::Rebind<double, D> df;
  const auto unit = hn::Set(d, hn::TFromD<D>{1});
  const auto lead =
      hn::Sub(hn::BitCast(d, hn::ShiftRight<52>(hn::BitCast(du, hn::ConvertTo(df, code)))), hn::Set(d, hn::TFromD<D>{1023}));
  const auto bottom = hn::Lt(lead, bottom_bits);
  const auto scale_bits = hn::IfThenElse(bottom, bottom_bits, lead);
  const auto region = hn::IfThenZeroElse(bottom, hn::Add(hn::Sub(lead, bottom_bits), unit));
  const auto offset = hn::IfThenElse(bottom, code, hn::Sub(code, hn::Shl(unit, hn::IfThenZeroElse(bottom, lead))));
  const auto scaled = hn::ShiftLeftSame(offset, segments_log2);
  return OctavePlace<D>{hn::Add(hn::ShiftLeftSame(region, segments_log2), hn::Shr(scaled, scale_bits)),
                        hn::And(scaled, hn::Sub(hn::Shl(unit, scale_bits), unit)), scale_bits};
}

// table[at] and table[at + 1] of each 64-bit lane.
template <class D>
HWY_INLINE void LookupAdjacent(D d, const std::int64_t* table, hn::Vec<D> at, hn::Vec<D>& first, hn::Vec<D>& second) {
  if constexpr (hn::MaxLanes(d) == 4) {
    hn::Vec<D> low, high;
    LoadWordPairs(d, table, at, low, high);
    first = hn::InterleaveLower(d, low, high);
    second = hn::InterleaveUpper(d, low, high);
  } else {
    first = hn::GatherIndex(d, table, at);
    second = hn::GatherIndex(d, table + 1, at);
  }
}

// first[i] = table[2 index[i]], second[i] = table[2 index[i] + 1].
template <class D>
HWY_INLINE void LookupPairs(D d, const std::int64_t* table, hn::Vec<D> index, hn::Vec<D>& first, hn::Vec<D>& second) {
  LookupAdjacent(d, table, hn::Add(index, index), first, second);
}
#endif

// Scalar forms, for the tails (the same expressions as the vector bodies and as the stage functions).
inline std::int64_t eotf_scalar(std::uint64_t blended, const EotfPlan& p) {
  const std::uint64_t upsampled = (blended + (std::uint64_t{1} << (p.blend_shift - 1))) >> p.blend_shift;
  const std::size_t node = static_cast<std::size_t>(upsampled >> p.weight_bits);
  const auto weight = static_cast<std::int64_t>(upsampled & ((std::uint64_t{1} << p.weight_bits) - 1));
  const std::int64_t exact = p.node[node] * (std::int64_t{1} << p.weight_bits) + p.step[node] * weight;
  return (exact + (std::int64_t{1} << (p.weight_bits - 1))) >> p.weight_bits;
}

inline std::uint16_t drive_scalar(std::int64_t x, std::size_t s, const DrivePlan& p) {
  const auto u = static_cast<std::uint64_t>(x);
  if (x < 0 || x >= p.value_limit) {  // threshold_search: the largest k with x >= T_k
    const std::int64_t* t = p.thresholds.data() + p.threshold_offset[s % 3];
    int lo = 0;
    int hi = p.threshold_count[s % 3] - 1;
    while (lo < hi) {
      const int mid = (lo + hi + 1) / 2;
      if (x >= t[mid]) lo = mid; else hi = mid - 1;
    }
    return static_cast<std::uint16_t>(lo);
  }
  const int lead = static_cast<int>(std::bit_width(u)) - 1;
  const int m = p.mantissa_bits;
  const std::int64_t bucket =
      lead < m ? static_cast<std::int64_t>(u)
               : (static_cast<std::int64_t>(lead - m + 1) << m) +
                     static_cast<std::int64_t>((u >> (lead - m)) & ((std::uint64_t{1} << m) - 1));
  const std::size_t channel = s % 3;
  std::int64_t k = p.base[static_cast<std::size_t>(p.bucket_offset[channel] + bucket)];
  for (int i = 0; i < p.steps; ++i) k += x >= p.thresholds[static_cast<std::size_t>(k + 1)] ? 1 : 0;
  return static_cast<std::uint16_t>(k - p.threshold_offset[channel]);
}

// The scalar target (x86-64 CPUs without SSSE3) has one lane, where the vector bodies' lane pairing does not apply:
// there the tails' loops do the whole line.
void BlendColumns(const std::uint16_t* row, const ColumnBlendPlan& plan, std::size_t n, std::uint32_t* out) {
  // The blend's formula, sample by sample: the scalar target, the tails, the quarter path's edges.
  const auto by_formula = [&](std::size_t begin, std::size_t end) {
    for (std::size_t s = begin; s < end; ++s) {
      const std::uint32_t w = plan.upper[s];
      out[s] = (plan.unit - w) * row[static_cast<std::size_t>(plan.left[s])] +
               w * row[static_cast<std::size_t>(plan.right[s])];
    }
  };
#if HWY_TARGET == HWY_SCALAR
  by_formula(0, n);
#else
  const std::size_t row_samples = static_cast<std::size_t>(std::max(plan.left.back(), plan.right.back())) + 1;
  const hn::ScalableTag<std::uint32_t> du;
  const hn::RebindToSigned<decltype(du)> di;
  const hn::Rebind<std::uint16_t, decltype(du)> d16;
  const std::size_t lanes = hn::Lanes(du);
  const auto unit = hn::Set(du, plan.unit);
  if (plan.half && lanes >= 8 && n == 2 * row_samples) {
    // Output vector at sample s: pixel pair P = s / 6 (its even column's first sample), the row windows at 3P (a_j)
    // and 3P -+ 3 (the neighbours); lane l reads window lane 3 ((s + l) / 6 - P) + (s + l) mod 3, from the window
    // after where (s + l) mod 6 >= 3 (an odd column). s mod 6 is 0, then lanes mod 6 and twice it: three patterns.
    HWY_ALIGN std::int32_t lane_of[3][hn::MaxLanes(di)];
    HWY_ALIGN std::int32_t odd_of[3][hn::MaxLanes(di)];
    for (std::size_t pattern = 0; pattern < 3; ++pattern) {
      const std::size_t s = pattern * lanes;
      for (std::size_t l = 0; l < lanes; ++l) {
        const std::size_t o = s + l;
        lane_of[pattern][l] = static_cast<std::int32_t>(3 * (o / 6 - s / 6) + o % 3);
        odd_of[pattern][l] = o % 6 >= 3 ? -1 : 0;
      }
    }
    const hn::Vec<decltype(di)> lane_vectors[3] = {hn::Load(di, lane_of[0]), hn::Load(di, lane_of[1]),
                                                   hn::Load(di, lane_of[2])};
    const hn::Vec<decltype(di)> odd_vectors[3] = {hn::Load(di, odd_of[0]), hn::Load(di, odd_of[1]),
                                                  hn::Load(di, odd_of[2])};
    const int quarter_shift = std::countr_zero(plan.unit) - 2;
    const auto load = [&](std::size_t at) { return hn::PromoteTo(du, hn::LoadU(d16, row + at)); };
    // From pixel pair 1 (a pixel before it; s = 6 is 0 mod 6, pattern 0) while the windows stay in the row.
    std::size_t s = 6;
    by_formula(0, s);
    for (std::size_t pattern = 0; s + lanes <= n && 3 * (s / 6) + 3 + lanes <= row_samples;
         s += lanes, pattern = pattern == 2 ? 0 : pattern + 1) {
      const std::size_t at = 3 * (s / 6);
      const auto index = hn::IndicesFromVec(du, lane_vectors[pattern]);
      const auto a = hn::TableLookupLanes(load(at), index);
      const auto before = hn::TableLookupLanes(load(at - 3), index);
      const auto after = hn::TableLookupLanes(load(at + 3), index);
      const auto other = hn::IfThenElse(hn::RebindMask(du, hn::MaskFromVec(odd_vectors[pattern])), after, before);
      hn::StoreU(hn::ShiftLeftSame(hn::Add(other, hn::Add(a, hn::ShiftLeft<1>(a))), quarter_shift), du, out + s);
    }
    by_formula(s, n);
    return;
  }
  // The reduced row's samples widened once, so the taps are 32-bit gathers.
  thread_local std::vector<std::uint32_t> wide;
  wide.resize(row_samples + 2 * lanes);  // a window's second vector may reach past the row
  std::size_t i = 0;
  for (; i + lanes <= row_samples; i += lanes) hn::StoreU(hn::PromoteTo(du, hn::LoadU(d16, row + i)), du, wide.data() + i);
  for (; i < row_samples; ++i) wide[i] = row[i];
  std::size_t s = 0;
  if (const ColumnBlendPlan::Windows* windows = plan.windows_for(lanes)) {
    for (std::size_t block = 0; s + lanes <= n; s += lanes, ++block) {
      const auto window = hn::LoadU(du, wide.data() + windows->start[block]);
      const auto a = hn::TableLookupLanes(window, hn::IndicesFromVec(du, hn::LoadU(di, windows->left.data() + s)));
      const auto b = hn::TableLookupLanes(window, hn::IndicesFromVec(du, hn::LoadU(di, windows->right.data() + s)));
      const auto w = hn::LoadU(du, plan.upper.data() + s);
      hn::StoreU(hn::Add(hn::Mul(hn::Sub(unit, w), a), hn::Mul(w, b)), du, out + s);
    }
  }
  if (const ColumnBlendPlan::Windows* windows = plan.double_windows_for(lanes); windows != nullptr && s + lanes <= n) {
    const auto lane_mask = hn::Set(di, static_cast<std::int32_t>(lanes - 1));
    const auto lanes_i = hn::Set(di, static_cast<std::int32_t>(lanes));
    for (std::size_t block = 0; s + lanes <= n; s += lanes, ++block) {
      const auto low = hn::LoadU(du, wide.data() + windows->start[block]);
      const auto high = hn::LoadU(du, wide.data() + windows->start[block] + lanes);
      const auto tap = [&](const std::int32_t* relative) {
        const auto index = hn::LoadU(di, relative + s);
        const auto lane = hn::IndicesFromVec(du, hn::And(index, lane_mask));
        return hn::IfThenElse(hn::RebindMask(du, hn::Lt(index, lanes_i)), hn::TableLookupLanes(low, lane),
                              hn::TableLookupLanes(high, lane));
      };
      const auto a = tap(windows->left.data());
      const auto b = tap(windows->right.data());
      const auto w = hn::LoadU(du, plan.upper.data() + s);
      hn::StoreU(hn::Add(hn::Mul(hn::Sub(unit, w), a), hn::Mul(w, b)), du, out + s);
    }
  }
  for (; s + lanes <= n; s += lanes) {
    const auto a = hn::GatherIndex(du, wide.data(), hn::LoadU(di, plan.left.data() + s));
    const auto b = hn::GatherIndex(du, wide.data(), hn::LoadU(di, plan.right.data() + s));
    const auto w = hn::LoadU(du, plan.upper.data() + s);
    hn::StoreU(hn::Add(hn::Mul(hn::Sub(unit, w), a), hn::Mul(w, b)), du, out + s);
  }
  by_formula(s, n);
#endif
}

// A linear value into a kernel's output line of either width (FixedLinePlans::code_rom32 says why 32 bits hold it).
template <typename Linear>
inline void store_linear(std::int64_t value, Linear* out) {
  *out = static_cast<Linear>(value);
}

#if HWY_TARGET != HWY_SCALAR
// A 64-bit lane's value into a line of either width (a 32-bit line holds only values within 32 bits).
template <class D, typename Linear>
HWY_INLINE void StoreLinear(D d, hn::Vec<D> v, Linear* line) {
  if constexpr (sizeof(Linear) == 8) {
    hn::StoreU(v, d, line);
  } else {
    const hn::RebindToUnsigned<D> du;
    const hn::Rebind<std::uint32_t, D> du32;
    hn::StoreU(hn::TruncateTo(du32, hn::BitCast(du, v)), du32, reinterpret_cast<std::uint32_t*>(line));
  }
}
#endif

// U's exact path over one output row (EotfPlan::node32): sample s's node place ((2^q_r - r) T' + r B') 2^up from the
// column blends T = T' 2^down and B = B' 2^down (exactly), for the row weight r over 2^q_r.
struct ExactRow {
  ExactRow(const EotfPlan& p, std::uint32_t upper, int column_bits, int row_bits)
      : down(p.frac_bits - column_bits),
        r(upper >> (p.frac_bits - row_bits)),
        r_other((std::uint32_t{1} << row_bits) - r),
        up(p.segments_log2 - column_bits - row_bits) {}
  std::uint32_t place(std::uint32_t top, std::uint32_t bottom) const {
    return (r_other * (top >> down) + r * (bottom >> down)) << up;
  }
#if HWY_TARGET != HWY_SCALAR
  template <class D>
  HWY_INLINE hn::Vec<D> places(D du, const std::uint32_t* top, const std::uint32_t* bottom) const {
    const auto t = hn::ShiftRightSame(hn::LoadU(du, top), down);
    const auto b = hn::ShiftRightSame(hn::LoadU(du, bottom), down);
    return hn::ShiftLeftSame(hn::Add(hn::Mul(hn::Set(du, r_other), t), hn::Mul(hn::Set(du, r), b)), up);
  }
#endif
  int down;
  std::uint32_t r;
  std::uint32_t r_other;
  int up;
};

// BlendRowsEotfInto where the blend is exact above the ROM's input (EotfPlan::node32): one 32-bit node per sample.
template <typename Linear>
void BlendRowsEotfExact(const std::uint32_t* top, const std::uint32_t* bottom, std::size_t n, std::uint32_t upper,
                        int column_bits, int row_bits, const EotfPlan& p, Linear* out) {
  const ExactRow row(p, upper, column_bits, row_bits);
  const std::int32_t* node = p.node32.data();
  prefetch_table(p.node32);  // 16 KiB at the defaults
  std::size_t s = 0;
#if HWY_TARGET != HWY_SCALAR
  const hn::ScalableTag<std::uint32_t> du;
  const std::size_t lanes = hn::Lanes(du);
  // In passes (kPassChunk): the nodes' places, then the nodes by scalar loads.
  HWY_ALIGN std::uint32_t places[kPassChunk];
  while (s + lanes <= n) {
    const std::size_t count = pass_chunk(n - s, lanes);
    for (std::size_t i = 0; i < count; i += lanes) hn::Store(row.places(du, top + s + i, bottom + s + i), du, places + i);
    look_up_into(node, places, count, out + s);
    s += count;
  }
#endif
  for (; s < n; ++s) out[s] = node[row.place(top[s], bottom[s])];
}

template <typename Linear>
void BlendRowsEotfInto(const std::uint32_t* top, const std::uint32_t* bottom, std::size_t n, std::uint32_t upper,
                       int column_bits, const EotfPlan& p, Linear* out) {
  const int row_bits = p.exact_row_bits(upper, column_bits);
  if (row_bits >= 0) {
    BlendRowsEotfExact(top, bottom, n, upper, column_bits, row_bits, p, out);
    return;
  }
  std::size_t s = 0;
#if HWY_TARGET != HWY_SCALAR
  const hn::ScalableTag<std::int64_t> d;
  const hn::RebindToUnsigned<decltype(d)> du;
  const hn::Rebind<std::uint32_t, decltype(du)> d32h;  // half-width loads of the uQb.W rows (and 32-bit stores)
  const hn::Repartition<std::uint32_t, decltype(du)> du32;
  const std::size_t lanes = hn::Lanes(d);
  // The plan's fields in locals: the compiler reloads whatever a vector store could alias.
  const int blend_shift = p.blend_shift;
  const int weight_bits = p.weight_bits;
  const std::int64_t* packed = p.packed.data();
  const auto lower_weight = hn::BitCast(du32, hn::Set(du, p.unit - upper));
  const auto upper_weight = hn::BitCast(du32, hn::Set(du, upper));
  const auto blend_half = hn::Set(du, std::uint64_t{1} << (blend_shift - 1));
  const auto weight_mask = hn::Set(du, (std::uint64_t{1} << weight_bits) - 1);
  // In passes (kPassChunk): the blend (each sample's ROM weight kept), the ROM words, the interpolation.
  HWY_ALIGN std::int64_t words[kPassChunk];
  HWY_ALIGN std::uint64_t weights[kPassChunk];
  while (s + lanes <= n) {
    const std::size_t count = pass_chunk(n - s, lanes);
    for (std::size_t i = 0; i < count; i += lanes) {
      const auto t = hn::BitCast(du32, hn::PromoteTo(du, hn::LoadU(d32h, top + s + i)));
      const auto b = hn::BitCast(du32, hn::PromoteTo(du, hn::LoadU(d32h, bottom + s + i)));
      const auto blended = hn::Add(hn::MulEven(lower_weight, t), hn::MulEven(upper_weight, b));  // uQb.2W
      const auto upsampled = hn::ShiftRightSame(hn::Add(blended, blend_half), blend_shift);       // uQb.U
      hn::Store(hn::And(upsampled, weight_mask), du, weights + i);
      hn::Store(hn::BitCast(d, hn::ShiftRightSame(upsampled, weight_bits)), d, words + i);
    }
    look_up(packed, words, count);
    for (std::size_t i = 0; i < count; i += lanes) {
      const auto weight = hn::BitCast(d, hn::Load(du, weights + i));
      const auto linear = InterpolateWord(d, hn::Load(d, words + i), weight, weight_bits);
      StoreLinear(d, linear, out + s + i);
    }
    s += count;
  }
#endif
  for (; s < n; ++s) {
    const std::uint64_t blended = static_cast<std::uint64_t>(p.unit - upper) * top[s] + static_cast<std::uint64_t>(upper) * bottom[s];
    store_linear(eotf_scalar(blended, p), out + s);
  }
}

// BlendRowsEotfExact's nodes as drive codes (FixedLinePlans::drive_of_node): node place i of sample s reads word
// 3 i + s mod 3 of the composed table.
void BlendRowsDriveExact(const std::uint32_t* top, const std::uint32_t* bottom, std::size_t n, std::uint32_t upper,
                         int column_bits, int row_bits, const EotfPlan& p, const std::uint16_t* drive_of_node,
                         std::uint16_t* codes) {
  const ExactRow row(p, upper, column_bits, row_bits);
  std::size_t s = 0;
#if HWY_TARGET != HWY_SCALAR
  const hn::ScalableTag<std::uint32_t> du;
  const std::size_t lanes = hn::Lanes(du);
  const auto three = hn::Set(du, 3u);
  // Element e: e mod 3, the channels of the samples s0.. of a vector from element s0 mod 3.
  static const std::array<std::uint32_t, 3 + DrivePlan::kMaxLanes> channel_of = [] {
    std::array<std::uint32_t, 3 + DrivePlan::kMaxLanes> t{};
    for (std::size_t e = 0; e < t.size(); ++e) t[e] = static_cast<std::uint32_t>(e % 3);
    return t;
  }();
  const std::size_t phase_step = lanes % 3;
  std::size_t phase = 0;
  HWY_ALIGN std::uint32_t places[kPassChunk];
  while (s + lanes <= n) {
    const std::size_t count = pass_chunk(n - s, lanes);
    for (std::size_t i = 0; i < count; i += lanes, phase = next_phase(phase, phase_step)) {
      const auto place = row.places(du, top + s + i, bottom + s + i);
      hn::Store(hn::Add(hn::Mul(place, three), hn::LoadU(du, channel_of.data() + phase)), du, places + i);
    }
    look_up_into(drive_of_node, places, count, codes + s);
    s += count;
  }
#endif
  for (; s < n; ++s) codes[s] = drive_of_node[3 * static_cast<std::size_t>(row.place(top[s], bottom[s])) + s % 3];
}

void BlendRowsEotf(const std::uint32_t* top, const std::uint32_t* bottom, std::size_t n, std::uint32_t upper,
                   int column_bits, const EotfPlan& p, std::int64_t* out) {
  BlendRowsEotfInto(top, bottom, n, upper, column_bits, p, out);
}
void BlendRowsEotf32(const std::uint32_t* top, const std::uint32_t* bottom, std::size_t n, std::uint32_t upper,
                     int column_bits, const EotfPlan& p, std::int32_t* out) {
  BlendRowsEotfInto(top, bottom, n, upper, column_bits, p, out);
}

#if HWY_TARGET != HWY_SCALAR
// ThresholdIndex::search over a vector, either lane width: the bucket (x itself below 2^m, else its octave, the
// leading-one position less m - 1, and the m bits below the leading one), the code at its lower end, then the few
// thresholds inside it. Returns the codes plus the channels' threshold offsets, which the caller subtracts.
template <class D, typename T>
HWY_INLINE hn::Vec<D> IndexSearch(D d, hn::Vec<D> x, hn::Vec<D> octave, hn::Vec<D> top_bits, int m, int steps,
                                  const T* base, const T* bucket_offset, const T* thresholds) {
  const auto one = hn::Set(d, T{1});
  const auto bucket = hn::IfThenElse(hn::Lt(x, hn::Set(d, T{1} << m)), x, hn::Add(hn::ShiftLeftSame(octave, m), top_bits));
  auto k = hn::GatherIndex(d, base, hn::Add(bucket, hn::LoadU(d, bucket_offset)));
  for (int i = 0; i < steps; ++i) {
    const auto threshold = hn::GatherIndex(d, thresholds, hn::Add(k, one));
    k = hn::Add(k, hn::IfThenZeroElse(hn::Lt(x, threshold), one));
  }
  return k;
}
#endif

// DriveCodes in 32-bit lanes (DrivePlan::base32 ..): the bucket from a float's exponent and fraction, exact because
// a value of 2^24 or more (below 2^30) is converted shifted right by 6, below 2^24 and so without rounding, which keeps
// its top m + 1 bits (m <= 17), and a smaller value is converted as it is.
#if HWY_TARGET != HWY_SCALAR
// A table laid out by a value's float with m fraction bits (float_bucket; DrivePlan::packed32, LcdPlan::composed), in
// 32-bit lanes: a value's bucket (its float's bits shifted right by 23 - m, less 126 << m; 0 for 0) and the value less
// the bucket's lower end (that float with its fraction bits below the top m cleared, converted back), for a value whose
// float is exact; and the code from the bucket's word, the code at the lower end shifted left by offset_bits above
// the offset of the next threshold, which the value reaches or not.
template <class D>
struct FloatBuckets {
  FloatBuckets(D d, int m, int offset_bits)
      : fraction_shift(23 - m),
        offset_bits(offset_bits),
        first_bucket(hn::Set(d, std::int32_t{126} << m)),
        below_fraction(hn::Set(hn::RebindToUnsigned<D>(), (std::uint32_t{1} << (23 - m)) - 1)),
        offset_mask(hn::Set(hn::RebindToUnsigned<D>(), (std::uint32_t{1} << offset_bits) - 1)) {}
  void place(D d, hn::Vec<D> x, hn::Vec<D>& bucket, hn::Vec<hn::RebindToUnsigned<D>>& above_lo) const {
    const hn::RebindToUnsigned<D> du;
    const hn::Rebind<float, D> df;
    const auto bits = hn::BitCast(du, hn::ConvertTo(df, x));
    bucket = hn::Max(hn::Sub(hn::BitCast(d, hn::ShiftRightSame(bits, fraction_shift)), first_bucket), hn::Zero(d));
    above_lo = hn::BitCast(du, hn::Sub(x, hn::ConvertTo(d, hn::BitCast(df, hn::AndNot(below_fraction, bits)))));
  }
  hn::Vec<hn::RebindToUnsigned<D>> code(hn::Vec<hn::RebindToUnsigned<D>> word,
                                        hn::Vec<hn::RebindToUnsigned<D>> above_lo) const {
    const hn::RebindToUnsigned<D> du;
    return hn::Add(hn::ShiftRightSame(word, offset_bits),
                   hn::IfThenZeroElse(hn::Lt(above_lo, hn::And(word, offset_mask)), hn::Set(du, 1u)));
  }
  int fraction_shift;
  int offset_bits;
  hn::Vec<D> first_bucket;
  hn::Vec<hn::RebindToUnsigned<D>> below_fraction;
  hn::Vec<hn::RebindToUnsigned<D>> offset_mask;
};
#endif

template <typename Linear>
std::size_t DriveCodesNarrow([[maybe_unused]] const Linear* linear, [[maybe_unused]] std::size_t n,
                             [[maybe_unused]] const DrivePlan& p, [[maybe_unused]] std::uint16_t* out) {
  std::size_t s = 0;
#if HWY_TARGET != HWY_SCALAR
  const hn::ScalableTag<std::int32_t> d;
  const hn::RebindToUnsigned<decltype(d)> du;
  const hn::Rebind<float, decltype(d)> df;
  const hn::Half<decltype(du)> duh;
  const hn::Repartition<std::int64_t, decltype(d)> d64;
  const hn::RebindToUnsigned<decltype(d64)> du64;
  const hn::Rebind<std::uint16_t, decltype(d)> d16;
  const std::size_t lanes = hn::Lanes(d);
  const std::size_t half = lanes / 2;
  const int m = p.mantissa_bits;
  const auto zero64 = hn::Zero(d64);
  const auto limit64 = hn::Set(d64, p.value_limit);
  const auto exact_float = hn::Set(d, std::int32_t{1} << 24);
  const auto mantissa_mask = hn::Set(du, (std::uint32_t{1} << m) - 1);
  const auto exponent_bias = hn::Set(d, std::int32_t{127} + m - 1);
  const auto six = hn::Set(d, std::int32_t{6});
  const bool packed = !p.packed32.empty();
  const auto* packed_words = reinterpret_cast<const std::int32_t*>(p.packed32.data());
  const std::size_t phase_step = lanes % 3;
  std::size_t phase = 0;
  // x in 32-bit lanes, its octave and its top bits; false where a lane is outside the index (the generic search).
  struct Place {
    hn::Vec<decltype(d)> x, octave, top_bits;
  };
  const auto limit32 = hn::Set(d, static_cast<std::int32_t>(std::min<std::int64_t>(p.value_limit, INT32_MAX)));
  const auto load_x = [&](std::size_t at, hn::Vec<decltype(d)>& x) {
    if constexpr (sizeof(Linear) == 4) {  // value_limit <= 2^30 (base32)
      x = hn::LoadU(d, linear + at);
      return hn::AllFalse(d, hn::Or(hn::Lt(x, hn::Zero(d)), hn::Not(hn::Lt(x, limit32))));
    } else {
      const auto low = hn::LoadU(d64, linear + at);
      const auto high = hn::LoadU(d64, linear + at + half);
      const auto outside = [&](const auto v) { return hn::Or(hn::Lt(v, zero64), hn::Not(hn::Lt(v, limit64))); };
      if (!hn::AllFalse(d64, hn::Or(outside(low), outside(high)))) return false;
      x = hn::BitCast(d, hn::Combine(du, hn::TruncateTo(duh, hn::BitCast(du64, high)),
                                     hn::TruncateTo(duh, hn::BitCast(du64, low))));
      return true;
    }
  };
  const auto place_of = [&](std::size_t at, Place& place) {
    hn::Vec<decltype(d)> x;
    if (!load_x(at, x)) return false;
    const auto large = hn::Not(hn::Lt(x, exact_float));
    const auto bits = hn::BitCast(du, hn::ConvertTo(df, hn::IfThenElse(large, hn::ShiftRight<6>(x), x)));
    const auto exponent = hn::Add(hn::BitCast(d, hn::ShiftRight<23>(bits)), hn::IfThenElseZero(large, six));
    place = Place{x, hn::Sub(exponent, exponent_bias), hn::BitCast(d, hn::And(hn::ShiftRightSame(bits, 23 - m), mantissa_mask))};
    return true;
  };
  const auto generic = [&](std::size_t at) {
    for (std::size_t i = 0; i < lanes; ++i) out[at + i] = drive_scalar(linear[at + i], at + i, p);
  };
  if (packed) {
    // One lookup per sample (DrivePlan::packed32): the bucket from x's float, x's bits below the bucket's lower end
    // against the next threshold's offset. In passes (kPassChunk): the words' places and those bits, the words, the
    // codes.
    HWY_ALIGN std::uint32_t words[kPassChunk];
    HWY_ALIGN std::uint32_t below[kPassChunk];
    std::array<bool, kPassChunk> by_generic_search{};
    const std::int32_t* packed_offset = p.packed_offset32.data();  // locals: a vector store may alias the plan
    const FloatBuckets<decltype(d)> buckets(d, m, p.offset_bits);
    const auto keep_all = hn::Set(d, std::int32_t{-1});
    const auto keep_top = hn::Set(d, ~std::int32_t{63});  // from 2^24 (below 2^30): the float's 24 bits
    while (s + lanes <= n) {
      const std::size_t count = pass_chunk(n - s, lanes);
      for (std::size_t i = 0; i < count; i += lanes, phase = next_phase(phase, phase_step)) {
        hn::Vec<decltype(d)> x;
        by_generic_search[i] = !load_x(s + i, x);
        if (by_generic_search[i]) {
          generic(s + i);
          hn::Store(hn::Zero(du), du, words + i);
          continue;
        }
        // x from 2^24 on with its low six bits cleared, so that its float is exact and the bucket unchanged; the bits
        // above the bucket's lower end are x's own.
        const auto exact = hn::And(x, hn::IfThenElse(hn::Lt(x, exact_float), keep_all, keep_top));
        hn::Vec<decltype(d)> bucket;
        hn::Vec<decltype(du)> above_lo;
        buckets.place(d, exact, bucket, above_lo);
        hn::Store(hn::BitCast(du, hn::Add(bucket, hn::LoadU(d, packed_offset + phase))), du, words + i);
        hn::Store(hn::Add(above_lo, hn::BitCast(du, hn::Sub(x, exact))), du, below + i);
      }
      look_up(reinterpret_cast<const std::uint32_t*>(packed_words), words, count);
      for (std::size_t i = 0; i < count; i += lanes) {
        if (by_generic_search[i]) continue;
        const auto code = buckets.code(hn::Load(du, words + i), hn::Load(du, below + i));
        hn::StoreU(hn::DemoteTo(d16, hn::BitCast(d, code)), d16, out + s + i);
      }
      s += count;
    }
    return s;
  }
  for (; s + lanes <= n; s += lanes, phase = next_phase(phase, phase_step)) {
    Place place;
    if (!place_of(s, place)) {
      generic(s);
      continue;
    }
    const auto k = IndexSearch(d, place.x, place.octave, place.top_bits, m, p.steps, p.base32.data(),
                               p.bucket_offset32.data() + phase, p.thresholds32.data());
    const auto code = hn::Sub(k, hn::LoadU(d, p.threshold_offset32.data() + phase));
    hn::StoreU(hn::DemoteTo(d16, code), d16, out + s);
  }
#endif
  return s;
}

// On a 32-bit line the vector search needs the 32-bit tables (DrivePlan::base32); without them, the generic one.
void DriveCodes32(const std::int32_t* linear, std::size_t n, const DrivePlan& p, std::uint16_t* out) {
  std::size_t s = p.base32.empty() ? 0 : DriveCodesNarrow(linear, n, p, out);
  for (; s < n; ++s) out[s] = drive_scalar(linear[s], s, p);
}

void DriveCodes(const std::int64_t* linear, std::size_t n, const DrivePlan& p, std::uint16_t* out) {
  std::size_t s = 0;
  if (!p.base32.empty()) {
    s = DriveCodesNarrow(linear, n, p, out);
    for (; s < n; ++s) out[s] = drive_scalar(linear[s], s, p);
    return;
  }
#if HWY_TARGET != HWY_SCALAR
  const hn::ScalableTag<std::int64_t> d;
  const hn::RebindToUnsigned<decltype(d)> du;
  const hn::Rebind<double, decltype(d)> df;
  const std::size_t lanes = hn::Lanes(d);
  const int m = p.mantissa_bits;
  const auto limit = hn::Set(d, p.value_limit);
  const auto zero = hn::Zero(d);
  const auto mantissa_mask = hn::Set(du, (std::uint64_t{1} << m) - 1);
  // A double holds x < 2^53 exactly: its exponent is x's leading-one position and the top m bits of its fraction are
  // the m bits below it, which is the bucket the scalar index computes with a leading-zero count.
  const auto exponent_bias = hn::Set(d, std::int64_t{1023} + m - 1);
  const std::size_t phase_step = lanes % 3;
  std::size_t phase = 0;
  for (; s + lanes <= n; s += lanes, phase = next_phase(phase, phase_step)) {
    const auto x = hn::LoadU(d, linear + s);
    if (!hn::AllFalse(d, hn::Or(hn::Lt(x, zero), hn::Not(hn::Lt(x, limit))))) {  // outside the index: generic search
      for (std::size_t i = 0; i < lanes; ++i) out[s + i] = drive_scalar(linear[s + i], s + i, p);
      continue;
    }
    const auto bits = hn::BitCast(du, hn::ConvertTo(df, x));
    const auto exponent = hn::BitCast(d, hn::ShiftRight<52>(bits));
    const auto top_bits = hn::BitCast(d, hn::And(hn::ShiftRightSame(bits, 52 - m), mantissa_mask));
    const auto k = IndexSearch(d, x, hn::Sub(exponent, exponent_bias), top_bits, m, p.steps, p.base.data(),
                               p.bucket_offset.data() + phase, p.thresholds.data());
    const auto code = hn::Sub(k, hn::LoadU(d, p.threshold_offset.data() + phase));
    HWY_ALIGN std::int64_t wide[DrivePlan::kMaxLanes];
    hn::Store(code, d, wide);
    for (std::size_t i = 0; i < lanes; ++i) out[s + i] = static_cast<std::uint16_t>(wide[i]);
  }
#endif
  for (; s < n; ++s) out[s] = drive_scalar(linear[s], s, p);
}

// The OLED's report drive values (FixedKernels::drive_value) on a line of either width: each sample's code x >> shift
// through its channel's octave ROM as InterpolatedLut::evaluate_raw takes it (the region by the code's leading one,
// the node and the weight, the word interpolated: LcdDrive's target does the same), 1 exactly from x = one on. Lanes
// outside [0, one] take the stage function.
template <typename Linear>
void DriveValuesOf(const Linear* linear, std::size_t n, const DriveValuePlan& p, const FixedKernels& kernels,
                   std::int64_t* out) {
  std::size_t s = 0;
#if HWY_TARGET == HWY_SCALAR
  (void)p;
#else
  const hn::ScalableTag<std::int64_t> d;
  const hn::Rebind<std::int32_t, decltype(d)> d32;
  const std::size_t lanes = hn::Lanes(d);
  const auto zero = hn::Zero(d);
  const auto one = hn::Set(d, p.one);
  const auto full_drive = hn::Set(d, p.full_drive);
  const auto top_code = hn::Set(d, p.top_code);
  const auto bottom_bits = hn::Set(d, std::int64_t{p.bottom_region_bits});
  // The plan's fields in locals: the compiler reloads whatever a vector store could alias.
  const int input_shift = p.input_shift;
  const int segments_log2 = p.segments_per_octave_log2;
  const std::int64_t* packed = p.packed.data();
  const std::int64_t* rom_offset = p.rom_offset.data();
  const std::size_t phase_step = lanes % 3;
  std::size_t phase = 0;
  for (; s + lanes <= n; s += lanes, phase = next_phase(phase, phase_step)) {
    hn::Vec<decltype(d)> x;
    if constexpr (sizeof(Linear) == 8) {
      x = hn::LoadU(d, linear + s);
    } else {
      x = hn::PromoteTo(d, hn::LoadU(d32, linear + s));
    }
    if (!hn::AllFalse(d, hn::Or(hn::Lt(x, zero), hn::Gt(x, one)))) {
      for (std::size_t i = 0; i < lanes; ++i) out[s + i] = kernels.drive_value(linear[s + i], static_cast<int>((s + i) % 3));
      continue;
    }
    const auto code = hn::Min(hn::ShiftRightSame(x, input_shift), top_code);
    const auto place = OctaveRomPlace(d, code, bottom_bits, segments_log2);
    const auto word = LookupWords(d, packed, hn::Add(place.node, hn::LoadU(d, rom_offset + phase)));
    const auto value = InterpolateWord(d, word, place.weight, place.scale_bits);
    hn::StoreU(hn::IfThenElse(hn::Lt(x, one), value, full_drive), d, out + s);
  }
#endif
  for (; s < n; ++s) out[s] = kernels.drive_value(linear[s], static_cast<int>(s % 3));
}

void DriveValues(const std::int64_t* linear, std::size_t n, const DriveValuePlan& p, const FixedKernels& kernels,
                 std::int64_t* out) {
  DriveValuesOf(linear, n, p, kernels, out);
}
void DriveValues32(const std::int32_t* linear, std::size_t n, const DriveValuePlan& p, const FixedKernels& kernels,
                   std::int64_t* out) {
  DriveValuesOf(linear, n, p, kernels, out);
}

// Eq. 2 and the split on lines of either width: the 32-bit lines (beta in [-2^F, 2^(F+1)], F <= 28) take twice the
// lanes and the clamp by the 32-bit minimum and maximum AVX2 has, where the 64-bit ones are emulated.
template <typename Linear>
std::uint64_t CompensateOf(const std::uint16_t* codes, const Linear* low, std::size_t n, const FixedLinePlans& plans,
                           Linear* shown, Linear* rho) {
  const Linear* code_rom = nullptr;
  if constexpr (sizeof(Linear) == 4) {
    code_rom = plans.code_rom32.data();
  } else {
    code_rom = plans.code_rom.data();
  }
  const auto one_value = static_cast<Linear>(plans.one);
  std::uint64_t clipped = 0;
  std::size_t s = 0;
#if HWY_TARGET != HWY_SCALAR
  const hn::ScalableTag<Linear> d;
  const std::size_t lanes = hn::Lanes(d);
  const auto zero = hn::Zero(d);
  const auto one = hn::Set(d, one_value);
  auto clipped_lanes = zero;
  // In passes (kPassChunk): lin(E) by scalar loads from the codes themselves, then the split.
  HWY_ALIGN Linear full[kPassChunk];
  while (s + lanes <= n) {
    const std::size_t count = pass_chunk(n - s, lanes);
    look_up_into(code_rom, codes + s, count, full);
    for (std::size_t i = 0; i < count; i += lanes) {
      const auto f = hn::Load(d, full + i);
      const auto beta = hn::Sub(hn::Add(f, f), hn::LoadU(d, low + s + i));
      const auto clamped = hn::Min(hn::Max(beta, zero), one);
      clipped_lanes = CountInto(d, clipped_lanes, hn::Not(hn::Eq(clamped, beta)));
      hn::StoreU(clamped, d, shown + s + i);
      hn::StoreU(hn::Sub(beta, clamped), d, rho + s + i);
    }
    s += count;
  }
  clipped += Total(d, clipped_lanes);
#endif
  for (; s < n; ++s) {
    const Linear beta = static_cast<Linear>(2 * code_rom[codes[s]] - low[s]);
    shown[s] = std::clamp(beta, Linear{0}, one_value);
    rho[s] = beta - shown[s];
    clipped += shown[s] != beta ? 1 : 0;
  }
  return clipped;
}

std::uint64_t Compensate(const std::uint16_t* codes, const std::int64_t* low, std::size_t n, const FixedLinePlans& plans,
                         std::int64_t* shown, std::int64_t* rho) {
  return CompensateOf(codes, low, n, plans, shown, rho);
}
std::uint64_t Compensate32(const std::uint16_t* codes, const std::int32_t* low, std::size_t n,
                           const FixedLinePlans& plans, std::int32_t* shown, std::int32_t* rho) {
  return CompensateOf(codes, low, n, plans, shown, rho);
}

// Into 64-bit or 32-bit line words (the sums are below 2^32 either way: GaussianPlan).
template <typename Line>
void GaussianColumnsOf(const std::uint16_t* row, [[maybe_unused]] std::size_t row_samples,
                       const GaussianColumnsPlan& plan, int shift, Line* out) {
  const std::size_t n = plan.samples;
  const auto scalar = [&](std::size_t s) {
    std::uint32_t acc = 0;
    for (std::size_t t = 0; t < plan.taps; ++t) {
      acc += plan.weight[t * n + s] * row[static_cast<std::size_t>(plan.index[t * n + s])];
    }
    const std::uint32_t kept = acc >> shift;
    const std::uint32_t first = (acc >> (shift - 1)) & 1u;
    const std::uint32_t rest = acc & ((std::uint32_t{1} << (shift - 1)) - 1u);
    return static_cast<Line>(kept + (first & ((rest != 0 ? 1u : 0u) | (kept & 1u))));
  };
  std::size_t s = 0;
#if HWY_TARGET != HWY_SCALAR
  const hn::ScalableTag<std::uint32_t> du;
  const hn::RebindToSigned<decltype(du)> di;
  const hn::Rebind<std::uint16_t, decltype(du)> d16;
  const hn::Half<decltype(du)> dh;
  const hn::Repartition<std::int64_t, decltype(du)> d64;
  const hn::RebindToUnsigned<decltype(d64)> du64;
  const std::size_t lanes = hn::Lanes(du);
  const auto one = hn::Set(du, 1u);
  const auto rest_mask = hn::Set(du, (std::uint32_t{1} << (shift - 1)) - 1u);
  const auto zero = hn::Zero(du);
  // Half to even: up where the first dropped bit is set and the rest or the kept LSB is.
  const auto rounded = [&](const auto acc) {
    const auto kept = hn::ShiftRightSame(acc, shift);
    const auto first = hn::And(hn::ShiftRightSame(acc, shift - 1), one);
    const auto rest = hn::IfThenElseZero(hn::Ne(hn::And(acc, rest_mask), zero), one);
    return hn::Add(kept, hn::And(first, hn::Or(rest, hn::And(kept, one))));
  };
  const auto widened_low = [&](const auto v) { return hn::BitCast(d64, hn::PromoteTo(du64, hn::LowerHalf(dh, v))); };
  const auto widened_high = [&](const auto v) { return hn::BitCast(d64, hn::PromoteTo(du64, hn::UpperHalf(dh, v))); };
  if (plan.decimation != 0) {
    const std::size_t f = plan.decimation;
    const std::size_t columns = plan.columns;
    const std::size_t length = plan.plane_length;
    thread_local std::vector<std::uint32_t> planes;
    const std::size_t plane_samples = 3 * f * length;
    planes.resize(plane_samples + lanes);
    // The planes from the row's channels over the columns c + j, j < f M (clamped at the row's ends): the row
    // deinterleaved into channels where the columns lie inside it, then each channel split into its f phases (at
    // f = 2 by even and odd lanes).
    const std::size_t span = f * length;
    thread_local std::vector<std::uint32_t> channel_rows;
    channel_rows.resize(3 * span + lanes);
    std::uint32_t* channel[3] = {channel_rows.data(), channel_rows.data() + span, channel_rows.data() + 2 * span};
    const auto width = static_cast<std::int64_t>(plan.full_width);
    const std::int64_t c0 = plan.first_column;
    const auto inside_begin = static_cast<std::size_t>(std::clamp<std::int64_t>(-c0, 0, static_cast<std::int64_t>(span)));
    const auto inside_end = static_cast<std::size_t>(
        std::clamp<std::int64_t>(width - c0, static_cast<std::int64_t>(inside_begin), static_cast<std::int64_t>(span)));
    const auto clamped_column = [&](std::size_t j) {
      return static_cast<std::size_t>(std::clamp<std::int64_t>(c0 + static_cast<std::int64_t>(j), 0, width - 1));
    };
    std::size_t j = 0;
    for (; j < inside_begin; ++j) {
      for (std::size_t ch = 0; ch < 3; ++ch) channel[ch][j] = row[3 * clamped_column(j) + ch];
    }
    for (; j + lanes <= inside_end; j += lanes) {
      hn::Vec<decltype(d16)> r, g, b;
      hn::LoadInterleaved3(d16, row + 3 * static_cast<std::size_t>(c0 + static_cast<std::int64_t>(j)), r, g, b);
      hn::StoreU(hn::PromoteTo(du, r), du, channel[0] + j);
      hn::StoreU(hn::PromoteTo(du, g), du, channel[1] + j);
      hn::StoreU(hn::PromoteTo(du, b), du, channel[2] + j);
    }
    for (; j < span; ++j) {
      for (std::size_t ch = 0; ch < 3; ++ch) channel[ch][j] = row[3 * clamped_column(j) + ch];
    }
    for (std::size_t ch = 0; ch < 3; ++ch) {
      std::uint32_t* even = planes.data() + ch * f * length;
      std::size_t m = 0;
      if (f == 2) {
        std::uint32_t* odd = even + length;
        for (; m + lanes <= length; m += lanes) {
          const auto low = hn::LoadU(du, channel[ch] + 2 * m);
          const auto high = hn::LoadU(du, channel[ch] + 2 * m + lanes);
          hn::StoreU(hn::ConcatEven(du, high, low), du, even + m);
          hn::StoreU(hn::ConcatOdd(du, high, low), du, odd + m);
        }
      }
      for (; m < length; ++m) {
        for (std::size_t p = 0; p < f; ++p) even[p * length + m] = channel[ch][f * m + p];
      }
    }
    const std::uint32_t* red = planes.data();
    const std::uint32_t* green = red + f * length;
    const std::uint32_t* blue = green + f * length;
    const std::size_t half = lanes / 2;
    std::size_t k = 0;
    for (; k + lanes <= columns; k += lanes) {
      auto acc0 = zero;
      auto acc1 = zero;
      auto acc2 = zero;
      // Symmetric taps (GaussianColumnsPlan::symmetric): w_t (x_t + x_{n-1-t}), the same exact sum with half the
      // products; the middle tap of an odd count alone.
      const std::size_t folded = plan.symmetric ? plan.taps / 2 : 0;
      for (std::size_t t = 0; t < folded; ++t) {
        const std::size_t mirror = plan.taps - 1 - t;
        const auto w = hn::LoadU(du, plan.planar_weight.data() + t * columns + k);
        const std::size_t at = plan.tap_offset[t] + k;
        const std::size_t at_mirror = plan.tap_offset[mirror] + k;
        acc0 = hn::Add(acc0, hn::Mul(w, hn::Add(hn::LoadU(du, red + at), hn::LoadU(du, red + at_mirror))));
        acc1 = hn::Add(acc1, hn::Mul(w, hn::Add(hn::LoadU(du, green + at), hn::LoadU(du, green + at_mirror))));
        acc2 = hn::Add(acc2, hn::Mul(w, hn::Add(hn::LoadU(du, blue + at), hn::LoadU(du, blue + at_mirror))));
      }
      for (std::size_t t = folded; t < plan.taps - folded; ++t) {
        const auto w = hn::LoadU(du, plan.planar_weight.data() + t * columns + k);
        const std::size_t at = plan.tap_offset[t] + k;
        acc0 = hn::Add(acc0, hn::Mul(w, hn::LoadU(du, red + at)));
        acc1 = hn::Add(acc1, hn::Mul(w, hn::LoadU(du, green + at)));
        acc2 = hn::Add(acc2, hn::Mul(w, hn::LoadU(du, blue + at)));
      }
      const auto r0 = rounded(acc0);
      const auto r1 = rounded(acc1);
      const auto r2 = rounded(acc2);
      if constexpr (sizeof(Line) == 4) {
        hn::StoreInterleaved3(r0, r1, r2, du, reinterpret_cast<std::uint32_t*>(out) + 3 * k);
      } else {
        hn::StoreInterleaved3(widened_low(r0), widened_low(r1), widened_low(r2), d64, out + 3 * k);
        hn::StoreInterleaved3(widened_high(r0), widened_high(r1), widened_high(r2), d64, out + 3 * (k + half));
      }
    }
    s = 3 * k;
  } else {
    // The row's samples widened once, so the taps are 32-bit gathers.
    thread_local std::vector<std::uint32_t> wide;
    wide.resize(row_samples + lanes);
    std::size_t i = 0;
    for (; i + lanes <= row_samples; i += lanes) hn::StoreU(hn::PromoteTo(du, hn::LoadU(d16, row + i)), du, wide.data() + i);
    for (; i < row_samples; ++i) wide[i] = row[i];
    for (; s + lanes <= n; s += lanes) {
      auto acc = zero;
      for (std::size_t t = 0; t < plan.taps; ++t) {
        const auto code = hn::GatherIndex(du, wide.data(), hn::LoadU(di, plan.index.data() + t * n + s));
        acc = hn::Add(acc, hn::Mul(hn::LoadU(du, plan.weight.data() + t * n + s), code));
      }
      const auto r = rounded(acc);
      if constexpr (sizeof(Line) == 4) {
        hn::StoreU(r, du, reinterpret_cast<std::uint32_t*>(out) + s);
      } else {
        hn::StoreU(widened_low(r), d64, out + s);
        hn::StoreU(widened_high(r), d64, out + s + lanes / 2);
      }
    }
  }
#endif
  for (; s < n; ++s) out[s] = scalar(s);
}

// From 64-bit or 32-bit line words. On 32-bit words a vector holds twice the samples: the products of its even and
// odd lanes are summed apart in 64-bit lanes and the two results' 16 bits put back in order.
template <typename Line>
void GaussianRowsOf(const Line* const* rows, const std::uint32_t* weight, std::size_t count, std::size_t n,
                    int shift, [[maybe_unused]] bool fold, std::uint16_t* out) {
  std::size_t i = 0;
#if HWY_TARGET != HWY_SCALAR
  const hn::ScalableTag<std::int64_t> d;
  const hn::RebindToUnsigned<decltype(d)> du;
  const hn::Repartition<std::uint32_t, decltype(du)> du32;
  const hn::Rebind<std::uint16_t, decltype(du)> d16;
  const std::size_t lanes = hn::Lanes(d);
  const auto half = hn::Set(du, std::uint64_t{1} << (shift - 1));
  // Symmetric weights: w_j (r_j + r_{n-1-j}), the same exact sum with half the products (the pair's sum within the
  // 32-bit operand: GaussianPlan::fold_rows).
  bool symmetric = fold;
  for (std::size_t j = 0; j < count / 2 && symmetric; ++j) symmetric = weight[j] == weight[count - 1 - j];
  const std::size_t folded = symmetric ? count / 2 : 0;
  if constexpr (sizeof(Line) == 4) {
    const std::size_t wide = hn::Lanes(du32);
    const auto* rows32 = reinterpret_cast<const std::uint32_t* const*>(rows);
    for (; i + wide <= n; i += wide) {
      auto even = hn::Zero(du);
      auto odd = hn::Zero(du);
      const auto add_products = [&](const auto w, const auto samples) {
        even = hn::Add(even, hn::MulEven(w, samples));
        odd = hn::Add(odd, hn::MulEven(w, hn::BitCast(du32, hn::ShiftRight<32>(hn::BitCast(du, samples)))));
      };
      for (std::size_t j = 0; j < folded; ++j) {
        add_products(hn::Set(du32, weight[j]),
                     hn::Add(hn::LoadU(du32, rows32[j] + i), hn::LoadU(du32, rows32[count - 1 - j] + i)));
      }
      for (std::size_t j = folded; j < count - folded; ++j) {
        add_products(hn::Set(du32, weight[j]), hn::LoadU(du32, rows32[j] + i));
      }
      // The even sample's 16 bits in a 64-bit lane's low half-word, the odd one's above it (each result truncated to
      // 16 bits, as the 64-bit lines' stores truncate it).
      const auto low = hn::And(hn::ShiftRightSame(hn::Add(even, half), shift), hn::Set(du, std::uint64_t{0xffff}));
      const auto high = hn::ShiftRightSame(hn::Add(odd, half), shift);
      const hn::Rebind<std::uint32_t, decltype(du)> du32_half;
      const hn::Repartition<std::uint16_t, decltype(du32_half)> d16_pairs;
      const auto pairs = hn::TruncateTo(du32_half, hn::Or(low, hn::ShiftLeft<16>(high)));
      hn::StoreU(hn::BitCast(d16_pairs, pairs), d16_pairs, out + i);
    }
  }
  if constexpr (sizeof(Line) == 8) {
    for (; i + lanes <= n; i += lanes) {
      auto acc = hn::Zero(du);
      for (std::size_t j = 0; j < folded; ++j) {
        const auto w = hn::BitCast(du32, hn::Set(du, std::uint64_t{weight[j]}));
        const auto pair = hn::Add(hn::LoadU(d, rows[j] + i), hn::LoadU(d, rows[count - 1 - j] + i));
        acc = hn::Add(acc, hn::MulEven(w, hn::BitCast(du32, pair)));
      }
      for (std::size_t j = folded; j < count - folded; ++j) {
        const auto w = hn::BitCast(du32, hn::Set(du, std::uint64_t{weight[j]}));
        acc = hn::Add(acc, hn::MulEven(w, hn::BitCast(du32, hn::LoadU(d, rows[j] + i))));
      }
      hn::StoreU(hn::TruncateTo(d16, hn::ShiftRightSame(hn::Add(acc, half), shift)), d16, out + i);
    }
  }
#endif
  for (; i < n; ++i) {
    std::uint64_t acc = 0;
    for (std::size_t j = 0; j < count; ++j) acc += std::uint64_t{weight[j]} * static_cast<std::uint64_t>(rows[j][i]);
    out[i] = static_cast<std::uint16_t>((acc + (std::uint64_t{1} << (shift - 1))) >> shift);
  }
}

void GaussianColumns(const std::uint16_t* row, std::size_t row_samples, const GaussianColumnsPlan& plan, int shift,
                     std::int64_t* out) {
  GaussianColumnsOf(row, row_samples, plan, shift, out);
}
void GaussianColumns32(const std::uint16_t* row, std::size_t row_samples, const GaussianColumnsPlan& plan, int shift,
                       std::uint32_t* out) {
  GaussianColumnsOf(row, row_samples, plan, shift, out);
}
void GaussianRows(const std::int64_t* const* rows, const std::uint32_t* weight, std::size_t count, std::size_t n,
                  int shift, bool fold, std::uint16_t* out) {
  GaussianRowsOf(rows, weight, count, n, shift, fold, out);
}
void GaussianRows32(const std::uint32_t* const* rows, const std::uint32_t* weight, std::size_t count, std::size_t n,
                    int shift, bool fold, std::uint16_t* out) {
  GaussianRowsOf(rows, weight, count, n, shift, fold, out);
}

#if HWY_TARGET != HWY_SCALAR
// The largest k with M(T_k, v_{t-1}) <= m, branch-free over the merge table's row at `row_offset` (its first word):
// target_scaled = m scale, compared with the row's integers.
template <class D>
HWY_INLINE hn::Vec<D> LcdBinarySearch(D d, const LcdPlan& p, hn::Vec<D> target_scaled, hn::Vec<D> row_offset) {
  const auto unit = hn::Set(d, std::int64_t{1});
  auto lo = hn::Zero(d);
  auto hi = hn::Set(d, std::int64_t{p.top});
  for (int i = 0; i < p.steps; ++i) {
    const auto active = hn::Lt(lo, hi);
    const auto mid = hn::ShiftRight<1>(hn::Add(hn::Add(lo, hi), unit));
    const auto merge = hn::GatherIndex(d, p.merge.data(), hn::Add(row_offset, hn::IfThenElse(active, mid, unit)));
    const auto up = hn::And(active, hn::Not(hn::Lt(target_scaled, merge)));
    const auto down = hn::AndNot(up, active);
    lo = hn::IfThenElse(up, mid, lo);
    hi = hn::IfThenElse(down, hn::Sub(mid, unit), hi);
  }
  return lo;
}

// LcdPlan::index's shape, in locals (the compiler reloads a plan's fields after every vector store).
struct LcdIndexShape {
  explicit LcdIndexShape(const LcdPlan& p)
      : one(p.one), shift(p.index_shift), offset_bits(p.index_offset_bits), buckets(p.index_buckets) {}
  std::int64_t one;
  int shift;
  int offset_bits;
  std::int64_t buckets;
};

// LcdPlan::index's word for target m in the row numbered row (v_{t-1}, or 2^o for the held row): its index.
template <class D>
HWY_INLINE hn::Vec<D> LcdIndexAt(D d, const LcdIndexShape& p, hn::Vec<D> target, hn::Vec<D> row) {
  const hn::RebindToUnsigned<D> du;
  const hn::Repartition<std::uint32_t, decltype(du)> du32;
  const auto q = hn::ShiftRightSame(hn::Min(hn::Max(target, hn::Zero(d)), hn::Set(d, p.one)), p.shift);
  return hn::Add(hn::BitCast(d, hn::MulEven(hn::BitCast(du32, row),
                                            hn::BitCast(du32, hn::Set(du, static_cast<std::uint64_t>(p.buckets))))),
                 q);
}

// The code of target m from its LcdPlan::index word.
template <class D>
HWY_INLINE hn::Vec<D> LcdIndexCode(D d, const LcdIndexShape& p, hn::Vec<D> target, hn::Vec<D> word) {
  const auto t = hn::Min(hn::Max(target, hn::Zero(d)), hn::Set(d, p.one));
  const auto low = hn::And(t, hn::Set(d, (std::int64_t{1} << p.shift) - 1));
  const auto offset = hn::And(word, hn::Set(d, (std::int64_t{1} << p.offset_bits) - 1));
  const auto k = hn::ShiftRightSame(word, p.offset_bits);
  return hn::Add(k, hn::IfThenZeroElse(hn::Lt(low, offset), hn::Set(d, std::int64_t{1})));
}

// The same code through LcdPlan::index (one gather).
template <class D>
HWY_INLINE hn::Vec<D> LcdIndexSearch(D d, const LcdPlan& p, hn::Vec<D> target, hn::Vec<D> row) {
  const hn::Rebind<std::int32_t, D> d32;
  const hn::Rebind<std::uint32_t, D> du32;
  const LcdIndexShape shape(p);
  const auto at = hn::BitCast(d32, hn::TruncateTo(du32, hn::BitCast(hn::RebindToUnsigned<D>(), LcdIndexAt(d, shape, target, row))));
  const auto* words = reinterpret_cast<const std::int32_t*>(p.index.data());
  return LcdIndexCode(d, shape, target, hn::BitCast(d, hn::PromoteTo(hn::RebindToUnsigned<D>(), hn::BitCast(du32, hn::GatherIndex(d32, words, at)))));
}
#endif

void LcdSearch(const std::int64_t* target, const std::int64_t* rows, std::size_t n, const LcdPlan& p,
               std::uint16_t* codes) {
  std::size_t s = 0;
#if HWY_TARGET != HWY_SCALAR
  const hn::ScalableTag<std::int64_t> d;
  const hn::RebindToUnsigned<decltype(d)> du;
  const hn::Repartition<std::uint32_t, decltype(du)> du32;
  const hn::Rebind<std::uint16_t, decltype(du)> d16;
  const auto scale = hn::BitCast(du32, hn::Set(du, std::uint64_t{p.scale}));
  for (; s + hn::Lanes(d) <= n; s += hn::Lanes(d)) {
    const auto t = hn::LoadU(d, target + s);
    const auto row = hn::LoadU(d, rows + s);
    const auto code = p.index.empty()
                          ? LcdBinarySearch(d, p, hn::BitCast(d, hn::MulEven(hn::BitCast(du32, t), scale)),
                                            hn::ShiftLeftSame(row, p.width_log2))
                          : LcdIndexSearch(d, p, t, row);
    hn::StoreU(hn::TruncateTo(d16, hn::BitCast(du, code)), d16, codes + s);
  }
#endif
  for (; s < n; ++s) {  // the search of FixedKernels::lcd_drive (FixedKernels::lcd_search of the merge table's row)
    const std::int64_t* row = p.merge.data() + rows[s] * p.width;
    const int code = FixedKernels::merge_search(p.top, target[s] * static_cast<std::int64_t>(p.scale),
                                                [row](int k) { return row[k]; });
    codes[s] = static_cast<std::uint16_t>(code);
  }
}

#if HWY_TARGET != HWY_SCALAR
// m = ((x_t + x_{t-1}) / 2)^(1/gamma) of sums in 64-bit lanes through the plan's octave ROM (FixedKernels::
// lcd_target): the region by the ROM input's leading one, the node and the weight, then the node's word
// interpolated. (A sum of 2 or more reads 1, not the ROM: its input is clamped as evaluate_raw clamps it.)
template <class D>
struct LcdTargetRom {
  LcdTargetRom(D d, const LcdPlan& p)
      : zero(hn::Zero(d)),
        one(hn::Set(d, p.one)),
        full_sum(hn::Set(d, std::int64_t{1} << (p.linear_frac_bits + 1))),
        bottom_bits(hn::Set(d, std::int64_t{p.bottom_region_bits})),
        top_input(hn::Set(d, (std::int64_t{1} << p.target_input_bits) - 1)),
        shift(p.target_shift),
        segments_log2(p.segments_per_octave_log2),
        packed(p.target_packed.data()) {}
  OctavePlace<D> place(D d, hn::Vec<D> sum) const {
    const auto input = hn::Min(hn::ShiftRightSame(hn::Max(sum, zero), shift), top_input);
    return OctaveRomPlace(d, input, bottom_bits, segments_log2);
  }
  // The target from the place's ROM word.
  hn::Vec<D> from(D d, hn::Vec<D> sum, hn::Vec<D> word, hn::Vec<D> weight, hn::Vec<D> scale_bits) const {
    const auto rom_target = InterpolateWord(d, word, weight, scale_bits);
    return hn::IfThenElse(hn::Lt(sum, full_sum), hn::IfThenElseZero(hn::Gt(sum, zero), rom_target), one);
  }
  hn::Vec<D> operator()(D d, hn::Vec<D> sum) const {
    const OctavePlace<D> at = place(d, sum);
    return from(d, sum, LookupWords(d, packed, at.node), at.weight, at.scale_bits);
  }
  hn::Vec<D> zero, one, full_sum, bottom_bits, top_input;
  int shift;
  int segments_log2;
  const std::int64_t* packed;
};
#endif

void LcdTargets(const std::int64_t* sum, std::size_t n, const LcdPlan& p, const FixedKernels& kernels,
                std::int64_t* target) {
  std::size_t s = 0;
#if HWY_TARGET != HWY_SCALAR
  const hn::ScalableTag<std::int64_t> d;
  const LcdTargetRom<std::remove_const_t<decltype(d)>> rom(d, p);
  for (; s + hn::Lanes(d) <= n; s += hn::Lanes(d)) hn::StoreU(rom(d, hn::LoadU(d, sum + s)), d, target + s);
#else
  (void)p;
#endif
  for (; s < n; ++s) target[s] = kernels.lcd_target(sum[s]);
}

#if HWY_TARGET != HWY_SCALAR
// a b mod 2^64 of 64-bit lanes for 0 <= a < 2^32 (the products a b_low and a b_high by MulEven).
template <class D>
HWY_INLINE hn::Vec<D> MulNarrow(D d, hn::Vec<D> a, hn::Vec<D> b) {
  const hn::RebindToUnsigned<D> du;
  const hn::Repartition<std::uint32_t, decltype(du)> du32;
  const auto a32 = hn::BitCast(du32, a);
  const auto low = hn::MulEven(a32, hn::BitCast(du32, b));
  const auto high = hn::MulEven(a32, hn::BitCast(du32, hn::ShiftRight<32>(hn::BitCast(du, b))));
  return hn::BitCast(d, hn::Add(low, hn::ShiftLeft<32>(high)));
}
#endif

void LcdDriveValues(const std::int64_t* sum, const std::int64_t* target, const std::uint16_t* rows,
                    const std::uint16_t* codes, std::size_t n, const LcdPlan& p, const FixedKernels& kernels,
                    std::int64_t* drive) {
  std::size_t s = 0;
#if HWY_TARGET != HWY_SCALAR
  if (!p.report_merge.empty()) {
    const hn::ScalableTag<std::int64_t> d;
    const hn::RebindToUnsigned<decltype(d)> du;
    const hn::Repartition<std::uint32_t, decltype(du)> du32;
    const hn::Rebind<std::uint32_t, decltype(du)> du32h;
    const hn::Rebind<std::uint16_t, decltype(du)> d16;
    const hn::Rebind<double, decltype(d)> df;
    const std::size_t lanes = hn::Lanes(d);
    const auto zero = hn::Zero(d);
    const auto one = hn::Set(d, std::int64_t{1});
    const auto two_top = hn::Set(d, 2 * std::int64_t{p.top});
    const auto row_words = hn::Set(d, p.report_row_words);
    const auto scale = hn::BitCast(du32, hn::Set(du, std::uint64_t{p.scale}));
    const int shift = p.drive_frac_bits;
    const auto full_drive = hn::Set(d, std::int64_t{1} << shift);
    const auto drive_scale = hn::Set(df, static_cast<double>(std::int64_t{1} << shift));
    const auto half = hn::Set(df, 0.5);
    const std::int64_t* merge = p.report_merge.data();
    const std::int64_t* ends = p.ends.data();
    const auto widen = [&](const std::uint16_t* v) {
      return hn::BitCast(d, hn::PromoteTo(du, hn::PromoteTo(du32h, hn::LoadU(d16, v))));
    };
    for (; s + lanes <= n; s += lanes) {
      const auto x_sum = hn::LoadU(d, sum + s);
      const auto j = widen(rows + s);
      const auto code = widen(codes + s);
      // The unreachable ends (FixedKernels::lcd_clamped_end): below the dark end 0, above the bright end 1.
      hn::Vec<decltype(d)> dark, bright;
      LookupPairs(d, ends, j, dark, bright);
      const auto below = hn::Lt(x_sum, hn::Add(dark, dark));
      const auto above = hn::Gt(x_sum, hn::Add(bright, bright));
      // FixedKernels::lcd_drive_value: the merges at the code's thresholds t_lo = max(2c - 1, 0) and t_hi = min(2c +
      // 1, 2 Mx), side by side in the row of v_{t-1}, and round(2^D (t_lo span + offset dt) / (span 2 Mx)), half up.
      hn::Vec<decltype(d)> m_lo, m_hi;
      LookupAdjacent(d, merge, hn::Add(MulNarrow(d, j, row_words), code), m_lo, m_hi);
      const auto t_lo = hn::Max(hn::Sub(hn::Add(code, code), one), zero);
      const auto t_hi = hn::Min(hn::Add(hn::Add(code, code), one), two_top);
      const auto span = hn::Sub(m_hi, m_lo);
      const auto target_scaled = hn::BitCast(d, hn::MulEven(hn::BitCast(du32, hn::LoadU(d, target + s)), scale));
      const auto offset = hn::Min(hn::Max(hn::Sub(target_scaled, m_lo), zero), span);
      const auto offset_dt = hn::IfThenElse(hn::Eq(hn::Sub(t_hi, t_lo), one), offset, hn::Add(offset, offset));
      // Below 2^63 and 2^62 (LcdPlan::report_merge).
      const auto part = hn::Add(MulNarrow(d, t_lo, span), offset_dt);
      const auto denominator = MulNarrow(d, two_top, span);
      // The quotient within one of the estimate (fx::detail::rounded_quotient), settled by the remainder, which lies
      // in [-denominator, 2 denominator) and so is exact mod 2^64.
      // A flat merge's lanes (span <= 0, the stage function's below) estimate 0 / 1: no lane converts a NaN or a
      // double beyond int64 back (undefined in the scalar emulation of the conversion).
      const auto flat = hn::Not(hn::Gt(span, zero));
      const auto estimate =
          hn::Add(hn::Div(hn::Mul(hn::ConvertTo(df, hn::IfThenZeroElse(flat, part)), drive_scale),
                          hn::ConvertTo(df, hn::IfThenElse(flat, one, denominator))),
                  half);
      auto quotient = hn::ConvertTo(d, estimate);
      const auto rounded = hn::Add(hn::ShiftLeftSame(part, shift), hn::ShiftRight<1>(denominator));
      const auto remainder = hn::Sub(rounded, MulNarrow(d, quotient, denominator));
      quotient = hn::IfThenElse(hn::Lt(remainder, zero), hn::Sub(quotient, one),
                                hn::IfThenElse(hn::Lt(remainder, denominator), quotient, hn::Add(quotient, one)));
      const auto value = hn::IfThenElseZero(hn::Not(below), hn::IfThenElse(above, full_drive, quotient));
      hn::StoreU(value, d, drive + s);
      // A flat merge (quantised coefficients) takes the stage function, as its division by a zero span would.
      if (!hn::AllFalse(d, hn::AndNot(hn::Or(below, above), flat))) {
        for (std::size_t k = s; k < s + lanes; ++k) {
          drive[k] = kernels.lcd_report_drive(sum[k], target[k], rows[k], codes[k]);
        }
      }
    }
  }
#else
  (void)p;
#endif
  for (; s < n; ++s) drive[s] = kernels.lcd_report_drive(sum[s], target[s], rows[s], codes[s]);
}

// One sample of the LCD drive by the stage function, with emit's frame-store update.
inline std::uint16_t lcd_scalar(std::int64_t wanted, const LcdPlan& p, const FixedKernels& kernels,
                                std::uint8_t& previous_code, std::int32_t& previous_linear, bool held,
                                std::int64_t* shortfall, std::uint64_t& unreachable) {
  const LcdSample sample = kernels.lcd_drive(wanted, previous_linear, previous_code, held, false);
  unreachable += sample.unreachable ? 1 : 0;
  if (shortfall != nullptr) *shortfall = sample.shortfall;
  previous_code = static_cast<std::uint8_t>(sample.code);
  previous_linear = static_cast<std::int32_t>(p.contributed ? sample.contributed : wanted);
  return sample.code;
}

#if HWY_TARGET != HWY_SCALAR
// FixedKernels::lcd_drive's unreachable ends, for both lane widths of the kernels: a sum below twice_dark = 2 M(0,
// v_{t-1})^gamma drives code 0, above twice_bright = 2 M(1, v_{t-1})^gamma the top code, and either contributes
// 2 M^gamma - x_{t-1}; a sum between them drives the searched code and contributes x_t.
template <class D>
struct LcdEnds {
  LcdEnds(hn::Vec<D> x, hn::Vec<D> x_previous, hn::Vec<D> sum, hn::Vec<D> code, hn::Vec<D> twice_dark,
          hn::Vec<D> twice_bright, hn::Vec<D> top)
      : above(hn::Gt(sum, twice_bright)),
        clamped(hn::Or(hn::Lt(sum, twice_dark), above)),
        drive(hn::IfThenElse(clamped, hn::IfThenElseZero(above, top), code)),
        contributed(hn::IfThenElse(clamped, hn::Sub(hn::IfThenElse(above, twice_bright, twice_dark), x_previous), x)) {}
  hn::Mask<D> above;
  hn::Mask<D> clamped;
  hn::Vec<D> drive;
  hn::Vec<D> contributed;
};
#endif

#if HWY_TARGET != HWY_SCALAR
// The LCD drive of a 32-bit line through LcdPlan::composed, in 32-bit lanes: per sample the composed word and the
// row's ends (a second word lookup on the eye's first frame, for v_{t-1} from the held row). Vectors with a value
// outside (-2^29, 2^29) take lcd_scalar: within it the sum, 2 M^gamma - x_{t-1} and the shortfall stay within 32 bits
// (ends32 holds 2 M^gamma <= 2^30). Returns the samples done (whole vectors); adds the unreachable ones to
// `unreachable`.
std::size_t LcdDriveComposed(const std::int32_t* wanted, std::size_t n, const LcdPlan& p, const FixedKernels& kernels,
                             std::uint8_t* previous_code, std::int32_t* previous_linear, bool held,
                             std::uint16_t* codes, std::int64_t* shortfall, std::uint64_t& unreachable) {
  const hn::ScalableTag<std::int32_t> d;
  const hn::RebindToUnsigned<decltype(d)> du;
  const hn::Rebind<std::uint16_t, decltype(d)> d16;
  const hn::Rebind<std::uint8_t, decltype(d)> d8;
  const hn::Half<decltype(d)> dh;
  const hn::Repartition<std::int64_t, decltype(d)> d64;
  const std::size_t lanes = hn::Lanes(d);
  // The plan's fields in locals: the compiler reloads whatever a vector store could alias.
  const std::uint32_t* composed = p.composed.data();
  const std::uint64_t* ends = p.ends32.data();
  const FloatBuckets<decltype(d)> float_buckets(d, p.composed_mantissa_bits, p.composed_offset_bits);
  const int target_shift = p.target_shift;
  const std::int32_t buckets = p.composed_buckets;
  const bool contributed_stored = p.contributed;
  const auto zero = hn::Zero(d);
  const auto top_c = hn::Set(d, std::int32_t{1} << p.target_input_bits);
  const auto row_words = hn::Set(d, buckets);
  const auto held_row = hn::Set(d, static_cast<std::int32_t>(p.width * buckets));
  const auto top = hn::Set(d, p.top);
  const auto bound = hn::Set(d, (std::int32_t{1} << 29) - 1);
  auto unreachable_lanes = zero;
  const auto load_previous = [&](std::size_t i, const auto x) {
    return held ? x : hn::LoadU(d, previous_linear + i);
  };
  const auto previous_row = [&](std::size_t i) {
    return hn::BitCast(d, hn::PromoteTo(du, hn::LoadU(d8, previous_code + i)));
  };
  // The code from a composed word and c's bits above its bucket's lower end.
  const auto code_of = [&](const auto word, const auto above) { return hn::BitCast(d, float_buckets.code(word, above)); };
  HWY_ALIGN std::uint32_t words[kPassChunk];
  HWY_ALIGN std::uint32_t above_lo[kPassChunk];
  HWY_ALIGN std::int32_t bucket_of[kPassChunk];
  HWY_ALIGN std::int32_t rows[kPassChunk];
  HWY_ALIGN std::uint64_t row_ends[kPassChunk];
  std::array<bool, kPassChunk> by_scalar{};
  std::size_t s = 0;
  while (s + lanes <= n) {
    const std::size_t count = pass_chunk(n - s, lanes);
    // c's bucket and the bits above its lower end; the word's place in v_{t-1}'s row (the held row first).
    for (std::size_t i = 0; i < count; i += lanes) {
      const auto x = hn::LoadU(d, wanted + s + i);
      const auto x_previous = load_previous(s + i, x);
      const auto outside = [&](const auto v) { return hn::Or(hn::Lt(v, hn::Neg(bound)), hn::Gt(v, bound)); };
      by_scalar[i] = !hn::AllFalse(d, hn::Or(outside(x), outside(x_previous)));
      const auto sum = hn::Add(x, x_previous);
      const auto c = hn::Min(hn::ShiftRightSame(hn::Max(sum, zero), target_shift), top_c);
      hn::Vec<decltype(d)> bucket;
      hn::Vec<decltype(du)> above;
      float_buckets.place(d, c, bucket, above);
      hn::Store(above, du, above_lo + i);
      hn::Store(bucket, d, bucket_of + i);
      const auto row = held ? held_row : hn::Mul(previous_row(s + i), row_words);
      hn::Store(hn::BitCast(du, hn::Add(bucket, row)), du, words + i);
    }
    look_up(composed, words, count);
    if (held) {  // v_{t-1} from the held row, then the word of its row
      for (std::size_t i = 0; i < count; i += lanes) {
        const auto j = code_of(hn::Load(du, words + i), hn::Load(du, above_lo + i));
        hn::Store(j, d, rows + i);
        hn::Store(hn::BitCast(du, hn::Add(hn::Load(d, bucket_of + i), hn::Mul(j, row_words))), du, words + i);
      }
      look_up(composed, words, count);
      look_up_into(ends, rows, count, row_ends);
    } else {
      look_up_into(ends, previous_code + s, count, row_ends);
    }
    for (std::size_t i = 0; i < count; i += lanes) {
      if (by_scalar[i]) {
        for (std::size_t k = s + i; k < s + i + lanes; ++k) {
          codes[k] = lcd_scalar(wanted[k], p, kernels, previous_code[k], previous_linear[k], held,
                                shortfall != nullptr ? shortfall + k : nullptr, unreachable);
        }
        continue;
      }
      const auto x = hn::LoadU(d, wanted + s + i);
      const auto x_previous = load_previous(s + i, x);
      const auto sum = hn::Add(x, x_previous);
      const auto code = code_of(hn::Load(du, words + i), hn::Load(du, above_lo + i));
      hn::Vec<decltype(du)> dark_bits, bright_bits;
      hn::LoadInterleaved2(du, reinterpret_cast<const std::uint32_t*>(row_ends + i), dark_bits, bright_bits);
      const LcdEnds<decltype(d)> ends_rule(x, x_previous, sum, code, hn::BitCast(d, dark_bits),
                                           hn::BitCast(d, bright_bits), top);
      const auto drive = ends_rule.drive;
      const auto contributed = ends_rule.contributed;
      unreachable_lanes = CountInto(d, unreachable_lanes, ends_rule.clamped);
      if (shortfall != nullptr) {
        const auto gap = hn::Sub(x, contributed);
        hn::StoreU(hn::PromoteTo(d64, hn::LowerHalf(dh, gap)), d64, shortfall + s + i);
        hn::StoreU(hn::PromoteTo(d64, hn::UpperHalf(dh, gap)), d64, shortfall + s + i + lanes / 2);
      }
      hn::StoreU(hn::DemoteTo(d16, drive), d16, codes + s + i);
      hn::StoreU(hn::DemoteTo(d8, drive), d8, previous_code + s + i);
      hn::StoreU(contributed_stored ? contributed : x, d, previous_linear + s + i);
    }
    s += count;
  }
  unreachable += Total(d, unreachable_lanes);
  return s;
}
#endif

template <typename Wanted>
std::uint64_t LcdDriveOf(const Wanted* wanted, std::size_t n, const LcdPlan& p, const FixedKernels& kernels,
                         std::uint8_t* previous_code, std::int32_t* previous_linear, bool held, std::uint16_t* codes,
                         std::int64_t* shortfall) {
  std::uint64_t unreachable = 0;
  std::size_t s = 0;
#if HWY_TARGET != HWY_SCALAR
  if constexpr (sizeof(Wanted) == 4) {
    if (!p.composed.empty()) s = LcdDriveComposed(wanted, n, p, kernels, previous_code, previous_linear, held, codes,
                                                  shortfall, unreachable);
  }
  const hn::ScalableTag<std::int64_t> d;
  const hn::RebindToUnsigned<decltype(d)> du;
  const hn::Repartition<std::uint32_t, decltype(du)> du32;
  const hn::Repartition<std::int32_t, decltype(d)> di32;
  const hn::Rebind<std::int32_t, decltype(d)> d32;
  const hn::Rebind<std::uint32_t, decltype(du)> du32h;
  const hn::Rebind<std::uint16_t, decltype(du)> d16;
  const hn::Rebind<std::uint8_t, decltype(du)> d8;
  const std::size_t lanes = hn::Lanes(d);
  const auto zero = hn::Zero(d);
  const auto scale = hn::BitCast(du32, hn::Set(du, std::uint64_t{p.scale}));
  const auto top = hn::Set(d, std::int64_t{p.top});
  auto unreachable_lanes = zero;
  const auto held_row = hn::Set(d, p.width);  // M(v, v)'s row, after the 2^o rows of v_{t-1}
  // The plan's fields in locals: the compiler reloads whatever a vector store could alias.
  const std::int64_t* target_packed = p.target_packed.data();
  const std::int64_t* ends = p.ends.data();
  const bool contributed_stored = p.contributed;
  const LcdIndexShape shape(p);
  // x_t from a line of either width (FixedLinePlans::code_rom32 says why 32 bits hold it).
  const auto load_wanted = [&](std::size_t i) {
    if constexpr (sizeof(Wanted) == 8) {
      return hn::LoadU(d, wanted + i);
    } else {
      return hn::PromoteTo(d, hn::LoadU(d32, wanted + i));
    }
  };
  // The eye's first frame takes the pixel as held at x_t (FixedKernels::lcd_drive): x_{t-1} = x_t, and v_{t-1} is
  // found from the held row.
  const auto previous_of = [&](std::size_t i, const auto x) {
    return held ? x : hn::PromoteTo(d, hn::LoadU(d32, previous_linear + i));
  };
  const auto previous_row = [&](std::size_t i) {
    return hn::BitCast(d, hn::PromoteTo(du, hn::PromoteTo(du32h, hn::LoadU(d8, previous_code + i))));
  };
  const LcdTargetRom<std::remove_const_t<decltype(d)>> target_rom(d, p);
  // Given v_{t-1} = j and lo, the largest k with M(T_k, v_{t-1}) <= m: the unreachable ends, the codes and the
  // frame stores.
  const auto finish = [&](std::size_t i, const auto x, const auto x_previous, const auto sum, const auto j,
                          const auto lo) {
    hn::Vec<decltype(d)> end_dark, end_bright;
    LookupPairs(d, ends, j, end_dark, end_bright);
    const LcdEnds<decltype(d)> ends_rule(x, x_previous, sum, lo, hn::Add(end_dark, end_dark),
                                         hn::Add(end_bright, end_bright), top);
    const auto drive = ends_rule.drive;
    const auto contributed = ends_rule.contributed;
    unreachable_lanes = CountInto(d, unreachable_lanes, ends_rule.clamped);
    if (shortfall != nullptr) hn::StoreU(hn::Sub(x, contributed), d, shortfall + i);
    const auto stored = contributed_stored ? contributed : x;
    hn::StoreU(hn::TruncateTo(d16, hn::BitCast(du, drive)), d16, codes + i);
    hn::StoreU(hn::TruncateTo(d8, hn::BitCast(du, drive)), d8, previous_code + i);
    hn::StoreU(hn::BitCast(d32, hn::TruncateTo(du32h, hn::BitCast(du, stored))), d32, previous_linear + i);
  };
  if (p.index.empty()) {  // the binary search of the merge table's row
    for (; s + lanes <= n; s += lanes) {
      const auto x = load_wanted(s);
      const auto x_previous = previous_of(s, x);
      const auto sum = hn::Add(x, x_previous);
      const auto target_scaled = hn::BitCast(d, hn::MulEven(hn::BitCast(du32, target_rom(d, sum)), scale));
      const auto search = [&](const auto row) {
        return LcdBinarySearch(d, p, target_scaled, hn::ShiftLeftSame(row, p.width_log2));
      };
      const auto j = held ? search(held_row) : previous_row(s);
      finish(s, x, x_previous, sum, j, search(j));
    }
  } else {
    // Through the index, in passes (kPassChunk): m's ROM places, its ROM words, m and the index words' places, those
    // words, then the codes.
    HWY_ALIGN std::int64_t targets[kPassChunk];
    HWY_ALIGN std::int64_t words[kPassChunk];
    HWY_ALIGN std::int64_t held_codes[kPassChunk];
    HWY_ALIGN std::int64_t rom_weights[kPassChunk];
    HWY_ALIGN std::int64_t rom_shifts[kPassChunk];
    const std::uint32_t* index = p.index.data();
    while (s + lanes <= n) {
      const std::size_t m = pass_chunk(n - s, lanes);
      for (std::size_t i = 0; i < m; i += lanes) {  // m's ROM places, then its words
        const auto x = load_wanted(s + i);
        const auto place = target_rom.place(d, hn::Add(x, previous_of(s + i, x)));
        hn::Store(place.node, d, targets + i);
        hn::Store(place.weight, d, rom_weights + i);
        hn::Store(place.scale_bits, d, rom_shifts + i);
      }
      look_up(target_packed, targets, m);
      for (std::size_t i = 0; i < m; i += lanes) {
        const auto x = load_wanted(s + i);
        const auto target = target_rom.from(d, hn::Add(x, previous_of(s + i, x)), hn::Load(d, targets + i),
                                            hn::Load(d, rom_weights + i), hn::Load(d, rom_shifts + i));
        hn::Store(target, d, targets + i);
        hn::Store(LcdIndexAt(d, shape, target, held ? held_row : previous_row(s + i)), d, words + i);
      }
      look_up(index, words, m);
      if (held) {  // v_{t-1} from the held row, then the code from v_{t-1}'s row
        for (std::size_t i = 0; i < m; i += lanes) {
          const auto target = hn::Load(d, targets + i);
          const auto j = LcdIndexCode(d, shape, target, hn::Load(d, words + i));
          hn::Store(j, d, held_codes + i);
          hn::Store(LcdIndexAt(d, shape, target, j), d, words + i);
        }
        look_up(index, words, m);
      }
      for (std::size_t i = 0; i < m; i += lanes) {
        const auto x = load_wanted(s + i);
        const auto x_previous = previous_of(s + i, x);
        const auto j = held ? hn::Load(d, held_codes + i) : previous_row(s + i);
        finish(s + i, x, x_previous, hn::Add(x, x_previous), j,
               LcdIndexCode(d, shape, hn::Load(d, targets + i), hn::Load(d, words + i)));
      }
      s += m;
    }
  }
  unreachable += Total(d, unreachable_lanes);
#endif
  for (; s < n; ++s) {
    codes[s] = lcd_scalar(wanted[s], p, kernels, previous_code[s], previous_linear[s], held,
                          shortfall != nullptr ? shortfall + s : nullptr, unreachable);
  }
  return unreachable;
}

std::uint64_t LcdDrive(const std::int64_t* wanted, std::size_t n, const LcdPlan& p, const FixedKernels& kernels,
                       std::uint8_t* previous_code, std::int32_t* previous_linear, bool held, std::uint16_t* codes,
                       std::int64_t* shortfall) {
  return LcdDriveOf(wanted, n, p, kernels, previous_code, previous_linear, held, codes, shortfall);
}
std::uint64_t LcdDrive32(const std::int32_t* wanted, std::size_t n, const LcdPlan& p, const FixedKernels& kernels,
                         std::uint8_t* previous_code, std::int32_t* previous_linear, bool held, std::uint16_t* codes,
                         std::int64_t* shortfall) {
  return LcdDriveOf(wanted, n, p, kernels, previous_code, previous_linear, held, codes, shortfall);
}

// The motion weight of one pixel and Eq. 4 of one sample by the stage functions (tails and out-of-lane operands).
inline std::int64_t weight_scalar(const std::int64_t* previous, const std::int64_t* alpha, const FixedKernels& kernels,
                                  MotionTally& tally) {
  bool underflow = false;
  const std::int64_t w = kernels.motion_weight(kernels.luma(previous), kernels.luma(alpha), underflow);
  tally.underflow += underflow ? 1 : 0;
  tally.weight_sum += w;
  return w;
}

inline std::int64_t weighted_scalar(std::int64_t alpha, std::int64_t weight, std::int32_t residual,
                                    const FixedKernels& kernels, MotionTally& tally) {
  const WeightedSample s = kernels.add_weighted_residual(alpha, weight, residual);
  tally.clipped += s.clipped ? 1 : 0;
  tally.dropped_sum += s.dropped;
  const std::int64_t magnitude = residual < 0 ? -std::int64_t{residual} : std::int64_t{residual};
  tally.residual_abs_sum += magnitude;
  tally.residual_abs_max = std::max(tally.residual_abs_max, magnitude);
  return s.alpha_prime;
}


void MotionWeights(const std::int64_t* previous, const std::int64_t* alpha, std::size_t pixels, [[maybe_unused]] const MotionPlan& p,
                   const FixedKernels& kernels, std::int64_t* weight, MotionTally& tally) {
  std::size_t x = 0;
#if HWY_TARGET != HWY_SCALAR
  const hn::ScalableTag<std::int64_t> d;
  const hn::RebindToUnsigned<decltype(d)> du;
  const hn::Repartition<std::uint32_t, decltype(du)> du32;
  const hn::Repartition<std::int32_t, decltype(d)> di32;
  const hn::Rebind<double, decltype(d)> df;
  const std::size_t lanes = hn::Lanes(d);
  const auto zero = hn::Zero(d);
  const auto one = hn::Set(d, p.one);
  const auto unit = hn::Set(d, std::int64_t{1});
  const auto fifteen = hn::Set(d, std::int64_t{15});
  const auto luma_weight_r = hn::BitCast(du32, hn::Set(du, std::uint64_t{p.luma_weight[0]}));
  const auto luma_weight_g = hn::BitCast(du32, hn::Set(du, std::uint64_t{p.luma_weight[1]}));
  const auto luma_weight_b = hn::BitCast(du32, hn::Set(du, std::uint64_t{p.luma_weight[2]}));
  const auto luma_half = hn::Set(du, std::uint64_t{1} << (p.luma_shift - 1));
  const auto exponent_bias = hn::Set(d, std::int64_t{1023});
  const auto one_half = hn::Set(du32, static_cast<std::uint32_t>(p.one));
  const auto two_to_52 = hn::Set(df, 4503599627370496.0);
  const auto two_to_52_bits = hn::BitCast(du, two_to_52);
  // c's rounding shift is lead + (reciprocal fraction bits - F); below 1 the stage function takes the pixel.
  const auto contrast_shift_offset = hn::Set(d, std::int64_t{p.reciprocal_frac_bits - p.linear_frac_bits});
  const auto sensitivity = hn::BitCast(du32, hn::Set(du, std::uint64_t{p.sensitivity}));
  const auto exponent_half = hn::Set(du, std::uint64_t{1} << (p.exponent_shift - 1));
  const auto fraction_mask = hn::Set(du, (std::uint64_t{1} << p.exp_input_frac_bits) - 1);
  const auto linear_half = hn::Set(du, std::uint64_t{1} << (p.linear_frac_bits - 1));
  // The plan's fields in locals: the compiler reloads whatever a vector store could alias.
  const int luma_shift = p.luma_shift;
  const int reciprocal_input_bits = p.reciprocal_input_bits;
  const int exponent_shift = p.exponent_shift;
  const int exp_input_frac_bits = p.exp_input_frac_bits;
  const int linear_frac_bits = p.linear_frac_bits;
  struct Rom {
    const std::int64_t* packed;
    int weight_bits;
  };
  const Rom reciprocal{p.reciprocal.packed.data(), p.reciprocal.weight_bits};
  const Rom exp_fraction{p.exp_fraction.packed.data(), p.exp_fraction.weight_bits};
  // A ROM's node of code into words[i], and (after the lookup pass) its interpolation from words[i].
  HWY_ALIGN std::int64_t words[kPassChunk];
  const auto place_in = [&](const Rom& rom, const auto code, std::size_t i) {
    hn::Store(hn::BitCast(d, hn::ShiftRightSame(code, rom.weight_bits)), d, words + i);
  };
  const auto interpolated = [&](const Rom& rom, const auto code, std::size_t i) {
    const int j = rom.weight_bits;
    const auto low = hn::BitCast(d, hn::And(code, hn::Set(du, (std::uint64_t{1} << j) - 1)));
    return InterpolateWord(d, hn::Load(d, words + i), low, j);
  };
  const auto luma = [&](const auto r, const auto g, const auto b) {
    const auto sum = hn::Add(hn::Add(hn::MulEven(luma_weight_r, hn::BitCast(du32, r)),
                                     hn::MulEven(luma_weight_g, hn::BitCast(du32, g))),
                             hn::MulEven(luma_weight_b, hn::BitCast(du32, b)));
    return hn::BitCast(d, hn::ShiftRightSame(hn::Add(sum, luma_half), luma_shift));  // uQ1.F
  };
  auto weight_sum = zero;
  auto underflow_lanes = zero;  // counted here, not through `tally` (a store per vector)
  // In passes (kPassChunk pixels): Eq. 5 up to the reciprocal ROM's places; its words; c and Eq. 6's places (the
  // exp ROM and exp(-i)); their words; w. Vectors with a pixel outside the lanes take the stage functions in the
  // first pass.
  std::array<bool, kPassChunk> by_stage_functions{};
  HWY_ALIGN std::int64_t codes[kPassChunk];  // the reciprocal ROM's input, then x = s c
  HWY_ALIGN std::int64_t differences[kPassChunk];  // |Yp - Ya|, 0 for a still pixel
  HWY_ALIGN std::int64_t shifts[kPassChunk];  // c's rounding shift
  HWY_ALIGN std::int64_t integers[kPassChunk];  // i, then exp(-i)
  const std::int64_t* exp_integer = p.exp_integer.data();
  while (x + lanes <= pixels) {
    const std::size_t count = pass_chunk(pixels - x, lanes);
    for (std::size_t i = 0; i < count; i += lanes) {
      const std::size_t at = x + i;
      hn::Vec<decltype(d)> pr, pg, pb, ar, ag, ab;
      hn::LoadInterleaved3(d, previous + 3 * at, pr, pg, pb);
      hn::LoadInterleaved3(d, alpha + 3 * at, ar, ag, ab);
      // The six in [0, 1]: every 32-bit half at most one (the unsigned 32-bit maximum AVX2 has; a negative value's
      // upper half is all ones) and every upper half zero.
      const auto halves = [&](const auto v) { return hn::BitCast(du32, v); };
      const auto largest_half = hn::Max(hn::Max(hn::Max(halves(pr), halves(pg)), hn::Max(halves(pb), halves(ar))),
                                        hn::Max(halves(ag), halves(ab)));
      const auto upper_halves = hn::ShiftRight<32>(
          hn::BitCast(du, hn::Or(hn::Or(hn::Or(pr, pg), hn::Or(pb, ar)), hn::Or(ag, ab))));
      const bool out_of_lanes = !hn::AllTrue(du32, hn::Eq(hn::Max(largest_half, one_half), one_half)) ||
                                !hn::AllTrue(du, hn::Eq(upper_halves, hn::Zero(du)));
      const auto yp = luma(pr, pg, pb);
      const auto ya = luma(ar, ag, ab);
      const auto sum = hn::Add(yp, ya);                                  // uQ2.F
      const auto difference = hn::Abs(hn::Sub(yp, ya));
      const auto still = hn::Eq(difference, zero);                       // c = 0: w = 1
      // The leading one of the sum from its double's exponent, then Eq. 5 by the normalised reciprocal: m's fraction
      // aligned to the ROM's input bits is (sum - 2^lead) 2^B >> lead. The double is exact: the sum (below 2^52) as
      // the fraction bits of 2^52, less 2^52 (two operations, where AVX2 has no 64-bit integer conversion).
      const auto exact_sum = hn::Sub(hn::BitCast(df, hn::Or(hn::BitCast(du, sum), two_to_52_bits)), two_to_52);
      const auto lead = hn::Sub(hn::BitCast(d, hn::ShiftRight<52>(hn::BitCast(du, exact_sum))), exponent_bias);
      const auto contrast_shift = hn::Add(lead, contrast_shift_offset);
      by_stage_functions[i] = out_of_lanes || !hn::AllFalse(d, hn::AndNot(still, hn::Lt(contrast_shift, unit)));
      if (by_stage_functions[i]) {
        for (std::size_t k = 0; k < lanes; ++k) {
          weight[at + k] = weight_scalar(previous + 3 * (at + k), alpha + 3 * (at + k), kernels, tally);
        }
        hn::Store(zero, d, words + i);  // a place the lookup pass may read
        continue;
      }
      const auto lead_u = hn::BitCast(du, hn::IfThenElse(still, zero, lead));
      const auto below = hn::Sub(hn::BitCast(du, sum), hn::BitCast(du, hn::IfThenElse(still, zero, hn::BitCast(d, hn::Shl(hn::BitCast(du, unit), lead_u)))));
      // (A still pixel, whose w is 1 whatever c, reads node 0.)
      const auto code = hn::BitCast(du, hn::IfThenZeroElse(still, hn::BitCast(d, hn::Shr(hn::ShiftLeftSame(below, reciprocal_input_bits), lead_u))));
      place_in(reciprocal, code, i);
      hn::Store(hn::BitCast(d, code), d, codes + i);
      hn::Store(difference, d, differences + i);
      hn::Store(hn::IfThenElse(still, unit, contrast_shift), d, shifts + i);
    }
    look_up(reciprocal.packed, words, count);
    for (std::size_t i = 0; i < count; i += lanes) {
      if (by_stage_functions[i]) {
        hn::Store(zero, d, words + i);
        hn::Store(zero, d, integers + i);
        continue;
      }
      const auto mantissa = interpolated(reciprocal, hn::BitCast(du, hn::Load(d, codes + i)), i);  // 1/m, uQ2.24 at the defaults
      const auto product = hn::MulEven(hn::BitCast(du32, hn::Load(d, differences + i)), hn::BitCast(du32, mantissa));
      const auto shift_u = hn::BitCast(du, hn::Load(d, shifts + i));
      const auto half = hn::Shr(hn::Shl(hn::BitCast(du, unit), shift_u), hn::BitCast(du, unit));
      const auto contrast = hn::Min(hn::BitCast(d, hn::Shr(hn::Add(product, half), shift_u)), one);  // uQ1.F
      // Eq. 6: x = s c in uQ5.X, w = exp(-i) exp(-f).
      const auto exponent = hn::ShiftRightSame(hn::Add(hn::MulEven(sensitivity, hn::BitCast(du32, contrast)), exponent_half),
                                               exponent_shift);
      hn::Store(hn::BitCast(d, exponent), d, codes + i);
      place_in(exp_fraction, hn::And(exponent, fraction_mask), i);
      hn::Store(hn::Min(hn::BitCast(d, hn::ShiftRightSame(exponent, exp_input_frac_bits)), fifteen), d, integers + i);
    }
    look_up(exp_fraction.packed, words, count);
    look_up(exp_integer, integers, count);
    for (std::size_t i = 0; i < count; i += lanes) {
      if (by_stage_functions[i]) continue;
      const std::size_t at = x + i;
      const auto still = hn::Eq(hn::Load(d, differences + i), zero);
      const auto exponent = hn::BitCast(du, hn::Load(d, codes + i));
      const auto integer = hn::BitCast(d, hn::ShiftRightSame(exponent, exp_input_frac_bits));
      const auto underflow = hn::AndNot(still, hn::Gt(integer, fifteen));
      const auto e_fraction = interpolated(exp_fraction, hn::And(exponent, fraction_mask), i);
      const auto e_integer = hn::Load(d, integers + i);
      const auto w = hn::BitCast(d, hn::ShiftRightSame(hn::Add(hn::MulEven(hn::BitCast(du32, e_integer),
                                                                           hn::BitCast(du32, e_fraction)), linear_half),
                                                       linear_frac_bits));
      const auto result = hn::IfThenElse(still, one, hn::IfThenZeroElse(underflow, w));
      underflow_lanes = CountInto(d, underflow_lanes, underflow);
      weight_sum = hn::Add(weight_sum, result);
      hn::StoreU(result, d, weight + at);
    }
    x += count;
  }
  tally.weight_sum += hn::GetLane(hn::SumOfLanes(d, weight_sum));
  tally.underflow += Total(d, underflow_lanes);
#endif
  for (; x < pixels; ++x) weight[x] = weight_scalar(previous + 3 * x, alpha + 3 * x, kernels, tally);
}

template <typename Shown>
void AddWeightedResidualsOf(const std::int64_t* alpha, const std::int64_t* weight, const std::int32_t* residual,
                            std::size_t n, [[maybe_unused]] const MotionPlan& p, const FixedKernels& kernels,
                            Shown* shown, MotionTally& tally) {
  std::size_t s = 0;
#if HWY_TARGET != HWY_SCALAR
  const hn::ScalableTag<std::int64_t> d;
  const hn::Rebind<std::int32_t, decltype(d)> d32;
  const hn::Repartition<std::int32_t, decltype(d)> di32;
  const std::size_t lanes = hn::Lanes(d);
  const auto zero = hn::Zero(d);
  const auto one = hn::Set(d, p.one);
  const int residual_frac_bits = p.residual_frac_bits;  // a local: the compiler reloads what a store could alias
  const auto residual_half = hn::Set(d, std::int64_t{1} << (residual_frac_bits - 1));
  // Element e: e / 3, so that the pixels of the samples s0.. of a vector are s0 / 3 plus the elements (s0 mod 3)..
  static const std::array<std::int64_t, 3 + DrivePlan::kMaxLanes> third = [] {
    std::array<std::int64_t, 3 + DrivePlan::kMaxLanes> t{};
    for (std::size_t e = 0; e < t.size(); ++e) t[e] = static_cast<std::int64_t>(e / 3);
    return t;
  }();
  const hn::RebindToUnsigned<decltype(d)> du;
  const hn::Rebind<std::uint32_t, decltype(d)> du32h;
  auto dropped = zero;
  auto clipped_lanes = zero;
  auto magnitude_sum = zero;
  auto magnitude_max = hn::Zero(du32h);
  std::size_t phase = 0;
  const std::size_t phase_step = lanes % 3;
  // Sample s + i of a vector reads pixel s / 3 + third[phase + i] (phase = s mod 3), all within the vector's first
  // lanes / 3 + 1 pixels: one load of the pixels from s / 3 and a lane permutation, where that load stays within the
  // n / 3 weights; else a gather.
  const std::size_t pixels = n / 3;
  for (; s + lanes <= n; s += lanes, phase = next_phase(phase, phase_step)) {
    const auto pixel = hn::LoadU(d, third.data() + phase);
    const auto w = s / 3 + lanes <= pixels
                       ? hn::TableLookupLanes(hn::LoadU(d, weight + s / 3), hn::IndicesFromVec(d, pixel))
                       : hn::GatherIndex(d, weight + s / 3, pixel);
    if (!hn::AllFalse(d, hn::Or(hn::Lt(w, zero), hn::Gt(w, one)))) {
      for (std::size_t i = 0; i < lanes; ++i) {
        store_linear(weighted_scalar(alpha[s + i], weight[(s + i) / 3], residual[s + i], kernels, tally), shown + s + i);
      }
      continue;
    }
    const auto rho32 = hn::LoadU(d32, residual + s);
    const auto rho = hn::PromoteTo(d, rho32);
    // Eq. 4: alpha' = clamp(alpha + w rho, 0, 1); w rho (uQ1.F x sQ.R) rounded to F fraction bits.
    const auto product = hn::MulEven(hn::BitCast(di32, w), hn::BitCast(di32, rho));
    const auto sum = hn::Add(hn::LoadU(d, alpha + s), hn::ShiftRightSame(hn::Add(product, residual_half), residual_frac_bits));
    // The clamp and what it drops (|sum - clamped|) from two comparisons: AVX2 has no 64-bit minimum or maximum.
    const auto negative = hn::Lt(sum, zero);
    const auto above = hn::Gt(sum, one);
    StoreLinear(d, hn::IfThenZeroElse(negative, hn::IfThenElse(above, one, sum)), shown + s);
    clipped_lanes = CountInto(d, clipped_lanes, hn::Or(negative, above));
    dropped = hn::Add(dropped, hn::IfThenElse(negative, hn::Neg(sum), hn::IfThenElseZero(above, hn::Sub(sum, one))));
    // |rho| in 32-bit lanes, read unsigned (|INT32_MIN| = 2^31 too).
    const auto magnitude = hn::BitCast(du32h, hn::Abs(rho32));
    magnitude_sum = hn::Add(magnitude_sum, hn::BitCast(d, hn::PromoteTo(du, magnitude)));
    magnitude_max = hn::Max(magnitude_max, magnitude);
  }
  tally.clipped += Total(d, clipped_lanes);
  tally.dropped_sum += hn::GetLane(hn::SumOfLanes(d, dropped));
  tally.residual_abs_sum += hn::GetLane(hn::SumOfLanes(d, magnitude_sum));
  tally.residual_abs_max =
      std::max(tally.residual_abs_max, static_cast<std::int64_t>(hn::GetLane(hn::MaxOfLanes(du32h, magnitude_max))));
#endif
  for (; s < n; ++s) store_linear(weighted_scalar(alpha[s], weight[s / 3], residual[s], kernels, tally), shown + s);
}

void AddWeightedResiduals(const std::int64_t* alpha, const std::int64_t* weight, const std::int32_t* residual,
                          std::size_t n, const MotionPlan& p, const FixedKernels& kernels, std::int64_t* shown,
                          MotionTally& tally) {
  AddWeightedResidualsOf(alpha, weight, residual, n, p, kernels, shown, tally);
}
// Eq. 4 into a 32-bit line in 32-bit lanes (MotionPlan::narrow_weighted_sum: alpha, w, rho of the residual format
// and alpha + w rho all within 32 bits): twice the samples per vector of AddWeightedResidualsOf, where the clamp is
// AVX2's native 32-bit minimum and maximum. w rho is a 64-bit product of the even lanes and one of the odd lanes; the
// rounded shift by R keeps bits [R, R + 32) of each, which a logical shift right (even) or left by 32 - R (odd) puts
// in the lane's 32-bit half, equal to the arithmetic shift's low half for R <= 32. Vectors with an operand outside
// [0, 1] (w, alpha) or a residual outside its format take the stage functions. Returns the samples done; the caller
// does the rest.
std::size_t AddWeightedResidualsNarrow([[maybe_unused]] const std::int64_t* alpha,
                                       [[maybe_unused]] const std::int64_t* weight,
                                       [[maybe_unused]] const std::int32_t* residual, [[maybe_unused]] std::size_t n,
                                       [[maybe_unused]] const MotionPlan& p,
                                       [[maybe_unused]] const FixedKernels& kernels,
                                       [[maybe_unused]] std::int32_t* shown, [[maybe_unused]] MotionTally& tally) {
  std::size_t s = 0;
#if HWY_TARGET != HWY_SCALAR
  const hn::ScalableTag<std::int32_t> d;
  const hn::RebindToUnsigned<decltype(d)> du;
  const hn::Repartition<std::int64_t, decltype(d)> d64;
  const hn::RebindToUnsigned<decltype(d64)> du64;
  const std::size_t lanes = hn::Lanes(d);
  const std::size_t pixels_read = lanes / 2;  // one vector of 64-bit weights
  // The pixels of `lanes` samples span at most (lanes + 1) / 3 + 1 of them: within one weight vector from 4 lanes on.
  if (lanes < 4 || !p.narrow_weighted_sum) return 0;
  const auto zero = hn::Zero(d);
  const auto one = hn::Set(d, static_cast<std::int32_t>(p.one));
  // A 64-bit value in [0, 1] has its lower 32-bit half at most one and its upper half 0.
  const auto half_limit = hn::OddEven(zero, one);
  const auto magnitude_limit = hn::Set(du, p.residual_magnitude_limit);
  const int residual_frac_bits = p.residual_frac_bits;
  const int odd_shift = 32 - residual_frac_bits;
  const auto residual_half = hn::Set(du64, std::uint64_t{1} << (residual_frac_bits - 1));
  const auto low_halves = hn::Set(du64, std::uint64_t{0xFFFFFFFF});
  // A vector's unsigned 32-bit lanes summed in pairs into 64-bit lanes (sums that 32 bits would overflow).
  const auto pair_sums = [&](const auto v) {
    const auto wide = hn::BitCast(du64, v);
    return hn::Add(hn::And(wide, low_halves), hn::ShiftRight<32>(wide));
  };
  // Element e: 2 (e / 3), the 32-bit half holding the weight of sample e's pixel in a vector of 64-bit weights.
  static const std::array<std::int32_t, 3 + DrivePlan::kMaxLanes> half_of_pixel = [] {
    std::array<std::int32_t, 3 + DrivePlan::kMaxLanes> t{};
    for (std::size_t e = 0; e < t.size(); ++e) t[e] = static_cast<std::int32_t>(2 * (e / 3));
    return t;
  }();
  auto clipped_lanes = zero;
  auto dropped = hn::Zero(du64);
  auto magnitude_sum = hn::Zero(du64);
  auto magnitude_max = hn::Zero(du);
  std::size_t phase = 0;
  const std::size_t phase_step = lanes % 3;
  const std::size_t pixels = n / 3;
  for (; s + lanes <= n && s / 3 + pixels_read <= pixels; s += lanes, phase = next_phase(phase, phase_step)) {
    const auto weights = hn::BitCast(d, hn::LoadU(d64, weight + s / 3));
    const auto alpha_low = hn::LoadU(d64, alpha + s);
    const auto alpha_high = hn::LoadU(d64, alpha + s + pixels_read);
    // The weights and alphas in [0, 1]: every lower half at most one and every upper half 0, read unsigned (a
    // negative value's upper half is all ones).
    const auto largest = hn::Max(hn::BitCast(du, weights),
                                 hn::Max(hn::BitCast(du, alpha_low), hn::BitCast(du, alpha_high)));
    const auto limit = hn::BitCast(du, half_limit);
    // |rho| read unsigned (|INT32_MIN| = 2^31 too), within the residual format's 2^(width - 1).
    const auto rho = hn::LoadU(d, residual + s);
    const auto magnitude = hn::BitCast(du, hn::Abs(rho));
    if (!hn::AllTrue(du, hn::And(hn::Eq(hn::Max(largest, limit), limit),
                                 hn::Eq(hn::Max(magnitude, magnitude_limit), magnitude_limit)))) {
      for (std::size_t i = 0; i < lanes; ++i) {
        shown[s + i] = static_cast<std::int32_t>(
            weighted_scalar(alpha[s + i], weight[(s + i) / 3], residual[s + i], kernels, tally));
      }
      continue;
    }
    const auto w = hn::TableLookupLanes(weights, hn::IndicesFromVec(d, hn::LoadU(d, half_of_pixel.data() + phase)));
    const auto even = hn::BitCast(du64, hn::MulEven(w, rho));
    const auto odd = hn::BitCast(du64, hn::MulEven(hn::BitCast(d, hn::ShiftRight<32>(hn::BitCast(du64, w))),
                                                    hn::BitCast(d, hn::ShiftRight<32>(hn::BitCast(du64, rho)))));
    const auto weighted = hn::OddEven(hn::BitCast(d, hn::ShiftLeftSame(hn::Add(odd, residual_half), odd_shift)),
                                      hn::BitCast(d, hn::ShiftRightSame(hn::Add(even, residual_half), residual_frac_bits)));
    const auto sum = hn::Add(hn::ConcatEven(d, hn::BitCast(d, alpha_high), hn::BitCast(d, alpha_low)), weighted);
    const auto clamped = hn::Min(hn::Max(sum, zero), one);
    hn::StoreU(clamped, d, shown + s);
    const auto clipped = hn::Ne(clamped, sum);
    clipped_lanes = CountInto(d, clipped_lanes, clipped);
    if (!hn::AllFalse(d, clipped)) {  // what the clamp drops, at most 2^30 a sample: summed in 64 bits
      dropped = hn::Add(dropped, pair_sums(hn::Abs(hn::Sub(sum, clamped))));
    }
    magnitude_sum = hn::Add(magnitude_sum, pair_sums(magnitude));
    magnitude_max = hn::Max(magnitude_max, magnitude);
  }
  tally.clipped += Total(d, clipped_lanes);
  tally.dropped_sum += static_cast<std::int64_t>(hn::GetLane(hn::SumOfLanes(du64, dropped)));
  tally.residual_abs_sum += static_cast<std::int64_t>(hn::GetLane(hn::SumOfLanes(du64, magnitude_sum)));
  tally.residual_abs_max =
      std::max(tally.residual_abs_max, static_cast<std::int64_t>(hn::GetLane(hn::MaxOfLanes(du, magnitude_max))));
#endif
  return s;
}

void AddWeightedResidualsInto32(const std::int64_t* alpha, const std::int64_t* weight, const std::int32_t* residual,
                                std::size_t n, const MotionPlan& p, const FixedKernels& kernels, std::int32_t* shown,
                                MotionTally& tally) {
  const std::size_t done = AddWeightedResidualsNarrow(alpha, weight, residual, n, p, kernels, shown, tally);
  if (done == 0) {
    AddWeightedResidualsOf(alpha, weight, residual, n, p, kernels, shown, tally);
    return;
  }
  for (std::size_t s = done; s < n; ++s) {
    shown[s] = static_cast<std::int32_t>(weighted_scalar(alpha[s], weight[s / 3], residual[s], kernels, tally));
  }
}

inline std::int32_t stored_scalar(std::int64_t rho, const FixedKernels& kernels, ResidualTally& tally) {
  if (rho == 0) return 0;
  const StoredResidual stored = kernels.store_residual(rho);
  tally.add(stored);
  return static_cast<std::int32_t>(stored.value);
}

template <typename Linear>
bool StoreResidualsOf(const Linear* rho, std::size_t n, const FixedKernels& kernels, std::int32_t* stored,
                      ResidualTally& tally) {
  std::size_t s = 0;
  std::int32_t any_bits = 0;  // the OR of the stored values
#if HWY_TARGET != HWY_SCALAR
  const hn::ScalableTag<Linear> d;
  const hn::Rebind<std::int32_t, decltype(d)> d32;
  const std::size_t lanes = hn::Lanes(d);
  const auto zero = hn::Zero(d);
  const auto zero32 = hn::Zero(d32);
  for (; s + lanes <= n; s += lanes) {
    if (hn::AllTrue(d, hn::Eq(hn::LoadU(d, rho + s), zero))) {
      hn::StoreU(zero32, d32, stored + s);
      continue;
    }
    for (std::size_t i = 0; i < lanes; ++i) any_bits |= stored[s + i] = stored_scalar(rho[s + i], kernels, tally);
  }
#endif
  for (; s < n; ++s) any_bits |= stored[s] = stored_scalar(rho[s], kernels, tally);
  return any_bits != 0;
}

bool StoreResiduals(const std::int64_t* rho, std::size_t n, const FixedKernels& kernels, std::int32_t* stored,
                    ResidualTally& tally) {
  return StoreResidualsOf(rho, n, kernels, stored, tally);
}
bool StoreResiduals32(const std::int32_t* rho, std::size_t n, const FixedKernels& kernels, std::int32_t* stored,
                      ResidualTally& tally) {
  return StoreResidualsOf(rho, n, kernels, stored, tally);
}

const char* TargetName() { return hwy::TargetName(HWY_TARGET); }

}  // namespace HWY_NAMESPACE
}  // namespace trm::fixed_detail::lines
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace trm::fixed_detail {

namespace {

// node << 32 | (step mod 2^32) per word, or nothing where a node leaves [0, 2^31), a step int32 or node + step
// [0, ...) (InterpolateWord's shifts are unsigned).
std::optional<std::vector<std::int64_t>> packed_rom(const std::vector<std::int64_t>& node,
                                                    const std::vector<std::int64_t>& step) {
  // One word more than the ROM: LookupWords reads each word with the next.
  std::vector<std::int64_t> packed(node.size() + 1, 0);
  for (std::size_t i = 0; i < node.size(); ++i) {
    if (node[i] < 0 || node[i] > INT32_MAX || step[i] < INT32_MIN || step[i] > INT32_MAX || node[i] + step[i] < 0) {
      return std::nullopt;
    }
    packed[i] = static_cast<std::int64_t>((static_cast<std::uint64_t>(node[i]) << 32) |
                                          static_cast<std::uint32_t>(step[i]));
  }
  return packed;
}

// The same of a ROM's words with the steps between them (the last word's 0).
std::optional<std::vector<std::int64_t>> packed_rom(const std::vector<std::int64_t>& rom) {
  std::vector<std::int64_t> step(rom.size(), 0);
  for (std::size_t i = 0; i + 1 < rom.size(); ++i) step[i] = rom[i + 1] - rom[i];
  return packed_rom(rom, step);
}

// The shift form of a uniform ROM (ShiftedRomPlan), where its segment position per code is 2^k with 1 <= k <= 31,
// it rounds half up, and the interpolation's sum stays in 62 bits.
std::optional<ShiftedRomPlan> shifted_rom_plan(const fx::InterpolatedLut& lut) {
  if (lut.is_direct() || lut.is_octave_segmented() || lut.shape().rounding != fx::Quant::Rnd) return std::nullopt;
  const std::uint64_t segment = lut.segment_step();
  if (!std::has_single_bit(segment)) return std::nullopt;
  const int k = std::countr_zero(segment);
  if (k < 1 || k > 31) return std::nullopt;
  ShiftedRomPlan plan;
  plan.weight_bits = 32 - k;
  const std::vector<std::int64_t>& rom = lut.rom();
  const std::uint64_t top_node = ((std::uint64_t{1} << lut.shape().input_bits) - 1) >> plan.weight_bits;
  if (top_node >= rom.size()) return std::nullopt;
  const std::int64_t limit = std::int64_t{1} << (61 - plan.weight_bits);
  for (const std::int64_t word : rom) {
    if (word <= -limit || word >= limit) return std::nullopt;
  }
  std::optional<std::vector<std::int64_t>> packed = packed_rom(rom);
  if (!packed) return std::nullopt;
  plan.packed = std::move(*packed);
  return plan;
}

// The OLED's report drive value ROMs as one table (DriveValuePlan), or nothing where a channel's ROM does not fit it.
// luts: each channel's ROM; input_shift: the linear value's bits below its input code.
std::optional<DriveValuePlan> drive_value_plan(const std::array<const fx::InterpolatedLut*, 3>& luts, int input_shift,
                                               std::int64_t one, int drive_frac_bits) {
  DriveValuePlan plan;
  plan.one = one;
  plan.full_drive = std::int64_t{1} << drive_frac_bits;
  plan.input_shift = input_shift;
  std::array<std::int64_t, 3> first{};
  for (int ch = 0; ch < 3; ++ch) {
    const fx::InterpolatedLut& lut = *luts[static_cast<std::size_t>(ch)];
    const fx::LutShape& shape = lut.shape();
    const int segments_log2 = lut.segments_per_octave_log2();
    // Node (region << S) + (offset << S >> scale) of the top code is (octaves << S) - 1.
    if (!lut.is_octave_segmented() || shape.rounding != fx::Quant::Rnd || shape.output_signed ||
        shape.input_bits > 30 || lut.bottom_region_bits() < 1 ||
        lut.rom().size() < (static_cast<std::size_t>(shape.octaves) << segments_log2)) {
      return std::nullopt;
    }
    if (ch > 0 && (shape.input_bits != luts[0]->shape().input_bits ||
                   segments_log2 != plan.segments_per_octave_log2 ||
                   lut.bottom_region_bits() != plan.bottom_region_bits)) {
      return std::nullopt;
    }
    plan.top_code = (std::int64_t{1} << shape.input_bits) - 1;
    plan.bottom_region_bits = lut.bottom_region_bits();
    plan.segments_per_octave_log2 = segments_log2;
    std::optional<std::vector<std::int64_t>> packed = packed_rom(lut.rom());
    if (!packed) return std::nullopt;
    first[static_cast<std::size_t>(ch)] = static_cast<std::int64_t>(plan.packed.size());
    plan.packed.insert(plan.packed.end(), packed->begin(), packed->end());
  }
  for (int i = 0; i < 3 + DrivePlan::kMaxLanes; ++i) plan.rom_offset.push_back(first[static_cast<std::size_t>(i % 3)]);
  return plan;
}

// The motion test's plan: every product of MotionWeights / AddWeightedResiduals of 32-bit operands (F <= 30, the
// weights, s, the ROM words and the mantissa below 2^32), every rounding shift at least 1.
std::optional<MotionPlan> motion_plan(const FixedKernels& kernels, const std::array<std::int64_t, 3>& luma_weights,
                                      const fx::InterpolatedLut& reciprocal, const fx::InterpolatedLut& exp_fraction,
                                      std::int64_t sensitivity, const std::vector<std::int64_t>& exp_integer) {
  const FixedDecoderConfig& c = kernels.config();
  const int F = c.linear_frac_bits;
  MotionPlan m;
  m.linear_frac_bits = F;
  m.one = kernels.one();
  m.luma_shift = c.luma_weight_frac_bits;
  m.reciprocal_input_bits = reciprocal.shape().input_bits;
  m.reciprocal_frac_bits = reciprocal.shape().output_frac_bits;
  m.exp_input_frac_bits = c.exp_input_frac_bits;
  m.exponent_shift = c.sensitivity_frac_bits + F - c.exp_input_frac_bits;
  m.residual_frac_bits = c.residual.frac_bits;
  // |rho| <= 2^(width - 1) = 2^(int_bits + R - 1) and w <= 2^F, so w rho rounded to F fraction bits is at most
  // 2^(F + int_bits - 1) in magnitude, and alpha + w rho with alpha in [0, 2^F] stays within 32 bits where
  // F + int_bits <= 30.
  m.narrow_weighted_sum = F + c.residual.int_bits <= 30 && m.residual_frac_bits <= 32;
  m.residual_magnitude_limit = std::uint32_t{1} << (c.residual.width() - 1);
  const auto below32 = [](std::int64_t v) { return v >= 0 && v < (std::int64_t{1} << 32); };
  bool fits = F >= 1 && F <= 30 && m.luma_shift >= 1 && m.luma_shift + F <= 60 &&
              F + 2 + m.reciprocal_input_bits <= 63 && reciprocal.shape().output_bits <= 32 &&
              !reciprocal.shape().output_signed && exp_fraction.shape().output_bits <= 32 &&
              !exp_fraction.shape().output_signed && exp_fraction.shape().input_bits == c.exp_input_frac_bits &&
              m.exponent_shift >= 1 && m.residual_frac_bits >= 1 && below32(sensitivity) && exp_integer.size() == 16;
  for (std::size_t i = 0; i < 3; ++i) {
    fits = fits && below32(luma_weights[i]);
    m.luma_weight[i] = static_cast<std::uint32_t>(luma_weights[i]);
  }
  for (std::size_t i = 0; i < 16 && fits; ++i) {
    fits = fits && below32(exp_integer[i]);
    m.exp_integer[i] = exp_integer[i];
  }
  std::optional<ShiftedRomPlan> r = shifted_rom_plan(reciprocal);
  std::optional<ShiftedRomPlan> e = shifted_rom_plan(exp_fraction);
  if (!fits || !r || !e) return std::nullopt;
  m.sensitivity = static_cast<std::uint32_t>(sensitivity);
  m.reciprocal = std::move(*r);
  m.exp_fraction = std::move(*e);
  return m;
}

// LcdPlan::report_merge of a plan (its top and width set); merge(t, j): FixedKernels::scaled_merge of the panel's
// coefficients.
template <typename Merge>
void lcd_report_table(LcdPlan& plan, Merge merge, int drive_frac_bits) {
  // The quotient (at most 2^D + 1) a 32-bit operand of MulNarrow, and its estimate within 1 (FixedDecoderConfig
  // bounds D to [8, 30]).
  if (drive_frac_bits < 0 || drive_frac_bits > 30) return;
  const std::int64_t two_top = 2 * static_cast<std::int64_t>(plan.top);
  const std::int64_t words = plan.width + 1;
  std::vector<std::int64_t> table(static_cast<std::size_t>(plan.width * words));
  constexpr std::int64_t kWordLimit = std::int64_t{1} << 61;
  const std::int64_t span_limit = (std::int64_t{1} << 62) / (two_top + 2);
  for (std::int64_t j = 0; j < plan.width; ++j) {
    std::int64_t* row = table.data() + j * words;
    for (std::int64_t c = 0; c < words; ++c) {
      row[c] = merge(std::clamp<std::int64_t>(2 * c - 1, 0, two_top), j);
      if (row[c] <= -kWordLimit || row[c] >= kWordLimit) return;
      if (c > 0 && row[c] - row[c - 1] >= span_limit) return;
    }
  }
  plan.report_merge = std::move(table);
  plan.report_row_words = words;
  plan.drive_frac_bits = drive_frac_bits;
}

}  // namespace

FixedLinePlans FixedLinePlans::build(const FixedKernels& kernels) {
  const FixedDecoderConfig& c = kernels.config();
  FixedLinePlans plans;
  if (!c.line_kernels) return plans;
  plans.code_rom = kernels.code_rom();
  plans.one = kernels.one();
  const int F = c.linear_frac_bits;
  plans.code_rom32.assign(plans.code_rom.begin(), plans.code_rom.end());
  const int W = c.bilinear_weight_frac_bits;
  const int U = c.upsample_frac_bits;
  const fx::InterpolatedLut* eotf = kernels.eotf_lut();
  const int weight_bits = U - c.eotf_segments_per_code_log2;
  // The lanes' bounds: U's column sums in 32 bits, its row sum in 64, the rounding shift and the ROM weight in the
  // 32-bit operands of MulEven, the interpolation's exact sum in 63 bits, half-up rounding (as the ROM's).
  const bool eotf_fits = !kernels.linear_space() && eotf != nullptr && W <= 31 &&
                         (static_cast<std::uint64_t>(kernels.max_code()) << W) < (std::uint64_t{1} << 32) &&
                         2 * W - U >= 1 && weight_bits >= 1 && weight_bits <= 31 && F + 1 + weight_bits <= 62 &&
                         eotf->shape().rounding == fx::Quant::Rnd && !eotf->is_direct() && !eotf->is_octave_segmented();
  if (eotf_fits) {
    const std::vector<std::int64_t>& rom = eotf->rom();
    const std::uint64_t top_node = (static_cast<std::uint64_t>(kernels.max_code()) << U) >> weight_bits;
    EotfPlan e;
    e.node = rom;
    e.step.resize(rom.size(), 0);
    bool steps_fit = top_node + 1 == rom.size();
    for (std::size_t i = 0; i + 1 < rom.size(); ++i) {
      e.step[i] = rom[i + 1] - rom[i];
      steps_fit = steps_fit && e.step[i] >= INT32_MIN && e.step[i] <= INT32_MAX;
    }
    e.unit = std::uint32_t{1} << W;
    e.blend_shift = 2 * W - U;
    e.weight_bits = weight_bits;
    e.frac_bits = W;
    e.segments_log2 = c.eotf_segments_per_code_log2;
    e.within_unit = std::all_of(rom.begin(), rom.end(), [&](std::int64_t v) { return v >= 0 && v <= plans.one; });
    if (std::all_of(rom.begin(), rom.end(), [](std::int64_t v) { return v >= INT32_MIN && v <= INT32_MAX; })) {
      e.node32.assign(rom.begin(), rom.end());
    }
    std::optional<std::vector<std::int64_t>> packed = packed_rom(e.node, e.step);
    if (steps_fit && packed) {
      e.packed = std::move(*packed);
      plans.eotf = std::move(e);
    }
  }
  if (!kernels.sensitivity_infinite_ && c.decoder.sensitivity != 0.0 && kernels.reciprocal_ && kernels.exp_fraction_) {
    plans.motion = motion_plan(kernels, kernels.luma_weights_, *kernels.reciprocal_, *kernels.exp_fraction_,
                               kernels.sensitivity_raw_, kernels.exp_integer_rom_);
  }
  {
    const int T = c.gaussian_tap_frac_bits;
    const int L = c.gaussian_line_frac_bits;
    const auto max_code = static_cast<std::uint64_t>(kernels.max_code());
    if (!kernels.linear_space() && T <= 31 && L >= 0 && T - L >= 1 && (max_code << T) < (std::uint64_t{1} << 32) &&
        (max_code << L) < (std::uint64_t{1} << 32)) {
      plans.gaussian = GaussianPlan{T - L, T + L, (max_code << (L + 1)) < (std::uint64_t{1} << 32)};
    }
  }
  if (kernels.lcd() && !kernels.lcd_merge_table_.empty() && kernels.lcd_target_lut_) {
    const fx::InterpolatedLut& target = *kernels.lcd_target_lut_;
    LcdPlan l;
    l.linear_frac_bits = F;
    l.one = kernels.one();
    l.top = kernels.max_output_code();
    l.width = l.top + 1;
    while ((std::int64_t{1} << l.width_log2) < l.width) ++l.width_log2;
    const auto scale = static_cast<std::uint64_t>(2 * l.top) * static_cast<std::uint64_t>(2 * l.top);
    l.scale = static_cast<std::uint32_t>(scale);
    l.target_shift = F + 1 - target.shape().input_bits;
    l.target_input_bits = target.shape().input_bits;
    l.bottom_region_bits = target.bottom_region_bits();
    l.segments_per_octave_log2 = target.segments_per_octave_log2();
    while ((1 << l.steps) < l.width) ++l.steps;
    l.merge = kernels.lcd_merge_table_;
    const auto& [end_dark, end_bright] = kernels.lcd_end_luminance_;
    for (std::size_t v = 0; v < end_dark.size() && v < end_bright.size(); ++v) {
      l.ends.push_back(end_dark[v]);
      l.ends.push_back(end_bright[v]);
    }
    l.contributed = c.decoder.lcd_history == LcdHistory::Contributed;
    const std::vector<std::int64_t>& rom = target.rom();
    std::optional<std::vector<std::int64_t>> packed = packed_rom(rom);
    // 32-bit operands for the target's scaling and the ROM weight (scale bits up to the ROM's 24 address bits), the
    // octave nodes within the ROM, the merges of every (v_{t-1}, k) present.
    const bool fits = packed && F <= 30 && (std::int64_t{1} << l.width_log2) == l.width && scale < (std::uint64_t{1} << 32) && l.target_shift >= 0 &&
                      target.is_octave_segmented() && target.shape().rounding == fx::Quant::Rnd &&
                      !target.shape().output_signed && target.shape().input_bits <= 30 && l.bottom_region_bits >= 1 &&
                      rom.size() >= (static_cast<std::size_t>(target.shape().octaves) << l.segments_per_octave_log2) &&
                      l.merge.size() >= static_cast<std::size_t>(l.width * (l.width + 1)) &&  // the held row too
                      end_dark.size() == static_cast<std::size_t>(l.width) &&
                      end_bright.size() == static_cast<std::size_t>(l.width);
    if (fits) {
      l.target_packed = std::move(*packed);
      lcd_search_index(l);
      lcd_composed_index(l, target);
      lcd_report_table(
          l, [&](std::int64_t t, std::int64_t j) { return kernels.scaled_merge(kernels.lcd_coefficients_, t, j); },
          c.drive_frac_bits);
      plans.lcd = std::move(l);
    }
  }
  if (!kernels.lcd()) {
    plans.drive = drive_plan({&kernels.drive_index(0), &kernels.drive_index(1), &kernels.drive_index(2)});
    plans.drive_value = drive_value_plan({kernels.drive_luts_[0].get(), kernels.drive_luts_[1].get(),
                                          kernels.drive_luts_[2].get()},
                                         kernels.drive_lut_shift_, kernels.one(), c.drive_frac_bits);
  }
  if (plans.drive && plans.eotf && plans.eotf->within_unit && !plans.eotf->node32.empty() &&
      plans.eotf->node32.size() <= (std::size_t{1} << 17)) {
    const std::vector<std::int32_t>& node = plans.eotf->node32;
    plans.drive_of_node.resize(3 * node.size());
    for (std::size_t i = 0; i < node.size(); ++i) {
      for (int ch = 0; ch < 3; ++ch) plans.drive_of_node[3 * i + static_cast<std::size_t>(ch)] = kernels.drive_code(node[i], ch);
    }
  }
  return plans;
}

namespace {

// The values of bucket b of a table addressed by a value's float (DrivePlan::packed32, LcdPlan::composed: the float's
// bits shifted right by 23 - m, less 126 << m, 0 for the value 0): [lo, lo + width). Bucket b >= 2^m: leading one
// e = (b >> m) - 1, the m fraction bits f = b mod 2^m; below e = m a bucket is one value, and exists where f's low
// m - e bits are 0. Bucket 0 is the value 0; buckets 1 .. 2^m - 1 are never addressed. False for a bucket no value
// addresses.
bool float_bucket(std::int32_t b, int m, std::int64_t& lo, std::int64_t& width) {
  lo = 0;
  width = 1;
  if (b == 0) return true;
  if (b < (1 << m)) return false;
  const int e = (b >> m) - 1;
  const std::int64_t f = b & ((1 << m) - 1);
  if (e >= m) {
    lo = ((std::int64_t{1} << m) + f) << (e - m);
    width = std::int64_t{1} << (e - m);
    return true;
  }
  if ((f & ((std::int64_t{1} << (m - e)) - 1)) != 0) return false;
  lo = (std::int64_t{1} << e) + (f >> (m - e));
  return true;
}

// DrivePlan::packed32 for a plan whose 32-bit tables are built, where every channel's every bucket holds at most one
// threshold.
void packed_drive_search(const std::array<const ThresholdIndex*, 3>& channels, DrivePlan& d) {
  const int m = d.mantissa_bits;
  const int value_bits = channels[0]->value_bits();
  const int offset_bits = value_bits - m;  // a bucket is at most 2^(value_bits - 1 - m) wide
  int code_bits = 0;
  for (const ThresholdIndex* index : channels) {
    if (index->steps() < 1) return;
    code_bits = std::max(code_bits, static_cast<int>(std::bit_width(index->padded().size())));
  }
  if (value_bits > 30 || m > 16 || offset_bits < 1 || offset_bits + code_bits > 32) return;
  const std::int32_t buckets = (value_bits + 1) << m;
  std::vector<std::uint32_t> packed(3 * static_cast<std::size_t>(buckets), 0);
  for (std::size_t ch = 0; ch < 3; ++ch) {
    const ThresholdIndex& index = *channels[ch];
    const std::vector<std::int64_t>& padded = index.padded();
    for (std::int32_t b = 0; b < buckets; ++b) {
      std::int64_t lo = 0;
      std::int64_t width = 1;
      if (!float_bucket(b, m, lo, width)) continue;
      const std::uint16_t k = index.search(lo);
      const std::int64_t next = padded[std::size_t{k} + 1];  // above lo (k is lo's code); the padding no x reaches
      if (next <= lo || index.search(lo + width - 1) > k + 1) return;  // two thresholds inside: not one lookup
      const std::int64_t offset = next - lo < width ? next - lo : width;
      packed[ch * static_cast<std::size_t>(buckets) + static_cast<std::size_t>(b)] =
          (std::uint32_t{k} << offset_bits) | static_cast<std::uint32_t>(offset);
    }
  }
  d.packed32 = std::move(packed);
  d.packed_buckets = buckets;
  d.packed_offset32.clear();
  for (int i = 0; i < 3 + DrivePlan::kMaxLanes; ++i) d.packed_offset32.push_back((i % 3) * buckets);
  d.offset_bits = offset_bits;
}

// Each row's merge thresholds in the target's units (LcdPlan::index), rows of plan.top: U_k = ceil(merge[r][k] /
// scale), nondecreasing in k and every one in [1, one]; empty where a row's are not.
std::vector<std::int64_t> lcd_thresholds(const LcdPlan& plan) {
  const std::int64_t rows = plan.width + 1;
  const auto scale = static_cast<std::int64_t>(plan.scale);
  if (scale <= 0 || plan.top < 1 || plan.merge.size() < static_cast<std::size_t>(rows * plan.width)) return {};
  std::vector<std::int64_t> thresholds(static_cast<std::size_t>(rows * plan.top));
  for (std::int64_t r = 0; r < rows; ++r) {
    for (std::int64_t k = 1; k <= plan.top; ++k) {
      const std::int64_t merge = plan.merge[static_cast<std::size_t>(r * plan.width + k)];
      const std::int64_t u = merge <= 0 ? 0 : (merge + scale - 1) / scale;
      if (u < 1 || u > plan.one || (k > 1 && u < thresholds[static_cast<std::size_t>(r * plan.top + k - 2)])) return {};
      thresholds[static_cast<std::size_t>(r * plan.top + k - 1)] = u;
    }
  }
  return thresholds;
}

}  // namespace

void lcd_search_index(LcdPlan& plan) {
  plan.index.clear();
  const std::int64_t rows = plan.width + 1;
  const std::int64_t one = plan.one;
  const std::vector<std::int64_t> thresholds = lcd_thresholds(plan);
  if (thresholds.empty()) return;
  const int F = plan.linear_frac_bits;
  const int code_bits = static_cast<int>(std::bit_width(static_cast<std::uint64_t>(plan.top)));
  for (int shift = F - 8; shift >= std::max(1, F - 14); --shift) {
    const int offset_bits = shift + 1;
    if (offset_bits + code_bits > 32) continue;
    const std::int64_t width = std::int64_t{1} << shift;
    const std::int64_t buckets = (one >> shift) + 1;
    std::vector<std::uint32_t> index(static_cast<std::size_t>(rows * buckets));
    bool fits = true;
    for (std::int64_t r = 0; r < rows && fits; ++r) {
      const std::int64_t* u = thresholds.data() + r * plan.top;
      std::int64_t code = 0;  // thresholds at or below the bucket's lower end
      for (std::int64_t q = 0; q < buckets; ++q) {
        const std::int64_t lo = q * width;
        while (code < plan.top && u[code] <= lo) ++code;
        const std::int64_t next = code < plan.top ? u[code] - lo : width;
        if (code + 1 < plan.top && u[code + 1] < lo + width) {  // two thresholds inside: too wide
          fits = false;
          break;
        }
        index[static_cast<std::size_t>(r * buckets + q)] =
            (static_cast<std::uint32_t>(code) << offset_bits) | static_cast<std::uint32_t>(std::min(next, width));
      }
    }
    if (!fits) continue;
    plan.index = std::move(index);
    plan.index_shift = shift;
    plan.index_offset_bits = offset_bits;
    plan.index_buckets = buckets;
    return;
  }
}

void lcd_composed_index(LcdPlan& plan, const fx::InterpolatedLut& target) {
  plan.composed.clear();
  plan.ends32.clear();
  const int input_bits = plan.target_input_bits;
  const std::int64_t rows = plan.width + 1;
  if (input_bits < 1 || input_bits > 24 || plan.target_shift < 0 || plan.linear_frac_bits > 28 ||
      plan.ends.size() != static_cast<std::size_t>(2 * plan.width) || target.shape().input_bits != input_bits) {
    return;
  }
  const std::vector<std::int64_t> thresholds = lcd_thresholds(plan);
  if (thresholds.empty()) return;
  // The target of c, as LcdDriveOf and FixedKernels::lcd_drive take it: 0 for a sum at or below 0 (so the ROM's first
  // word must be 0, which a sum in (0, 2^target_shift) reads), the ROM below 2^input_bits, one at it. It rises with c
  // where the ROM's words do: within a segment the interpolation's rounding is monotone in the weight, and a segment
  // ends where the next begins.
  const std::vector<std::int64_t>& rom = target.rom();
  if (rom.empty() || rom.front() != 0 || !std::is_sorted(rom.begin(), rom.end())) return;
  const std::int64_t top_c = std::int64_t{1} << input_bits;
  const auto target_of = [&](std::int64_t c) {
    return c >= top_c ? plan.one : target.evaluate_raw(static_cast<std::uint32_t>(c));
  };
  if (target_of(top_c - 1) > plan.one) return;
  // C_k per row: the least c with target(c) >= U_k (top_c, whose target is one, for a U_k above one), and not below
  // C_{k-1}. The target at every 2^grid_shift-th c first (and at top_c): every row's thresholds ask the same function.
  // Between two grid points the target is close to their line, so each search starts at the line's c and widens by
  // doubling steps to a bracket, then bisects it: a few evaluations where a bisection over the grid's step takes
  // grid_shift.
  const int grid_shift = std::max(0, input_bits - 10);
  std::vector<std::int64_t> grid(static_cast<std::size_t>((top_c >> grid_shift) + 1));
  for (std::size_t j = 0; j < grid.size(); ++j) grid[j] = target_of(static_cast<std::int64_t>(j) << grid_shift);
  // The least c in [lo, hi] whose target reaches u, where the target at hi reaches it and at lo - 1 does not.
  const auto least_reaching = [&](std::int64_t lo, std::int64_t hi, std::int64_t guess, std::int64_t u) {
    guess = std::clamp(guess, lo, hi);
    if (target_of(guess) >= u) {
      hi = guess;
      for (std::int64_t step = 1; hi - step >= lo; step *= 2) {
        if (target_of(hi - step) < u) {
          lo = hi - step + 1;
          break;
        }
        hi -= step;
      }
    } else {
      lo = guess + 1;
      for (std::int64_t step = 1; lo + step - 1 < hi; step *= 2) {
        if (target_of(lo + step - 1) >= u) {
          hi = lo + step - 1;
          break;
        }
        lo += step;
      }
    }
    while (lo < hi) {
      const std::int64_t mid = lo + (hi - lo) / 2;
      if (target_of(mid) >= u) {
        hi = mid;
      } else {
        lo = mid + 1;
      }
    }
    return lo;
  };
  std::vector<std::int64_t> least_c(thresholds.size());
  for (std::int64_t r = 0; r < rows; ++r) {
    std::int64_t from = 0;
    for (std::int64_t k = 0; k < plan.top; ++k) {
      const std::size_t at = static_cast<std::size_t>(r * plan.top + k);
      const std::int64_t u = thresholds[at];
      // The first grid point that reaches U_k; none (U_k above one): top_c, as a search up to it gives.
      const auto reached = std::lower_bound(grid.begin(), grid.end(), u);
      const std::int64_t j = reached - grid.begin();
      std::int64_t c = top_c;
      if (reached != grid.end()) {
        c = 0;
        if (j > 0) {
          const std::int64_t below = grid[static_cast<std::size_t>(j - 1)];  // < u <= *reached
          const std::int64_t base = (j - 1) << grid_shift;
          const std::int64_t along = ((u - below) << grid_shift) + (*reached - below) - 1;
          c = least_reaching(base + 1, j << grid_shift, base + along / (*reached - below), u);
        }
      }
      least_c[at] = from = std::max(from, c);
    }
  }
  // The unreachable ends of the sums, in 32 bits.
  std::vector<std::uint64_t> ends(static_cast<std::size_t>(plan.width));
  for (std::size_t v = 0; v < ends.size(); ++v) {
    const std::int64_t dark = 2 * plan.ends[2 * v];
    const std::int64_t bright = 2 * plan.ends[2 * v + 1];
    if (dark < 0 || bright < 0 || dark > (std::int64_t{1} << 30) || bright > (std::int64_t{1} << 30)) return;
    ends[v] = static_cast<std::uint64_t>(dark) | (static_cast<std::uint64_t>(bright) << 32);
  }
  // Whether, with m fraction bits, no bucket holds two of a row's C_k above its lower end (float_bucket's buckets: one
  // value below 2^m, else the values sharing c's top m + 1 bits): the table's condition, asked before it is built.
  const auto fits_buckets = [&](int m) {
    for (std::int64_t r = 0; r < rows; ++r) {
      const std::int64_t* c_k = least_c.data() + r * plan.top;
      for (std::int64_t k = 0; k + 1 < plan.top; ++k) {
        const std::int64_t c = c_k[k];
        const int e = static_cast<int>(std::bit_width(static_cast<std::uint64_t>(c))) - 1;
        if (e < m) continue;
        const std::int64_t width = std::int64_t{1} << (e - m);
        const std::int64_t lo = c & ~(width - 1);
        if (c != lo && c_k[k + 1] < lo + width) return false;
      }
    }
    return true;
  };
  const int code_bits = static_cast<int>(std::bit_width(static_cast<std::uint64_t>(plan.top)));
  // The coarsest addressing whose words hold a code and an offset, whose table is not too large, and whose buckets
  // each hold at most one C_k above the lower end.
  const auto usable = [&](int m) {
    const int offset_bits = input_bits - m + 1;  // a bucket is at most 2^(input_bits - m) wide
    const std::int32_t buckets = (input_bits + 2) << m;
    return offset_bits >= 1 && offset_bits + code_bits <= 32 &&
           static_cast<std::size_t>(rows) * static_cast<std::size_t>(buckets) * sizeof(std::uint32_t) <=
               LcdPlan::kMaxComposedBytes &&
           fits_buckets(m);
  };
  int m = 6;
  while (m <= 10 && !usable(m)) ++m;
  if (m > 10) return;
  const int offset_bits = input_bits - m + 1;
  const std::int32_t buckets = (input_bits + 2) << m;
  // The buckets every row has: index, lower end and width of each that some c in [0, top_c] addresses.
  struct Bucket {
    std::int32_t index;
    std::int64_t lo;
    std::int64_t width;
  };
  std::vector<Bucket> addressed;
  for (std::int32_t b = 0; b < buckets; ++b) {
    Bucket bucket{b, 0, 1};
    if (float_bucket(b, m, bucket.lo, bucket.width) && bucket.lo <= top_c) addressed.push_back(bucket);
  }
  std::vector<std::uint32_t> composed(static_cast<std::size_t>(rows) * static_cast<std::size_t>(buckets), 0);
  for (std::int64_t r = 0; r < rows; ++r) {
    const std::int64_t* c_k = least_c.data() + r * plan.top;
    std::int64_t code = 0;  // C_k at or below the bucket's lower end
    for (const auto& [b, lo, width] : addressed) {
      while (code < plan.top && c_k[code] <= lo) ++code;
      const std::int64_t next = code < plan.top ? std::min(c_k[code] - lo, width) : width;
      composed[static_cast<std::size_t>(r * buckets + b)] =
          (static_cast<std::uint32_t>(code) << offset_bits) | static_cast<std::uint32_t>(next);
    }
  }
  plan.composed = std::move(composed);
  plan.composed_mantissa_bits = m;
  plan.composed_offset_bits = offset_bits;
  plan.composed_buckets = buckets;
  plan.ends32 = std::move(ends);
}

std::optional<DrivePlan> drive_plan(const std::array<const ThresholdIndex*, 3>& channels) {
  DrivePlan d;
  d.mantissa_bits = ThresholdIndex::kMantissaBits;
  bool usable = true;
  std::array<std::int64_t, 3> bucket_start{};
  std::array<std::int64_t, 3> threshold_start{};
  for (int ch = 0; ch < 3; ++ch) {
    const ThresholdIndex& index = *channels[static_cast<std::size_t>(ch)];
    usable = usable && index.steps() > 0 && index.value_bits() == channels[0]->value_bits();
    if (!usable) break;
    bucket_start[static_cast<std::size_t>(ch)] = static_cast<std::int64_t>(d.base.size());
    threshold_start[static_cast<std::size_t>(ch)] = static_cast<std::int64_t>(d.thresholds.size());
    for (std::uint16_t code : index.base()) d.base.push_back(threshold_start[static_cast<std::size_t>(ch)] + code);
    d.thresholds.insert(d.thresholds.end(), index.padded().begin(), index.padded().end());
    d.threshold_count[static_cast<std::size_t>(ch)] =
        static_cast<int>(index.padded().size()) - (ThresholdIndex::kMaxSteps + 1);
    // More steps than a channel needs stop at its code (its thresholds increase, then the padding no x reaches).
    d.steps = std::max(d.steps, index.steps());
  }
  if (usable) {
    d.value_limit = std::int64_t{1} << channels[0]->value_bits();
    for (int i = 0; i < 3 + DrivePlan::kMaxLanes; ++i) {
      d.bucket_offset.push_back(bucket_start[static_cast<std::size_t>(i % 3)]);
      d.threshold_offset.push_back(threshold_start[static_cast<std::size_t>(i % 3)]);
    }
    if (channels[0]->value_bits() <= 30 && d.mantissa_bits <= 17 && d.thresholds.size() < (std::size_t{1} << 30)) {
      const auto narrow = [](std::int64_t v) {
        return static_cast<std::int32_t>(std::clamp<std::int64_t>(v, INT32_MIN, INT32_MAX));
      };
      std::ranges::transform(d.base, std::back_inserter(d.base32), narrow);
      std::ranges::transform(d.thresholds, std::back_inserter(d.thresholds32), narrow);
      std::ranges::transform(d.bucket_offset, std::back_inserter(d.bucket_offset32), narrow);
      std::ranges::transform(d.threshold_offset, std::back_inserter(d.threshold_offset32), narrow);
      packed_drive_search(channels, d);
    }
    return d;
  }
  return std::nullopt;
}

ColumnBlendPlan column_blend_plan(const Geometry& g, std::uint32_t unit) {
  ColumnBlendPlan plan;
  plan.unit = unit;
  const int W = std::countr_zero(unit);
  const std::size_t samples = 3 * static_cast<std::size_t>(g.full.width);
  plan.left.resize(samples);
  plan.right.resize(samples);
  plan.upper.resize(samples);
  for (int x = 0; x < g.full.width; ++x) {
    const BilinearWeights& col = g.bilinear_cols[static_cast<std::size_t>(x)];
    for (int ch = 0; ch < 3; ++ch) {
      const std::size_t s = 3 * static_cast<std::size_t>(x) + static_cast<std::size_t>(ch);
      plan.left[s] = 3 * col.i0 + ch;
      plan.right[s] = 3 * col.i1 + ch;
      plan.upper[s] = static_cast<std::uint32_t>(col.upper);
    }
    if (col.upper != 0) plan.weight_bits = std::max(plan.weight_bits, W - std::countr_zero(static_cast<std::uint32_t>(col.upper)));
  }
  // Blocks of `lanes` output samples, each with a window of `span` row samples from its first tap.
  const auto build = [&](std::size_t lanes, std::size_t span) {
    ColumnBlendPlan::Windows w;
    for (std::size_t start = 0; start + lanes <= samples; start += lanes) {
      const auto first = std::min(*std::min_element(plan.left.begin() + static_cast<std::ptrdiff_t>(start),
                                                    plan.left.begin() + static_cast<std::ptrdiff_t>(start + lanes)),
                                  *std::min_element(plan.right.begin() + static_cast<std::ptrdiff_t>(start),
                                                    plan.right.begin() + static_cast<std::ptrdiff_t>(start + lanes)));
      w.start.push_back(first);
      for (std::size_t s = start; s < start + lanes; ++s) {
        w.left.push_back(plan.left[s] - first);
        w.right.push_back(plan.right[s] - first);
        if (w.left.back() >= static_cast<std::int32_t>(span) || w.right.back() >= static_cast<std::int32_t>(span)) {
          return ColumnBlendPlan::Windows{};
        }
      }
    }
    return w;
  };
  for (std::size_t i = 0; i < plan.windows.size(); ++i) {
    const std::size_t lanes = std::size_t{4} << i;
    plan.windows[i] = build(lanes, lanes);
    plan.double_windows[i] = build(lanes, 2 * lanes);  // also where the single fit, for the tests to take them
  }
  // r = 1/2: each sample's coefficients per row sample against the quarters (ColumnBlendPlan::half).
  const int pixels = g.reduced.width;
  plan.half = std::has_single_bit(unit) && W >= 2 && pixels >= 2 && g.full.width == 2 * pixels;
  for (std::size_t s = 0; s < samples && plan.half; ++s) {
    const int x = static_cast<int>(s / 3);
    const int ch = static_cast<int>(s % 3);
    const int m = x / 2;
    const int outer = x % 2 == 0 ? std::max(m - 1, 0) : std::min(m + 1, pixels - 1);
    // The row samples a sample reads with a coefficient other than 0, and the coefficients, in order.
    const auto coefficients = [](std::int32_t a, std::uint64_t wa, std::int32_t b, std::uint64_t wb) {
      std::array<std::pair<std::int32_t, std::uint64_t>, 2> c{std::pair{a, wa}, std::pair{b, wb}};
      if (c[0].first == c[1].first) c = {std::pair{a, wa + wb}, std::pair{-1, std::uint64_t{0}}};
      for (auto& [index, weight] : c) {
        if (weight == 0) index = -1;
      }
      if (c[0].first > c[1].first) std::swap(c[0], c[1]);
      return c;
    };
    plan.half = coefficients(plan.left[s], unit - plan.upper[s], plan.right[s], plan.upper[s]) ==
                coefficients(3 * outer + ch, unit / 4, 3 * m + ch, 3 * (unit / 4));
  }
  return plan;
}

GaussianColumnsPlan gaussian_columns_plan(const Geometry& g) {
  GaussianColumnsPlan plan;
  plan.samples = 3 * static_cast<std::size_t>(g.reduced.width);
  for (const PolyphaseTaps& taps : g.gauss_cols) plan.taps = std::max(plan.taps, taps.weight.size());
  plan.index.assign(plan.taps * plan.samples, 0);
  plan.weight.assign(plan.taps * plan.samples, 0);
  for (std::size_t k = 0; k < g.gauss_cols.size(); ++k) {
    const PolyphaseTaps& taps = g.gauss_cols[k];
    for (std::size_t t = 0; t < taps.weight.size(); ++t) {
      for (std::size_t ch = 0; ch < 3; ++ch) {
        const std::size_t at = t * plan.samples + 3 * k + ch;
        plan.index[at] = 3 * taps.index[t] + static_cast<int>(ch);
        plan.weight[at] = static_cast<std::uint32_t>(taps.weight[t]);
      }
    }
  }
  // The polyphase form, where column k's support starts at f k + c (the taps are clamped, so the planes are too).
  const auto full_width = static_cast<std::size_t>(g.full.width);
  const std::size_t columns = g.gauss_cols.size();
  if (columns == 0 || full_width % columns != 0) return plan;
  const std::size_t f = full_width / columns;
  // Column k's unclamped start, from a column whose support is inside the row (the middle one, for any sane sigma).
  const std::size_t middle = columns / 2;
  const std::int64_t start = static_cast<std::int64_t>(g.gauss_cols[middle].index.front()) -
                             static_cast<std::int64_t>(f * middle);
  const auto clamped = [&](std::int64_t column) {
    return static_cast<int>(std::clamp<std::int64_t>(column, 0, static_cast<std::int64_t>(full_width) - 1));
  };
  for (std::size_t k = 0; k < columns; ++k) {
    const PolyphaseTaps& taps = g.gauss_cols[k];
    for (std::size_t t = 0; t < taps.index.size(); ++t) {
      if (taps.index[t] != clamped(start + static_cast<std::int64_t>(f * k + t))) return plan;
    }
  }
  plan.decimation = f;
  plan.first_column = start;
  plan.full_width = full_width;
  plan.columns = columns;
  plan.plane_length = columns + (plan.taps - 1) / f;
  plan.planar_weight.assign(plan.taps * columns, 0);
  for (std::size_t t = 0; t < plan.taps; ++t) plan.tap_offset.push_back((t % f) * plan.plane_length + t / f);
  for (std::size_t k = 0; k < columns; ++k) {
    const PolyphaseTaps& taps = g.gauss_cols[k];
    for (std::size_t t = 0; t < taps.weight.size(); ++t) {
      plan.planar_weight[t * columns + k] = static_cast<std::uint32_t>(taps.weight[t]);
    }
  }
  plan.symmetric = true;
  for (std::size_t t = 0; t < plan.taps / 2; ++t) {
    const std::size_t mirror = plan.taps - 1 - t;
    plan.symmetric = plan.symmetric && std::equal(plan.planar_weight.begin() + static_cast<std::ptrdiff_t>(t * columns),
                                                  plan.planar_weight.begin() + static_cast<std::ptrdiff_t>((t + 1) * columns),
                                                  plan.planar_weight.begin() + static_cast<std::ptrdiff_t>(mirror * columns));
  }
  return plan;
}

}  // namespace trm::fixed_detail

namespace trm::fixed_detail::lines {

HWY_EXPORT(BlendColumns);
HWY_EXPORT(BlendRowsEotf);
HWY_EXPORT(DriveCodes);
HWY_EXPORT(Compensate);
HWY_EXPORT(GaussianColumns);
HWY_EXPORT(GaussianRows);
HWY_EXPORT(GaussianColumns32);
HWY_EXPORT(GaussianRows32);
HWY_EXPORT(LcdDrive);
HWY_EXPORT(LcdSearch);
HWY_EXPORT(LcdTargets);
HWY_EXPORT(LcdDriveValues);
HWY_EXPORT(MotionWeights);
HWY_EXPORT(AddWeightedResiduals);
HWY_EXPORT(StoreResiduals);
HWY_EXPORT(TargetName);
HWY_EXPORT(BlendRowsEotf32);
HWY_EXPORT(BlendRowsDriveExact);
HWY_EXPORT(DriveCodes32);
HWY_EXPORT(DriveValues);
HWY_EXPORT(DriveValues32);
HWY_EXPORT(Compensate32);
HWY_EXPORT(AddWeightedResidualsInto32);
HWY_EXPORT(StoreResiduals32);
HWY_EXPORT(LcdDrive32);

// Each step on 64-bit lines, then (where the decoder has one) its overload on 32-bit lines.
void blend_columns(const std::uint16_t* row, const ColumnBlendPlan& plan, std::size_t n, std::uint32_t* out) {
  HWY_DYNAMIC_DISPATCH(BlendColumns)(row, plan, n, out);
}
void blend_rows_eotf(const std::uint32_t* top, const std::uint32_t* bottom, std::size_t n, std::uint32_t upper,
                     int column_weight_bits, const EotfPlan& plan, std::int64_t* out) {
  HWY_DYNAMIC_DISPATCH(BlendRowsEotf)(top, bottom, n, upper, column_weight_bits, plan, out);
}
void blend_rows_eotf(const std::uint32_t* top, const std::uint32_t* bottom, std::size_t n, std::uint32_t upper,
                     int column_weight_bits, const EotfPlan& plan, std::int32_t* out) {
  HWY_DYNAMIC_DISPATCH(BlendRowsEotf32)(top, bottom, n, upper, column_weight_bits, plan, out);
}
bool blend_rows_drive(const std::uint32_t* top, const std::uint32_t* bottom, std::size_t n, std::uint32_t upper,
                      int column_weight_bits, const EotfPlan& plan, const std::vector<std::uint16_t>& drive_of_node,
                      std::uint16_t* codes) {
  const int row_bits = plan.exact_row_bits(upper, column_weight_bits);
  if (row_bits < 0 || drive_of_node.size() != 3 * plan.node32.size()) return false;
  HWY_DYNAMIC_DISPATCH(BlendRowsDriveExact)(top, bottom, n, upper, column_weight_bits, row_bits, plan,
                                            drive_of_node.data(), codes);
  return true;
}
void drive_codes(const std::int64_t* linear, std::size_t n, const DrivePlan& plan, std::uint16_t* out) {
  HWY_DYNAMIC_DISPATCH(DriveCodes)(linear, n, plan, out);
}
void drive_codes(const std::int32_t* linear, std::size_t n, const DrivePlan& plan, std::uint16_t* out) {
  HWY_DYNAMIC_DISPATCH(DriveCodes32)(linear, n, plan, out);
}
void drive_values(const std::int64_t* linear, std::size_t n, const DriveValuePlan& plan, const FixedKernels& kernels,
                  std::int64_t* out) {
  HWY_DYNAMIC_DISPATCH(DriveValues)(linear, n, plan, kernels, out);
}
void drive_values(const std::int32_t* linear, std::size_t n, const DriveValuePlan& plan, const FixedKernels& kernels,
                  std::int64_t* out) {
  HWY_DYNAMIC_DISPATCH(DriveValues32)(linear, n, plan, kernels, out);
}
std::uint64_t compensate(const std::uint16_t* codes, const std::int64_t* low, std::size_t n,
                         const FixedLinePlans& plans, std::int64_t* shown, std::int64_t* rho) {
  return HWY_DYNAMIC_DISPATCH(Compensate)(codes, low, n, plans, shown, rho);
}
std::uint64_t compensate(const std::uint16_t* codes, const std::int32_t* low, std::size_t n,
                         const FixedLinePlans& plans, std::int32_t* shown, std::int32_t* rho) {
  return HWY_DYNAMIC_DISPATCH(Compensate32)(codes, low, n, plans, shown, rho);
}
void gaussian_columns(const std::uint16_t* row, std::size_t row_samples, const GaussianColumnsPlan& plan, int shift,
                      std::int64_t* out) {
  HWY_DYNAMIC_DISPATCH(GaussianColumns)(row, row_samples, plan, shift, out);
}
void gaussian_rows(const std::int64_t* const* rows, const std::uint32_t* weight, std::size_t count, std::size_t n,
                   int shift, bool fold, std::uint16_t* out) {
  HWY_DYNAMIC_DISPATCH(GaussianRows)(rows, weight, count, n, shift, fold, out);
}
void gaussian_columns(const std::uint16_t* row, std::size_t row_samples, const GaussianColumnsPlan& plan, int shift,
                      std::uint32_t* out) {
  HWY_DYNAMIC_DISPATCH(GaussianColumns32)(row, row_samples, plan, shift, out);
}
void gaussian_rows(const std::uint32_t* const* rows, const std::uint32_t* weight, std::size_t count, std::size_t n,
                   int shift, bool fold, std::uint16_t* out) {
  HWY_DYNAMIC_DISPATCH(GaussianRows32)(rows, weight, count, n, shift, fold, out);
}
void lcd_search(const std::int64_t* target, const std::int64_t* rows, std::size_t n, const LcdPlan& plan,
                std::uint16_t* codes) {
  HWY_DYNAMIC_DISPATCH(LcdSearch)(target, rows, n, plan, codes);
}
void lcd_targets(const std::int64_t* sum, std::size_t n, const LcdPlan& plan, const FixedKernels& kernels,
                 std::int64_t* target) {
  HWY_DYNAMIC_DISPATCH(LcdTargets)(sum, n, plan, kernels, target);
}
void lcd_drive_values(const std::int64_t* sum, const std::int64_t* target, const std::uint16_t* rows,
                      const std::uint16_t* codes, std::size_t n, const LcdPlan& plan, const FixedKernels& kernels,
                      std::int64_t* drive) {
  HWY_DYNAMIC_DISPATCH(LcdDriveValues)(sum, target, rows, codes, n, plan, kernels, drive);
}
std::uint64_t lcd_drive(const std::int64_t* wanted, std::size_t n, const LcdPlan& plan, const FixedKernels& kernels,
                        std::uint8_t* previous_code, std::int32_t* previous_linear, bool held, std::uint16_t* codes,
                        std::int64_t* shortfall) {
  return HWY_DYNAMIC_DISPATCH(LcdDrive)(wanted, n, plan, kernels, previous_code, previous_linear, held, codes,
                                        shortfall);
}
std::uint64_t lcd_drive(const std::int32_t* wanted, std::size_t n, const LcdPlan& plan, const FixedKernels& kernels,
                        std::uint8_t* previous_code, std::int32_t* previous_linear, bool held, std::uint16_t* codes,
                        std::int64_t* shortfall) {
  return HWY_DYNAMIC_DISPATCH(LcdDrive32)(wanted, n, plan, kernels, previous_code, previous_linear, held, codes,
                                          shortfall);
}
void motion_weights(const std::int64_t* previous, const std::int64_t* alpha, std::size_t pixels, const MotionPlan& plan,
                    const FixedKernels& kernels, std::int64_t* weight, MotionTally& tally) {
  HWY_DYNAMIC_DISPATCH(MotionWeights)(previous, alpha, pixels, plan, kernels, weight, tally);
}
void add_weighted_residuals(const std::int64_t* alpha, const std::int64_t* weight, const std::int32_t* residual,
                            std::size_t n, const MotionPlan& plan, const FixedKernels& kernels, std::int64_t* shown,
                            MotionTally& tally) {
  HWY_DYNAMIC_DISPATCH(AddWeightedResiduals)(alpha, weight, residual, n, plan, kernels, shown, tally);
}
void add_weighted_residuals(const std::int64_t* alpha, const std::int64_t* weight, const std::int32_t* residual,
                            std::size_t n, const MotionPlan& plan, const FixedKernels& kernels, std::int32_t* shown,
                            MotionTally& tally) {
  HWY_DYNAMIC_DISPATCH(AddWeightedResidualsInto32)(alpha, weight, residual, n, plan, kernels, shown, tally);
}
bool store_residuals(const std::int64_t* rho, std::size_t n, const FixedKernels& kernels, std::int32_t* stored,
                     ResidualTally& tally) {
  return HWY_DYNAMIC_DISPATCH(StoreResiduals)(rho, n, kernels, stored, tally);
}
bool store_residuals(const std::int32_t* rho, std::size_t n, const FixedKernels& kernels, std::int32_t* stored,
                     ResidualTally& tally) {
  return HWY_DYNAMIC_DISPATCH(StoreResiduals32)(rho, n, kernels, stored, tally);
}
const char* target_name() { return HWY_DYNAMIC_DISPATCH(TargetName)(); }

}  // namespace trm::fixed_detail::lines
#endif
