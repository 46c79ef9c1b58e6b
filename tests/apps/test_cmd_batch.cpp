// SPDX-License-Identifier: AGPL-3.0-or-later
// `surftex batch` end to end on Snakemake (issue 20): isolation of a broken
// input, resume, the generic --cluster mode, SIGTERM, progress, the contact
// sheet in headless Chromium, and the demo's page. Jobs are tiny renders and
// syntheses so that each test takes seconds.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <thread>

#include "apps/report_schema.h"
#include "batch/batch_manifest.h"
#include "test_support.h"

namespace fs = std::filesystem;
using surftex::test::run_surftex;
using surftex::test::shared_data;
using surftex::test::temp_dir;

namespace {

using surftex::test::file_bytes;
using surftex::test::write_text_file;

using surftex::test::q;

using surftex::test::read_json;

const nlohmann::json* job(const nlohmann::json& summary, const std::string& name) {
  for (const auto& j : summary["jobs"])
    if (j["name"] == name) return &j;
  return nullptr;
}

std::vector<nlohmann::json> json_lines(const std::string& text) {
  std::vector<nlohmann::json> v;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);)
    if (!line.empty()) v.push_back(nlohmann::json::parse(line));
  return v;
}

std::vector<std::string> started_jobs(const std::vector<nlohmann::json>& events) {
  std::vector<std::string> s;
  for (const auto& e : events)
    if (e["event"] == "start") s.push_back(e["job"]);
  std::sort(s.begin(), s.end());
  return s;
}

int count_of(const std::string& text, const std::string& what) {
  int n = 0;
  for (std::size_t p = text.find(what); p != std::string::npos; p = text.find(what, p + 1)) ++n;
  return n;
}

// Three tiny jobs and a broken mesh.
std::string four_jobs() {
  return "# a render, a synthesis, a method, and a broken input\n"
         "spot: render " + q(shared_data("meshes/spot.ply")) + " --size 64\n"
         "beans: synth " + q(shared_data("textures/coffee_beans_64.png")) + " --size 20x20 --window 5\n"
         "\n"
         "eight: patches " + q(shared_data("meshes/eight_genus2.off")) + " " +
         q(shared_data("textures/leather_64.png")) +
         " --patch-res 16 --rotations 1 --window 5 --max-patch-faces 400\n"
         "broken: render " + q(shared_data("broken/truncated.off")) + " --size 64\n";
}

void check_isolation_and_summary(const surftex::test::RunResult& run, const fs::path& out) {
  EXPECT_EQ(run.exit_code, 1) << run.err;
  const nlohmann::json s = read_json(out / "summary.json");
  EXPECT_EQ(s["counts"]["ok"], 3) << s.dump(2);
  EXPECT_EQ(s["counts"]["failed"], 1);
  const nlohmann::json* broken = job(s, "broken");
  ASSERT_NE(broken, nullptr);
  EXPECT_EQ((*broken)["status"], "failed");
  EXPECT_EQ((*broken)["exit_code"], 2);
  EXPECT_EQ((*broken)["error"].get<std::string>().rfind("error: ", 0), 0u) << broken->dump();
  EXPECT_NE((*broken)["command"].get<std::string>().find("truncated.off"), std::string::npos);
  EXPECT_FALSE(fs::exists(out / "broken"));
  EXPECT_TRUE(!fs::exists(out / ".surftex" / "stage") || fs::is_empty(out / ".surftex" / "stage"));
  EXPECT_NE(file_bytes(out / ".surftex" / "logs" / "broken.log").find("error:"), std::string::npos);
  for (const char* ok : {"spot", "beans", "eight"}) {
    const nlohmann::json* j = job(s, ok);
    ASSERT_NE(j, nullptr) << ok;
    EXPECT_EQ((*j)["status"], "ok") << j->dump();
    EXPECT_GT((*j)["seconds"].get<double>(), 0.0);
    EXPECT_TRUE(fs::exists(out / ok / "report.json")) << ok;
    EXPECT_FALSE((*j)["images"].empty()) << j->dump();
    for (const auto& f : (*j)["outputs"]) EXPECT_TRUE(fs::exists(out / f.get<std::string>())) << f;
  }
  EXPECT_TRUE(fs::exists(out / "eight" / "render.png"));
  EXPECT_TRUE(fs::exists(out / "spot" / "render.png"));
  // The keys every report has (issue 16 item 7): the manifest hashed, the sheet and the jobs' files as outputs.
  surftex::test::expect_report_schema(s, "batch", {}, {(out / "index.html").string(), (out / "spot" / "render.png").string()});
  ASSERT_EQ(s["inputs"].size(), 1u);
  EXPECT_EQ(s["inputs"][0]["path"], s["manifest"]);
  EXPECT_TRUE(fs::exists(out / "beans" / "synth.png"));
  EXPECT_FALSE(job(s, "eight")->at("figures").empty());  // seam ratio, patches, faces
  EXPECT_TRUE(job(s, "eight")->at("figures").contains("seam ratio"));
  // The Snakefile has one rule per job and declares the inputs it found.
  const std::string sf = file_bytes(out / "Snakefile");
  EXPECT_EQ(count_of(sf, "\nrule job_"), 4);
  EXPECT_NE(sf.find(shared_data("meshes/spot.ply")), std::string::npos);
}

