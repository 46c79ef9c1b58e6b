// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// The job list of `surftex batch` (issue 20, item 1): a text file with one job
// per line, `NAME: SUBCOMMAND ARGS...`, without -o (the batch gives each job
// the output folder OUT/NAME/). Blank lines and `#` comments are allowed;
// arguments are split as a POSIX shell would (single and double quotes,
// backslash escapes, a trailing backslash continues the line). Every error
// names the file and line: "jobs.txt:12: ...".
#include <string>
#include <vector>

namespace surftex::batch {

/// What a subcommand writes for its -o: a folder, or one file that the batch
/// names inside the job folder.
struct OutputKind {
  bool folder = true;
  std::string file;  ///< the file name for -o when !folder ("render.png")
};

/// The -o of each subcommand a batch can run; false for one it cannot (no -o,
/// or the batch itself). New subcommands must be added here (a test checks
/// every registered subcommand is listed or refused on purpose).
bool batch_output_kind(const std::string& subcommand, OutputKind& kind);
/// The subcommands the batch refuses on purpose (no output to collect).
const std::vector<std::string>& batch_refused_subcommands();

struct BatchJob {
  std::string name;                ///< [A-Za-z0-9][A-Za-z0-9_.-]*, at most 100 characters
  std::string subcommand;          ///< a surftex subcommand ("patches")
  std::vector<std::string> args;   ///< its arguments, without -o
  OutputKind output;
  int line = 0;                    ///< the manifest line the job starts on (1-based)
};

struct BatchManifest {
  std::string path;  ///< the manifest file as given
  std::string dir;   ///< its folder, absolute: relative paths in jobs are relative to it
  std::vector<BatchJob> jobs;
};

/// Splits `text` into words as POSIX sh does (no expansion): quotes, escapes.
/// Throws InvalidInputError("unterminated quote") on a bad line.
std::vector<std::string> split_shell_words(const std::string& text);

/// Parses manifest text; `path` is used in messages and to resolve `dir`.
/// Throws InvalidInputError "PATH:LINE: ..." for a bad name, a duplicate name
/// (names differing only in case too, since folders collide on some file
/// systems), a job with -o/--output or --report (the batch sets them), an
/// unknown or non-batchable subcommand, or bytes that are not UTF-8.
BatchManifest parse_batch_manifest(const std::string& text, const std::string& path);
/// Reads and parses a manifest file (IOError if unreadable; an empty manifest
/// is refused).
BatchManifest read_batch_manifest(const std::string& path);

/// The job's full surftex command line as a user would type it, shell-quoted.
std::string job_command_line(const BatchJob& job);
/// `word` quoted for a POSIX shell when it needs it.
std::string shell_quote(const std::string& word);

}  // namespace surftex::batch
