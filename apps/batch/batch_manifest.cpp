// SPDX-License-Identifier: AGPL-3.0-or-later
#include "batch/batch_manifest.h"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "geometry/errors.h"

namespace fs = std::filesystem;

namespace surftex::batch {

bool batch_output_kind(const std::string& subcommand, OutputKind& kind) {
  // Folder subcommands write several files into -o; the others write one file
  // whose format follows the extension, named here.
  static const std::map<std::string, OutputKind> kinds{
      {"patches", {true, ""}},         {"subdiv", {true, ""}},          {"material-map", {true, ""}},
      {"material-tile", {true, ""}},   {"demo", {true, ""}},            {"quilt", {false, "quilt.obj"}},
      {"elements", {false, "elements.obj"}}, {"convert", {false, "mesh.glb"}}, {"repair", {false, "mesh.obj"}},
      {"swatch", {false, "swatch.obj"}}, {"render", {false, "render.png"}}, {"synth", {false, "synth.png"}},
      {"tile", {false, "tile.png"}}};
  auto it = kinds.find(subcommand);
  if (it == kinds.end()) return false;
  kind = it->second;
  return true;
}

const std::vector<std::string>& batch_refused_subcommands() {
  static const std::vector<std::string> refused{"info", "version", "batch"};
  return refused;
}

namespace {

// One logical line: text after joining backslash-newline continuations, and
// the physical line it starts on.
struct LogicalLine {
  std::string text;
  int line;
};

std::vector<LogicalLine> logical_lines(const std::string& text) {
  std::vector<LogicalLine> out;
  std::string cur;
  int line = 1, start = 1;
  for (std::size_t i = 0; i <= text.size(); ++i) {
    const bool end = i == text.size();
    const char c = end ? '\n' : text[i];
    if (c == '\r' && i + 1 < text.size() && text[i + 1] == '\n') continue;
    if (c != '\n') {
      cur += c;
      continue;
    }
    // An odd number of trailing backslashes continues the line.
    std::size_t bs = 0;
    while (bs < cur.size() && cur[cur.size() - 1 - bs] == '\\') ++bs;
    if (bs % 2 == 1 && !end) {
      cur.pop_back();
      cur += ' ';
    } else {
      if (!(end && cur.empty())) out.push_back({cur, start});
      cur.clear();
      start = line + 1;
    }
    ++line;
  }
  return out;
}

bool valid_utf8(const std::string& s) {
  for (std::size_t i = 0; i < s.size();) {
    const auto c = static_cast<unsigned char>(s[i]);
    const int n = c < 0x80 ? 0 : (c & 0xE0) == 0xC0 ? 1 : (c & 0xF0) == 0xE0 ? 2 : (c & 0xF8) == 0xF0 ? 3 : -1;
    if (n < 0 || i + n >= s.size()) return false;
    for (int k = 1; k <= n; ++k)
      if ((static_cast<unsigned char>(s[i + k]) & 0xC0) != 0x80) return false;
    i += n + 1;
  }
  return true;
}

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  return s;
}

// A reason the name cannot be a job folder, or "".
std::string name_problem(const std::string& name) {
  if (name.empty()) return "the job name is empty";
  if (name.size() > 100) return "the job name is longer than 100 characters";
  if (!std::isalnum(static_cast<unsigned char>(name[0])))
    return "the job name '" + name + "' must start with a letter or digit";
  for (char c : name)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.'))
      return "the job name '" + name + "' may only contain letters, digits, '_', '-' and '.'";
  for (const char* reserved : {"summary.json", "index.html", "snakefile"})
    if (lower(name) == reserved) return "the job name '" + name + "' is reserved for the batch's own files";
  return "";
}

// The first argument that names an output (the batch gives each job its own).
std::string output_argument(const std::vector<std::string>& args) {
  for (const std::string& a : args) {
    for (const char* opt : {"--output", "--report", "--render"}) {
      const std::string o = opt;
      if (a == o || a.rfind(o + "=", 0) == 0) return o;
    }
    if (a.rfind("-o", 0) == 0) return "-o";
  }
  return "";
}

}  // namespace

