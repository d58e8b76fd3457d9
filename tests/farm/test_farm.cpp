// SPDX-License-Identifier: Apache-2.0
// chromatrace farm on a real single-node Slurm cluster on localhost (tests/farm/local_slurm.sh: munged,
// slurmctld and slurmd with a generated slurm.conf, all in a temporary directory, stopped after each test):
// the split render of the cluster is the same bytes as the same split run locally, also after a task was
// cancelled and the rest submitted with --resume. Skipped, saying why, only where Slurm cannot start.
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include <fmt/core.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/file_io.h"
#include "tests/cli/run_command.h"
#include "tests/core/spectral_exr_fixtures.h"

namespace ct {
namespace {
namespace fs = std::filesystem;
using test::CommandResult;

const std::string kSource = CHROMATRACE_SOURCE_DIR;
const std::string kBox = kSource + "/scenes/paper/box.json";
const std::string kSlurm = kSource + "/tests/farm/local_slurm.sh";
// The paper's box, small: 4 parts of 4 paths per pixel.
const std::vector<std::string> kRender = {kBox, "--resolution", "32x32", "--spp", "16", "--seeds", "4"};
// Parts that take a second or more, so that one can be cancelled while it renders.
const std::vector<std::string> kLongRender = {kBox, "--resolution", "64x64", "--spp", "512", "--seeds", "4"};

std::vector<std::string> with(std::vector<std::string> args, const std::vector<std::string>& more) {
  args.insert(args.end(), more.begin(), more.end());
  return args;
}

std::vector<std::string> farm_render(const fs::path& dir, const std::vector<std::string>& more,
                                     const std::vector<std::string>& render = kRender) {
  return with(with({"farm", "render"}, render), with({"-o", dir.string(), "--quiet"}, more));
}

// Slurm's state of a job or array task ("RUNNING", "PENDING", …; "" once it has left the queue).
std::string job_state(const std::string& id) {
  const CommandResult r = test::run_program("/usr/bin/squeue", {"--noheader", "--array", "--jobs", id, "--format", "%T"});
  return r.out.substr(0, r.out.find('\n'));
}

// The first line of stdout that starts with `prefix`, its third word: "tasks: job 12 (...)" -> "12".
std::string job_id(const std::string& out, const std::string& prefix) {
  const std::size_t at = out.find(prefix + ": job ");
  if (at == std::string::npos) return "";
  const std::size_t start = at + prefix.size() + 6;
  return out.substr(start, out.find_first_of(" \n", start) - start);
}

class Slurm : public ::testing::Test {
 protected:
  void SetUp() override {
    const CommandResult up = test::run_program("/bin/bash", {kSlurm, "start", cluster_.string()});
    if (up.exit_code == 77) GTEST_SKIP() << "Slurm cannot start here: " << up.err;
    ASSERT_EQ(up.exit_code, 0) << up.err;
    started_ = true;
    setenv("SLURM_CONF", (cluster_ / "slurm.conf").c_str(), 1);
  }
  void TearDown() override {
    if (started_) test::run_program("/bin/bash", {kSlurm, "stop", cluster_.string()});
    unsetenv("SLURM_CONF");
  }

  // The same split run locally: what every Slurm run must equal byte for byte.
  std::string local_split(const std::vector<std::string>& render = kRender) {
    const fs::path local = dir_.file("local.exr");
    const CommandResult r = test::run_chromatrace(with(with({"render"}, render), {"-o", local.string(), "--quiet"}));
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return read_file(local);
  }

