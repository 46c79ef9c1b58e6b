// SPDX-License-Identifier: AGPL-3.0-or-later
#include "batch/batch_progress.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>

namespace surftex::batch {

double estimate_remaining_seconds(double elapsed, int finished, int total) {
  if (finished <= 0 || total <= 0) return -1;
  return elapsed / finished * std::max(0, total - finished);
}

std::string format_clock(double s) {
  if (s < 0 || !std::isfinite(s)) return "--";
  const long t = std::lround(s);
  char buf[32];
  if (t >= 3600) std::snprintf(buf, sizeof buf, "%ld:%02ld:%02ld", t / 3600, (t / 60) % 60, t % 60);
  else std::snprintf(buf, sizeof buf, "%ld:%02ld", t / 60, t % 60);
  return buf;
}

BatchProgress::BatchProgress(ProgressMode mode, std::FILE* text, std::FILE* json)
    : mode_(mode), text_(text), json_(json) {}

double BatchProgress::elapsed() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

std::string BatchProgress::status_line() const {
  const int done = ok_ + failed_;
  std::string s = std::to_string(done) + "/" + std::to_string(total_) + " done, " + std::to_string(running_) +
                  " running, " + std::to_string(failed_) + " failed, " + format_clock(elapsed()) + " elapsed, ETA " +
                  format_clock(estimate_remaining_seconds(elapsed(), done, total_));
  return s;
}

void BatchProgress::emit(const std::string& line) {
  if (mode_ != ProgressMode::Json) return;
  std::fprintf(json_, "%s\n", line.c_str());
  std::fflush(json_);
}

void BatchProgress::clear_line() {
  if (mode_ == ProgressMode::Terminal && line_shown_) {
    std::fputs("\r\033[K", text_);
    line_shown_ = false;
  }
}

void BatchProgress::plan(int to_run, int all) {
  total_ = to_run;
  all_ = all;
  emit(nlohmann::json{{"event", "plan"}, {"to_run", to_run}, {"jobs", all}}.dump());
  if (mode_ == ProgressMode::Terminal || mode_ == ProgressMode::Lines) {
    clear_line();
    std::fprintf(text_, "batch: %d of %d jobs to run (%d up to date)\n", to_run, all, all - to_run);
    std::fflush(text_);
  }
  tick();
}

void BatchProgress::started(const std::string& job, const std::string& reason) {
  ++running_;
  emit(nlohmann::json{{"event", "start"}, {"job", job}, {"reason", reason}, {"elapsed", elapsed()}}.dump());
  tick();
}

void BatchProgress::finished(const std::string& job, const JobStatus& st) {
  running_ = std::max(0, running_ - 1);
  const bool ok = st.status == "ok";
  (ok ? ok_ : failed_)++;
  const double eta = estimate_remaining_seconds(elapsed(), ok_ + failed_, total_);
  emit(nlohmann::json{{"event", "finish"},
                      {"job", job},
                      {"status", st.status.empty() ? "failed" : st.status},
                      {"seconds", st.seconds},
                      {"exit_code", st.exit_code},
                      {"error", st.error.empty() ? nlohmann::json() : nlohmann::json(st.error)},
                      {"done", ok_ + failed_},
                      {"running", running_},
                      {"failed", failed_},
                      {"total", total_},
                      {"elapsed", elapsed()},
                      {"eta", eta >= 0 ? nlohmann::json(eta) : nlohmann::json()}}
           .dump());
  if (mode_ == ProgressMode::Terminal || mode_ == ProgressMode::Lines) {
    clear_line();
    char head[64];
    std::snprintf(head, sizeof head, "[%d/%d]", ok_ + failed_, total_);
    std::fprintf(text_, "batch: %s %-6s %s %.1f s", head, ok ? "ok" : st.status.empty() ? "failed" : st.status.c_str(),
                 job.c_str(), st.seconds);
    if (!ok && !st.error.empty()) std::fprintf(text_, ": %s", st.error.c_str());
    if (mode_ == ProgressMode::Lines)
      std::fprintf(text_, " (%d running, %d failed, %s elapsed, ETA %s)", running_, failed_,
                   format_clock(elapsed()).c_str(), format_clock(eta).c_str());
    std::fputc('\n', text_);
    std::fflush(text_);
  }
  tick();
}

void BatchProgress::tick() {
  if (mode_ != ProgressMode::Terminal || total_ == 0) return;
  const std::string line = status_line();
  if (line_shown_ && line == last_line_) return;
  std::fprintf(text_, "\r\033[Kbatch: %s", line.c_str());
  std::fflush(text_);
  line_shown_ = true;
  last_line_ = line;
}

void BatchProgress::end(int ok, int failed, int other, const std::string& summary_path, const std::string& index_path) {
  clear_line();
  emit(nlohmann::json{{"event", "end"},
                      {"ok", ok},
                      {"failed", failed},
                      {"other", other},
                      {"elapsed", elapsed()},
                      {"summary", summary_path},
                      {"index", index_path}}
           .dump());
  if (text_) std::fflush(text_);
}

}  // namespace surftex::batch
