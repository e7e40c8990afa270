#include "sweep_shard.hpp"

#include "sweep_report.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <optional>
#include <stdexcept>
#include <system_error>

namespace fs = std::filesystem;

namespace trm::cli {

namespace {

std::string shard_text(const SweepShard& shard) {
  return std::to_string(shard.index) + "/" + std::to_string(shard.count);
}

std::string part_name(const SweepPart& part) {
  return "'" + part.dir.string() + "' (shard " + shard_text(part.result.options.shard) + ")";
}

nlohmann::json unordered(const Json& ordered) { return nlohmann::json::parse(ordered.dump()); }

nlohmann::json options_json(const std::vector<GivenOption>& options) {
  nlohmann::json list = nlohmann::json::array();
  for (const GivenOption& o : options) list.push_back({{"name", o.name}, {"values", o.values}});
  return list;
}

// The path with symbolic links and dot components resolved, so that two spellings of one directory compare equal.
fs::path resolved_path(const fs::path& path) {
  std::error_code ec;
  const fs::path resolved = fs::weakly_canonical(path, ec);
  return ec ? fs::absolute(path).lexically_normal() : resolved;
}

// Every field of a point but the perceived PSNR, by name, for to_json / from_json.
template <class Point, class Visit>
void for_each_field(Point& p, Visit&& visit) {
  visit("value", p.value);
  visit("is_default", p.is_default);
  visit("status", p.status);
  visit("message", p.message);
  visit("codes", p.codes);
  visit("differing", p.differing);
  visit("identical_percent", p.identical_percent);
  visit("max_lsb", p.max_lsb);
  visit("mean_lsb", p.mean_lsb);
  visit("rms_lsb", p.rms_lsb);
  visit("linear_max", p.linear_max);
  visit("linear_rms", p.linear_rms);
  visit("drive_max_lsb", p.drive_max_lsb);
  visit("visual_difference", p.visual_difference);
  visit("eye_seconds_per_frame", p.eye_seconds_per_frame);
  visit("residual_saturated", p.residual_saturated);
  visit("residual_rounded", p.residual_rounded);
  visit("seconds_per_frame", p.seconds_per_frame);
  visit("min_seconds_per_frame", p.min_seconds_per_frame);
  visit("repeat_seconds_per_frame", p.repeat_seconds_per_frame);
  visit("setup_seconds", p.setup_seconds);
  visit("on_chip_bits", p.on_chip_bits);
  visit("off_chip_bits", p.off_chip_bits);
  visit("delta_on_chip_bits", p.delta_on_chip_bits);
  visit("delta_off_chip_bits", p.delta_off_chip_bits);
  visit("residual_format", p.residual_format);
}

nlohmann::json optional_point(const std::optional<SweepPoint>& p) {
  return p ? nlohmann::json(*p) : nlohmann::json(nullptr);
}

}  // namespace

void to_json(nlohmann::json& j, const SweepPoint& p) {
  j = nlohmann::json::object();
  for_each_field(p, [&j](const char* name, const auto& field) { j[name] = field; });
  j["perceived_psnr_db"] = std::isinf(p.perceived_psnr_db) ? nlohmann::json(nullptr) : nlohmann::json(p.perceived_psnr_db);
}

void from_json(const nlohmann::json& j, SweepPoint& p) {
  for_each_field(p, [&j](const char* name, auto& field) { j.at(name).get_to(field); });
  const nlohmann::json& psnr = j.at("perceived_psnr_db");
  p.perceived_psnr_db = psnr.is_null() ? std::numeric_limits<double>::infinity() : psnr.get<double>();
}

SweepShard parse_sweep_shard(const std::string& text) {
  const auto malformed = [&text] {
    return std::invalid_argument("expected K/N, whole numbers with 1 <= K <= N (shard K of N, e.g. 2/8), got '" +
                                 text + "'");
  };
  const std::size_t slash = text.find('/');
  if (slash == std::string::npos) throw malformed();
  SweepShard shard;
  const auto whole = [&](std::size_t begin, std::size_t end, int& value) {
    const char* first = text.data() + begin;
    const char* last = text.data() + end;
    const auto [stop, error] = std::from_chars(first, last, value);
    if (first == last || error != std::errc() || stop != last) throw malformed();
  };
  whole(0, slash, shard.index);
  whole(slash + 1, text.size(), shard.count);
  if (shard.count < 1) throw std::invalid_argument("N must be at least 1, got '" + text + "'");
  if (shard.index < 1 || shard.index > shard.count) {
    throw std::invalid_argument("K must be between 1 and N = " + std::to_string(shard.count) + ", got '" + text + "'");
  }
  return shard;
}

std::string sweep_command_text(const std::vector<GivenOption>& options) {
  std::string line = "trm sweep";
  for (const GivenOption& o : options) {
    if (o.values.empty()) line.append(" ").append(o.name);
    for (const std::string& value : o.values) {
      const bool quote = value.find_first_of(" *?'\"") != std::string::npos;
      line.append(" ").append(o.name).append(" ");
      line.append(quote ? "'" : "").append(value).append(quote ? "'" : "");
    }
  }
  return line;
}

std::string sweep_part_text(const SweepResult& r, const std::vector<GivenOption>& options, const std::string& version) {
  nlohmann::json j;
  j["tool"] = "trm sweep";
  j["format"] = kSweepPartFormat;
  j["version"] = version;
  j["shard"] = {{"index", r.options.shard.index}, {"count", r.options.shard.count}};
  j["options"] = options_json(options);
  j["parameters"] = unordered(sweep_parameters_json(r));
  j["recording_hash"] = r.recording_hash;
  j["linear_recording_hash"] = r.linear_recording_hash;
  j["size"] = {r.size.width, r.size.height};
  j["reduced"] = {r.reduced.width, r.reduced.height};
  j["views"] = r.views;
  j["reference_seconds_per_frame"] = r.reference_seconds_per_frame;
  j["wall_seconds"] = r.wall_seconds;
  j["base"] = r.options.shard.owns(0) ? nlohmann::json(r.base) : nlohmann::json(nullptr);
  j["linear_base"] = optional_point(r.linear_base);
  j["eye"] = {{"pixels_per_degree", r.pixels_per_degree},
              {"target_velocity_deg_s", r.target_velocity_deg_s},
              {"eye_velocity_deg_s", r.eye_velocity_deg_s},
              {"scan_line", r.scan_line}};
  nlohmann::json knobs = nlohmann::json::array();
  for (const SweepKnobResult& k : r.knobs) {
    knobs.push_back(
        {{"name", k.knob->name}, {"default_value", k.default_value}, {"resample_space", trm::to_string(k.resample_space)},
         {"skipped", k.skipped}, {"points", k.points}});
  }
  j["knobs"] = std::move(knobs);
  return j.dump(1) + "\n";
}

SweepPart read_sweep_part(const fs::path& dir) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) {
    throw std::runtime_error("--merge: '" + dir.string() + "' is not a directory (give the directories that `trm sweep "
                             "--shard K/N` wrote)");
  }
  const fs::path file = dir / kSweepPartFile;
  std::ifstream in(file, std::ios::binary);
  if (!fs::is_regular_file(file, ec) || !in) {
    throw std::runtime_error("--merge: '" + dir.string() + "' holds no " + kSweepPartFile +
                             ", so it is not a part of a sharded sweep (a `trm sweep --shard K/N` output is)");
  }
  const nlohmann::json j = nlohmann::json::parse(in, nullptr, false);
  const auto malformed = [&](const std::string& why) {
    return std::runtime_error("--merge: '" + file.string() + "' is not a trm sweep part: " + why);
  };
  if (j.is_discarded()) throw malformed("not valid JSON (cut short?)");
  if (!j.is_object() || j.value("format", "") != kSweepPartFormat) {
    throw malformed(std::string("its format is not ") + kSweepPartFormat);
  }
  SweepPart part;
  part.dir = dir;
  try {
    part.version = j.at("version").get<std::string>();
    SweepShard& shard = part.result.options.shard;
    shard.index = j.at("shard").at("index").get<int>();
    shard.count = j.at("shard").at("count").get<int>();
    if (shard.count < 1 || shard.index < 1 || shard.index > shard.count) throw malformed("its shard is not K/N");
    for (const auto& o : j.at("options")) {
      part.options.push_back({o.at("name").get<std::string>(), o.at("values").get<std::vector<std::string>>()});
    }
    part.parameters = j.at("parameters");
    SweepResult& r = part.result;
    r.recording_hash = j.at("recording_hash").get<std::uint64_t>();
    r.linear_recording_hash = j.at("linear_recording_hash").get<std::uint64_t>();
    r.size = cv::Size(j.at("size").at(0).get<int>(), j.at("size").at(1).get<int>());
    r.reduced = cv::Size(j.at("reduced").at(0).get<int>(), j.at("reduced").at(1).get<int>());
    r.views = j.at("views").get<std::int64_t>();
    r.reference_seconds_per_frame = j.at("reference_seconds_per_frame").get<double>();
    r.wall_seconds = j.at("wall_seconds").get<double>();
    part.has_base = !j.at("base").is_null();
    if (part.has_base) r.base = j.at("base").get<SweepPoint>();
    part.has_linear_base = !j.at("linear_base").is_null();
    if (part.has_linear_base) r.linear_base = j.at("linear_base").get<SweepPoint>();
    const nlohmann::json& eye = j.at("eye");
    r.pixels_per_degree = eye.at("pixels_per_degree").get<double>();
    r.target_velocity_deg_s = eye.at("target_velocity_deg_s").get<double>();
    r.eye_velocity_deg_s = eye.at("eye_velocity_deg_s").get<double>();
    r.scan_line = eye.at("scan_line").get<int>();
    for (const auto& k : j.at("knobs")) {
      SweepKnobResult kr;
      const std::string name = k.at("name").get<std::string>();
      kr.knob = find_sweep_knob(name);
      if (!kr.knob) throw malformed("it sweeps knob '" + name + "', which this trm does not know");
      kr.default_value = k.at("default_value").get<int>();
      try {
        kr.resample_space = parse_resample_space(k.at("resample_space").get<std::string>());
      } catch (const std::invalid_argument& e) {
        throw malformed(e.what());
      }
      kr.skipped = k.at("skipped").get<std::string>();
      kr.points = k.at("points").get<std::vector<SweepPoint>>();
      r.knobs.push_back(std::move(kr));
    }
  } catch (const nlohmann::json::exception& e) {
    throw malformed(e.what());
  }
  return part;
}