  test::TempDir dir_;
  fs::path cluster_ = dir_.file("slurm");
  bool started_ = false;
};

TEST_F(Slurm, TracerSplitIntoFourSeedsIsByteIdenticalToTheLocalSplit) {
  const fs::path out = dir_.file("farm");
  const CommandResult r = test::run_chromatrace(farm_render(out, {"--wait"}));
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_FALSE(job_id(r.out, "tasks").empty()) << r.out;
  EXPECT_FALSE(job_id(r.out, "assembly").empty()) << r.out;
  for (int part = 0; part < 4; ++part) EXPECT_TRUE(fs::exists(out / "parts" / ("part_" + std::to_string(part) + ".exr")));
  EXPECT_TRUE(fs::exists(out / "slurm" / "tasks.sh"));
  const std::string farm = read_file(out / "render.exr");
  EXPECT_TRUE(farm == local_split()) << "the cluster's render differs from the local split";
}

TEST_F(Slurm, CancelledTasksThenResumeGiveTheSameBytes) {
  const fs::path out = dir_.file("farm");
  // One task at a time: task 1 is cancelled while it renders, task 3 while it still waits.
  const CommandResult submitted = test::run_chromatrace(farm_render(out, {"--max-concurrent", "1"}, kLongRender));
  ASSERT_EQ(submitted.exit_code, 0) << submitted.err;
  const std::string tasks = job_id(submitted.out, "tasks");
  ASSERT_FALSE(tasks.empty()) << submitted.out;
  std::string state;
  for (int i = 0; i < 1200 && (state = job_state(tasks + "_1")) != "RUNNING"; ++i) usleep(100'000);
  ASSERT_EQ(state, "RUNNING") << "task 1 was never seen running";
  ASSERT_EQ(job_state(tasks + "_3"), "PENDING");
  for (const char* task : {"_1", "_3"}) {
    const CommandResult cancelled = test::run_program("/usr/bin/scancel", {tasks + task});
    ASSERT_EQ(cancelled.exit_code, 0) << cancelled.err;
  }

  // Following the jobs: tasks 0 and 2 succeed, 1 and 3 never do, so the assembly cannot run.
  const CommandResult followed = test::run_chromatrace(farm_render(out, {"--follow"}, kLongRender));
  EXPECT_EQ(followed.exit_code, 1) << followed.err;
  EXPECT_NE(followed.err.find("tasks 1, 3 did not finish"), std::string::npos) << followed.err;
  EXPECT_FALSE(fs::exists(out / "render.exr"));
  EXPECT_TRUE(fs::exists(out / "parts" / "part_0.exr"));
  EXPECT_TRUE(fs::exists(out / "parts" / "part_2.exr"));
  // The task stopped in the middle of its render left nothing in parts/, not even a temporary file.
  std::vector<std::string> left;
  for (const auto& entry : fs::directory_iterator(out / "parts")) left.push_back(entry.path().filename().string());
  std::sort(left.begin(), left.end());
  EXPECT_EQ(left, (std::vector<std::string>{"part_0.exr", "part_2.exr"}));

  const CommandResult resumed = test::run_chromatrace(farm_render(out, {"--resume", "--wait"}, kLongRender));
  ASSERT_EQ(resumed.exit_code, 0) << resumed.err;
  EXPECT_NE(resumed.out.find("(array 1,3, 2 of 4 tasks)"), std::string::npos) << resumed.out;
  EXPECT_TRUE(read_file(out / "render.exr") == local_split(kLongRender))
      << "the resumed render differs from the local split";

  const CommandResult again = test::run_chromatrace(farm_render(out, {"--resume"}, kLongRender));
  EXPECT_EQ(again.exit_code, 0) << again.err;
  EXPECT_NE(again.out.find("nothing to submit"), std::string::npos) << again.out;
}

// A spectral Cycles render of the paper box in 3 band groups (9 bands, 3 per render), one task each, then the
// assembly: a complete spectral EXR whose components sum to the total (info --check) with the channels of the
// same render made by the add-on's batch on one machine.
TEST_F(Slurm, CyclesBandGroupsAssembleToTheChannelsOfTheLocalBatch) {
  if (std::string(BLENDER_EXE).empty() || !fs::exists(BLENDER_EXE)) GTEST_SKIP() << "Blender is not installed";
  setenv("CHROMATRACE_EXE", CHROMATRACE_EXE, 1);
  const std::vector<std::string> options = {"--bands", "420:690:30", "--resolution", "16x16", "--samples", "4"};
  const fs::path out = dir_.file("farm");
  const CommandResult r = test::run_chromatrace(with({"farm", "cycles", kBox, "-o", out.string(), "--wait"}, options));
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("(array 0-2, 3 of 3 tasks)"), std::string::npos) << r.out;

  const fs::path local = dir_.file("local.exr");
  const CommandResult batch = test::run_program(
      BLENDER_EXE, with({"--background", "--factory-startup", "--python", kSource + "/blender_addon/batch.py", "--",
                         "--scene", kBox, "--out", local.string(), "--cache-dir", dir_.file("cache").string(), "--quiet"},
                        options));
  ASSERT_EQ(batch.exit_code, 0) << batch.err;

  const auto checked = [](const fs::path& file) {
    const CommandResult info = test::run_chromatrace({"info", "--check", "--json", "--quiet", file.string()});
    EXPECT_EQ(info.exit_code, 0) << file << ": " << info.err;
    return nlohmann::json::parse(info.out.empty() ? "{}" : info.out);
  };
  const nlohmann::json farm = checked(out / "render.exr"), mine = checked(local);
  ASSERT_TRUE(farm.contains("channels") && mine.contains("channels"));
  EXPECT_EQ(farm["channels"], mine["channels"]);
  EXPECT_EQ(farm["bands"], mine["bands"]);
  EXPECT_EQ(farm["channels"].size(), 3u + 9u * 7u + 1u) << "R, G, B, 9 bands of the total and 6 components, object ids";
}

// Timings and whether a render came from the cache say how a run went, not what it found.
void strip_run_details(nlohmann::json& j) {
  if (j.is_object()) {
    for (const char* key : {"seconds", "cpu_seconds", "reused"}) j.erase(key);
    for (auto& [key, value] : j.items()) strip_run_details(value);
  } else if (j.is_array()) {
    for (auto& value : j) strip_run_details(value);
  }
}

// The paper's series: one task per distinct render, then camera, analysis and the page in the assembly job.
// Every render is the same bytes as the local series' and every finding is the same.
TEST_F(Slurm, SeriesRendersAndFindingsEqualTheLocalSeries) {
  const std::vector<std::string> options = {"--resolution", "32x32", "--spp", "8"};
  const std::string series = kSource + "/scenes/paper/series.json";
  const fs::path out = dir_.file("farm"), local = dir_.file("local");
  const CommandResult r = test::run_chromatrace(with({"farm", "series", series, "-o", out.string(), "--wait", "-q"}, options));
  ASSERT_EQ(r.exit_code, 0) << r.out << r.err;
  const CommandResult l = test::run_chromatrace(with({"series", series, "-o", local.string(), "-q"}, options));
  ASSERT_EQ(l.exit_code, 0) << l.err;

  int renders = 0;
  for (const auto& entry : fs::directory_iterator(local / "renders")) {
    if (entry.path().extension() != ".exr") continue;
    ++renders;
    const fs::path farm = out / "renders" / entry.path().filename();
    ASSERT_TRUE(fs::exists(farm)) << farm;
    EXPECT_TRUE(read_file(farm) == read_file(entry.path())) << entry.path().filename() << " differs";
  }
  EXPECT_NE(r.out.find(fmt::format("(array 0-{}, {} of {} tasks)", renders - 1, renders, renders)), std::string::npos)
      << r.out;
  nlohmann::json farm = nlohmann::json::parse(read_file(out / "series.json")),
                 mine = nlohmann::json::parse(read_file(local / "series.json"));
  strip_run_details(farm);
  strip_run_details(mine);
  farm.erase("options");
  mine.erase("options");
  EXPECT_EQ(farm, mine);
  EXPECT_TRUE(fs::exists(out / "index.html"));
}

// With the bounces components each band group has a Cycles render per bounce limit: one task each (here 3
// groups × limits k1, k2 and main). --dry-run runs the batch's pre-flight check and submits nothing.
TEST(FarmInput, CyclesWithBouncesIsOneTaskPerBandGroupAndBounceLimit) {
  if (std::string(BLENDER_EXE).empty() || !fs::exists(BLENDER_EXE)) GTEST_SKIP() << "Blender is not installed";
  setenv("CHROMATRACE_EXE", CHROMATRACE_EXE, 1);
  test::TempDir dir;
  const fs::path out = dir.file("farm");
  const CommandResult r = test::run_chromatrace({"farm", "cycles", kBox, "-o", out.string(), "--dry-run", "--bands",
                                                 "420:690:30", "--components", "all", "--max-bounces", "3"});
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("--array=0-8 "), std::string::npos) << r.out;
  const std::string script = read_file(out / "slurm" / "tasks.sh");
  for (int g = 0; g < 3; ++g)
    for (const char* limit : {"k1", "k2", "main"}) {
      const std::string task = fmt::format("--band-group {} --quiet --bounce-limit {} ", g, limit);
      EXPECT_NE(script.find(task), std::string::npos) << task;
    }
  EXPECT_FALSE(fs::exists(out / "farm.json"));
  EXPECT_TRUE(fs::exists(out / "slurm" / "preflight.json"));

