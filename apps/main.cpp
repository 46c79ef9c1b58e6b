// SPDX-License-Identifier: AGPL-3.0-or-later
// The `surftex` command: decorate 3D surface meshes with textures grown from
// examples. Subcommands live in apps/surftex/cmd_*.cpp.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <exception>
#include <new>

#include "geometry/errors.h"
#include "surftex/command.h"

int main(int argc, char** argv) {
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
  try {
    for (auto& [sub, run] : runs)
      if (sub->parsed()) {
        surftex::cli::check_parsed_arguments(*sub);
        return run();
      }
  } catch (const surftex::Error& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "error: out of memory\n");
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  }
  return 2;
}
