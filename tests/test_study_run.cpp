// Studies (`wheelins study`): running jobs and their results (a result writer failing
// half-way, a killed job, a failed job, an interrupt, datasets deleted when done), the same
// report however the jobs ran (one command, shuffled --job calls, GNU parallel, a Slurm
// array task by task), the experiment as a built-in study, and the example studies.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "io_test_util.hpp"
#include "study_test_util.hpp"
#include "wheelins/study/job.hpp"
#include "wheelins/study/report.hpp"
#include "wheelins/study/spec.hpp"

using namespace wheelins;
using namespace wheelins::study;
using namespace wheelins::studytest;
using wheelins::iotest::ScratchDir;
namespace fs = std::filesystem;

namespace {

/// The report files that depend only on the results (timing.csv does not).
const char* kReportFiles[] = {"report.md",
                              "summary.csv",
                              "differences.csv",
                              "jobs.csv",
                              "report.json",
                              "plots/drift.gp",
                              "plots/heading.gp",
                              "plots/data/drift_summary.csv",
                              "plots/data/drift_jobs.csv",
                              "plots/data/heading_summary.csv"};

/// A job file without its timing and with one name for the cache directory (the rest must
/// not depend on how or where the job ran).
std::string result_part(std::string json) {
  const auto a = json.find("\"timing\":");
  const auto b = json.find("\"status\":");
  if (a != std::string::npos && b != std::string::npos) json = json.substr(0, a) + json.substr(b);
  for (std::size_t p; (p = json.find("/parcache/")) != std::string::npos;)
    json.replace(p, 10, "/cache/");
  return json;
}

}  // namespace

// --- Jobs, results and reports ----------------------------------------------------------

TEST(StudyRun, FailingResultWriterLeavesNoResult) {
  ScratchDir d;
  put(d / "s.yaml", kSmall);
  const Study s = Study::load(d / "s.yaml");
  const Job j = s.job(2);
  JobOptions o;
  std::size_t written = 0;
  o.write_chunk = [&](int fd, std::string_view chunk) {
    // Half of the result reaches the disk, then the writer fails (a full disk, a kill).
    const std::size_t half = chunk.size() / 2;
    ASSERT_EQ(::write(fd, chunk.data(), half), static_cast<ssize_t>(half));
    written += half;
    throw std::runtime_error("disk full (simulated)");
  };
  const JobOutcome r = run_job(s, j, o);
  EXPECT_FALSE(r.ok);
  EXPECT_GT(written, 100u);
  EXPECT_HAS(r.error, "disk full (simulated)");
  EXPECT_FALSE(fs::exists(s.jobs_dir() / "2.json"));
  for (const auto& e : fs::directory_iterator(s.jobs_dir()))
    EXPECT_EQ(e.path().filename().string().find(".tmp-"), std::string::npos)
        << "left behind: " << e.path();
  EXPECT_EQ(job_status(s, j).state, JobState::kFailed);
  EXPECT_HAS(job_status(s, j).detail, "disk full");

  // A half-written result file (as a writer without the temporary file would leave) is
  // not read as complete either.
  std::string full;
  ASSERT_TRUE(run_job(s, j).ok);
  ASSERT_TRUE(read_file(s.jobs_dir() / "2.json", full));
  EXPECT_FALSE(fs::exists(s.jobs_dir() / "2.failed.json"));
  put(s.jobs_dir() / "2.json", full.substr(0, full.size() / 2));
  EXPECT_EQ(job_status(s, j).state, JobState::kUnreadable);
  std::string error;
  EXPECT_FALSE(read_job_record(s.jobs_dir() / "2.json", error));
  ReportOptions ro;
  ro.plots = false;
  const Report rep = write_report(s, ro);
  EXPECT_EQ(rep.done, 0u);
  EXPECT_EQ(rep.not_done.size(), 6u);
  EXPECT_HAS(rep.markdown, "## Jobs not in this report");
  EXPECT_HAS(rep.markdown, "| 2 | unreadable |");
  EXPECT_HAS(rep.markdown, "| 0 | missing |");
}