std::vector<std::string> split_shell_words(const std::string& text) {
  std::vector<std::string> words;
  std::string cur;
  bool in_word = false;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (c == ' ' || c == '\t') {
      if (in_word) words.push_back(cur), cur.clear(), in_word = false;
    } else if (c == '#' && !in_word) {
      break;  // a comment to the end of the line
    } else if (c == '\'') {
      const std::size_t end = text.find('\'', i + 1);
      if (end == std::string::npos) throw InvalidInputError("unterminated single quote");
      cur += text.substr(i + 1, end - i - 1), i = end, in_word = true;
    } else if (c == '"') {
      std::size_t j = i + 1;
      for (; j < text.size() && text[j] != '"'; ++j) {
        // Inside double quotes a backslash escapes only " \ $ and `.
        if (text[j] == '\\' && j + 1 < text.size() && std::string("\"\\$`").find(text[j + 1]) != std::string::npos)
          ++j;
        cur += text[j];
      }
      if (j >= text.size()) throw InvalidInputError("unterminated double quote");
      i = j, in_word = true;
    } else if (c == '\\') {
      if (i + 1 < text.size()) cur += text[++i];
      in_word = true;
    } else {
      cur += c, in_word = true;
    }
  }
  if (in_word) words.push_back(cur);
  return words;
}

BatchManifest parse_batch_manifest(const std::string& text, const std::string& path) {
  BatchManifest m;
  m.path = path;
  std::error_code ec;
  fs::path abs = fs::absolute(path, ec);
  m.dir = (ec ? fs::current_path() : abs.parent_path()).lexically_normal().string();
  std::map<std::string, int> seen;  // lower-case name -> line
  for (const LogicalLine& ll : logical_lines(text)) {
    const std::string where = path + ":" + std::to_string(ll.line) + ": ";
    auto fail = [&](const std::string& msg) { throw InvalidInputError(where + msg); };
    if (!valid_utf8(ll.text)) fail("the line is not UTF-8 text");
    std::size_t first = ll.text.find_first_not_of(" \t");
    if (first == std::string::npos || ll.text[first] == '#') continue;
    const std::size_t colon = ll.text.find(':', first);
    if (colon == std::string::npos) fail("expected 'NAME: SUBCOMMAND ARGS...'");
    std::string name = ll.text.substr(first, colon - first);
    while (!name.empty() && (name.back() == ' ' || name.back() == '\t')) name.pop_back();
    if (std::string p = name_problem(name); !p.empty()) fail(p);
    if (auto it = seen.find(lower(name)); it != seen.end())
      fail("the job name '" + name + "' is used again (first on line " + std::to_string(it->second) + ")");
    seen[lower(name)] = ll.line;
    std::vector<std::string> words;
    try {
      words = split_shell_words(ll.text.substr(colon + 1));
    } catch (const InvalidInputError& e) {
      fail(e.what());
    }
    if (words.empty()) fail("job '" + name + "' has no subcommand");
    BatchJob job;
    job.name = name;
    job.subcommand = words[0];
    job.args.assign(words.begin() + 1, words.end());
    job.line = ll.line;
    const auto& refused = batch_refused_subcommands();
    if (std::find(refused.begin(), refused.end(), job.subcommand) != refused.end())
      fail("job '" + name + "': `surftex " + job.subcommand + "` writes no output a batch can collect");
    if (!batch_output_kind(job.subcommand, job.output))
      fail("job '" + name + "': '" + job.subcommand + "' is not a surftex subcommand");
    if (std::string o = output_argument(job.args); !o.empty())
      fail("job '" + name + "' gives " + o + "; the batch sets each job's outputs (OUT/" + name +
           "/, its report.json) itself: remove it");
    m.jobs.push_back(std::move(job));
  }
  return m;
}

BatchManifest read_batch_manifest(const std::string& path) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) throw IOError("manifest '" + path + "' does not exist or is not a file");
  std::ifstream f(path, std::ios::binary);
  if (!f) throw IOError("cannot read manifest '" + path + "'");
  std::stringstream ss;
  ss << f.rdbuf();
  BatchManifest m = parse_batch_manifest(ss.str(), path);
  if (m.jobs.empty()) throw InvalidInputError("manifest '" + path + "' lists no jobs (one 'NAME: SUBCOMMAND ARGS...' a line)");
  return m;
}

std::string shell_quote(const std::string& word) {
  const bool plain = !word.empty() && std::all_of(word.begin(), word.end(), [](unsigned char c) {
    return std::isalnum(c) || std::string("_-./=:,+@%").find(static_cast<char>(c)) != std::string::npos;
  });
  if (plain) return word;
  std::string q = "'";
  for (char c : word) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

std::string job_command_line(const BatchJob& job) {
  std::string s = "surftex " + shell_quote(job.subcommand);
  for (const std::string& a : job.args) s += " " + shell_quote(a);
  return s;
}

}  // namespace surftex::batch