  // What the batch refuses is refused before anything is written or queued, in the batch's words.
  const fs::path bad = dir.file("bad");
  const CommandResult refused = test::run_chromatrace({"farm", "cycles", kBox, "-o", bad.string(), "--dry-run",
                                                       "--samples", "0"});
  EXPECT_EQ(refused.exit_code, 2) << refused.err;
  EXPECT_EQ(refused.err, "chromatrace farm: error: --samples: must be at least 1, got 0\n");
  EXPECT_FALSE(fs::exists(bad));

  // The batch's --ggx-masking reaches every task.
  const fs::path masked = dir.file("masked");
  const CommandResult m = test::run_chromatrace({"farm", "cycles", kBox, "-o", masked.string(), "--dry-run", "--ggx-masking", "cycles"});
  ASSERT_EQ(m.exit_code, 0) << m.err;
  EXPECT_NE(read_file(masked / "slurm" / "tasks.sh").find("--ggx-masking cycles"), std::string::npos);

  // A band plan's samples per band group reach the batch, which each task runs: its pre-flight renders each group
  // with its own, and --samples beside them is refused in the batch's words.
  const fs::path plan = dir.file("plan.json");
  write_file_atomically(plan, R"({"format": "chromatrace-bands/1", "edges_nm": [400, 450, 500, 550, 600, 650, 700],
                                  "cycles_samples": [64, 16]})");
  const fs::path planned = dir.file("planned");
  const CommandResult p = test::run_chromatrace({"farm", "cycles", kBox, "-o", planned.string(), "--dry-run",
                                                 "--bands-file", plan.string()});
  ASSERT_EQ(p.exit_code, 0) << p.err;
  EXPECT_NE(p.out.find("--array=0-1 "), std::string::npos) << p.out;
  EXPECT_EQ(nlohmann::json::parse(read_file(planned / "slurm" / "preflight.json"))["samples"],
            nlohmann::json::array({64, 16}));
  const CommandResult both = test::run_chromatrace({"farm", "cycles", kBox, "-o", dir.file("both").string(),
                                                    "--dry-run", "--bands-file", plan.string(), "--samples", "4"});
  EXPECT_EQ(both.exit_code, 2) << both.err;
  EXPECT_NE(both.err.find("--samples: the band plan " + plan.string() + " gives each band group its samples"),
            std::string::npos)
      << both.err;
  EXPECT_FALSE(fs::exists(dir.file("both")));
}