void check_pipe_progress(const surftex::test::RunResult& run) {
  const std::regex line(R"(batch: \[(\d)/4\] (ok|failed) +(\w+) [0-9.]+ s.*\((\d) running, (\d) failed, [0-9:]+ elapsed, ETA [-0-9:]+\))");
  int lines = 0;
  std::istringstream in(run.err);
  for (std::string l; std::getline(in, l);) lines += std::regex_match(l, line) ? 1 : 0;
  EXPECT_EQ(lines, 4) << run.err;
  EXPECT_NE(run.err.find("batch: 4 of 4 jobs to run (0 up to date)"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("batch: 3 ok, 1 failed of 4 jobs"), std::string::npos) << run.err;
  EXPECT_EQ(run.err.find('\r'), std::string::npos);
}

void check_contact_sheet(const fs::path& out) {
  const std::string html = file_bytes(out / "index.html");
  EXPECT_EQ(count_of(html, "<article class=\"card"), 4);
  EXPECT_LT(html.find("id=\"card-broken\""), html.find("id=\"card-spot\""));  // failed first
  EXPECT_EQ(html.find("src=\"/"), std::string::npos);
  EXPECT_EQ(html.find(out.string()), std::string::npos);  // relative links only
  const fs::path profile = temp_dir("chromium-profile");
  const fs::path dom = profile / "dom.html";
  const std::string cmd =
      "chromium --headless --no-sandbox --disable-gpu --disable-quic --no-first-run --disable-background-networking "
      "--disable-component-update --disable-sync --user-data-dir=" + q(profile.string()) +
      " --virtual-time-budget=10000 --dump-dom " + q("file://" + (out / "index.html").string()) + " > " +
      q(dom.string()) + " 2>/dev/null";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << "chromium failed (scripts/setup.sh --tests installs it)";
  const std::string d = file_bytes(dom);
  EXPECT_EQ(count_of(d, "<article class=\"card"), 4) << d.substr(0, 2000);
  const int images = count_of(d, "<img ");
  EXPECT_GE(images, 3);
  EXPECT_EQ(count_of(d, "data-loaded=\"1\""), images) << "an image did not load";
  EXPECT_EQ(count_of(d, "data-loaded=\"0\""), 0);
  EXPECT_NE(d.find("data-images-ok=\"" + std::to_string(images) + "\""), std::string::npos);
  fs::remove_all(profile);
}

}  // namespace

