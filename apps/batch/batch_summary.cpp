// SPDX-License-Identifier: AGPL-3.0-or-later
#include "batch/batch_summary.h"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "batch/batch_job.h"
#include "batch/batch_snakefile.h"

namespace fs = std::filesystem;

namespace surftex::batch {

namespace {

// The value at a '/'-separated path; "$last" picks an array's last element.
const nlohmann::json* at_path(const nlohmann::json& j, const std::string& path) {
  const nlohmann::json* cur = &j;
  std::stringstream ss(path);
  for (std::string key; std::getline(ss, key, '/');) {
    if (key.empty()) continue;
    if (cur->is_array()) {
      if (cur->empty()) return nullptr;
      if (key == "$last") {
        cur = &cur->back();
        continue;
      }
      return nullptr;
    }
    if (!cur->is_object() || !cur->contains(key)) return nullptr;
    cur = &(*cur)[key];
  }
  return cur;
}

struct Figure {
  const char* label;
  std::vector<const char*> paths;  // the first present one is used
};

const std::map<std::string, std::vector<Figure>>& figure_table() {
  static const std::map<std::string, std::vector<Figure>> t{
      {"patches", {{"seam ratio", {"seam/ratio"}}, {"patches", {"patches"}}, {"faces", {"faces"}}}},
      {"subdiv",
       {{"vertices", {"levels/$last/vertices"}},
        {"atlas coverage", {"outputs/atlas/coverage", "atlas/coverage"}},
        {"atlas flipped faces", {"outputs/atlas/flipped_faces", "atlas/flipped_faces"}}}},
      {"quilt",
       {{"elements", {"elements"}},
        {"faces", {"faces"}},
        {"stretch", {"stretch_after"}},
        {"self-intersections", {"self_intersections"}}}},
      {"material-map",
       {{"singular fraction", {"singular_fraction"}},
        {"distorted faces", {"distorted_faces"}},
        {"mismatched edges", {"mismatched_edges"}},
        {"faces", {"faces"}}}},
      {"material-tile", {{"layers", {"layers"}}, {"mask agreement", {"mask_agreement"}}}},
      {"synth",
       {{"bidirectional similarity", {"bidirectional_similarity/total", "bidirectional_similarity"}},
        {"histogram chi2", {"histogram_chi_square", "histogram_chi2"}}}},
      {"tile", {{"wrap seam ratio", {"wrap_seam_ratio"}}, {"worst line ratio", {"worst_line_ratio"}}}},
      {"render", {{"coverage", {"coverage"}}, {"triangles", {"triangles"}}}},
  };
  return t;
}

bool is_image(const fs::path& p) {
  std::string e = p.extension().string();
  std::transform(e.begin(), e.end(), e.begin(), [](unsigned char c) { return std::tolower(c); });
  return e == ".png" || e == ".jpg" || e == ".jpeg";
}

nlohmann::json read_json_file(const fs::path& p) {
  std::ifstream f(p);
  if (!f) return nullptr;
  nlohmann::json j = nlohmann::json::parse(f, nullptr, false);
  return j.is_discarded() ? nlohmann::json() : j;
}

std::vector<std::string> folder_files(const fs::path& out, const std::string& name) {
  std::vector<std::string> files;
  std::error_code ec;
  const fs::path dir = out / name;
  if (!fs::is_directory(dir, ec)) return files;
  for (auto it = fs::recursive_directory_iterator(dir, ec); !ec && it != fs::recursive_directory_iterator();
       it.increment(ec)) {
    if (!it->is_regular_file(ec)) continue;
    const std::string fn = it->path().filename().string();
    if (fn.rfind(".snakemake", 0) == 0) continue;  // Snakemake's timestamp marker
    files.push_back(fs::relative(it->path(), out, ec).generic_string());
  }
  std::sort(files.begin(), files.end());
  return files;
}

}  // namespace

double report_total_seconds(const nlohmann::json& r) {
  if (!r.is_object()) return -1;
  for (const char* p : {"seconds/total", "seconds", "seconds_total"}) {
    const nlohmann::json* v = at_path(r, p);
    if (v && v->is_number()) return v->get<double>();
  }
  return -1;
}

std::vector<std::pair<std::string, double>> report_figures(const std::string& subcommand, const nlohmann::json& r) {
  std::vector<std::pair<std::string, double>> out;
  if (!r.is_object()) return out;
  static const std::vector<Figure> generic{{"faces", {"faces", "output/faces"}}, {"vertices", {"vertices"}}};
  auto it = figure_table().find(subcommand);
  for (const Figure& f : it == figure_table().end() ? generic : it->second)
    for (const char* p : f.paths) {
      const nlohmann::json* v = at_path(r, p);
      if (v && v->is_number()) {
        out.emplace_back(f.label, v->get<double>());
        break;
      }
    }
  return out;
}

std::vector<std::string> order_images(std::vector<std::string> images) {
  std::stable_sort(images.begin(), images.end(), [](const std::string& a, const std::string& b) {
    const bool ra = fs::path(a).filename().string().rfind("render", 0) == 0;
    const bool rb = fs::path(b).filename().string().rfind("render", 0) == 0;
    if (ra != rb) return ra;
    return a < b;
  });
  return images;
}

JobSummary summarize_job(const BatchJob& job, const std::string& out_dir) {
  const fs::path out(out_dir);
  JobSummary s;
  s.name = job.name;
  s.command = job_command_line(job);
  s.log = job_log_path(job.name);
  std::error_code ec;
  const bool folder = fs::is_directory(out / job.name, ec);
  JobStatus st;
  const bool recorded = read_job_status((out / job_status_path(job.name)).string(), st);
  const bool have = recorded && st.command == s.command;  // an outcome of the job's current command
  if (have) {
    s.exit_code = st.exit_code;
    s.seconds = st.seconds;
    s.cpu_seconds = st.cpu_seconds;
    s.finished_at = st.finished_at;
  }
  if (folder && (have ? st.status == "ok" : !recorded)) {
    s.status = "ok";  // without a status file: its status was removed
  } else if (have && st.status != "ok") {
    s.status = st.status;
    s.error = st.error;
  } else {
    s.status = "not_run";  // never run, or its folder is from an older command
  }
  if (s.status != "ok") return s;
  const nlohmann::json report = read_json_file(out / job.name / "report.json");
  s.report_seconds = report_total_seconds(report);
  s.figures = report_figures(job.subcommand, report);
  s.outputs = folder_files(out, job.name);
  for (const std::string& f : s.outputs)
    if (is_image(f)) s.images.push_back(f);
  s.images = order_images(s.images);
  return s;
}

nlohmann::json summary_json(const BatchManifest& m, const std::vector<JobSummary>& jobs) {
  nlohmann::json j;
  j["manifest"] = m.path;
  std::map<std::string, int> counts{{"ok", 0}, {"failed", 0}, {"interrupted", 0}, {"not_run", 0}};
  double sum = 0, cpu = 0;
  for (const JobSummary& s : jobs) {
    ++counts[s.status];
    if (s.seconds > 0) sum += s.seconds;
    if (s.cpu_seconds > 0) cpu += s.cpu_seconds;
    nlohmann::json e{{"name", s.name},
                     {"command", s.command},
                     {"status", s.status},
                     {"error", s.error.empty() ? nlohmann::json() : nlohmann::json(s.error)},
                     {"exit_code", s.exit_code},
                     {"seconds", s.seconds >= 0 ? nlohmann::json(s.seconds) : nlohmann::json()},
                     {"cpu_seconds", s.cpu_seconds >= 0 ? nlohmann::json(s.cpu_seconds) : nlohmann::json()},
                     {"report_seconds", s.report_seconds >= 0 ? nlohmann::json(s.report_seconds) : nlohmann::json()},
                     {"figures", nlohmann::json::object()},
                     {"outputs", s.outputs},
                     {"images", s.images},
                     {"log", s.log}};
    for (const auto& [k, v] : s.figures) e["figures"][k] = v;
    j["jobs"].push_back(e);
  }
  j["counts"] = counts;
  j["counts"]["total"] = jobs.size();
  j["seconds_sum"] = sum;
  j["cpu_seconds_sum"] = cpu;
  return j;
}

}  // namespace surftex::batch
