// `trm sweep --shard K/N` and `--merge DIR...`: the partition rule, parts that merge into what a single run writes
// (every field carried through the part file), and every bad input refused with its own message and no output.
#include "csv_reader.hpp"
#include "sweep.hpp"
#include "sweep_report.hpp"
#include "sweep_shard.hpp"
#include "trm_process.hpp"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <cstdint>
#include <filesystem>
#include <functional>
#include <iterator>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;
using trm::test::read_csv;
using trm::test::run_trm;
using trm::test::ScratchDir;

// The sweep the tests shard: two knobs at a tiny size, 23 rows of 22 points (the base point is both knobs' base
// value), a rejected value among them (linear_frac_bits 16).
const std::string kSweep = "sweep --quick --size 16x12 --hw-size 16x12 --knob linear_frac_bits --knob residual_bits";
const std::set<std::string> kTimingColumns = {"seconds_per_frame", "min_seconds_per_frame",
                                              "reference_seconds_per_frame", "setup_seconds",
                                              "eye_seconds_per_frame"};

std::string text_of(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// report.json without what is run-specific: each point's "time", the reference's time, the wall time and the
// points on the Pareto fronts against time.
nlohmann::json without_timings(nlohmann::json j) {
  if (j.is_object()) {
    for (const char* key : {"time", "reference_seconds_per_frame", "wall_seconds"}) j.erase(key);
    if (j.contains("chart") && j["chart"].get<std::string>().find("time") != std::string::npos) j.erase("front");
    for (auto& [key, value] : j.items()) value = without_timings(value);
  } else if (j.is_array()) {
    for (auto& value : j) value = without_timings(value);
  }
  return j;
}

std::vector<std::map<std::string, std::string>> rows_without_timings(const fs::path& csv) {
  std::vector<std::string> header;
  auto rows = read_csv(csv, &header);
  for (auto& row : rows) {
    for (const std::string& column : kTimingColumns) row.erase(column);
  }
  return rows;
}

// sweep.md without its table rows and the lines that give times.
std::vector<std::string> md_without_tables(const fs::path& md) {
  std::istringstream in(text_of(md));
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("|", 0) != 0 && line.find("ms per view") == std::string::npos) lines.push_back(line);
  }
  return lines;
}

std::vector<std::string> manifest_of(const fs::path& dir) {
  return nlohmann::json::parse(text_of(dir / ".trm-output.json"))["files"].get<std::vector<std::string>>();
}

// One single run and the three parts of the same sweep, made once for every test here.
class SweepShards : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    scratch_ = new ScratchDir("trm-sweep-shard-");
    // The single run writes into work/sweep and is moved aside, so that a merge into work/sweep names the same command.
    const auto single = run_trm(kSweep + " -o " + scratch_->str("work/sweep"));
    ASSERT_EQ(single.exit_code, 0) << single.output;
    fs::rename(scratch_->path() / "work/sweep", scratch_->path() / "single");
    for (int k = 1; k <= 3; ++k) {
      const auto part = run_trm(kSweep + " --shard " + std::to_string(k) + "/3 -o " + part_dir(k).string());
      ASSERT_EQ(part.exit_code, 0) << part.output;
    }
  }
  static void TearDownTestSuite() {
    delete scratch_;
    scratch_ = nullptr;
  }
  static fs::path part_dir(int k) { return scratch_->path() / ("parts/part-" + std::to_string(k)); }
  static std::string parts(const std::vector<int>& ks) {
    std::string list;
    for (int k : ks) list.append(" ").append(part_dir(k).string());
    return list;
  }
  // A copy of part k under another name, to be altered.
  static fs::path copy_of_part(int k, const std::string& name) {
    const fs::path copy = scratch_->path() / name;
    fs::remove_all(copy);
    fs::copy(part_dir(k), copy, fs::copy_options::recursive);
    return copy;
  }
  static void edit_part(const fs::path& dir, const std::function<void(nlohmann::json&)>& edit) {
    nlohmann::json j = nlohmann::json::parse(text_of(dir / trm::cli::kSweepPartFile));
    edit(j);
    std::ofstream(dir / trm::cli::kSweepPartFile) << j.dump(1);
  }
  // A merge that must fail: non-zero exit, the message, no output directory and no staging left behind.
  static void expect_refused(const std::string& merge_args, const std::string& message) {
    const fs::path out = scratch_->path() / "refused";
    const auto r = run_trm("sweep --merge" + merge_args + " -o " + out.string());
    EXPECT_NE(r.exit_code, 0) << r.output;
    EXPECT_NE(r.output.find("trm: error: "), std::string::npos) << r.output;
    EXPECT_NE(r.output.find(message), std::string::npos) << r.output;
    EXPECT_EQ(r.output.find("terminate called"), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(out)) << merge_args;
    for (const auto& entry : fs::directory_iterator(scratch_->path())) {
      EXPECT_EQ(entry.path().filename().string().find(".partial-"), std::string::npos) << entry.path();
    }
  }

  static ScratchDir* scratch_;
};

