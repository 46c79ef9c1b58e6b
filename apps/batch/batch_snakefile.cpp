// SPDX-License-Identifier: AGPL-3.0-or-later
#include "batch/batch_snakefile.h"

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <set>

namespace fs = std::filesystem;

namespace surftex::batch {

std::string job_log_path(const std::string& name) { return ".surftex/logs/" + name + ".log"; }
std::string job_status_path(const std::string& name) { return ".surftex/status/" + name + ".json"; }
std::string job_stage_path(const std::string& name) { return ".surftex/stage/" + name; }

std::vector<std::string> job_rule_names(const BatchManifest& m) {
  std::vector<std::string> names;
  std::set<std::string> used{"all"};
  for (const BatchJob& j : m.jobs) {
    std::string base = "job_" + j.name;
    std::replace_if(base.begin(), base.end(), [](char c) { return c == '-' || c == '.'; }, '_');
    std::string r = base;
    for (int k = 2; used.count(r); ++k) r = base + "_" + std::to_string(k);
    used.insert(r);
    names.push_back(r);
  }
  return names;
}

namespace {

bool inside(const fs::path& p, const fs::path& dir) {
  auto [a, b] = std::mismatch(dir.begin(), dir.end(), p.begin(), p.end());
  return a == dir.end();
}

// Doubles the braces Snakemake would read as format fields.
std::string snakemake_literal(const std::string& s) {
  std::string o;
  for (char c : s) {
    if (c == '{' || c == '}') o += c;
    o += c;
  }
  return o;
}

bool has_threads_option(const BatchJob& job, std::string* value) {
  for (std::size_t i = 0; i < job.args.size(); ++i) {
    const std::string& a = job.args[i];
    if (a == "--threads" && i + 1 < job.args.size()) {
      if (value) *value = job.args[i + 1];
      return true;
    }
    if (a.rfind("--threads=", 0) == 0) {
      if (value) *value = a.substr(10);
      return true;
    }
  }
  return false;
}

}  // namespace

std::vector<std::string> job_input_files(const BatchJob& job, const std::string& manifest_dir,
                                         const std::string& out_dir) {
  std::vector<std::string> files;
  std::set<std::string> seen;
  const fs::path out = fs::path(out_dir).lexically_normal();
  auto add = [&](const fs::path& p) {
    const fs::path n = p.lexically_normal();
    if (inside(n, out) || !seen.insert(n.string()).second) return;
    files.push_back(n.string());
  };
  for (const std::string& arg : job.args) {
    std::string v = arg;
    if (v.rfind("--", 0) == 0) {
      const std::size_t eq = v.find('=');
      if (eq == std::string::npos) continue;
      v = v.substr(eq + 1);
    }
    // Files only from words that look like paths: an option value such as
    // "up" is not an input because a file of that name happens to exist (the
    // job would only re-run more often). Folders by any name but ".", "..".
    if (v.empty() || v == "." || v == ".." || v == "/") continue;
    std::error_code ec;
    const fs::path p = (fs::path(v).is_absolute() ? fs::path(v) : fs::path(manifest_dir) / v).lexically_normal();
    const bool looks_like_path = v.find_first_of("/.") != std::string::npos;
    if (looks_like_path && fs::is_regular_file(p, ec)) {
      add(p);
    } else if (fs::is_directory(p, ec) && !inside(out, p) && p != fs::path(manifest_dir).lexically_normal()) {
      std::vector<fs::path> inner;
      for (const auto& e : fs::directory_iterator(p, ec))
        if (e.is_regular_file(ec) && inner.size() < 4096) inner.push_back(e.path());
      std::sort(inner.begin(), inner.end());
      for (const fs::path& f : inner) add(f);
    }
  }
  return files;
}

std::string job_fingerprint(const BatchJob& job, const std::string& manifest_dir, const std::string& out_dir) {
  std::string text = job_command_line(job) + "\n" + manifest_dir + "\n";
  for (const std::string& f : job_input_files(job, manifest_dir, out_dir)) {
    std::error_code ec;
    const auto size = fs::file_size(f, ec);
    const auto mtime = fs::last_write_time(f, ec).time_since_epoch().count();
    text += f + " " + std::to_string(size) + " " + std::to_string(mtime) + "\n";
  }
  std::uint64_t h = 1469598103934665603ull;  // FNV-1a, 64 bits
  for (unsigned char c : text) h = (h ^ c) * 1099511628211ull;
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
  return buf;
}

std::string job_threads_expression(const BatchJob& job) {
  std::string v;
  if (!has_threads_option(job, &v)) return "1";
  if (v == "0") return "workflow.cores";
  const bool digits = !v.empty() && std::all_of(v.begin(), v.end(), [](unsigned char c) { return std::isdigit(c); });
  return digits && v.size() < 6 ? v : "1";  // a bad value fails the job itself
}

std::string python_string(const std::string& s) {
  std::string o = "\"";
  for (unsigned char c : s) {
    if (c == '"' || c == '\\') {
      o += '\\';
      o += static_cast<char>(c);
    } else if (c < 0x20 || c == 0x7f) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02x", c);
      o += buf;
    } else {
      o += static_cast<char>(c);
    }
  }
  return o + "\"";
}