TEST(StudyRun, KilledJobLeavesNoCompleteResultAndResumes) {
  ScratchDir d;
  // Long enough (car, 150 s) to be killed while generating or navigating.
  put(d / "s.yaml",
      "simulate: {preset: car, chips: 1, static_s: 10, duration_s: 150}\n"
      "configurations: [triple]\n");
  const pid_t pid = ::fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    ::execl(WHEELINS_BINARY, WHEELINS_BINARY, "study", "run", (d / "s.yaml").c_str(), "--job", "0",
            "--quiet", static_cast<char*>(nullptr));
    ::_exit(127);
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(400));
  ::kill(pid, SIGKILL);
  int status = 0;
  ::waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFSIGNALED(status)) << "the job finished before the kill; make it longer";
  const Study s = Study::load(d / "s.yaml");
  EXPECT_FALSE(fs::exists(s.jobs_dir() / "0.json"));
  EXPECT_EQ(job_status(s, s.job(0)).state, JobState::kMissing);
  // The cache holds no dataset that is not complete (a killed generator's copy is temporary).
  const fs::path data = s.cache_dir() / s.job(0).dataset.cache_name;
  if (fs::exists(data)) {
    EXPECT_EQ(slurp(data / "settings.txt"), s.job(0).dataset.canonical);
  }

  const Cmd again = shell(bin() + " study run s.yaml --job 0", d.path());
  ASSERT_EQ(again.code, 0) << again.err;
  EXPECT_EQ(job_status(s, s.job(0)).state, JobState::kDone);
  for (const auto& e : fs::directory_iterator(s.cache_dir()))
    EXPECT_EQ(e.path().filename().string().rfind(".tmp.", 0), std::string::npos) << e.path();
  const Cmd done = shell(bin() + " study run s.yaml --job 0", d.path());
  EXPECT_EQ(done.code, 0);
  EXPECT_HAS(done.out, "already done");
}

TEST(StudyRun, FailedJobIsReported) {
  ScratchDir d;
  put(d / "s.yaml", std::string(kSmall).substr(0, std::string(kSmall).find("seeds")) +
                        "seeds: [1]\nconfigurations: [single, {name: bad, configuration: triple, "
                        "chips: [C1, C1, C9]}]\n");
  const Cmd r = shell(bin() + " study run s.yaml", d.path());
  EXPECT_EQ(r.code, 1);
  EXPECT_HAS(r.err, "job 1 failed");
  EXPECT_HAS(r.err, "C9");
  const std::string md = slurp(d / "s" / "report.md");
  EXPECT_HAS(md, "**1 not done**");
  EXPECT_HAS(md, "| 1 | failed | 1 | bad |");
  EXPECT_HAS(md, "C9");
  EXPECT_HAS(slurp(d / "s" / "jobs.csv"), "1,1,bad,failed,");
  const Cmd strict = shell(bin() + " study report s.yaml --strict --no-plots", d.path());
  EXPECT_EQ(strict.code, 3);
  EXPECT_HAS(strict.out, "job 1 (1 | bad): failed");
}

// A results directory holding the user's own report.md and plot script (issue 33, item 5):
// the jobs run, the report names the file it will not replace, and the user's files survive.
TEST(StudyRun, AReportNeverReplacesTheUsersOwnFiles) {
  ScratchDir d;
  put(d / "s.yaml", std::string(kSmall).substr(0, std::string(kSmall).find("seeds")) +
                        "seeds: [1]\nconfigurations: [single]\n");
  put(d / "r" / "report.md", "# my own notes\n");
  put(d / "r" / "plots" / "drift.gp", "# my own script\n");
  const Cmd r = shell(bin() + " study run s.yaml --results r --no-plots", d.path());
  EXPECT_NE(r.code, 0);
  EXPECT_HAS(r.err, "report.md");
  EXPECT_HAS(r.err, "not written by a study report");
  EXPECT_EQ(slurp(d / "r" / "report.md"), "# my own notes\n");
  EXPECT_EQ(slurp(d / "r" / "plots" / "drift.gp"), "# my own script\n");
  EXPECT_TRUE(fs::exists(d / "r" / "jobs" / "0.json"));  // the job's result is kept
  // Reporting again (there is no --force for a report) refuses the same way.
  const Cmd again = shell(bin() + " study report s.yaml --results r --no-plots", d.path());
  EXPECT_NE(again.code, 0);
  EXPECT_HAS(again.err, "not written by a study report");
  EXPECT_EQ(slurp(d / "r" / "report.md"), "# my own notes\n");
  // Once the user moves their notes away, the report is written.
  fs::remove(d / "r" / "report.md");
  fs::remove(d / "r" / "plots" / "drift.gp");
  const Cmd ok = shell(bin() + " study report s.yaml --results r --no-plots", d.path());
  EXPECT_EQ(ok.code, 0) << ok.err;
  EXPECT_HAS(slurp(d / "r" / "report.md"), "# Study");
}

