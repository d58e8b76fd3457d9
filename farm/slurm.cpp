// SPDX-License-Identifier: Apache-2.0
#include "farm/slurm.h"

#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <cstring>
#include <algorithm>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <stdexcept>
#include <thread>

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/file_io.h"
#include "core/json_input.h"
#include "core/process.h"


namespace ct::farm {
namespace fs = std::filesystem;
namespace {

constexpr const char* kFormat = "chromatrace-farm/1";

std::string first_line(const std::string& text) {
  std::string line = text.substr(0, text.find('\n'));
  return line.empty() ? "(no message)" : line;
}

bool on_path(const std::string& program) {
  const char* path = std::getenv("PATH");
  std::stringstream dirs(path ? path : "");
  for (std::string dir; std::getline(dirs, dir, ':');)
    if (!dir.empty() && access((fs::path(dir) / program).c_str(), X_OK) == 0) return true;
  return false;
}

void require_slurm() {
  for (const char* program : {"sbatch", "squeue", "scancel"})
    if (!on_path(program))
      throw InputError(fmt::format("{}: not found on PATH (install Slurm's client commands, e.g. Debian's slurm-client, "
                                   "or use --dry-run to only write the scripts)",
                                   program));
}

// "0-3", "1,3-5", with "%N" for the most tasks at once.
std::string array_spec(const std::vector<int>& tasks, std::optional<int> max_concurrent) {
  std::string spec;
  for (std::size_t i = 0; i < tasks.size();) {
    std::size_t j = i;
    while (j + 1 < tasks.size() && tasks[j + 1] == tasks[j] + 1) ++j;
    spec += (spec.empty() ? "" : ",") + (i == j ? std::to_string(tasks[i]) : fmt::format("{}-{}", tasks[i], tasks[j]));
    i = j + 1;
  }
  if (max_concurrent) spec += fmt::format("%{}", *max_concurrent);
  return spec;
}

std::string header(const FarmJob& job, const SlurmOptions& options, const std::string& name, const std::string& log,
                   const std::string& purpose) {
  std::string text = fmt::format(
      "#!/bin/bash\n"
      "# chromatrace farm {}: {} (docs/farm.md).\n"
      "# Written and submitted by chromatrace farm; the same command with --resume submits again what is missing.\n"
      "#SBATCH --job-name={}\n#SBATCH --output={}\n#SBATCH --cpus-per-task={}\n",
      job.kind, purpose, name, (job.directory / "logs" / log).string(), options.cpus_per_task);
  if (!options.partition.empty()) text += fmt::format("#SBATCH --partition={}\n", options.partition);
  if (!options.time_limit.empty()) text += fmt::format("#SBATCH --time={}\n", options.time_limit);
  if (!options.memory.empty()) text += fmt::format("#SBATCH --mem={}\n", options.memory);
  for (const std::string& arg : options.sbatch_args) text += fmt::format("#SBATCH {}\n", arg);
  text += "set -euo pipefail\nTHREADS=\"${SLURM_CPUS_PER_TASK:-1}\"\n";
  return text;
}

std::string tasks_script(const FarmJob& job, const SlurmOptions& options) {
  std::string text = header(job, options, fmt::format("chromatrace-{}-tasks", job.kind), "tasks-%A_%a.out",
                            fmt::format("{} independent tasks towards {}", job.task_commands.size(), job.result.string()));
  text += "case \"${SLURM_ARRAY_TASK_ID:?not a Slurm array task}\" in\n";
  for (std::size_t i = 0; i < job.task_commands.size(); ++i)
    text += fmt::format("  {})\n    {}\n    ;;\n", i, job.task_commands[i]);
  text += "  *) echo \"tasks.sh: no task $SLURM_ARRAY_TASK_ID\" >&2; exit 2 ;;\nesac\n";
  return text;
}

std::string assembly_script(const FarmJob& job, const SlurmOptions& options) {
  return header(job, options, fmt::format("chromatrace-{}-assemble", job.kind), "assemble-%j.out",
                fmt::format("assembles {} from the tasks' outputs", job.result.string())) +
         job.assembly_command + "\n";
}

std::string submit_job(const std::vector<std::string>& args, const fs::path& script) {
  std::vector<std::string> argv = {"sbatch", "--parsable"};
  argv.insert(argv.end(), args.begin(), args.end());
  argv.push_back(script.string());
  const ProgramOutput result = run_program(argv);
  if (result.status != 0) throw std::runtime_error(fmt::format("sbatch {}: {}", script.string(), first_line(result.err)));
  // --parsable prints "<id>" or "<id>;<cluster>"
  const std::string id = first_line(result.out).substr(0, result.out.find_first_of(";\n"));
  if (id.empty() || id.find_first_not_of("0123456789") != std::string::npos)
    throw std::runtime_error(fmt::format("sbatch {}: unexpected answer \"{}\"", script.string(), first_line(result.out)));
  return id;
}

struct QueuedJob {
  std::string id;  // "12" or, for an array task, "12_3"
  std::string state, reason;
};

bool active(const std::string& state) {
  static const std::set<std::string> kFinished{"COMPLETED", "CANCELLED",     "FAILED",  "TIMEOUT",
                                               "NODE_FAIL", "PREEMPTED",     "BOOT_FAIL", "DEADLINE",
                                               "OUT_OF_MEMORY", "REVOKED", "SPECIAL_EXIT"};
  return !kFinished.contains(state);
}

// The jobs (array tasks one by one) still in the queue, not yet finished.
std::vector<QueuedJob> queued(const std::vector<std::string>& ids) {
  std::string list;
  for (const std::string& id : ids)
    if (!id.empty()) list += (list.empty() ? "" : ",") + id;
  if (list.empty()) return {};
  const ProgramOutput result = run_program({"squeue", "--noheader", "--array", "--jobs", list, "--format", "%i|%T|%r"});
  if (result.status != 0) {
    // Jobs that finished long enough ago are forgotten: "Invalid job id specified".
    if (result.err.find("Invalid job id") != std::string::npos) return {};
    throw std::runtime_error(fmt::format("squeue: {}", first_line(result.err)));
  }
  std::vector<QueuedJob> jobs;
  std::stringstream lines(result.out);
  for (std::string line; std::getline(lines, line);) {
    const std::size_t a = line.find('|'), b = line.find('|', a + 1);
    if (a == std::string::npos || b == std::string::npos) continue;
    QueuedJob job{line.substr(0, a), line.substr(a + 1, b - a - 1), line.substr(b + 1)};
    if (active(job.state)) jobs.push_back(job);
  }
  return jobs;
}

bool of_job(const QueuedJob& queued_job, const std::string& id) {
  return queued_job.id == id || queued_job.id.starts_with(id + "_");
}

void cancel(const std::string& id) {
  const ProgramOutput result = run_program({"scancel", id});
  if (result.status != 0) throw std::runtime_error(fmt::format("scancel {}: {}", id, first_line(result.err)));
}

struct Record {
  std::string tasks_job, assembly_job;
  std::vector<int> tasks;
};

fs::path record_file(const FarmJob& job) { return job.directory / "farm.json"; }

std::optional<Record> read_record(const FarmJob& job) {
  if (!fs::exists(record_file(job))) return std::nullopt;
  const Json json = read_json(record_file(job));
  Record r;
  r.tasks_job = json.at("tasks_job").get<std::string>();
  r.assembly_job = json.at("assembly_job").get<std::string>();
  r.tasks = json.at("tasks").get<std::vector<int>>();
  return r;
}

void write_record(const FarmJob& job, const Record& r) {
  nlohmann::json tasks = nlohmann::json::array();
  for (std::size_t i = 0; i < job.task_commands.size(); ++i)
    tasks.push_back({{"command", job.task_commands[i]}, {"output", job.task_outputs[i].string()}});
  const nlohmann::json json = {{"format", kFormat},           {"kind", job.kind},
                               {"result", job.result.string()}, {"tasks_job", r.tasks_job},
                               {"assembly_job", r.assembly_job}, {"tasks", r.tasks},
                               {"all_tasks", tasks},            {"assembly", job.assembly_command}};
  write_file_atomically(record_file(job), json.dump(1, ' ', false, kReplaceInvalidUtf8) + "\n");
}

std::string join_ids(const std::vector<QueuedJob>& jobs) {
  std::string text;
  for (const QueuedJob& j : jobs) text += (text.empty() ? "" : ",") + j.id;
  return text;
}

// A submission into the directory whose jobs are still queued must finish (or be cancelled) first, so that no
// task runs twice at once. An assembly left waiting for tasks that failed can never run: it is cancelled.
void check_earlier_submission(const FarmJob& job) {
  const std::optional<Record> earlier = read_record(job);
  if (!earlier) return;
  std::vector<QueuedJob> jobs = queued({earlier->tasks_job, earlier->assembly_job});
  const bool tasks_queued = std::any_of(jobs.begin(), jobs.end(), [&](auto& j) { return of_job(j, earlier->tasks_job); });
  if (!tasks_queued && jobs.size() == 1 && jobs[0].reason == "DependencyNeverSatisfied") {
    cancel(jobs[0].id);
    fmt::print(stderr, "chromatrace farm: cancelled job {}, the assembly of the earlier submission (its tasks did not all "
                       "succeed)\n", jobs[0].id);
    return;
  }
  if (!jobs.empty())
    throw InputError(fmt::format("{}: jobs {} of the earlier submission are still queued; wait for them (--wait) or "
                                 "cancel them (scancel) first",
                                 record_file(job).string(), join_ids(jobs)));
}

}  // namespace

void check_options(const SlurmOptions& o) {
  static const std::regex partition(R"([A-Za-z0-9_.\-]+(,[A-Za-z0-9_.\-]+)*)");
  static const std::regex time(
      R"((\d+|\d+:\d+|\d+:\d+:\d+|\d+-\d+|\d+-\d+:\d+|\d+-\d+:\d+:\d+|UNLIMITED|INFINITE|unlimited|infinite))");
  static const std::regex memory(R"(\d+[KMGT]?)");
  if (!o.partition.empty() && !std::regex_match(o.partition, partition))
    throw InputError(fmt::format("--partition: expected partition names separated by commas, got \"{}\"", o.partition));
  if (!o.time_limit.empty() && !std::regex_match(o.time_limit, time))
    throw InputError(fmt::format("--time: expected minutes, MM:SS, HH:MM:SS or D-HH[:MM[:SS]], got \"{}\"", o.time_limit));
  if (o.cpus_per_task < 1) throw InputError(fmt::format("--cpus-per-task: must be at least 1, got {}", o.cpus_per_task));
  if (!o.memory.empty() && !std::regex_match(o.memory, memory))
    throw InputError(fmt::format("--mem: expected a size such as 4000, 500M or 4G, got \"{}\"", o.memory));
  if (o.max_concurrent && *o.max_concurrent < 1)
    throw InputError(fmt::format("--max-concurrent: must be at least 1, got {}", *o.max_concurrent));
  for (const std::string& arg : o.sbatch_args)
    if (!arg.starts_with("-") || arg.find_first_of("\n\r") != std::string::npos)
      throw InputError(fmt::format("--sbatch-arg: expected one sbatch option on one line (e.g. --qos=long), got \"{}\"", arg));
}

std::string shell_quote(const std::string& word) {
  if (!word.empty() && word.find_first_not_of("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789_-./:=,+@%") ==
                           std::string::npos)
    return word;
  std::string quoted = "'";
  for (const char c : word) {
    if (c == '\'') quoted += "'\\''";
    else quoted += c;
  }
  quoted += '\'';
  return quoted;
}

std::string shell_command(const std::vector<std::string>& words) {
  std::string line;
  for (const std::string& w : words) {
    if (!line.empty()) line += ' ';
    line += shell_quote(w);
  }
  return line;
}

void submit(const FarmJob& job, const SlurmOptions& options, Mode mode) {
  check_options(options);
  if (mode != Mode::DryRun) require_slurm();
  for (const char* sub : {"slurm", "logs", "parts"}) fs::create_directories(job.directory / sub);
  if (mode != Mode::DryRun) check_earlier_submission(job);

  const fs::path tasks_file = job.directory / "slurm" / "tasks.sh", assembly_file = job.directory / "slurm" / "assemble.sh";
  write_file_atomically(tasks_file, tasks_script(job, options));
  write_file_atomically(assembly_file, assembly_script(job, options));
  for (const auto& [name, text] : job.notes) write_file_atomically(job.directory / "slurm" / name, text);

  std::vector<int> tasks;
  for (std::size_t i = 0; i < job.task_commands.size(); ++i)
    if (mode != Mode::Resume || !fs::exists(job.task_outputs[i])) tasks.push_back(static_cast<int>(i));
  if (mode == Mode::Resume && fs::exists(job.result)) {
    fmt::print("{}: already assembled; nothing to submit\n", job.result.string());
    return;
  }
  const std::string spec = array_spec(tasks, options.max_concurrent);
  if (mode == Mode::DryRun) {
    fmt::print("sbatch --parsable --array={} {}\n", spec, tasks_file.string());
    fmt::print("sbatch --parsable --dependency=afterok:<tasks job> {}\n", assembly_file.string());
    return;
  }
  // What an earlier run left must not pass for this run's work: the tasks run again write their outputs anew.
  fs::remove(job.result);
  if (mode == Mode::Submit)
    for (const fs::path& output : job.task_outputs) fs::remove(output);

  Record record;
  record.tasks = tasks;
  if (!tasks.empty()) {
    record.tasks_job = submit_job({"--array=" + spec}, tasks_file);
    fmt::print("tasks: job {} (array {}, {} of {} tasks)\n", record.tasks_job, spec, tasks.size(), job.task_commands.size());
  }
  record.assembly_job = submit_job(
      record.tasks_job.empty() ? std::vector<std::string>{} : std::vector<std::string>{"--dependency=afterok:" + record.tasks_job},
      assembly_file);
  fmt::print("assembly: job {}{}\n", record.assembly_job,
             record.tasks_job.empty() ? "" : fmt::format(" (when job {} has succeeded)", record.tasks_job));
  std::fflush(stdout);
  write_record(job, record);
}

int wait(const FarmJob& job, bool progress) {
  const std::optional<Record> record = read_record(job);
  if (!record) throw InputError(fmt::format("{}: no submission to wait for", record_file(job).string()));
  require_slurm();
  std::string last;
  bool assembly_stuck = false;
  for (;;) {
    const std::vector<QueuedJob> jobs = queued({record->tasks_job, record->assembly_job});
    int running = 0, pending = 0;
    std::string assembly = "finished";
    for (const QueuedJob& j : jobs) {
      if (!record->tasks_job.empty() && of_job(j, record->tasks_job)) (j.state == "PENDING" ? pending : running) += 1;
      if (j.id == record->assembly_job) {
        assembly = j.state == "PENDING" ? "waiting" : "running";
        assembly_stuck = j.state == "PENDING" && j.reason == "DependencyNeverSatisfied";
      }
    }
    std::size_t done = 0;
    for (const fs::path& output : job.task_outputs) done += fs::exists(output) ? 1 : 0;
    const std::string line = fmt::format("farm: {}/{} tasks done, {} running, {} pending; assembly {}", done,
                                         job.task_outputs.size(), running, pending, assembly);
    if (progress && line != last) fmt::print(stderr, "{}\n", line);
    last = line;
    if (jobs.empty()) break;
    if (assembly_stuck && running + pending == 0) {
      cancel(record->assembly_job);
      break;
    }
    std::this_thread::sleep_for(std::chrono::seconds(1));
  }
  if (!assembly_stuck && fs::exists(job.result)) {
    fmt::print("{}\n", job.result.string());
    return 0;
  }
  std::string missing;
  for (std::size_t i = 0; i < job.task_outputs.size(); ++i)
    if (!fs::exists(job.task_outputs[i])) missing += (missing.empty() ? "" : ", ") + std::to_string(i);
  const fs::path logs = job.directory / "logs";
  if (!missing.empty())
    fmt::print(stderr,
               "chromatrace farm: failed: tasks {} did not finish (their logs: {}/tasks-{}_<task>.out){}; run the same "
               "command with --resume to submit them again\n",
               missing, logs.string(), record->tasks_job, assembly_stuck ? ", so the assembly was cancelled" : "");
  else
    fmt::print(stderr, "chromatrace farm: failed: the assembly did not write {} (its log: {}/assemble-{}.out)\n",
               job.result.string(), logs.string(), record->assembly_job);
  return 1;
}

}  // namespace ct::farm