// Bad input needs no cluster: one line naming the option (or the missing command), exit 2, nothing submitted.
TEST(FarmInput, BadValuesAndAMissingSbatchExitTwoWithOneLine) {
  test::TempDir dir;
  const fs::path out = dir.file("farm");
  const auto check = [&](const std::vector<std::string>& more, const std::string& named) {
    const CommandResult r = test::run_chromatrace(farm_render(out, more));
    EXPECT_EQ(r.exit_code, 2) << r.err;
    EXPECT_NE(r.err.find(named), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << r.err;
    EXPECT_FALSE(fs::exists(out)) << "bad input left " << out;
  };
  check({"--time", "soon", "--dry-run"}, "--time");
  check({"--mem", "4 GB", "--dry-run"}, "--mem");
  check({"--cpus-per-task", "0", "--dry-run"}, "--cpus-per-task");
  check({"--max-concurrent", "0", "--dry-run"}, "--max-concurrent");
  check({"--partition", "a b", "--dry-run"}, "--partition");
  check({"--sbatch-arg", "qos=long", "--dry-run"}, "--sbatch-arg");
  check({"--seeds", "17", "--dry-run"}, "--seeds");
  check({"--resume", "--dry-run"}, "--dry-run");

  const char* path = std::getenv("PATH");
  const std::string saved = path ? path : "";
  setenv("PATH", dir.path().c_str(), 1);
  check({}, "sbatch: not found on PATH");
  setenv("PATH", saved.c_str(), 1);

  // --dry-run writes the scripts and submits nothing.
  const CommandResult dry = test::run_chromatrace(farm_render(out, {"--dry-run", "--max-concurrent", "2"}));
  ASSERT_EQ(dry.exit_code, 0) << dry.err;
  EXPECT_NE(dry.out.find("--array=0-3%2"), std::string::npos) << dry.out;
  EXPECT_TRUE(fs::exists(out / "slurm" / "tasks.sh"));
  EXPECT_TRUE(fs::exists(out / "slurm" / "assemble.sh"));
  EXPECT_FALSE(fs::exists(out / "farm.json"));
}

}  // namespace
}  // namespace ct
