// SPDX-License-Identifier: Apache-2.0
#pragma once
// Work split into Slurm jobs (docs/farm.md): a job array whose tasks are independent, then one assembly job
// that runs when every task succeeded (--dependency=afterok). Slurm's own client commands (sbatch, squeue,
// scancel) do the talking; the scripts need only a shared file system and chromatrace (or Blender) on the nodes.
//
// Output directory layout:
//   slurm/tasks.sh     the job array: one command per task, chosen by $SLURM_ARRAY_TASK_ID
//   slurm/assemble.sh  the assembly
//   logs/              each task's and the assembly's output (tasks-<job>_<task>.out, assemble-<job>.out)
//   parts/             what the tasks write (each file atomically)
//   farm.json          what was submitted: the job ids, the tasks and their outputs
//   <result>           the assembly's output

#include <filesystem>
#include <optional>
#include <utility>
#include <string>
#include <vector>

namespace ct::farm {

// What a cluster user sets for every job; checked by check_options.
struct SlurmOptions {
  std::string partition;                // --partition; empty: the cluster's default
  std::string time_limit;               // --time, Slurm's forms (minutes, [D-]HH:MM:SS …); empty: the default
  int cpus_per_task = 1;                // --cpus-per-task; the task's tool gets as many threads
  std::string memory;                   // --mem per task (e.g. 4G); empty: the default
  std::optional<int> max_concurrent;    // the array's %N
  std::vector<std::string> sbatch_args; // further #SBATCH lines, each one option ("--qos=long")
};

// InputError naming the option when a value is not one Slurm takes.
void check_options(const SlurmOptions& options);

// One word for bash, single-quoted where needed.
std::string shell_quote(const std::string& word);
// A command line for bash: each word quoted.
std::string shell_command(const std::vector<std::string>& words);

// The work: tasks that can run in any order, each with the file it leaves when done, and the assembly.
struct FarmJob {
  std::string kind;                       // "render", "cycles": names the jobs (chromatrace-<kind>-tasks)
  std::filesystem::path directory;        // the output directory (absolute)
  std::filesystem::path result;           // the assembly's output
  std::vector<std::string> task_commands; // bash lines; "$THREADS" is the task's CPU count
  std::vector<std::filesystem::path> task_outputs;  // what each task leaves when it succeeded
  std::string assembly_command;           // bash line
  // Further files written beside the scripts (name in slurm/, contents), e.g. the Blender batch's pre-flight.
  std::vector<std::pair<std::string, std::string>> notes;
};

enum class Mode { Submit, Resume, DryRun };

// Writes the scripts and submits them (Submit: every task; Resume: the tasks whose output is missing, or only
// the assembly, or nothing when the result is there; DryRun: writes the scripts and prints the sbatch
// commands). Prints the job ids on stdout. InputError when sbatch is not on PATH (except DryRun) or when
// jobs of an earlier submission into the directory are still queued.
void submit(const FarmJob& job, const SlurmOptions& options, Mode mode);

// Follows the submission recorded in the directory until its jobs have left the queue, with progress on
// stderr. Returns 0 when the result is there; otherwise says which tasks' outputs are missing and where
// their logs are, cancels an assembly that can no longer run, and returns 1.
int wait(const FarmJob& job, bool progress);

}  // namespace ct::farm