ScratchDir* SweepShards::scratch_ = nullptr;

}  // namespace

TEST(SweepShard, ParsesKOfNAndRefusesEverythingElse) {
  const trm::cli::SweepShard shard = trm::cli::parse_sweep_shard("2/8");
  EXPECT_EQ(shard.index, 2);
  EXPECT_EQ(shard.count, 8);
  EXPECT_TRUE(trm::cli::parse_sweep_shard("1/1").whole());
  for (const char* bad : {"3", "a/b", "/3", "1/", "1/3x", " 1/3", "+1/3", "1//3", "1/3/5", "99999999999/3", ""}) {
    EXPECT_THROW((void)trm::cli::parse_sweep_shard(bad), std::invalid_argument) << bad;
  }
  for (const char* out_of_range : {"0/3", "4/3", "-1/3", "1/0", "0/0"}) {
    try {
      (void)trm::cli::parse_sweep_shard(out_of_range);
      ADD_FAILURE() << "accepted " << out_of_range;
    } catch (const std::invalid_argument& e) {
      const std::string what = e.what();
      EXPECT_TRUE(what.find("must be") != std::string::npos || what.find("expected K/N") != std::string::npos) << what;
    }
  }
}

TEST(SweepShard, EveryPointBelongsToExactlyOneShard) {
  for (int count = 1; count <= 5; ++count) {
    for (std::int64_t number = 0; number < 23; ++number) {
      int owners = 0;
      for (int index = 1; index <= count; ++index) owners += trm::cli::SweepShard{index, count}.owns(number) ? 1 : 0;
      EXPECT_EQ(owners, 1) << number << " of " << count << " shards";
    }
  }
}