TEST(StudyRun, SameReportHoweverTheJobsRan) {
  ScratchDir d;
  put(d / "s.yaml", kSmall);
  const Study s = Study::load(d / "s.yaml");
  ASSERT_EQ(s.job_count(), 6u);

  // 1. One command: every job on all cores, then the report.
  const Cmd one = shell(bin() + " study run s.yaml --results one --cache cache -j 2", d.path());
  ASSERT_EQ(one.code, 0) << one.err;
  EXPECT_HAS(one.out, "6 done, 0 failed");

  // 2. Separate --job calls in shuffled order (one of them a range), then the report.
  std::vector<std::string> order{"4", "1", "5", "0", "2-3"};
  std::shuffle(order.begin(), order.end(), std::mt19937(7));
  for (const auto& k : order) {
    const Cmd c =
        shell(bin() + " study run s.yaml --results shuffled --cache cache --job " + k, d.path());
    ASSERT_EQ(c.code, 0) << c.err;
  }
  const Cmd rep = shell(bin() + " study report s.yaml --results shuffled --cache cache", d.path());
  ASSERT_EQ(rep.code, 0) << rep.err;
  EXPECT_HAS(rep.out, "6 of 6 jobs in the report");

  // 3. GNU parallel, through the ssh-login path to this machine, with its own cache: three
  //    processes want each dataset at once.
  bool have_parallel = std::system("command -v parallel >/dev/null 2>&1") == 0;
  if (have_parallel) {
    const Cmd p = shell(script("study-parallel.sh") + " --wheelins " + bin() +
                            " -j 3 --sshlogin 3/: --results par --cache parcache s.yaml",
                        d.path());
    ASSERT_EQ(p.code, 0) << p.out << p.err;
  }

  // 4. The Slurm array script, task by task in reverse order.
  for (int task = 5; task >= 0; --task) {
    const Cmd c =
        shell("SLURM_ARRAY_TASK_ID=" + std::to_string(task) + " WHEELINS=" + bin() + " bash " +
                  script("study.sbatch") + " s.yaml --results slurm --cache cache --quiet",
              d.path());
    ASSERT_EQ(c.code, 0) << c.out << c.err;
  }
  ASSERT_EQ(shell(bin() + " study report s.yaml --results slurm --cache cache -q", d.path()).code,
            0);

  std::vector<std::string> ways{"shuffled", "slurm"};
  if (have_parallel) ways.push_back("par");
  for (const char* f : kReportFiles) {
    const std::string ref = slurp(d / "one" / f);
    ASSERT_FALSE(ref.empty()) << f;
    for (const auto& w : ways) EXPECT_EQ(slurp(d / w / f), ref) << w << "/" << f << " differs";
  }
  for (int k = 0; k < 6; ++k) {
    const std::string ref = result_part(slurp(d / "one" / "jobs" / (std::to_string(k) + ".json")));
    for (const auto& w : ways)
      EXPECT_EQ(result_part(slurp(d / w / "jobs" / (std::to_string(k) + ".json"))), ref)
          << w << " job " << k;
  }
  // The report has the numbers: every cell filled, intervals, paired differences, plots.
  const std::string md = slurp(d / "one" / "report.md");
  EXPECT_HAS(md, "6 in this report.");
  EXPECT_HAS(md, "Student t interval");
  EXPECT_HAS(md, "| triple - single |");
  EXPECT_EQ(md.find("| - |"), std::string::npos) << md;
  EXPECT_EQ(md.find("not done"), std::string::npos);
  if (std::system("command -v gnuplot >/dev/null 2>&1") == 0) {
    EXPECT_TRUE(fs::exists(d / "one" / "plots" / "drift.png"));
    EXPECT_TRUE(fs::exists(d / "one" / "plots" / "heading.png"));
    EXPECT_TRUE(fs::exists(d / "one" / "plots" / "paired_drift.png"));
  }
  // The plots say what their axes and marks are: an x label, the bars explained in the key,
  // and the paired differences of the compared configurations around a zero line.
  const std::string gp = slurp(d / "one" / "plots" / "drift.gp");
  EXPECT_HAS(gp, "set xlabel \"");
  EXPECT_HAS(gp, "square and bars: mean and its ");
  const std::string paired = slurp(d / "one" / "plots" / "paired_drift.gp");
  EXPECT_HAS(paired, "triple - single");
  EXPECT_HAS(paired, "set arrow from graph 0, first 0");
  EXPECT_HAS(md, "plots/paired_drift.png");
  // A done job is not run again; a changed setting makes the results stale, and they are kept.
  const Cmd resume = shell(bin() + " study run s.yaml --results one --cache cache", d.path());
  EXPECT_EQ(resume.code, 0);
  EXPECT_HAS(resume.out, "all 6 jobs already done");
  std::string changed = kSmall;
  changed.replace(changed.find("duration_s: 60"), 14, "duration_s: 61");
  put(d / "s.yaml", changed);
  const Cmd plan = shell(bin() + " study plan s.yaml --results one --cache cache", d.path());
  ASSERT_EQ(plan.code, 0) << plan.err;
  EXPECT_HAS(plan.out, "0 done, 0 failed, 6 stale");
  ASSERT_EQ(shell(bin() + " study run s.yaml --results one --cache cache --job 0", d.path()).code,
            0);
  EXPECT_EQ(
      std::distance(fs::directory_iterator(d / "one" / "jobs" / "stale"), fs::directory_iterator{}),
      1);
}