std::string snakefile_text(const BatchManifest& m, const std::string& surftex_exe, const std::string& job_exe,
                           const std::string& out_dir) {
  const std::vector<std::string> rules = job_rule_names(m);
  std::string t;
  t += "# Written by `surftex batch " + m.path + "`: one rule per job of the manifest.\n";
  t += "# Each job runs `surftex-job`, which writes the job into .surftex/stage/NAME\n";
  t += "# and renames it to NAME only when the job succeeded (no partial folder).\n";
  t += "# Run it again through `surftex batch`, or with Snakemake itself from this folder:\n";
  t += "#   snakemake -s Snakefile -d . --jobs 2 --keep-going --rerun-incomplete\n";
  t += "#   snakemake -s Snakefile -d . --slurm --jobs 100 --keep-going --rerun-incomplete \\\n";
  t += "#     --default-resources slurm_account=ACCOUNT slurm_partition=PARTITION\n";
  t += "# (then `surftex batch` again writes summary.json and index.html).\n\n";
  t += "localrules: all\n\n";
  t += "rule all:\n    default_target: True\n    input:\n";
  for (const BatchJob& j : m.jobs) t += "        " + python_string(j.name) + ",\n";
  for (std::size_t i = 0; i < m.jobs.size(); ++i) {
    const BatchJob& j = m.jobs[i];
    t += "\n# " + m.path + ":" + std::to_string(j.line) + "\n";
    t += "rule " + rules[i] + ":\n";
    const std::vector<std::string> in = job_input_files(j, m.dir, out_dir);
    if (!in.empty()) {
      t += "    input:\n";
      for (const std::string& f : in) t += "        " + python_string(f) + ",\n";
    }
    t += "    output: directory(" + python_string(j.name) + ")\n";
    t += "    log: log=" + python_string(job_log_path(j.name)) + ", status=" + python_string(job_status_path(j.name)) +
         "\n";
    t += "    params: command=" + python_string(job_command_line(j)) + "\n";
    t += "    threads: " + job_threads_expression(j) + "\n";
    std::string cmd = shell_quote(job_exe) + " --surftex " + shell_quote(surftex_exe) + " --name " +
                      shell_quote(j.name) + " --workdir " + shell_quote(m.dir);
    if (!j.output.folder) cmd += " --output-file " + shell_quote(j.output.file);
    std::string shell = snakemake_literal(cmd);
    if (!has_threads_option(j, nullptr)) shell += " --threads {threads}";
    std::string job_cmd = " -- " + shell_quote(j.subcommand);
    for (const std::string& a : j.args) job_cmd += " " + shell_quote(a);
    shell += snakemake_literal(job_cmd);
    t += "    shell: " + python_string(shell) + "\n";
  }
  return t;
}

}  // namespace surftex::batch
