// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Safe output (brief: "no half-written output, nothing the user gave is
// overwritten silently"; issue 21 item 3: "a run's outputs as one unit").
//
// Every writer goes through AtomicOutputFile, AtomicOutputFolder or
// ensure_directory: a temporary beside the destination, renamed when complete.
// While an OutputStaging is active (the CLI's whole run) everything is staged
// in `.surftex-stage-PID-START` folders and moved into place by commit() only
// when the run succeeded (undone on failure or signal; a journal lets a later
// run undo a SIGKILLed one). In full: docs/decisions/601-run-output-staging.md.

#include <string>
#include <vector>

namespace surftex {

class AtomicOutputFile {
 public:
  /// Prepares a temporary path for `destination` (same extension so that
  /// format-sniffing writers behave). Throws IOError if the destination is a
  /// folder, exists and !overwrite, is already an output of this run, or its
  /// folder does not exist (or was not created by this run).
  explicit AtomicOutputFile(std::string destination, bool overwrite = true);
  ~AtomicOutputFile();  // removes the temporary if commit() was not reached
  AtomicOutputFile(const AtomicOutputFile&) = delete;
  AtomicOutputFile& operator=(const AtomicOutputFile&) = delete;

  const std::string& temp_path() const { return temp_; }
  const std::string& destination() const { return dest_; }
  /// Renames the temporary onto the destination (or, in a staged run, onto
  /// its place in the staging folder). Throws IOError.
  void commit();

 private:
  std::string dest_, temp_, final_;
  long entry_ = -1;  // staging entry owned by this writer, or -1
  bool committed_ = false;
};

/// A folder written whole and then put in place, replacing an existing one
/// (when overwrite) as a unit: write into temp_path(), then commit().
class AtomicOutputFolder {
 public:
  /// Throws IOError if `destination` exists and is not a folder, exists and
  /// !overwrite, or its parent folder does not exist.
  explicit AtomicOutputFolder(std::string destination, bool overwrite = true);
  ~AtomicOutputFolder();  // removes the temporary folder if commit() was not reached
  AtomicOutputFolder(const AtomicOutputFolder&) = delete;
  AtomicOutputFolder& operator=(const AtomicOutputFolder&) = delete;

  const std::string& temp_path() const { return temp_; }
  void commit();

 private:
  std::string dest_, temp_;
  long entry_ = -1;
  bool committed_ = false;
};

/// Writes `bytes` to `path` atomically.
void write_file_atomic(const std::string& path, const std::string& bytes, bool overwrite = true);

/// Creates `dir` (and parents) if absent. Throws IOError if it cannot, or if
/// it exists and is not a folder. In a staged run the folder is created in
/// the staging folder and appears with the run's other outputs.
void ensure_directory(const std::string& dir);

/// True when both paths name the same file: the same existing file (after
/// resolving links), or, when either does not exist yet, the same path once
/// made absolute and normalised (so two outputs of one run that do not exist
/// yet are recognised as one).
bool same_file(const std::string& a, const std::string& b);

/// Where `path`, an output of the current staged run, is while the run lasts
/// (to read back what an earlier step wrote); `path` itself when no run is
/// staged or `path` was not written by it.
std::string staged_path(const std::string& path);

/// Renames an output written earlier in this run (`from`) to `to` (same
/// folder); without staging, a plain rename. Throws IOError.
void rename_output(const std::string& from, const std::string& to);

/// Drops an output written earlier in this run (nothing happens if absent).
void discard_output(const std::string& path);

/// Removes, in `dir`, the staging folders and temporaries of surftex runs that
/// no longer exist (undoing a run killed mid-commit from its journal); a live
/// run's files are never touched. Returns the entries removed. Never throws.
std::size_t sweep_stale_outputs(const std::string& dir);

/// The run-level staging (one per process at a time; the CLI's main keeps it
/// for the whole subcommand). While alive, every writer above stages.
class OutputStaging {
 public:
  OutputStaging();
  ~OutputStaging();  // abandon() unless commit() succeeded
  OutputStaging(const OutputStaging&) = delete;
  OutputStaging& operator=(const OutputStaging&) = delete;

  /// Moves every staged output into place, in the order written; if a move
  /// fails or a signal arrives, the moves made are undone and the error
  /// (IOError or Cancelled) is thrown. Then removes the staging folders.
  void commit();
  /// Removes every staging folder and what it holds.
  void abandon() noexcept;
  /// The destinations staged so far (for tests and messages).
  std::vector<std::string> destinations() const;
};

}  // namespace surftex