TEST(StudyRun, ExperimentIsABuiltInStudy) {
  ScratchDir d;
  ASSERT_EQ(
      shell(bin() + " simulate --out data --preset car --chips 2 --static 10 --duration 40 -q",
            d.path())
          .code,
      0);
  // One command, as before.
  const Cmd one = shell(
      bin() + " experiment data -o one --only single,triple,centralized --no-plots -q", d.path());
  ASSERT_EQ(one.code, 0) << one.err;
  EXPECT_HAS(one.out, "## Table 4: single Wheel-INS");
  EXPECT_HAS(one.out, "Each run navigates all the data (no --duration).");
  EXPECT_TRUE(fs::exists(d / "one" / "study.yaml"));
  // Sharded: the study file, jobs in reverse order, then the study's report.
  const Cmd prep = shell(
      bin() + " experiment data -o sharded --only single,triple,centralized --prepare", d.path());
  ASSERT_EQ(prep.code, 0) << prep.err;
  const Cmd count = shell(bin() + " study plan sharded/study.yaml --count", d.path());
  const int n = std::stoi(count.out);
  EXPECT_EQ(n, 4 + 4 + 4);  // 4 single, 4 triple, 4 centralized with two chips per module
  for (int k = n - 1; k >= 0; --k)
    ASSERT_EQ(
        shell(bin() + " study run sharded/study.yaml -q --job " + std::to_string(k), d.path()).code,
        0);
  const Cmd rep = shell(bin() + " study report sharded/study.yaml --no-plots -q", d.path());
  ASSERT_EQ(rep.code, 0) << rep.err;
  // The tables but the timing (Table 8, the wall time) are the same.
  auto tables = [](std::string md) {
    md = md.substr(0, md.find("## Table 8"));
    const auto a = md.find("runs in "), b = md.find(" s.", a);
    return md.erase(a, b - a);
  };
  EXPECT_EQ(tables(slurp(d / "sharded" / "experiment.md")),
            tables(slurp(d / "one" / "experiment.md")));
  auto metrics = [](const std::string& csv) {  // runs.csv without the timing columns
    std::string out;
    std::istringstream in(csv);
    for (std::string line; std::getline(in, line);) {
      std::vector<std::string> f;
      std::stringstream ls(line);
      for (std::string x; std::getline(ls, x, ',');) f.push_back(x);
      for (std::size_t i = 0; i < f.size(); ++i)
        if (i < 12 || i == 16) out += f[i] + ",";
      out += "\n";
    }
    return out;
  };
  EXPECT_EQ(metrics(slurp(d / "sharded" / "runs.csv")), metrics(slurp(d / "one" / "runs.csv")));
  // The one command's output appears as a whole: the study, its jobs, the tables.
  EXPECT_TRUE(fs::exists(d / "one" / "jobs" / "0.json"));
  EXPECT_TRUE(fs::exists(d / "one" / ".wheelins"));
  // Existing results are refused without --force, as before; another experiment's study too.
  const Cmd again = shell(
      bin() + " experiment data -o one --only single,triple,centralized --no-plots -q", d.path());
  EXPECT_EQ(again.code, 2);
  EXPECT_HAS(again.err, "already holds experiment");
  const Cmd other = shell(bin() + " experiment data -o sharded --only single --prepare", d.path());
  EXPECT_EQ(other.code, 2);
  EXPECT_HAS(other.err, "holds the study of another experiment");
  const Cmd full = shell(bin() + " experiment data -o one --prepare", d.path());
  EXPECT_EQ(full.code, 2);
  EXPECT_HAS(full.err, "holds the finished output of `wheelins experiment`");
  fs::create_directories(d / "mine");
  put(d / "mine" / "notes.txt", "the user's file");
  const Cmd foreign = shell(bin() + " experiment data -o mine --prepare", d.path());
  EXPECT_EQ(foreign.code, 2);
  EXPECT_HAS(foreign.err, "is not empty");
}

