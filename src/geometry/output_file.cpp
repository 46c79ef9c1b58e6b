// SPDX-License-Identifier: AGPL-3.0-or-later
#include "geometry/output_file.h"

#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>

#include "geometry/cancellation.h"
#include "geometry/errors.h"

namespace fs = std::filesystem;

namespace surftex {

namespace {

constexpr const char* kStagePrefix = ".surftex-stage-";
constexpr const char* kTempPrefix = ".surftex-tmp-";
constexpr const char* kJournal = "journal";
constexpr const char* kBackup = ".surftex-old";

// ------------------------------------------------------------ process identity

// Start time of process `pid` in clock ticks since boot (/proc/PID/stat field
// 22), or 0 if unknown. With the pid it names a process uniquely (pids are reused).
unsigned long long process_start(long pid) {
  std::ifstream f("/proc/" + std::to_string(pid) + "/stat");
  std::string s((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  const auto close = s.rfind(')');
  if (close == std::string::npos) return 0;
  std::istringstream rest(s.substr(close + 1));
  std::string tok;
  for (int field = 3; field <= 22 && (rest >> tok); ++field)
    if (field == 22) return std::strtoull(tok.c_str(), nullptr, 10);
  return 0;
}

const std::string& self_tag() {
  static const std::string tag = [] {
    const long pid = static_cast<long>(::getpid());
    return std::to_string(pid) + "-" + std::to_string(process_start(pid));
  }();
  return tag;
}

// Whether the run that named a file "<prefix>PID-START..." may still be alive.
bool owner_alive(const std::string& name, const std::string& prefix) {
  const char* p = name.c_str() + prefix.size();
  char* end = nullptr;
  const long pid = std::strtol(p, &end, 10);
  if (end == p || pid <= 0) return true;  // not ours to judge: keep
  unsigned long long start = 0;
  bool have_start = false;
  if (*end == '-') {
    char* e2 = nullptr;
    start = std::strtoull(end + 1, &e2, 10);
    have_start = e2 != end + 1;
  }
  if (::kill(static_cast<pid_t>(pid), 0) != 0 && errno == ESRCH) return false;
  const unsigned long long now = process_start(pid);
  if (have_start && now != 0 && now != start) return false;  // the pid was reused
  return true;
}

std::atomic<unsigned> g_counter{0};

std::string temp_name(const fs::path& dest) {
  std::string ext = dest.extension().string();
  if (ext.size() > 16) ext.clear();
  return std::string(kTempPrefix) + self_tag() + "-" + std::to_string(g_counter.fetch_add(1)) + ext;
}

fs::path normalised(const std::string& p) {
  std::error_code ec;
  fs::path a = fs::absolute(fs::path(p), ec);
  if (ec) a = fs::path(p);
  a = a.lexically_normal();
  if (a.has_parent_path() && a.filename().empty()) a = a.parent_path();
  return a;
}

// True if `p` lies strictly inside `root`; `rel` receives the relative part.
bool inside(const fs::path& p, const fs::path& root, fs::path& rel) {
  auto pi = p.begin();
  for (auto ri = root.begin(); ri != root.end(); ++ri, ++pi)
    if (pi == p.end() || *pi != *ri) return false;
  if (pi == p.end()) return false;
  rel.clear();
  for (; pi != p.end(); ++pi) rel /= *pi;
  return true;
}

bool in_staging_area(const fs::path& p) {
  for (const auto& c : p)
    if (c.string().rfind(kStagePrefix, 0) == 0) return true;
  return false;
}

bool exists_nofollow(const fs::path& p) {
  std::error_code ec;
  return fs::exists(fs::symlink_status(p, ec));
}

// ------------------------------------------------------------ fault injection
// SURFTEX_TEST_FAULT=first-temp:SIG or first-rename:SIG (SIG = INT, TERM or
// KILL) makes a staged run send itself SIG right after its first staged
// temporary is created, or right after the first output is moved into place:
// the CLI tests use it to interrupt a run at those exact points.
struct Fault {
  std::string at;
  int sig = 0;
};
Fault read_fault() {
  Fault f;
  const char* v = std::getenv("SURFTEX_TEST_FAULT");
  if (!v) return f;
  const std::string s(v);
  const auto colon = s.find(':');
  if (colon == std::string::npos) return f;
  f.at = s.substr(0, colon);
  const std::string sig = s.substr(colon + 1);
  f.sig = sig == "INT" ? SIGINT : sig == "TERM" ? SIGTERM : sig == "KILL" ? SIGKILL : 0;
  return f;
}

// ------------------------------------------------------------ the staged run

struct Entry {
  fs::path dest;    // absolute destination
  fs::path staged;  // where it is written meanwhile
  fs::path area;    // its staging folder
  std::size_t id = 0;
  bool dir = false;      // a folder (created, or replacing one whole)
  bool replace = false;  // a folder that may replace an existing one
  bool done = false;     // written completely (files) / created (folders)
  bool moved = false;    // commit: in place
  bool backed_up = false;
};

class Stage {
 public:
  Stage() : fault_(read_fault()) {}

  std::mutex mu;
  std::vector<std::unique_ptr<Entry>> entries;  // null = released
  std::map<fs::path, fs::path> areas;           // destination folder -> staging folder
  Fault fault_;
  bool fired_temp = false, fired_rename = false;

  void fire(const char* at, bool& fired) {
    if (fired || fault_.sig == 0 || fault_.at != at) return;
    fired = true;
    ::raise(fault_.sig);
  }

  fs::path area_for(const fs::path& folder) {
    auto it = areas.find(folder);
    if (it != areas.end()) return it->second;
    sweep_stale_outputs(folder.string());
    const fs::path a = folder / (std::string(kStagePrefix) + self_tag());
    std::error_code ec;
    fs::create_directory(a, ec);
    if (ec) throw IOError("cannot create a staging folder in '" + folder.string() + "': " + ec.message());
    areas[folder] = a;
    return a;
  }

  void journal(const fs::path& area, const nlohmann::json& line) {
    std::ofstream j(area / kJournal, std::ios::app | std::ios::binary);
    j << line.dump() << "\n";
    j.flush();
    if (!j) throw IOError("cannot write the staging journal in '" + area.parent_path().string() + "'");
  }

  // A new entry for `dest` (its parent folder exists for real).
  Entry& add(const fs::path& dest, bool dir, bool replace) {
    const fs::path area = area_for(dest.parent_path());
    auto e = std::make_unique<Entry>();
    e->id = entries.size();
    e->dest = dest;
    e->dir = dir;
    e->replace = replace;
    e->area = area;
    const fs::path slot = area / ("e" + std::to_string(e->id));
    std::error_code ec;
    fs::create_directory(slot, ec);
    if (ec) throw IOError("cannot create a staging folder for '" + dest.string() + "': " + ec.message());
    e->staged = slot / dest.filename();
    journal(area, {{"entry", e->id}, {"dest", dest.string()}, {"name", dest.filename().string()}, {"dir", dir}});
    entries.push_back(std::move(e));
    fire("first-temp", fired_temp);
    return *entries.back();
  }

  void release(long id) {
    if (id < 0 || static_cast<std::size_t>(id) >= entries.size() || !entries[id]) return;
    std::error_code ec;
    fs::remove_all(entries[id]->staged.parent_path(), ec);
    entries[id].reset();
  }

  // The folder entry `p` lies in, with the relative part.
  Entry* folder_holding(const fs::path& p, fs::path& rel) {
    for (auto& e : entries)
      if (e && e->dir && inside(p, e->dest, rel)) return e.get();
    return nullptr;
  }
  Entry* exact(const fs::path& p) {
    for (auto& e : entries)
      if (e && e->dest == p) return e.get();
    return nullptr;
  }

  void commit();
  void undo() noexcept;
  void remove_areas() noexcept {
    std::error_code ec;
    for (auto& [folder, area] : areas) fs::remove_all(area, ec);
    areas.clear();
    entries.clear();
  }
};

Stage* g_stage = nullptr;

[[noreturn]] void twice(const std::string& dest) {
  throw IOError("output '" + dest +
                "' is written twice in this run (two outputs of the run name the same file); nothing was written");
}

void Stage::commit() {
  throw_if_cancelled();
  for (auto& e : entries) {
    if (!e) continue;
    if (!e->done) throw IOError("internal: output '" + e->dest.string() + "' was not completed");
    journal(e->area, {{"move", e->id}});
    const fs::path backup = e->staged.parent_path() / kBackup;
    std::error_code ec;
    if (exists_nofollow(e->dest)) {
      const bool is_dir = fs::is_directory(fs::symlink_status(e->dest, ec));
      if (e->dir && !e->replace)
        throw IOError("cannot create folder '" + e->dest.string() + "': it appeared during the run");
      if (is_dir != e->dir)
        throw IOError("cannot replace '" + e->dest.string() + "': it became a " + (is_dir ? "folder" : "file") +
                      " during the run");
      // A file is linked aside (its name never disappears); a folder moved aside.
      if (is_dir || ::link(e->dest.c_str(), backup.c_str()) != 0) {
        fs::rename(e->dest, backup, ec);
        if (ec) throw IOError("cannot move '" + e->dest.string() + "' aside to replace it: " + ec.message());
      }
      e->backed_up = true;
    }
    fs::rename(e->staged, e->dest, ec);
    if (ec) throw IOError("cannot move '" + e->dest.string() + "' into place: " + ec.message());
    e->moved = true;
    fire("first-rename", fired_rename);
    throw_if_cancelled();
  }
  for (auto& [folder, area] : areas) journal(area, {{"done", true}});
}

void Stage::undo() noexcept {
  for (auto it = entries.rbegin(); it != entries.rend(); ++it) {
    Entry* e = it->get();
    if (!e) continue;
    std::error_code ec;
    const fs::path backup = e->staged.parent_path() / kBackup;
    if (e->moved) fs::rename(e->dest, e->staged, ec);
    if (ec) fs::remove_all(e->dest, ec);
    if (e->backed_up && exists_nofollow(backup)) {
      if (exists_nofollow(e->dest)) fs::remove_all(backup, ec);  // linked aside: the original is still there
      else fs::rename(backup, e->dest, ec);
    }
    e->moved = e->backed_up = false;
  }
}

// Undoes an interrupted commit from a dead run's journal, then removes its area.
void recover_area(const fs::path& area) {
  std::ifstream j(area / kJournal, std::ios::binary);
  std::map<std::size_t, std::pair<fs::path, std::string>> entry;
  std::vector<std::size_t> moves;
  bool done = false;
  std::string line;
  while (std::getline(j, line)) {
    const nlohmann::json l = nlohmann::json::parse(line, nullptr, false);
    if (!l.is_object()) continue;  // a line cut by the kill
    if (l.contains("entry") && l["entry"].is_number_unsigned() && l.contains("dest") && l["dest"].is_string() &&
        l.contains("name") && l["name"].is_string())
      entry[l["entry"].get<std::size_t>()] = {fs::path(l["dest"].get<std::string>()), l["name"].get<std::string>()};
    if (l.contains("move") && l["move"].is_number_unsigned()) moves.push_back(l["move"].get<std::size_t>());
    if (l.contains("done")) done = true;
  }
  std::error_code ec;
  if (!done) {
    for (auto it = moves.rbegin(); it != moves.rend(); ++it) {
      const auto e = entry.find(*it);
      if (e == entry.end()) continue;
      const fs::path slot = area / ("e" + std::to_string(*it));
      const fs::path& dest = e->second.first;
      // Only a destination inside the folder the area sits in is ours to touch.
      std::error_code e2;
      if (dest.filename() != e->second.second || !fs::equivalent(dest.parent_path(), area.parent_path(), e2)) continue;
      if (!exists_nofollow(slot / e->second.second)) fs::remove_all(dest, ec);  // it was moved in: undo
      if (exists_nofollow(slot / kBackup)) {
        if (exists_nofollow(dest)) fs::remove_all(slot / kBackup, ec);
        else fs::rename(slot / kBackup, dest, ec);
      }
    }
  }
  fs::remove_all(area, ec);
}

}  // namespace

// ------------------------------------------------------------ public API

std::size_t sweep_stale_outputs(const std::string& dir) {
  std::size_t removed = 0;
  std::error_code ec;
  fs::directory_iterator it(dir.empty() ? "." : dir, ec), end;
  std::vector<fs::path> stale;
  for (; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.rfind(kStagePrefix, 0) == 0) {
      if (!owner_alive(name, kStagePrefix)) stale.push_back(it->path());
    } else if (name.rfind(kTempPrefix, 0) == 0) {
      if (!owner_alive(name, kTempPrefix)) stale.push_back(it->path());
    }
  }
  for (const fs::path& p : stale) {
    std::error_code e2;
    if (p.filename().string().rfind(kStagePrefix, 0) == 0 && fs::is_directory(fs::symlink_status(p, e2))) recover_area(p);
    else fs::remove_all(p, e2);
    ++removed;
  }
  return removed;
}

OutputStaging::OutputStaging() {
  if (g_stage) throw IOError("internal: a run's outputs are already being staged");
  g_stage = new Stage();
}

OutputStaging::~OutputStaging() {
  abandon();
  delete g_stage;
  g_stage = nullptr;
}

void OutputStaging::commit() {
  if (!g_stage) return;
  std::lock_guard<std::mutex> lock(g_stage->mu);
  try {
    g_stage->commit();
  } catch (...) {
    g_stage->undo();
    g_stage->remove_areas();
    throw;
  }
  g_stage->remove_areas();
}

void OutputStaging::abandon() noexcept {
  if (!g_stage) return;
  std::lock_guard<std::mutex> lock(g_stage->mu);
  g_stage->undo();
  g_stage->remove_areas();
}

std::vector<std::string> OutputStaging::destinations() const {
  std::vector<std::string> d;
  if (!g_stage) return d;
  std::lock_guard<std::mutex> lock(g_stage->mu);
  for (auto& e : g_stage->entries)
    if (e) d.push_back(e->dest.string());
  return d;
}

AtomicOutputFile::AtomicOutputFile(std::string destination, bool overwrite) : dest_(std::move(destination)) {
  if (dest_.empty()) throw IOError("output path is empty");
  throw_if_cancelled();
  const fs::path d = normalised(dest_);
  std::error_code ec;
  if (g_stage && !in_staging_area(d)) {
    std::lock_guard<std::mutex> lock(g_stage->mu);
    fs::path rel;
    if (Entry* f = g_stage->folder_holding(d, rel)) {  // inside a folder this run writes
      const fs::path target = f->staged / rel;
      if (!fs::is_directory(target.parent_path(), ec))
        throw IOError("cannot write '" + dest_ + "': folder '" + fs::path(dest_).parent_path().string() +
                      "' does not exist");
      if (fs::is_directory(target, ec)) throw IOError("cannot write '" + dest_ + "': it is a folder");
      if (exists_nofollow(target)) twice(dest_);
      final_ = target.string();
      temp_ = (target.parent_path() / temp_name(target)).string();
      return;
    }
    if (g_stage->exact(d)) twice(dest_);
  }
  const fs::path dir = d.parent_path();
  if (!fs::is_directory(dir, ec))
    throw IOError("cannot write '" + dest_ + "': folder '" +
                  (fs::path(dest_).parent_path().empty() ? std::string(".") : fs::path(dest_).parent_path().string()) +
                  "' does not exist");
  if (exists_nofollow(d)) {
    if (fs::is_directory(d, ec)) throw IOError("cannot write '" + dest_ + "': it is a folder");
    if (!overwrite) throw IOError("output '" + dest_ + "' already exists (pass --force to replace it)");
  }
  if (g_stage && !in_staging_area(d)) {
    std::lock_guard<std::mutex> lock(g_stage->mu);
    Entry& e = g_stage->add(d, false, false);
    entry_ = static_cast<long>(e.id);
    final_ = e.staged.string();
    temp_ = final_;  // the staging slot is private: written in place, moved at the end
    return;
  }
  final_ = d.string();
  temp_ = (dir / temp_name(d)).string();
}

AtomicOutputFile::~AtomicOutputFile() {
  if (committed_) return;
  std::error_code ec;
  fs::remove(temp_, ec);
  if (entry_ >= 0 && g_stage) {
    std::lock_guard<std::mutex> lock(g_stage->mu);
    g_stage->release(entry_);
  }
}

void AtomicOutputFile::commit() {
  throw_if_cancelled();
  std::error_code ec;
  if (!fs::exists(temp_, ec)) throw IOError("internal: temporary for '" + dest_ + "' was not written");
  if (temp_ != final_) {
    fs::rename(temp_, final_, ec);
    if (ec) throw IOError("cannot rename temporary onto '" + dest_ + "': " + ec.message());
  }
  if (entry_ >= 0 && g_stage) {
    std::lock_guard<std::mutex> lock(g_stage->mu);
    if (static_cast<std::size_t>(entry_) < g_stage->entries.size() && g_stage->entries[entry_])
      g_stage->entries[entry_]->done = true;
  }
  committed_ = true;
}

AtomicOutputFolder::AtomicOutputFolder(std::string destination, bool overwrite) : dest_(std::move(destination)) {
  if (dest_.empty()) throw IOError("output folder path is empty");
  throw_if_cancelled();
  const fs::path d = normalised(dest_);
  std::error_code ec;
  if (g_stage && !in_staging_area(d)) {
    std::lock_guard<std::mutex> lock(g_stage->mu);
    fs::path rel;
    if (Entry* f = g_stage->folder_holding(d, rel)) {
      const fs::path target = f->staged / rel;
      if (exists_nofollow(target)) twice(dest_);
      if (!fs::is_directory(target.parent_path(), ec))
        throw IOError("cannot write folder '" + dest_ + "': its parent folder does not exist");
      fs::create_directory(target, ec);
      if (ec) throw IOError("cannot create folder '" + dest_ + "': " + ec.message());
      temp_ = target.string();
      return;
    }
    if (g_stage->exact(d)) twice(dest_);
    for (auto& e : g_stage->entries)
      if (e && inside(e->dest, d, rel)) twice(e->dest.string());
  }
  if (!fs::is_directory(d.parent_path(), ec))
    throw IOError("cannot write folder '" + dest_ + "': its parent folder does not exist");
  if (exists_nofollow(d)) {
    if (!fs::is_directory(d, ec)) throw IOError("output '" + dest_ + "' exists and is not a folder");
    if (!overwrite) throw IOError("output folder '" + dest_ + "' already exists (pass --force to replace it)");
  }
  if (g_stage && !in_staging_area(d)) {
    std::lock_guard<std::mutex> lock(g_stage->mu);
    Entry& e = g_stage->add(d, true, true);
    entry_ = static_cast<long>(e.id);
    fs::create_directory(e.staged, ec);
    if (ec) throw IOError("cannot create folder '" + dest_ + "' in the staging folder: " + ec.message());
    temp_ = e.staged.string();
    return;
  }
  temp_ = (d.parent_path() / temp_name(d)).string();
  fs::create_directory(temp_, ec);
  if (ec) throw IOError("cannot create a temporary folder for '" + dest_ + "': " + ec.message());
}

AtomicOutputFolder::~AtomicOutputFolder() {
  if (committed_) return;
  std::error_code ec;
  if (entry_ >= 0 && g_stage) {
    std::lock_guard<std::mutex> lock(g_stage->mu);
    g_stage->release(entry_);
  } else if (!temp_.empty()) {
    fs::remove_all(temp_, ec);  // a temporary beside the destination, or inside a staged folder
  }
}

void AtomicOutputFolder::commit() {
  throw_if_cancelled();
  if (entry_ >= 0 && g_stage) {
    std::lock_guard<std::mutex> lock(g_stage->mu);
    if (static_cast<std::size_t>(entry_) < g_stage->entries.size() && g_stage->entries[entry_])
      g_stage->entries[entry_]->done = true;
    committed_ = true;
    return;
  }
  const fs::path d = normalised(dest_);
  if (g_stage && !in_staging_area(d)) {  // inside a staged folder: already in its place there
    committed_ = true;
    return;
  }
  std::error_code ec;
  fs::path old;
  if (exists_nofollow(d)) {
    old = d.parent_path() / temp_name(d);
    fs::rename(d, old, ec);
    if (ec) throw IOError("cannot move '" + dest_ + "' aside to replace it: " + ec.message());
  }
  fs::rename(temp_, d, ec);
  if (ec) {
    std::error_code e2;
    if (!old.empty()) fs::rename(old, d, e2);
    throw IOError("cannot move folder '" + dest_ + "' into place: " + ec.message());
  }
  if (!old.empty()) fs::remove_all(old, ec);
  committed_ = true;
}

void write_file_atomic(const std::string& path, const std::string& bytes, bool overwrite) {
  AtomicOutputFile out(path, overwrite);
  {
    std::ofstream f(out.temp_path(), std::ios::binary);
    if (!f) throw IOError("cannot open '" + out.temp_path() + "' for writing");
    f.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    f.flush();
    if (!f) throw IOError("write to '" + path + "' failed (disk full?)");
  }
  out.commit();
}

void ensure_directory(const std::string& dir) {
  throw_if_cancelled();
  std::error_code ec;
  const fs::path p = normalised(dir);
  if (g_stage && !in_staging_area(p)) {
    std::lock_guard<std::mutex> lock(g_stage->mu);
    fs::path rel;
    if (Entry* f = g_stage->folder_holding(p, rel)) {
      const fs::path target = f->staged / rel;
      if (exists_nofollow(target) && !fs::is_directory(target, ec))
        throw IOError("'" + dir + "' exists and is not a folder");
      fs::create_directories(target, ec);
      if (ec) throw IOError("cannot create folder '" + dir + "': " + ec.message());
      return;
    }
    if (Entry* e = g_stage->exact(p)) {
      if (!e->dir) throw IOError("'" + dir + "' exists and is not a folder");
      return;
    }
    if (!exists_nofollow(p)) {
      // The outermost missing folder becomes one staged output; the rest is made inside it.
      fs::path top = p;
      while (top.has_parent_path() && top.parent_path() != top && !exists_nofollow(top.parent_path()))
        top = top.parent_path();
      if (!fs::is_directory(top.parent_path(), ec))
        throw IOError("cannot create folder '" + dir + "': '" + top.parent_path().string() + "' is not a folder");
      Entry& e = g_stage->add(top, true, false);
      fs::path inner;
      const fs::path target = inside(p, top, inner) ? e.staged / inner : e.staged;
      fs::create_directories(target, ec);
      if (ec) throw IOError("cannot create folder '" + dir + "': " + ec.message());
      e.done = true;
      return;
    }
  }
  if (fs::exists(p, ec)) {
    if (!fs::is_directory(p, ec)) throw IOError("'" + dir + "' exists and is not a folder");
    return;
  }
  fs::create_directories(p, ec);
  if (ec) throw IOError("cannot create folder '" + dir + "': " + ec.message());
}

bool same_file(const std::string& a, const std::string& b) {
  std::error_code ec;
  if (a.empty() || b.empty()) return false;
  if (fs::exists(a, ec) && fs::exists(b, ec)) return fs::equivalent(a, b, ec);
  const fs::path ca = fs::weakly_canonical(fs::absolute(a, ec), ec);
  std::error_code ec2;
  const fs::path cb = fs::weakly_canonical(fs::absolute(b, ec2), ec2);
  if (ec || ec2) return normalised(a) == normalised(b);
  return ca == cb;
}

std::string staged_path(const std::string& path) {
  if (!g_stage) return path;
  std::lock_guard<std::mutex> lock(g_stage->mu);
  const fs::path p = normalised(path);
  fs::path rel;
  if (Entry* f = g_stage->folder_holding(p, rel)) return (f->staged / rel).string();
  if (Entry* e = g_stage->exact(p)) return e->staged.string();
  return path;
}

void rename_output(const std::string& from, const std::string& to) {
  std::error_code ec;
  if (!g_stage) {
    fs::rename(from, to, ec);
    if (ec) throw IOError("cannot rename '" + from + "' to '" + to + "': " + ec.message());
    return;
  }
  std::lock_guard<std::mutex> lock(g_stage->mu);
  const fs::path f = normalised(from), t = normalised(to);
  fs::path rf, rt;
  Entry* ff = g_stage->folder_holding(f, rf);
  if (ff && g_stage->folder_holding(t, rt) == ff) {
    if (exists_nofollow(ff->staged / rt)) twice(to);
    fs::rename(ff->staged / rf, ff->staged / rt, ec);
    if (ec) throw IOError("cannot rename '" + from + "' to '" + to + "': " + ec.message());
    return;
  }
  Entry* e = g_stage->exact(f);
  if (!e || e->dir || f.parent_path() != t.parent_path())
    throw IOError("internal: cannot rename '" + from + "' to '" + to + "' (not an output of this run in one folder)");
  if (g_stage->exact(t)) twice(to);
  const fs::path staged = e->staged.parent_path() / t.filename();
  fs::rename(e->staged, staged, ec);
  if (ec) throw IOError("cannot rename '" + from + "' to '" + to + "': " + ec.message());
  e->staged = staged;
  e->dest = t;
  g_stage->journal(e->area, {{"entry", e->id}, {"dest", t.string()}, {"name", t.filename().string()}, {"dir", false}});
}

void discard_output(const std::string& path) {
  std::error_code ec;
  if (!g_stage) {
    fs::remove(path, ec);
    return;
  }
  std::lock_guard<std::mutex> lock(g_stage->mu);
  const fs::path p = normalised(path);
  fs::path rel;
  if (Entry* f = g_stage->folder_holding(p, rel)) {
    fs::remove(f->staged / rel, ec);
    return;
  }
  if (Entry* e = g_stage->exact(p)) g_stage->release(static_cast<long>(e->id));
}

}  // namespace surftex