TEST(BatchCli, ABadManifestIsRefusedWithFileAndLineAndNothingIsWritten) {
  const std::string dir = temp_dir("batch-bad");
  write_text_file(fs::path(dir) / "jobs.txt", "a: render x.off\n# two lines later\nA: render y.off\n");
  auto r = run_surftex("batch " + q(dir + "/jobs.txt") + " -o " + q(dir + "/out"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("error: " + dir + "/jobs.txt:3: the job name 'A' is used again (first on line 1)"),
            std::string::npos)
      << r.err;
  write_text_file(fs::path(dir) / "jobs.txt", "a: render x.off -o mine.png\n");
  r = run_surftex("batch " + q(dir + "/jobs.txt") + " -o " + q(dir + "/out"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("jobs.txt:1: job 'a' gives -o"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(fs::path(dir) / "out"));
  // A folder the batch did not make is not taken over.
  write_text_file(fs::path(dir) / "jobs.txt", "a: render x.off\n");
  write_text_file(fs::path(dir) / "mine" / "keep.txt", "user file");
  r = run_surftex("batch " + q(dir + "/jobs.txt") + " -o " + q(dir + "/mine"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("was not made by `surftex batch`"), std::string::npos) << r.err;
  EXPECT_EQ(file_bytes(fs::path(dir) / "mine" / "keep.txt"), "user file");
  fs::remove_all(dir);
}

TEST(BatchCli, EverySubcommandIsBatchableOrRefusedOnPurpose) {
  const auto r = run_surftex("--help");
  ASSERT_EQ(r.exit_code, 0);
  const std::size_t at = r.out.find("SUBCOMMANDS:") != std::string::npos ? r.out.find("SUBCOMMANDS:")
                                                                          : r.out.find("Subcommands:");
  ASSERT_NE(at, std::string::npos) << r.out;
  std::istringstream in(r.out.substr(at));
  std::string line;
  std::getline(in, line);
  int n = 0;
  for (; std::getline(in, line);) {
    std::istringstream ls(line);
    std::string name;
    if (line.empty() || line[0] != ' ' || !(ls >> name)) continue;
    surftex::batch::OutputKind kind;
    const auto& refused = surftex::batch::batch_refused_subcommands();
    EXPECT_TRUE(surftex::batch::batch_output_kind(name, kind) ||
                std::find(refused.begin(), refused.end(), name) != refused.end())
        << "subcommand '" << name << "' is neither in batch_output_kind nor refused on purpose";
    ++n;
  }
  EXPECT_GE(n, 10);
}

// One batch of four tiny jobs, one broken, checked for isolation, summary,
// pipe progress and the contact sheet in Chromium: one test, because ctest
// runs each test in its own process and the batch is the costly part.
TEST(BatchCli, FourJobsOneBrokenIsolatedSummarizedAndShownOnTheContactSheet) {
  const fs::path dir = temp_dir("batch-four");
  write_text_file(dir / "jobs.txt", four_jobs());
  const auto run =
      run_surftex("batch " + q((dir / "jobs.txt").string()) + " -o " + q((dir / "out").string()) + " --jobs 2");
  {
    SCOPED_TRACE("isolation and summary");
    check_isolation_and_summary(run, dir / "out");
  }
  {
    SCOPED_TRACE("one progress line per job in a pipe");
    check_pipe_progress(run);
  }
  {
    SCOPED_TRACE("the contact sheet in headless Chromium");
    check_contact_sheet(dir / "out");
  }
  fs::remove_all(dir);
}

TEST(BatchCli, ASecondRunRerunsOnlyMissingOrChangedJobs) {
  const fs::path dir = temp_dir("batch-resume");
  fs::copy_file(shared_data("meshes/eight_genus2.off"), dir / "local.off");
  const std::string tex = q(shared_data("textures/coffee_beans_64.png"));
  auto manifest = [&](const std::string& size_a) {
    write_text_file(dir / "jobs.txt", "a: render " + q(shared_data("meshes/fish_blub.obj")) + " --size " + size_a +
                                "\nb: synth " + tex + " --size 16x16 --window 5\nc: render local.off --size 32\n");
  };
  manifest("32");
  const std::string run = "batch " + q((dir / "jobs.txt").string()) + " -o " + q((dir / "out").string()) + " --jobs 2";
  auto r = run_surftex(run + " --dry-run");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(count_of(r.out, "would run "), 3) << r.out;
  EXPECT_FALSE(fs::exists(dir / "out"));  // a dry run writes nothing
  r = run_surftex(run + " --json-progress");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  auto events = json_lines(r.out);
  EXPECT_EQ(started_jobs(events), (std::vector<std::string>{"a", "b", "c"}));
  EXPECT_EQ(events.back()["event"], "end");
  EXPECT_EQ(events.back()["ok"], 3);
  // Nothing changed: nothing runs.
  r = run_surftex(run + " --json-progress");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(started_jobs(json_lines(r.out)).empty()) << r.out;
  EXPECT_EQ(read_json(dir / "out" / "summary.json")["counts"]["ok"], 3);
  // Changed arguments of a, a newer input of c: those two run again.
  manifest("40");
  // (Snakemake compares the content: a touched input with the same bytes does not re-run its job.)
  fs::permissions(dir / "local.off", fs::perms::owner_write, fs::perm_options::add);
  fs::copy_file(shared_data("meshes/knot.off"), dir / "local.off", fs::copy_options::overwrite_existing);
  r = run_surftex(run + " --dry-run");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("would run a:"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("would run c:"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("would run b:"), std::string::npos) << r.out;
  r = run_surftex(run + " --json-progress");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  events = json_lines(r.out);
  EXPECT_EQ(started_jobs(events), (std::vector<std::string>{"a", "c"})) << r.out;
  EXPECT_EQ(events.front()["event"], "plan");
  EXPECT_EQ(events.front()["to_run"], 2);
  const nlohmann::json report = read_json(dir / "out" / "a" / "report.json");
  EXPECT_EQ(report["width"], 40);
  fs::remove_all(dir);
}

// Subcommands that write OUTDIR/report.json themselves (patches, subdiv,
// material-map, demo) run as folder jobs without a --report of the batch's
// (naming the same file twice is refused): the job succeeds and the summary
// reads the report the subcommand wrote.
TEST(BatchCli, FolderJobsThatWriteTheirOwnReportSucceedAndAreSummarized) {
  const fs::path dir = temp_dir("batch-folder-jobs");
  write_text_file(dir / "jobs.txt", "sub: subdiv " + q(shared_data("meshes/eight_genus2.off")) + " " +
                              q(shared_data("textures/leather_64.png")) +
                              " --levels 0 --passes 1 --region 5 --pyramid --atlas-size 256\n");
  const auto r =
      run_surftex("batch " + q((dir / "jobs.txt").string()) + " -o " + q((dir / "out").string()) + " --jobs 1");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json s = read_json(dir / "out" / "summary.json");
  EXPECT_EQ(s["counts"]["ok"], 1) << s.dump(2);
  const nlohmann::json* j = job(s, "sub");
  ASSERT_NE(j, nullptr);
  EXPECT_EQ((*j)["status"], "ok");
  const nlohmann::json report = read_json(dir / "out" / "sub" / "report.json");
  EXPECT_EQ(report["command"], "subdiv");
  EXPECT_FALSE((*j)["outputs"].empty());
  EXPECT_FALSE((*j)["images"].empty()) << j->dump(2);
  fs::remove_all(dir);
}

TEST(BatchCli, ABadInputIsNotRetriedUntilItChangesOrRetryFailedIsGiven) {
  const fs::path dir = temp_dir("batch-retry");
  fs::copy_file(shared_data("broken/truncated.off"), dir / "in.off");
  write_text_file(dir / "jobs.txt", "bad: render in.off --size 16\n");
  const std::string run = "batch " + q((dir / "jobs.txt").string()) + " -o " + q((dir / "out").string()) + " --json-progress";
  auto r = run_surftex(run);
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_EQ(started_jobs(json_lines(r.out)), (std::vector<std::string>{"bad"}));
  // Unchanged: exit code 2 is surftex's refusal of a bad input, the same every time.
  r = run_surftex(run);
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_TRUE(started_jobs(json_lines(r.out)).empty()) << r.out;
  EXPECT_EQ(read_json(dir / "out" / "summary.json")["jobs"][0]["status"], "failed");
  r = run_surftex(run + " --retry-failed");
  EXPECT_EQ(started_jobs(json_lines(r.out)), (std::vector<std::string>{"bad"})) << r.out;
  // A changed input is tried again, and now succeeds.
  fs::permissions(dir / "in.off", fs::perms::owner_write, fs::perm_options::add);
  fs::copy_file(shared_data("meshes/eight_genus2.off"), dir / "in.off", fs::copy_options::overwrite_existing);
  r = run_surftex(run);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(started_jobs(json_lines(r.out)), (std::vector<std::string>{"bad"})) << r.out;
  EXPECT_TRUE(fs::exists(dir / "out" / "bad" / "render.png"));
  fs::remove_all(dir);
}

TEST(BatchCli, TheSnakefileRunsThroughGenericClusterModeWithAStandInSubmitScript) {
  const fs::path dir = temp_dir("batch-cluster");
  // A stand-in for sbatch/qsub: records the submission, runs Snakemake's job
  // script in the background on this machine, prints a job id.
  write_text_file(dir / "submit.sh",
        "#!/bin/bash\necho \"$@\" >> " + q((dir / "submitted.txt").string()) +
            "\nbash \"${@: -1}\" > /dev/null 2>&1 &\necho standin-$!\n");
  write_text_file(dir / "jobs.txt", "s: render " + q(shared_data("meshes/knot.off")) + " --size 32\nt: render " +
                              q(shared_data("meshes/fish_blub.obj")) + " --size 32\n");
  const auto r = run_surftex("batch " + q((dir / "jobs.txt").string()) + " -o " + q((dir / "out").string()) +
                             " --jobs 2 --engine-args \"--cluster 'bash " + (dir / "submit.sh").string() + "' --latency-wait 30\"");
  ASSERT_EQ(r.exit_code, 0) << r.err << file_bytes(dir / "out" / ".surftex" / "snakemake.log");
  const std::string submitted = file_bytes(dir / "submitted.txt");
  EXPECT_EQ(count_of(submitted, "snakejob."), 2) << submitted;
  const nlohmann::json s = read_json(dir / "out" / "summary.json");
  EXPECT_EQ(s["counts"]["ok"], 2);
  EXPECT_TRUE(fs::exists(dir / "out" / "s" / "render.png"));
  EXPECT_TRUE(fs::exists(dir / "out" / "t" / "render.png"));
  fs::remove_all(dir);
}

TEST(BatchCli, SigtermStopsTheBatchWithoutPartialOutputAndTheNextRunCompletesIt) {
  const fs::path dir = temp_dir("batch-sigterm");
  // A synthesis that takes a few seconds.
  write_text_file(dir / "jobs.txt",
        "slow: synth " + q(shared_data("textures/leather_64.png")) + " --size 128x128 --window 9\n");
  const fs::path out = dir / "out";
  const pid_t pid = ::fork();
  if (pid == 0) {
    const int fd = ::open((dir / "stderr.txt").c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    ::dup2(fd, 2);
    ::dup2(fd, 1);
    ::execl(SURFTEX_BINARY, SURFTEX_BINARY, "batch", (dir / "jobs.txt").c_str(), "-o", out.c_str(), "--jobs", "1",
            static_cast<char*>(nullptr));
    ::_exit(127);
  }
  ASSERT_GT(pid, 0);
  // Wait until the job is running (its stage folder exists), then stop the batch.
  const fs::path stage = out / ".surftex" / "stage" / "slow";
  const auto t0 = std::chrono::steady_clock::now();
  while (!fs::exists(stage) && std::chrono::steady_clock::now() - t0 < std::chrono::seconds(120))
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  ASSERT_TRUE(fs::exists(stage)) << file_bytes(dir / "stderr.txt");
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  ::kill(pid, SIGTERM);
  int status = 0;
  ::waitpid(pid, &status, 0);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 128 + SIGTERM) << file_bytes(dir / "stderr.txt");
  EXPECT_FALSE(fs::exists(out / "slow"));
  EXPECT_FALSE(fs::exists(stage));
  const nlohmann::json s = read_json(out / "summary.json");
  EXPECT_EQ(job(s, "slow")->at("status"), "interrupted") << s.dump(2);
  // No process of the batch is left behind: the lock is free and a new run completes the job.
  const auto r = run_surftex("batch " + q((dir / "jobs.txt").string()) + " -o " + q(out.string()));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(fs::exists(out / "slow" / "synth.png"));
  EXPECT_TRUE(fs::exists(out / "slow" / "report.json"));
  EXPECT_EQ(read_json(out / "summary.json")["counts"]["ok"], 1);
  fs::remove_all(dir);
}

TEST(BatchCli, TheDemoEndsWithTheSameContactSheet) {
  const fs::path dir = fs::path(temp_dir("batch-demo")) / "demo";
  const auto r = run_surftex("demo -o " + q(dir.string()) + " --threads 2");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string html = file_bytes(dir / "index.html");
  const nlohmann::json report = read_json(dir / "report.json");
  ASSERT_TRUE(report.contains("steps"));
  for (const auto& [name, step] : report["steps"].items())
    EXPECT_NE(html.find("id=\"card-" + name + "\""), std::string::npos) << name;
  // Every image the page shows exists, by a relative link; every image the demo wrote is shown.
  const std::regex src("<img src=\"([^\"]+)\"");
  int shown = 0;
  for (auto it = std::sregex_iterator(html.begin(), html.end(), src); it != std::sregex_iterator(); ++it, ++shown) {
    const std::string s = (*it)[1];
    EXPECT_NE(s[0], '/') << s;
    EXPECT_TRUE(fs::exists(dir / s)) << s;
  }
  int pngs = 0;
  for (const auto& e : fs::recursive_directory_iterator(dir)) pngs += e.path().extension() == ".png" ? 1 : 0;
  EXPECT_EQ(shown, pngs);
  EXPECT_GE(shown, 10);
  fs::remove_all(dir.parent_path());
}