void check_sweep_parts(const std::vector<SweepPart>& parts, const fs::path& out) {
  if (parts.empty()) throw std::runtime_error("--merge needs the part directories of a sharded sweep");
  const SweepPart& first = parts.front();
  std::map<fs::path, const SweepPart*> by_path;
  std::map<int, const SweepPart*> by_index;
  for (const SweepPart& part : parts) {
    if (!by_path.emplace(resolved_path(part.dir), &part).second) {
      throw std::runtime_error("--merge: '" + part.dir.string() + "' is given more than once");
    }
    if (resolved_path(part.dir) == resolved_path(out)) {
      throw std::runtime_error("--merge: the output directory '" + out.string() +
                               "' is one of the parts; give the merged sweep a directory of its own");
    }
    if (part.version != first.version) {
      throw std::runtime_error("--merge: parts " + part_name(first) + " and " + part_name(part) +
                               " were written by different trm versions (" + first.version + " and " + part.version +
                               "); run every shard with one trm");
    }
    if (part.options != first.options) {
      throw std::runtime_error("--merge: parts " + part_name(first) + " and " + part_name(part) +
                               " are of different sweeps: `" + sweep_command_text(first.options) + "` and `" +
                               sweep_command_text(part.options) + "`");
    }
    const SweepShard& shard = part.result.options.shard;
    if (shard.count != first.result.options.shard.count) {
      throw std::runtime_error("--merge: parts " + part_name(first) + " and " + part_name(part) +
                               " split the sweep into different numbers of shards, so their points overlap; merge the "
                               "N parts of one --shard K/N series");
    }
    const auto [it, fresh] = by_index.emplace(shard.index, &part);
    if (!fresh) {
      throw std::runtime_error("--merge: parts '" + it->second->dir.string() + "' and '" + part.dir.string() +
                               "' are both shard " + shard_text(shard) + "; give each shard once");
    }
  }
  const int count = first.result.options.shard.count;
  std::string missing;
  for (int k = 1; k <= count; ++k) {
    if (by_index.count(k) == 0) missing.append(missing.empty() ? "" : ", ").append(shard_text({k, count}));
  }
  if (!missing.empty()) {
    throw std::runtime_error("--merge: shard(s) " + missing + " missing; a merge needs the parts of all " +
                             std::to_string(count) + " shards");
  }
}

