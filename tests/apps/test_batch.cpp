// SPDX-License-Identifier: AGPL-3.0-or-later
// The batch runner's library (apps/batch, issue 20): manifest parsing, the
// Snakefile, job staging, tolerant report reading, the contact sheet, progress.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "batch/batch_job.h"
#include "batch/batch_manifest.h"
#include "batch/batch_progress.h"
#include "batch/batch_snakefile.h"
#include "batch/batch_summary.h"
#include "batch/contact_sheet.h"
#include "batch/snakemake_engine.h"
#include "geometry/errors.h"
#include "test_support.h"

namespace fs = std::filesystem;
using namespace surftex::batch;
using surftex::InvalidInputError;

namespace {

using surftex::test::file_bytes;
using surftex::test::write_text_file;

int count_substr(const std::string& t, const std::string& what) {
  int n = 0;
  for (std::size_t p = t.find(what); p != std::string::npos; p = t.find(what, p + 1)) ++n;
  return n;
}

// The message of the InvalidInputError `f` throws, or "" if it throws none.
template <class F>
std::string error_of(F f) {
  try {
    f();
  } catch (const InvalidInputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(BatchManifest, SplitsWordsAsAShellDoes) {
  EXPECT_EQ(split_shell_words("a  b\tc"), (std::vector<std::string>{"a", "b", "c"}));
  EXPECT_EQ(split_shell_words("'a b' \"c \\\"d\\\"\" e\\ f"), (std::vector<std::string>{"a b", "c \"d\"", "e f"}));
  EXPECT_EQ(split_shell_words("x # a comment"), (std::vector<std::string>{"x"}));
  EXPECT_EQ(split_shell_words("x#not-a-comment ''"), (std::vector<std::string>{"x#not-a-comment", ""}));
  EXPECT_THROW(split_shell_words("'open"), InvalidInputError);
  EXPECT_THROW(split_shell_words("\"open"), InvalidInputError);
}

TEST(BatchManifest, ParsesJobsCommentsBlankLinesAndContinuations) {
  const std::string text =
      "# jobs\n"
      "\n"
      "cow: patches cow.off 'my tex.png' --patch-res 32\n"
      "  bunny-2.a : subdiv bunny.obj tex.png \\\n"
      "    --levels 1\r\n"
      "tiny: render m.off # the render\n";
  const BatchManifest m = parse_batch_manifest(text, "dir/jobs.txt");
  ASSERT_EQ(m.jobs.size(), 3u);
  EXPECT_EQ(m.jobs[0].name, "cow");
  EXPECT_EQ(m.jobs[0].subcommand, "patches");
  EXPECT_EQ(m.jobs[0].args, (std::vector<std::string>{"cow.off", "my tex.png", "--patch-res", "32"}));
  EXPECT_EQ(m.jobs[0].line, 3);
  EXPECT_TRUE(m.jobs[0].output.folder);
  EXPECT_EQ(m.jobs[1].name, "bunny-2.a");
  EXPECT_EQ(m.jobs[1].args, (std::vector<std::string>{"bunny.obj", "tex.png", "--levels", "1"}));
  EXPECT_EQ(m.jobs[1].line, 4);
  EXPECT_EQ(m.jobs[2].line, 6);
  EXPECT_FALSE(m.jobs[2].output.folder);
  EXPECT_EQ(m.jobs[2].output.file, "render.png");
  EXPECT_EQ(fs::path(m.dir), fs::absolute("dir").lexically_normal());
  EXPECT_EQ(job_command_line(m.jobs[0]), "surftex patches cow.off 'my tex.png' --patch-res 32");
}

TEST(BatchManifest, ErrorsNameTheFileAndLine) {
  auto parse = [](const std::string& t) { return error_of([&] { parse_batch_manifest(t, "jobs.txt"); }); };
  EXPECT_NE(parse("a: render x.off\n\nb: render y.off -o out.png\n").find("jobs.txt:3: job 'b' gives -o"),
            std::string::npos);
  EXPECT_NE(parse("a: render x.off --output=o.png\n").find("jobs.txt:1: job 'a' gives --output"), std::string::npos);
  EXPECT_NE(parse("a: patches x.off t.png --report r.json\n").find("gives --report"), std::string::npos);
  EXPECT_NE(parse("a: quilt x.off s.obj --render r.png\n").find("gives --render"), std::string::npos);
  const std::string dup = parse("cow: render a.off\n# x\nCow: render b.off\n");
  EXPECT_NE(dup.find("jobs.txt:3:"), std::string::npos) << dup;
  EXPECT_NE(dup.find("first on line 1"), std::string::npos) << dup;
  EXPECT_NE(parse("a/b: render x.off\n").find("jobs.txt:1: the job name 'a/b' may only contain"), std::string::npos);
  EXPECT_NE(parse("..: render x.off\n").find("must start with a letter or digit"), std::string::npos);
  EXPECT_NE(parse("index.html: render x.off\n").find("reserved"), std::string::npos);
  EXPECT_NE(parse("a render x.off\n").find("jobs.txt:1: expected 'NAME: SUBCOMMAND"), std::string::npos);
  EXPECT_NE(parse("a:\n").find("has no subcommand"), std::string::npos);
  EXPECT_NE(parse("a: frobnicate x\n").find("'frobnicate' is not a surftex subcommand"), std::string::npos);
  EXPECT_NE(parse("a: info x.off\n").find("writes no output"), std::string::npos);
  EXPECT_NE(parse("a: render 'x.off\n").find("jobs.txt:1: unterminated single quote"), std::string::npos);
  EXPECT_NE(parse("a: render \xff.off\n").find("jobs.txt:1: the line is not UTF-8"), std::string::npos);
  // -o inside a quoted value of another option is a value, not an option.
  EXPECT_EQ(parse("a: render 'x -o y.off' --view 1 2\n"), "");
}

TEST(BatchManifest, ReadingAnEmptyManifestIsRefused) {
  const std::string dir = surftex::test::temp_dir("batch-empty");
  write_text_file(fs::path(dir) / "jobs.txt", "# nothing\n\n");
  EXPECT_THROW(read_batch_manifest(dir + "/jobs.txt"), InvalidInputError);
  EXPECT_THROW(read_batch_manifest(dir + "/absent.txt"), surftex::IOError);
  fs::remove_all(dir);
}

TEST(BatchSnakefile, InputsAreExistingFilesThatLookLikePathsOutsideOut) {
  const fs::path dir = surftex::test::temp_dir("batch-inputs");
  write_text_file(dir / "m.off", "OFF\n");
  write_text_file(dir / "up", "a file named like an option value\n");
  write_text_file(dir / "tile" / "tile.json", "{}");
  write_text_file(dir / "tile" / "layer_000.png", "x");
  write_text_file(dir / "out" / "a" / "x.obj", "");
  BatchJob j;
  j.subcommand = "material-map";
  j.args = {"m.off", "--field", "up", "--tile", "tile", "--other=m.off", "missing.off", "out/a/x.obj", "0.5"};
  const std::vector<std::string> in = job_input_files(j, dir.string(), (dir / "out").string());
  EXPECT_EQ(in, (std::vector<std::string>{(dir / "m.off").string(), (dir / "tile" / "layer_000.png").string(),
                                          (dir / "tile" / "tile.json").string()}));
  fs::remove_all(dir);
}

TEST(BatchSnakefile, OneRulePerJobWithQuotedCommandAndDirectoryOutput) {
  const BatchManifest m = parse_batch_manifest(
      "a-1: render 'x {y}.off' --size 64\nb: patches m.off t.png --threads 2\na.1: synth t.png --size 8x8\n", "/tmp/j.txt");
  EXPECT_EQ(job_rule_names(m), (std::vector<std::string>{"job_a_1", "job_b", "job_a_1_2"}));
  const std::string t = snakefile_text(m, "/opt/bin/surftex", "/opt/bin/surftex-job", "/tmp/out");
  EXPECT_NE(t.find("rule all:"), std::string::npos);
  EXPECT_NE(t.find("rule job_a_1:"), std::string::npos);
  EXPECT_NE(t.find("rule job_a_1_2:"), std::string::npos);
  EXPECT_NE(t.find("output: directory(\"a-1\")"), std::string::npos);
  EXPECT_NE(t.find("log: log=\".surftex/logs/b.log\", status=\".surftex/status/b.json\""), std::string::npos);
  // Braces doubled for Snakemake's formatting, then shell-quoted.
  EXPECT_NE(t.find("'x {{y}}.off'"), std::string::npos) << t;
  EXPECT_NE(t.find("--output-file render.png --threads {threads} -- render"), std::string::npos) << t;
  // A job's own --threads is the rule's threads, and not given twice.
  EXPECT_NE(t.find("    threads: 2\n"), std::string::npos);
  EXPECT_NE(t.find("--workdir /tmp -- patches m.off t.png --threads 2"), std::string::npos) << t;
  EXPECT_NE(t.find("shell: \"/opt/bin/surftex-job --surftex /opt/bin/surftex --name b "), std::string::npos) << t;
  EXPECT_EQ(python_string("a\"b\\c\nd"), "\"a\\\"b\\\\c\\x0ad\"");
}

TEST(BatchSnakefile, TheFingerprintFollowsTheCommandAndTheInputFiles) {
  const fs::path dir = surftex::test::temp_dir("batch-fingerprint");
  write_text_file(dir / "m.off", "OFF\n0 0 0\n");
  BatchJob j;
  j.subcommand = "render";
  j.args = {"m.off", "--size", "64"};
  const std::string out = (dir / "out").string();
  const std::string f0 = job_fingerprint(j, dir.string(), out);
  EXPECT_EQ(f0.size(), 16u);
  EXPECT_EQ(job_fingerprint(j, dir.string(), out), f0);
  BatchJob k = j;
  k.args[2] = "32";
  EXPECT_NE(job_fingerprint(k, dir.string(), out), f0);
  fs::last_write_time(dir / "m.off", fs::last_write_time(dir / "m.off") - std::chrono::seconds(10));
  const std::string f1 = job_fingerprint(j, dir.string(), out);
  EXPECT_NE(f1, f0);
  write_text_file(dir / "m.off", "OFF\n0 0 0 \n");
  EXPECT_NE(job_fingerprint(j, dir.string(), out), f1);
  fs::remove_all(dir);
}

TEST(BatchJob, AJobThatSucceedsIsMovedIntoPlaceWhole) {
  const fs::path out = surftex::test::temp_dir("batch-job-ok");
  const fs::path work = surftex::test::temp_dir("batch-job-work");
  // A stand-in for surftex: /bin/sh runs the script with "-o STAGE --report R".
  write_text_file(work / "job.sh", "echo note: working >&2\necho hello > \"$2/out.txt\"\ncat input.txt > \"$2/copy.txt\"\n");
  write_text_file(work / "input.txt", "from the manifest folder\n");
  JobRunOptions o;
  o.name = "j1";
  o.out_dir = out.string();
  o.workdir = work.string();
  o.surftex_exe = "/bin/sh";
  o.command = {"job.sh"};
  EXPECT_EQ(run_batch_job(o), 0);
  EXPECT_EQ(file_bytes(out / "j1" / "out.txt"), "hello\n");
  EXPECT_EQ(file_bytes(out / "j1" / "copy.txt"), "from the manifest folder\n");
  EXPECT_FALSE(fs::exists(out / job_stage_path("j1")));
  EXPECT_NE(file_bytes(out / job_log_path("j1")).find("note: working"), std::string::npos);
  JobStatus s;
  ASSERT_TRUE(read_job_status((out / job_status_path("j1")).string(), s));
  EXPECT_EQ(s.status, "ok");
  EXPECT_EQ(s.exit_code, 0);
  EXPECT_EQ(s.command, "surftex job.sh");
  BatchJob as_job;
  as_job.subcommand = "job.sh";
  EXPECT_EQ(s.fingerprint, job_fingerprint(as_job, work.string(), out.string()));
  EXPECT_GE(s.seconds, 0.0);
  // A second run replaces the folder whole.
  write_text_file(work / "job.sh", "echo again > \"$2/other.txt\"\n");
  EXPECT_EQ(run_batch_job(o), 0);
  EXPECT_FALSE(fs::exists(out / "j1" / "out.txt"));
  EXPECT_TRUE(fs::exists(out / "j1" / "other.txt"));
  fs::remove_all(out);
  fs::remove_all(work);
}

TEST(BatchJob, AFailedJobLeavesNoFolderAndRecordsItsErrorLine) {
  const fs::path out = surftex::test::temp_dir("batch-job-fail");
  write_text_file(out / "job.sh", "echo partial > \"$2/part.txt\"\necho 'error: mesh is broken' >&2\necho more >&2\nexit 2\n");
  JobRunOptions o;
  o.name = "bad";
  o.out_dir = out.string();
  o.workdir = out.string();
  o.surftex_exe = "/bin/sh";
  o.command = {"job.sh"};
  EXPECT_EQ(run_batch_job(o), 2);
  EXPECT_FALSE(fs::exists(out / "bad"));
  EXPECT_FALSE(fs::exists(out / job_stage_path("bad")));
  JobStatus s;
  ASSERT_TRUE(read_job_status((out / job_status_path("bad")).string(), s));
  EXPECT_EQ(s.status, "failed");
  EXPECT_EQ(s.exit_code, 2);
  EXPECT_EQ(s.error, "error: mesh is broken");
  // Exit 0 without output is a failure too.
  write_text_file(out / "job.sh", "true\n");
  EXPECT_NE(run_batch_job(o), 0);
  ASSERT_TRUE(read_job_status((out / job_status_path("bad")).string(), s));
  EXPECT_EQ(s.error, "error: the job wrote no output");
  EXPECT_FALSE(fs::exists(out / "bad"));
  fs::remove_all(out);
}

TEST(BatchJob, OptionsGoBeforeTheJobsArguments) {
  const fs::path out = surftex::test::temp_dir("batch-job-argv");
  write_text_file(out / "job.sh", "printf '%s|' \"$@\" > \"$(dirname \"$2\")/argv.txt\"\n");
  JobRunOptions o;
  o.name = "a";
  o.out_dir = out.string();
  o.workdir = out.string();
  o.surftex_exe = "/bin/sh";
  o.output_file = "render.png";
  o.threads = 1;
  o.command = {"job.sh", "x.off", "--", "y"};
  ASSERT_EQ(run_batch_job(o), 0);
  // $2 was STAGE/render.png, a file: the script wrote argv.txt next to it, in the job folder.
  const std::string argv = file_bytes(out / "a" / "argv.txt");
  const std::string stage = (out / job_stage_path("a")).string();
  EXPECT_EQ(argv, "-o|" + stage + "/render.png|--report|" + stage + "/report.json|--threads|1|x.off|--|y|");
  fs::remove_all(out);
}

TEST(BatchSummary, ReadsOldAndNewReportKeys) {
  EXPECT_DOUBLE_EQ(report_total_seconds(nlohmann::json::parse(R"({"seconds":{"total":3.5,"read":1}})")), 3.5);
  EXPECT_DOUBLE_EQ(report_total_seconds(nlohmann::json::parse(R"({"seconds":2.5})")), 2.5);
  EXPECT_DOUBLE_EQ(report_total_seconds(nlohmann::json::parse(R"({"seconds_total":4})")), 4.0);
  EXPECT_DOUBLE_EQ(report_total_seconds(nlohmann::json::parse(R"({"x":1})")), -1.0);
  // subdiv: the atlas under "outputs" (old) or at the top (new schema, outputs a list).
  auto fig = [](const char* sub, const char* j) { return report_figures(sub, nlohmann::json::parse(j)); };
  auto old_subdiv = fig("subdiv", R"({"levels":[{"vertices":10},{"vertices":40}],"outputs":{"atlas":{"coverage":0.5}}})");
  ASSERT_EQ(old_subdiv.size(), 2u);
  EXPECT_EQ(old_subdiv[0], (std::pair<std::string, double>{"vertices", 40}));
  EXPECT_EQ(old_subdiv[1], (std::pair<std::string, double>{"atlas coverage", 0.5}));
  auto new_subdiv = fig("subdiv", R"({"levels":[],"outputs":["a.ply"],"atlas":{"coverage":0.25}})");
  ASSERT_EQ(new_subdiv.size(), 1u);
  EXPECT_EQ(new_subdiv[0].second, 0.25);
  auto patches = fig("patches", R"({"seam":{"ratio":1.25},"patches":12,"faces":"many"})");
  ASSERT_EQ(patches.size(), 2u);
  EXPECT_EQ(patches[0].first, "seam ratio");
  EXPECT_EQ(fig("convert", R"({"faces":7})").at(0), (std::pair<std::string, double>{"faces", 7}));
  EXPECT_EQ(order_images({"a/atlas.png", "a/render_fixed.png", "a/b.jpg", "a/render.png"}),
            (std::vector<std::string>{"a/render.png", "a/render_fixed.png", "a/atlas.png", "a/b.jpg"}));
}

TEST(BatchSummary, AJobIsOkOnlyWithItsFolderAndAStatusForItsCurrentCommand) {
  const fs::path out = surftex::test::temp_dir("batch-summary");
  const BatchManifest m = parse_batch_manifest("a: render m.off\nb: render n.off\nc: render o.off\n", "j.txt");
  JobStatus st;
  st.name = "a", st.command = job_command_line(m.jobs[0]), st.status = "ok", st.seconds = 1.5;
  write_text_file(out / job_status_path("a"), to_json(st).dump());
  write_text_file(out / "a" / "render.png", "png");
  write_text_file(out / "a" / "report.json", R"({"coverage":0.5,"seconds":{"total":1.2}})");
  st.name = "b", st.command = job_command_line(m.jobs[1]), st.status = "failed", st.exit_code = 2, st.error = "error: x";
  write_text_file(out / job_status_path("b"), to_json(st).dump());
  st.name = "c", st.command = "surftex render other.off", st.status = "failed";  // an older command
  write_text_file(out / job_status_path("c"), to_json(st).dump());
  const JobSummary a = summarize_job(m.jobs[0], out.string());
  EXPECT_EQ(a.status, "ok");
  EXPECT_DOUBLE_EQ(a.seconds, 1.5);
  EXPECT_DOUBLE_EQ(a.report_seconds, 1.2);
  EXPECT_EQ(a.images, (std::vector<std::string>{"a/render.png"}));
  EXPECT_EQ(a.outputs, (std::vector<std::string>{"a/render.png", "a/report.json"}));
  ASSERT_EQ(a.figures.size(), 1u);
  const JobSummary b = summarize_job(m.jobs[1], out.string());
  EXPECT_EQ(b.status, "failed");
  EXPECT_EQ(b.error, "error: x");
  EXPECT_EQ(b.exit_code, 2);
  EXPECT_EQ(summarize_job(m.jobs[2], out.string()).status, "not_run");
  write_text_file(out / "c" / "render.png", "png");  // a folder made by the older command is not this job's output
  EXPECT_EQ(summarize_job(m.jobs[2], out.string()).status, "not_run");
  fs::remove(out / job_status_path("c"));  // a folder without any status (status removed) counts
  EXPECT_EQ(summarize_job(m.jobs[2], out.string()).status, "ok");
  const nlohmann::json j = summary_json(m, {a, b});
  EXPECT_EQ(j["counts"]["ok"], 1);
  EXPECT_EQ(j["counts"]["failed"], 1);
  EXPECT_EQ(j["jobs"][1]["error"], "error: x");
  EXPECT_EQ(j["jobs"][0]["figures"]["coverage"], 0.5);
  fs::remove_all(out);
}

TEST(ContactSheet, FailedCardsFirstRelativeLinksEscapedText) {
  ContactSheet s;
  s.title = "t <1>";
  SheetCard ok{"good", "ok", "surftex render a.off", "", 1.0, {{"faces", "10"}}, {"good/render.png"}, {"good/m e.glb"}};
  SheetCard bad{"bad", "failed", "surftex render b.off", "error: <broken> & \"x\"", 0.1, {}, {}, {".surftex/logs/bad.log"}};
  s.cards = {ok, bad};
  const std::string h = contact_sheet_html(s);
  EXPECT_LT(h.find("id=\"card-bad\""), h.find("id=\"card-good\""));
  EXPECT_NE(h.find("error: &lt;broken&gt; &amp; &quot;x&quot;"), std::string::npos);
  EXPECT_NE(h.find("<img src=\"good/render.png\""), std::string::npos);
  EXPECT_NE(h.find("href=\"good/m%20e.glb\""), std::string::npos);
  EXPECT_NE(h.find("<title>t &lt;1&gt;</title>"), std::string::npos);
  EXPECT_EQ(h.find("src=\"/"), std::string::npos);
  EXPECT_EQ(h.find("http"), std::string::npos);  // nothing from a network
  EXPECT_EQ(relative_url("a b/c#d.png"), "a%20b/c%23d.png");
  EXPECT_EQ(format_figure(12), "12");
  EXPECT_EQ(format_figure(0.123456), "0.1235");
}

TEST(ContactSheet, DemoCardsClaimTheImagesOfTheirSteps) {
  const fs::path dir = surftex::test::temp_dir("batch-demo-sheet");
  std::vector<std::string> files;  // the demo run's outputs
  for (const char* f : {"synth_el2pass.png", "tile_noise.png", "exemplar_cells.png", "torus_tiled.png",
                        "patches/render.png", "patches_exemplar.png"}) {
    write_text_file(dir / f, "png");
    files.push_back((dir / f).string());
  }
  const nlohmann::json report = nlohmann::json::parse(R"({"seconds": {"synthesis": 1.0, "textured_torus": 0.5,
    "patches": 72.0}, "steps": {
    "synthesis": {"el2pass": {"bidirectional_similarity": 0.5}, "graphcut": {}, "tile": {"wrap_seam_ratio": 1.1},
                  "seconds": {"el2pass": 0.25}},
    "textured_torus": {"faces": 10, "outputs": ["torus_tiled.obj", "torus_tiled.png"]},
    "patches": {"patches": 4, "outputs": ["render.png"]}}})");
  write_demo_contact_sheet(dir.string(), report, files);
  const std::string h = file_bytes(dir / "index.html");
  auto card = [&](const std::string& name) {
    const std::size_t a = h.find("id=\"card-" + name + "\"");
    return a == std::string::npos ? std::string() : h.substr(a, h.find("</article>", a) - a);
  };
  EXPECT_NE(card("synthesis").find("synth_el2pass.png"), std::string::npos);
  EXPECT_EQ(card("synthesis").find("tile_noise.png"), std::string::npos);  // "tile" is too short a part name
  EXPECT_NE(card("textured_torus").find("torus_tiled.png"), std::string::npos);
  EXPECT_NE(card("patches").find("patches/render.png"), std::string::npos);
  EXPECT_NE(card("patches").find("patches_exemplar.png"), std::string::npos);
  EXPECT_NE(card("other images").find("exemplar_cells.png"), std::string::npos);
  EXPECT_NE(card("other images").find("tile_noise.png"), std::string::npos);
  EXPECT_NE(card("synthesis").find("el2pass bidirectional_similarity"), std::string::npos);
  // Step times from the report's "seconds" object (the shared schema), total in the subtitle.
  EXPECT_NE(card("patches").find("1m12s"), std::string::npos);
  EXPECT_NE(card("textured_torus").find("0.5 s"), std::string::npos);
  EXPECT_NE(h.find("1m13s"), std::string::npos);  // 1 + 0.5 + 72 s
  fs::remove_all(dir);
}

TEST(BatchProgress, EtaClockAndOneLinePerJobInPipes) {
  EXPECT_DOUBLE_EQ(estimate_remaining_seconds(10, 2, 6), 20);
  EXPECT_DOUBLE_EQ(estimate_remaining_seconds(10, 0, 6), -1);
  EXPECT_EQ(format_clock(65), "1:05");
  EXPECT_EQ(format_clock(3723), "1:02:03");
  EXPECT_EQ(format_clock(-1), "--");
  std::FILE* text = std::tmpfile();
  std::FILE* json = std::tmpfile();
  {
    BatchProgress lines(ProgressMode::Lines, text, json);
    lines.plan(2, 3);
    lines.started("a", "Missing output files: a");
    lines.started("b", "");
    JobStatus ok, bad;
    ok.status = "ok", ok.seconds = 1.25;
    bad.status = "failed", bad.error = "error: broken";
    lines.finished("a", ok);
    lines.finished("b", bad);
    lines.end(1, 1, 0, "s.json", "i.html");
    BatchProgress js(ProgressMode::Json, text, json);
    js.plan(1, 1);
    js.started("a", "r");
    js.finished("a", ok);
    js.end(1, 0, 0, "s.json", "i.html");
  }
  auto slurp = [](std::FILE* f) {
    std::rewind(f);
    std::string s;
    for (int c; (c = std::fgetc(f)) != EOF;) s += static_cast<char>(c);
    std::fclose(f);
    return s;
  };
  const std::string t = slurp(text), j = slurp(json);
  EXPECT_NE(t.find("batch: 2 of 3 jobs to run (1 up to date)\n"), std::string::npos) << t;
  EXPECT_NE(t.find("batch: [1/2] ok     a 1.2 s (1 running, 0 failed,"), std::string::npos) << t;
  EXPECT_NE(t.find("batch: [2/2] failed b 0.0 s: error: broken (0 running, 1 failed,"), std::string::npos) << t;
  EXPECT_EQ(t.find('\r'), std::string::npos);  // no terminal redraws in a pipe
  std::istringstream in(j);
  std::vector<std::string> events;
  for (std::string line; std::getline(in, line);) events.push_back(nlohmann::json::parse(line).at("event"));
  EXPECT_EQ(events, (std::vector<std::string>{"plan", "start", "finish", "end"}));
}

TEST(BatchProgress, OnATerminalAStatusLineIsRedrawnUnderTheJobLines) {
  std::FILE* text = std::tmpfile();
  {
    BatchProgress term(ProgressMode::Terminal, text, nullptr);
    term.plan(3, 3);
    term.started("a", "");
    term.started("b", "");
    JobStatus ok, bad;
    ok.status = "ok", ok.seconds = 2;
    bad.status = "failed", bad.error = "error: x";
    term.finished("a", ok);
    term.finished("b", bad);
    term.tick();
    term.end(1, 1, 1, "", "");
  }
  std::rewind(text);
  std::string t;
  for (int c; (c = std::fgetc(text)) != EOF;) t += static_cast<char>(c);
  std::fclose(text);
  EXPECT_NE(t.find("\r\033[Kbatch: 0/3 done, 2 running, 0 failed, 0:00 elapsed, ETA --"), std::string::npos) << t;
  EXPECT_NE(t.find("\r\033[Kbatch: [1/3] ok     a 2.0 s\n"), std::string::npos) << t;
  EXPECT_NE(t.find("\r\033[Kbatch: [2/3] failed b 0.0 s: error: x\n"), std::string::npos) << t;
  EXPECT_NE(t.find("\r\033[Kbatch: 2/3 done, 0 running, 1 failed, 0:00 elapsed, ETA 0:00"), std::string::npos) << t;
  // Redrawn only when it changes: the last tick() repeated nothing.
  EXPECT_EQ(count_substr(t, "2/3 done, 0 running, 1 failed"), 1) << t;
  EXPECT_EQ(t.substr(t.size() - 4), "\r\033[K");  // cleared at the end
}

TEST(SnakemakeEngine, ParsesTheJobStatsTable) {
  const std::string table =
      "Job stats:\njob          count    min threads    max threads\n"
      "---------  -------  -------------  -------------\nall              1              1              1\n"
      "job_a            1              1              1\njob_b_2          1              1              1\n"
      "total            3              1              1\n";
  EXPECT_EQ(parse_job_stats(table),
            (std::vector<std::pair<std::string, int>>{{"all", 1}, {"job_a", 1}, {"job_b_2", 1}}));
  EXPECT_NE(snakemake_event_handler_script().find("def log_handler(msg):"), std::string::npos);
}
