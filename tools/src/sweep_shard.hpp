// Sweeps that outgrow one machine: `trm sweep --shard K/N` evaluates one part of the points (SweepShard) and writes
// it as a part directory holding sweep-part.json; `trm sweep --merge DIR...` checks that the parts belong together
// and turns them back into the SweepResult a single run makes, which the same writers then write.
//
// A part carries the sweep's options as given (without --shard and --out), so the merge re-parses them with the
// sweep's own option definitions; its parameters block and a hash of the recorded sequence, so parts whose options
// read the same but whose inputs or arithmetic differ are refused; and every field of its points.
#pragma once

#include "sweep.hpp"

#include <filesystem>
#include <string>
#include <vector>

namespace trm::cli {

inline constexpr const char* kSweepPartFile = "sweep-part.json";
inline constexpr const char* kSweepPartFormat = "trm-sweep-part-1";

// "K/N" with whole numbers 1 <= K <= N; throws std::invalid_argument with the rule.
SweepShard parse_sweep_shard(const std::string& text);

// One option as given on the command line, in canonical form: its long name and its values (none for a flag).
struct GivenOption {
  std::string name;
  std::vector<std::string> values;
  bool operator==(const GivenOption&) const = default;
};

// "trm sweep" and the options, each value as its own word, quoted where a shell needs it.
std::string sweep_command_text(const std::vector<GivenOption>& options);

struct SweepPart {
  std::filesystem::path dir;
  bool has_base = false;             // the shard that owns the base point (point 0)
  bool has_linear_base = false;      // the shard that owns the linear base (point 1, when the sweep has one)
  std::string version;               // of the trm that wrote it
  std::vector<GivenOption> options;  // the sweep's, without --shard and --out
  SweepResult result;                // unfinished (see run_sweep): this shard's points only
  nlohmann::json parameters;         // sweep_parameters_json() of the shard
};

// sweep-part.json of a shard's unfinished result.
std::string sweep_part_text(const SweepResult& result, const std::vector<GivenOption>& options,
                            const std::string& version);
// Reads DIR/sweep-part.json; throws std::runtime_error naming the directory when it is missing or malformed.
SweepPart read_sweep_part(const std::filesystem::path& dir);

// Checks what can be checked before the options are parsed again: one trm version, the same options, one shard count,
// every shard 1..N exactly once, and that the merge's output directory `out` is none of them. Throws
// std::runtime_error naming the parts.
void check_sweep_parts(const std::vector<SweepPart>& parts, const std::filesystem::path& out);

// Joins checked parts into a finished result. `options` are the parts' options parsed again (with the merged
// output's command); throws std::runtime_error when a part's parameters, sequence or points are not those options'.
SweepResult merge_sweep_parts(const std::vector<SweepPart>& parts, const SweepOptions& options);

}  // namespace trm::cli