TEST_F(SweepShards, MergeWritesWhatASingleRunWrites) {
  const fs::path merged = scratch_->path() / "work/sweep";
  const auto r = run_trm("sweep --merge" + parts({3, 1, 2}) + " -o " + merged.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const fs::path single = scratch_->path() / "single";

  // The same files; every CSV row and every report field but the timings identical.
  EXPECT_EQ(manifest_of(merged), manifest_of(single));
  const auto rows = rows_without_timings(merged / "sweep.csv");
  EXPECT_EQ(rows, rows_without_timings(single / "sweep.csv"));
  ASSERT_EQ(rows.size(), 9u + 14u);  // every value of both knobs' default ranges
  EXPECT_EQ(rows[0].at("status"), "rejected");
  const auto report = nlohmann::json::parse(text_of(merged / "report.json"));
  EXPECT_EQ(without_timings(report), without_timings(nlohmann::json::parse(text_of(single / "report.json"))));
  EXPECT_NE(report["command"].get<std::string>().find(" --out " + merged.string()), std::string::npos);
  EXPECT_EQ(report["command"].get<std::string>().find("--shard"), std::string::npos);

  // The timings are the parts' own: the reference's from shard 1, which decoded the base point; the wall time summed.
  const auto part = [](int k) { return nlohmann::json::parse(text_of(part_dir(k) / trm::cli::kSweepPartFile)); };
  EXPECT_EQ(report["reference_seconds_per_frame"], part(1)["reference_seconds_per_frame"]);
  EXPECT_EQ(report["base"]["time"]["seconds_per_frame"], part(1)["base"]["seconds_per_frame"]);
  EXPECT_DOUBLE_EQ(report["wall_seconds"].get<double>(),
                   part(1)["wall_seconds"].get<double>() + part(2)["wall_seconds"].get<double>() +
                       part(3)["wall_seconds"].get<double>());
  // sweep.md differs from the single run's in its tables (their millisecond columns, and the Pareto table's fronts
  // against time, whose length varies) only: the lines outside them are the same.
  EXPECT_EQ(md_without_tables(merged / "sweep.md"), md_without_tables(single / "sweep.md"));
  EXPECT_GT(md_without_tables(merged / "sweep.md").size(), 20u);
  fs::remove_all(merged);
}

TEST(SweepShard, PartFilesCarryEveryFieldOfThePoints) {
  // Three shards run here, merged once from their part files and once as they are in memory: byte-identical
  // outputs, timings included, so no field of a point is lost on the way through sweep-part.json.
  ScratchDir tmp("trm-sweep-part-");
  trm::cli::SweepOptions options;
  options.pipeline.scene = "discs";
  options.pipeline.width = 16;
  options.pipeline.height = 12;
  options.pipeline.frames = 2;
  options.repeats = 2;
  options.hw_size = cv::Size(16, 12);
  options.knobs = {"linear_frac_bits"};  // 16 is rejected: a point with a message
  const std::vector<trm::cli::GivenOption> given = {{"--knob", {"linear_frac_bits"}}};
  std::vector<trm::cli::SweepPart> from_files, in_memory;
  for (int k = 1; k <= 3; ++k) {
    trm::cli::SweepOptions shard = options;
    shard.shard = {k, 3};
    trm::cli::SweepPart part;
    part.dir = tmp.path() / std::to_string(k);
    part.version = "test";
    part.options = given;
    part.result = trm::cli::run_sweep(shard);
    part.has_base = k == 1;
    part.parameters = nlohmann::json::parse(trm::cli::sweep_parameters_json(part.result).dump());
    fs::create_directories(part.dir);
    std::ofstream(part.dir / trm::cli::kSweepPartFile) << trm::cli::sweep_part_text(part.result, given, "test");
    from_files.push_back(trm::cli::read_sweep_part(part.dir));
    in_memory.push_back(std::move(part));
  }
  trm::cli::check_sweep_parts(from_files, tmp.path() / "merged");
  const trm::cli::SweepResult a = trm::cli::merge_sweep_parts(from_files, options);
  const trm::cli::SweepResult b = trm::cli::merge_sweep_parts(in_memory, options);
  EXPECT_EQ(trm::cli::sweep_csv(a), trm::cli::sweep_csv(b));
  EXPECT_EQ(trm::cli::sweep_json(a).dump(), trm::cli::sweep_json(b).dump());
  EXPECT_EQ(trm::cli::sweep_markdown(a), trm::cli::sweep_markdown(b));
  ASSERT_EQ(a.knobs.size(), 1u);
  EXPECT_EQ(a.knobs[0].points.size(), 9u);
  EXPECT_EQ(a.knobs[0].points[0].status, "rejected");
  EXPECT_EQ(a.base.repeat_seconds_per_frame.size(), 2u);
}

TEST_F(SweepShards, BadShardsAreRefusedBeforeAnyOutput) {
  const fs::path out = scratch_->path() / "bad-shard";
  for (const std::string shard : {"0/3", "4/3", "3", "2/x", "1/0", "-1/3"}) {
    const auto r = run_trm(kSweep + " --shard " + shard + " -o " + out.string());
    EXPECT_NE(r.exit_code, 0) << shard;
    EXPECT_NE(r.output.find("trm: error: --shard"), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(out)) << shard;
  }
  // More shards than points: 22 points (the base once) cannot make 23 parts.
  const auto r = run_trm(kSweep + " --shard 1/23 -o " + out.string());
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("this sweep has 22 point(s)"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("N must be at most 22"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(out));
}

TEST_F(SweepShards, MissingDuplicateAndOverlappingPartsAreRefused) {
  expect_refused(parts({1, 3}), "shard(s) 2/3 missing");
  expect_refused(parts({1}), "shard(s) 2/3, 3/3 missing");
  expect_refused(parts({1, 2, 3, 2}), "is given more than once");
  const fs::path again = copy_of_part(2, "part-2-again");
  expect_refused(parts({1, 2, 3}) + " " + again.string(), "are both shard 2/3; give each shard once");

  // A part of the same sweep split in two: its points overlap those of the three-way split.
  const fs::path halves = scratch_->path() / "half-1";
  ASSERT_EQ(run_trm(kSweep + " --shard 1/2 -o " + halves.string()).exit_code, 0);
  expect_refused(parts({1, 2, 3}) + " " + halves.string(), "split the sweep into different numbers of shards");

  // A part that holds a point of another shard as well as its own.
  const fs::path doubled = copy_of_part(3, "part-3-doubled");
  edit_part(doubled, [](nlohmann::json& j) {
    const nlohmann::json first = j["knobs"][1]["points"][0];
    j["knobs"][1]["points"].push_back(first);
  });
  expect_refused(parts({1, 2}) + " " + doubled.string(), "its points overlap another shard's");
  // And one that lacks one of its own.
  const fs::path thin = copy_of_part(2, "part-2-thin");
  edit_part(thin, [](nlohmann::json& j) { j["knobs"][1]["points"].erase(0); });
  expect_refused(parts({1, 3}) + " " + thin.string(), "lacks its point residual_bits");
}

TEST_F(SweepShards, PartsOfDifferentSweepsAreRefused) {
  // Other options: another seed.
  const fs::path other = scratch_->path() / "other-seed";
  ASSERT_EQ(run_trm(kSweep + " --seed 7 --shard 2/3 -o " + other.string()).exit_code, 0);
  expect_refused(parts({1, 3}) + " " + other.string(), "are of different sweeps");
  // The same options but another sequence (an input that changed between the shards, say).
  const fs::path changed = copy_of_part(2, "part-2-changed");
  edit_part(changed, [](nlohmann::json& j) { j["recording_hash"] = j["recording_hash"].get<std::uint64_t>() + 1; });
  expect_refused(parts({1, 3}) + " " + changed.string(), "decoded different sequences");
  // Parameters its options no longer give.
  const fs::path moved = copy_of_part(2, "part-2-parameters");
  edit_part(moved, [](nlohmann::json& j) { j["parameters"]["seed"] = 99; });
  expect_refused(parts({1, 3}) + " " + moved.string(), "/seed differs");
  // Another trm.
  const fs::path version = copy_of_part(3, "part-3-version");
  edit_part(version, [](nlohmann::json& j) { j["version"] = "0.0.1"; });
  expect_refused(parts({1, 2}) + " " + version.string(), "different trm versions");
}

TEST_F(SweepShards, WhatIsNotAPartIsRefused) {
  const fs::path empty = scratch_->path() / "not-a-part";
  fs::create_directories(empty);
  expect_refused(parts({1, 2}) + " " + empty.string(), "holds no sweep-part.json");
  expect_refused(parts({1, 2}) + " " + (scratch_->path() / "nothing-here").string(), "is not a directory");
  const fs::path cut = copy_of_part(3, "part-3-cut");
  const std::string text = text_of(cut / trm::cli::kSweepPartFile);
  std::ofstream(cut / trm::cli::kSweepPartFile) << text.substr(0, text.size() / 2);
  expect_refused(parts({1, 2}) + " " + cut.string(), "not valid JSON");
  const fs::path foreign = copy_of_part(3, "part-3-foreign");
  edit_part(foreign, [](nlohmann::json& j) { j["knobs"][0]["points"][0].erase("codes"); });
  expect_refused(parts({1, 2}) + " " + foreign.string(), "is not a trm sweep part");
  // A merge takes its options from the parts, and does not write over one of them.
  expect_refused(parts({1, 2, 3}) + " --seed 3", "leave out --seed");
  expect_refused(parts({1, 2, 3}) + " --shard 1/3", "leave out --shard");
  const auto r = run_trm("sweep --merge" + parts({1, 2, 3}) + " -o " + part_dir(2).string());
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("is one of the parts"), std::string::npos) << r.output;
  EXPECT_TRUE(fs::exists(part_dir(2) / trm::cli::kSweepPartFile));
  // Nor over a directory of the user's.
  const fs::path users = scratch_->path() / "users";
  fs::create_directories(users);
  std::ofstream(users / "notes.txt") << "mine\n";
  const auto into_users = run_trm("sweep --merge" + parts({1, 2, 3}) + " -o " + users.string());
  EXPECT_NE(into_users.exit_code, 0);
  EXPECT_EQ(text_of(users / "notes.txt"), "mine\n");
  EXPECT_EQ(std::distance(fs::directory_iterator(users), fs::directory_iterator()), 1);
}

TEST(SweepShard, LinearBaseAndEyeKnobMergeAsASingleRun) {
  // A linear-resample-space knob (swept around the linear base, point 1 of shard 2) and the eye model's sub-steps
  // (every value a point watching the base's output): shard 3 owns neither base yet decodes both for its points.
  ScratchDir tmp("trm-sweep-shard-linear-");
  const std::string sweep = "sweep --quick --size 16x12 --hw-size 16x12 --knob linear_resample_frac_bits "
                            "--knob eye_substeps";
  const auto single = run_trm(sweep + " -o " + tmp.str("work/sweep"));
  ASSERT_EQ(single.exit_code, 0) << single.output;
  fs::rename(tmp.path() / "work/sweep", tmp.path() / "single");
  std::string part_dirs;
  for (int k = 1; k <= 3; ++k) {
    const fs::path dir = tmp.path() / ("part-" + std::to_string(k));
    const auto part = run_trm(sweep + " --shard " + std::to_string(k) + "/3 -o " + dir.string());
    ASSERT_EQ(part.exit_code, 0) << part.output;
    part_dirs.append(" ").append(dir.string());
  }
  const auto part = [&](int k) {
    return nlohmann::json::parse(text_of(tmp.path() / ("part-" + std::to_string(k)) / trm::cli::kSweepPartFile));
  };
  EXPECT_FALSE(part(1)["base"].is_null());
  EXPECT_TRUE(part(1)["linear_base"].is_null());
  EXPECT_FALSE(part(2)["linear_base"].is_null());
  EXPECT_TRUE(part(3)["base"].is_null());
  EXPECT_TRUE(part(3)["linear_base"].is_null());
  EXPECT_NE(part(3)["linear_recording_hash"].get<std::uint64_t>(), 0u);

  const fs::path merged = tmp.path() / "work/sweep";
  const auto r = run_trm("sweep --merge" + part_dirs + " -o " + merged.string());
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const fs::path single_dir = tmp.path() / "single";
  EXPECT_EQ(manifest_of(merged), manifest_of(single_dir));
  const auto rows = rows_without_timings(merged / "sweep.csv");
  EXPECT_EQ(rows, rows_without_timings(single_dir / "sweep.csv"));
  std::size_t linear_rows = 0, eye_rows = 0;
  for (const auto& row : rows) {
    if (row.at("knob") == "linear_resample_frac_bits") {
      ++linear_rows;
      EXPECT_EQ(row.at("resample_space"), "linear");
    }
    if (row.at("knob") == "eye_substeps") ++eye_rows;
  }
  EXPECT_EQ(linear_rows, trm::cli::find_sweep_knob("linear_resample_frac_bits")->values.size());
  EXPECT_EQ(eye_rows, trm::cli::find_sweep_knob("eye_substeps")->values.size());
  const auto report = nlohmann::json::parse(text_of(merged / "report.json"));
  ASSERT_TRUE(report.contains("linear_base"));
  EXPECT_EQ(without_timings(report), without_timings(nlohmann::json::parse(text_of(single_dir / "report.json"))));
  EXPECT_EQ(md_without_tables(merged / "sweep.md"), md_without_tables(single_dir / "sweep.md"));
  // The eye points' decoder is the base of shard 1, the linear knob's base point the linear base of shard 2.
  for (const auto& knob : report["knobs"]) {
    for (const auto& point : knob["points"]) {
      if (knob["name"] == "eye_substeps" && point["status"] == "ok") {
        EXPECT_EQ(point["time"]["seconds_per_frame"], part(1)["base"]["seconds_per_frame"]);
      }
      if (knob["name"] == "linear_resample_frac_bits" && point["is_default"].get<bool>()) {
        EXPECT_EQ(point["time"]["seconds_per_frame"], part(2)["linear_base"]["seconds_per_frame"]);
      }
    }
  }

  // Merged from the part files and from the parts in memory: the same outputs, timings included.
  trm::cli::SweepOptions options;
  options.pipeline.scene = "discs";
  options.pipeline.width = 16;
  options.pipeline.height = 12;
  options.pipeline.frames = 2;
  options.repeats = 2;
  options.hw_size = cv::Size(16, 12);
  options.knobs = {"linear_resample_frac_bits", "eye_substeps"};
  const std::vector<trm::cli::GivenOption> given = {
      {"--knob", {"linear_resample_frac_bits", "eye_substeps"}}};
  std::vector<trm::cli::SweepPart> from_files, in_memory;
  for (int k = 1; k <= 3; ++k) {
    trm::cli::SweepOptions shard = options;
    shard.shard = {k, 3};
    trm::cli::SweepPart p;
    p.dir = tmp.path() / ("memory-" + std::to_string(k));
    p.version = "test";
    p.options = given;
    p.result = trm::cli::run_sweep(shard);
    p.has_base = k == 1;
    p.has_linear_base = k == 2;
    p.parameters = nlohmann::json::parse(trm::cli::sweep_parameters_json(p.result).dump());
    fs::create_directories(p.dir);
    std::ofstream(p.dir / trm::cli::kSweepPartFile) << trm::cli::sweep_part_text(p.result, given, "test");
    from_files.push_back(trm::cli::read_sweep_part(p.dir));
    in_memory.push_back(std::move(p));
  }
  trm::cli::check_sweep_parts(from_files, tmp.path() / "merged");
  const trm::cli::SweepResult a = trm::cli::merge_sweep_parts(from_files, options);
  const trm::cli::SweepResult b = trm::cli::merge_sweep_parts(in_memory, options);
  EXPECT_EQ(trm::cli::sweep_csv(a), trm::cli::sweep_csv(b));
  EXPECT_EQ(trm::cli::sweep_json(a).dump(), trm::cli::sweep_json(b).dump());
  EXPECT_EQ(trm::cli::sweep_markdown(a), trm::cli::sweep_markdown(b));
  ASSERT_TRUE(a.linear_base.has_value());
  ASSERT_EQ(a.knobs.size(), 2u);
  EXPECT_EQ(a.knobs[0].resample_space, trm::ResampleSpace::Linear);
  // And the same points as one unsharded run, but for what is timed.
  const trm::cli::SweepResult whole = trm::cli::run_sweep(options);
  EXPECT_EQ(without_timings(nlohmann::json::parse(trm::cli::sweep_json(a).dump())),
            without_timings(nlohmann::json::parse(trm::cli::sweep_json(whole).dump())));
}

TEST(SweepShard, PointCountHasTheLinearBaseAndEveryEyeValue) {
  trm::cli::SweepOptions options;
  options.knobs = {"linear_resample_frac_bits", "eye_substeps", "residual_bits"};
  const auto plan = trm::cli::plan_sweep(options);
  ASSERT_EQ(plan.size(), 3u);
  EXPECT_TRUE(trm::cli::sweep_has_linear_base(plan));
  EXPECT_TRUE(plan[0].linear_base);
  EXPECT_EQ(plan[0].resample_space, trm::ResampleSpace::Linear);
  std::int64_t expected = 2;  // the base and the linear base
  for (const auto& k : plan) expected += static_cast<std::int64_t>(k.values.size()) - (k.knob->eye_model ? 0 : 1);
  EXPECT_EQ(trm::cli::sweep_point_count(plan), expected);
  // In a linear-space run the linear knobs sweep around the run's own base: no second base.
  options.pipeline.encoder.resample_space = trm::ResampleSpace::Linear;
  const auto linear_run = trm::cli::plan_sweep(options);
  EXPECT_FALSE(trm::cli::sweep_has_linear_base(linear_run));
  EXPECT_EQ(trm::cli::sweep_point_count(linear_run), expected - 1);
}