TEST(StudyRun, InterruptedRunKeepsFinishedJobsAndResumes) {
  ScratchDir d;
  std::string text = kSmall;
  text.replace(text.find("seeds: [1, 2]"), 13, "seeds: 1..5");
  put(d / "s.yaml", text);
  const pid_t pid = ::fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    const int null = ::open("/dev/null", O_WRONLY);
    ::dup2(null, 1);
    ::execl(WHEELINS_BINARY, WHEELINS_BINARY, "study", "run", (d / "s.yaml").c_str(), "-j", "1",
            "--no-report", static_cast<char*>(nullptr));
    ::_exit(127);
  }
  const Study s = Study::load(d / "s.yaml");
  // Wait for a first finished job, then Ctrl-C.
  for (int i = 0; i < 400 && !fs::exists(s.jobs_dir() / "0.json"); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(25));
  ::kill(pid, SIGINT);
  int status = 0;
  ::waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFEXITED(status));
  ASSERT_EQ(WEXITSTATUS(status), 130) << "the study finished before the interrupt";
  std::size_t done = 0;
  for (std::size_t k = 0; k < s.job_count(); ++k) {
    const JobState st = job_status(s, s.job(k)).state;
    EXPECT_TRUE(st == JobState::kDone || st == JobState::kMissing)
        << "job " << k << ": " << job_state_name(st);
    done += st == JobState::kDone;
  }
  EXPECT_GE(done, 1u);
  EXPECT_LT(done, s.job_count());
  for (const auto& e : fs::directory_iterator(s.jobs_dir()))
    EXPECT_EQ(e.path().filename().string().find(".tmp-"), std::string::npos) << e.path();
  const Cmd resume = shell(bin() + " study run s.yaml --no-report", d.path());
  ASSERT_EQ(resume.code, 0) << resume.err;
  EXPECT_HAS(resume.out, "(" + std::to_string(done) + " were done before)");
}

TEST(StudyRun, DatasetsDeletedWhenEveryJobOnThemIsDone) {
  ScratchDir d;
  put(d / "s.yaml",
      "keep_datasets: false\nsimulate: {preset: car, chips: 1, static_s: 5, duration_s: 12}\n"
      "seeds: [1, 2]\nconfigurations: [single, triple]\n");
  const Study s = Study::load(d / "s.yaml");
  const fs::path seed1 = s.cache_dir() / s.job(0).dataset.cache_name;
  ASSERT_EQ(shell(bin() + " study run s.yaml --job 0 -q", d.path()).code, 0);
  EXPECT_TRUE(fs::exists(seed1));  // job 1 still needs it
  ASSERT_EQ(shell(bin() + " study run s.yaml -q --no-report", d.path()).code, 0);
  EXPECT_FALSE(fs::exists(seed1));
  EXPECT_FALSE(fs::exists(s.cache_dir() / s.job(2).dataset.cache_name));
  for (std::size_t k = 0; k < 4; ++k) EXPECT_EQ(job_status(s, s.job(k)).state, JobState::kDone);
}

TEST(StudyRun, JobListParsing) {
  EXPECT_EQ(parse_job_list("3", 10), (std::vector<std::size_t>{3}));
  EXPECT_EQ(parse_job_list("7-9,1,8", 10), (std::vector<std::size_t>{1, 7, 8, 9}));
  EXPECT_HAS(iotest::error_of([] { parse_job_list("10", 10); }), "job 10 does not exist");
  EXPECT_HAS(iotest::error_of([] { parse_job_list("x", 10); }), "not a job number");
  EXPECT_HAS(iotest::error_of([] { parse_job_list("5-2", 10); }), "empty");
}

TEST(StudyRun, ExampleStudiesAreValid) {
  // studies/*.yaml: every axis value resolves and every run configuration reads.
  int files = 0;
  for (const auto& e : fs::directory_iterator(fs::path(WHEELINS_SOURCE_DIR) / "studies")) {
    if (e.path().extension() != ".yaml") continue;
    ++files;
    LoadOptions o;
    ScratchDir d;
    o.results_dir = d.path();  // nothing is written next to the examples
    const Study s = Study::load(e.path(), o);
    std::set<std::string> checked;
    const std::size_t n = s.job_count(), step = std::max<std::size_t>(1, n / 97);
    for (std::size_t k = 0; k < n; k += step) {
      const Job j = s.job(k);
      if (checked.insert(j.run_yaml).second) check_run_yaml(j.run_yaml, e.path().string());
    }
    EXPECT_GT(n, 100u) << e.path();
  }
  EXPECT_GE(files, 2);
}
