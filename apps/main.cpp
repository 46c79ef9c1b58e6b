// SPDX-License-Identifier: AGPL-3.0-or-later
// The `surftex` command: decorate 3D surface meshes with textures grown from
// examples. Subcommands live in apps/surftex/cmd_*.cpp.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <exception>
#include <new>

#include "geometry/allocator_settings.h"
#include "geometry/cancellation.h"
#include "geometry/errors.h"
#include "geometry/output_file.h"
#include "surftex/command.h"

int main(int argc, char** argv) {
  surftex::keep_freed_memory_for_reuse();  // before any thread starts
  surftex::cli::record_command_line(argc, argv);  // for the reports (surftex/report.h)
  CLI::App app{
      "surftex: decorate 3D surface meshes with textures grown from examples.\n"
      "Run `surftex demo` for a tour on built-in data, `surftex SUBCOMMAND --help` for details."};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("surftex ") + surftex::cli::surftex_version());
  auto& reg = surftex::cli::registry();
  std::vector<std::pair<CLI::App*, std::function<int()>>> runs;
  for (auto& sc : reg) {
    CLI::App* sub = app.add_subcommand(sc.name, sc.description);
    runs.emplace_back(sub, sc.setup(*sub));
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    std::fprintf(stderr, "Run with --help for the options.\n");
    return 2;
  }
  // Every output of the run is staged and moved into place only when the
  // whole subcommand succeeded (geometry/output_file.h); SIGINT/SIGTERM/SIGHUP
  // stop it at the next check and leave nothing (geometry/cancellation.h).
  surftex::install_cancel_handlers();
  auto failed = [](const char* what) {
    const int sig = surftex::cancel_signal();  // whatever failed, a signal stopped it
    std::fprintf(stderr, "error: %s\n", sig != 0 ? surftex::Cancelled(sig).what() : what);
    return sig != 0 ? 128 + sig : 2;
  };
  try {
    for (auto& [sub, run] : runs)
      if (sub->parsed()) {
        surftex::cli::sweep_stale_outputs_of_arguments(*sub);
        surftex::cli::check_parsed_arguments(*sub);
        // `batch` is not staged: it keeps its state in OUT as it goes (lock,
        // Snakefile, per-job results) so that an interrupted batch resumes,
        // and each of its jobs is staged by surftex-job itself.
        if (sub->get_name() == "batch") return run();
        surftex::OutputStaging staging;
        const int rc = run();
        if (rc != 0) return rc;  // the staging is abandoned: nothing is written
        staging.commit();
        return 0;
      }
  } catch (const surftex::Error& e) {
    return failed(e.what());
  } catch (const std::bad_alloc&) {
    return failed("out of memory");
  } catch (const std::exception& e) {
    return failed(e.what());
  }
  return 2;
}