SweepResult merge_sweep_parts(const std::vector<SweepPart>& parts, const SweepOptions& options) {
  const std::vector<SweepPlanKnob> plan = plan_sweep(options);
  const bool has_linear_base = sweep_has_linear_base(plan);
  SweepResult merged;
  merged.options = options;
  const SweepPart* base_part = nullptr;
  const SweepPart* linear_part = nullptr;  // the part that recorded the linear base's sequence first
  for (const SweepPart& part : parts) {
    SweepResult as_merged = part.result;
    as_merged.options = options;
    const nlohmann::json parameters = unordered(sweep_parameters_json(as_merged));
    if (parameters != part.parameters) {
      const nlohmann::json patch = nlohmann::json::diff(part.parameters, parameters);
      throw std::runtime_error("--merge: part " + part_name(part) +
                               " was decoded with other parameters than its options give here (" +
                               patch.front().value("path", std::string("?")) +
                               " differs; did a file the options name change?)");
    }
    if (part.result.recording_hash != parts.front().result.recording_hash) {
      throw std::runtime_error("--merge: parts " + part_name(parts.front()) + " and " + part_name(part) +
                               " decoded different sequences (the encoded frames or the reference's drive codes "
                               "differ: an input file changed, or the machines' floating point differs)");
    }
    if (part.result.linear_recording_hash != 0) {
      if (!linear_part) linear_part = &part;
      if (part.result.linear_recording_hash != linear_part->result.linear_recording_hash) {
        throw std::runtime_error("--merge: parts " + part_name(*linear_part) + " and " + part_name(part) +
                                 " decoded different sequences in linear resample space (the encoded frames or the "
                                 "reference's drive codes differ: an input file changed, or the machines' floating "
                                 "point differs)");
      }
    }
    bool same_plan = part.result.knobs.size() == plan.size();
    for (std::size_t i = 0; same_plan && i < plan.size(); ++i) {
      const SweepKnobResult& k = part.result.knobs[i];
      same_plan = k.knob == plan[i].knob && k.default_value == plan[i].default_value && k.skipped == plan[i].skipped &&
                  k.resample_space == plan[i].resample_space;
    }
    if (!same_plan) {
      throw std::runtime_error("--merge: part " + part_name(part) +
                               " sweeps other knobs or base values than its options give here");
    }
    if (part.has_base != part.result.options.shard.owns(0)) {
      throw std::runtime_error("--merge: part " + part_name(part) + (part.has_base ? " holds" : " lacks") +
                               " the base point, which shard 1 alone evaluates");
    }
    const bool owns_linear_base = has_linear_base && part.result.options.shard.owns(1);
    if (part.has_linear_base != owns_linear_base) {
      throw std::runtime_error("--merge: part " + part_name(part) + (part.has_linear_base ? " holds" : " lacks") +
                               " the linear base point, which shard " + (part.result.options.shard.count > 1 ? "2" : "1") +
                               " alone evaluates");
    }
    if (part.has_base) base_part = &part;
    merged.wall_seconds += part.result.wall_seconds;
  }
  // Timings are each shard's own; the base point's shard gives the reference's.
  merged.size = base_part->result.size;
  merged.reduced = base_part->result.reduced;
  merged.views = base_part->result.views;
  merged.reference_seconds_per_frame = base_part->result.reference_seconds_per_frame;
  merged.recording_hash = base_part->result.recording_hash;
  merged.base = base_part->result.base;
  merged.pixels_per_degree = base_part->result.pixels_per_degree;
  merged.target_velocity_deg_s = base_part->result.target_velocity_deg_s;
  merged.eye_velocity_deg_s = base_part->result.eye_velocity_deg_s;
  merged.scan_line = base_part->result.scan_line;
  if (linear_part) merged.linear_recording_hash = linear_part->result.linear_recording_hash;

  // Every point once, from the part of the shard that owns its number.
  const int count = parts.front().result.options.shard.count;
  std::vector<const SweepPart*> part_of(static_cast<std::size_t>(count) + 1);
  for (const SweepPart& part : parts) part_of[static_cast<std::size_t>(part.result.options.shard.index)] = &part;
  std::map<const SweepPart*, std::size_t> used;
  if (has_linear_base) merged.linear_base = part_of[static_cast<std::size_t>(1 % count) + 1]->result.linear_base;
  std::int64_t number = has_linear_base ? 1 : 0;  // the last base point's
  for (std::size_t i = 0; i < plan.size(); ++i) {
    SweepKnobResult kr;
    kr.knob = plan[i].knob;
    kr.default_value = plan[i].default_value;
    kr.resample_space = plan[i].resample_space;
    kr.skipped = plan[i].skipped;
    for (int value : plan[i].values) {
      if (!sweep_is_point(plan[i], value)) continue;
      const SweepPart* owner = part_of[static_cast<std::size_t>(++number % count) + 1];
      const std::vector<SweepPoint>& points = owner->result.knobs[i].points;
      const auto it = std::find_if(points.begin(), points.end(), [value](const SweepPoint& p) { return p.value == value; });
      if (it == points.end()) {
        throw std::runtime_error("--merge: part " + part_name(*owner) + " lacks its point " + kr.knob->name + " = " +
                                 std::to_string(value));
      }
      kr.points.push_back(*it);
      ++used[owner];
    }
    merged.knobs.push_back(std::move(kr));
  }
  for (const SweepPart& part : parts) {
    std::size_t held = 0;
    for (const SweepKnobResult& k : part.result.knobs) held += k.points.size();
    if (held != used[&part]) {
      throw std::runtime_error("--merge: part " + part_name(part) + " holds " + std::to_string(held) +
                               " points, but shard " + shard_text(part.result.options.shard) + " of this sweep has " +
                               std::to_string(used[&part]) + "; its points overlap another shard's");
    }
  }
  finish_sweep(merged);
  return merged;
}

}  // namespace trm::cli
