// pneumid: from a step test to a running predictive controller.
#include <algorithm>
#include <cstdio>
#include <exception>
#include <iostream>
#include <malloc.h>
#include <unistd.h>

#include <CLI/CLI.hpp>

#include "command.hpp"
#include "pneumid/common/check.hpp"
#include "pneumid/common/version.hpp"

namespace pneumid::cli {

std::vector<CommandInfo>& Commands() {
  static std::vector<CommandInfo> commands;
  return commands;
}

Registrar::Registrar(std::string name, std::string description,
                     std::function<void(CLI::App&)> setup) {
  Commands().push_back({std::move(name), std::move(description), std::move(setup)});
}

bool StderrIsTerminal() { return isatty(STDERR_FILENO) != 0; }

}  // namespace pneumid::cli

int main(int argc, char** argv) {
  using namespace pneumid::cli;
  // Long records make many signal-sized temporaries (8 MB per 10^6 samples).
  // glibc serves each from a fresh mmap and unmaps it when freed, so every one
  // is paid again in page faults (about half of `identify -m arx` on 10^6
  // rows). Keeping freed memory in the heap lets the next temporary reuse it.
  mallopt(M_MMAP_THRESHOLD, 512 * 1024 * 1024);
  mallopt(M_TRIM_THRESHOLD, 1024 * 1024 * 1024);
  CLI::App app{"pneumid: identify models of a plant from a step test, compare them, and tune,\n"
               "simulate and run predictive controllers (DMC, GPC, MPC, PID) against it."};
  app.name("pneumid");
  app.set_version_flag("--version", std::string(pneumid::Version()));
  app.require_subcommand(1);
  app.fallthrough(false);

  auto& commands = Commands();
  std::sort(commands.begin(), commands.end(),
            [](const CommandInfo& a, const CommandInfo& b) { return a.name < b.name; });
  std::string current = "";
  for (auto& c : commands) {
    CLI::App* sub = app.add_subcommand(c.name, c.description);
    c.setup(*sub);
    sub->preparse_callback([name = c.name, &current](std::size_t) { current = name; });
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
    std::cerr << "pneumid" << (current.empty() ? "" : " " + current) << ": error: " << e.what()
              << "\nRun with --help for more information.\n";
    return 2;
  } catch (const ExitCode& e) {
    return e.code;
  } catch (const pneumid::InvalidArgument& e) {
    std::cerr << "pneumid" << (current.empty() ? "" : " " + current) << ": error: " << e.what()
              << "\n";
    return 1;
  } catch (const pneumid::DataError& e) {
    std::cerr << "pneumid" << (current.empty() ? "" : " " + current) << ": error: " << e.what()
              << "\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "pneumid" << (current.empty() ? "" : " " + current) << ": error: " << e.what()
              << "\n";
    return 1;
  }
  return 0;
}
