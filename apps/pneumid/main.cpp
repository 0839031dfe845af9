// pneumid: from a step test to a running predictive controller.
#include <malloc.h>
#include <unistd.h>
#include <algorithm>
#include <cstdio>
#include <exception>
#include <iostream>
#include <new>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <CLI/CLI.hpp>
#include <string>
#include <vector>

#include "command.hpp"
#include "pneumid/common/check.hpp"
#include "pneumid/common/version.hpp"
#include "pneumid/models/model_file_scope.hpp"

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

namespace {

// "; did you mean 'identify'?" for the name within edit distance 2 of
// `word`, or "".
std::string ClosestName(const std::string& word, const std::vector<std::string>& names) {
  auto distance = [](const std::string& a, const std::string& b) {
    std::vector<std::size_t> row(b.size() + 1);
    for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
    for (std::size_t i = 1; i <= a.size(); ++i) {
      std::size_t diagonal = row[0];
      row[0] = i;
      for (std::size_t j = 1; j <= b.size(); ++j) {
        const std::size_t up = row[j];
        row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
        diagonal = up;
      }
    }
    return row[b.size()];
  };
  std::string best;
  std::size_t best_distance = 3;
  for (const std::string& n : names) {
    const std::size_t d = distance(word, n);
    if (d < best_distance) {
      best_distance = d;
      best = n;
    }
  }
  return best.empty() ? "" : "; did you mean '" + best + "'?";
}

}  // namespace

int main(int argc, char** argv) {
  using namespace pneumid::cli;
  // Long records make many signal-sized temporaries (8 MB per 10^6 samples).
  // glibc serves each from a fresh mmap and unmaps it when freed, so every one
  // is paid again in page faults (about half of `identify -m arx` on 10^6
  // rows). Keeping freed memory in the heap lets the next temporary reuse it.
  mallopt(M_MMAP_THRESHOLD, 512 * 1024 * 1024);
  mallopt(M_TRIM_THRESHOLD, 1024 * 1024 * 1024);
  CLI::App app{
      "pneumid: identify models of a plant from a step test, compare them, and tune,\n"
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

  // A command reads each model file once, however often it consults it.
  pneumid::ModelFileScope model_files;
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    // A first word that is no command: name it (and the closest command)
    // instead of CLI11's "A subcommand is required".
    if (current.empty() && argc > 1 && argv[1][0] != '-') {
      std::vector<std::string> names;
      for (const auto& c : commands) names.push_back(c.name);
      std::cerr << "pneumid: error: unknown command '" << argv[1] << "'"
                << ClosestName(argv[1], names)
                << " (commands: " << fmt::format("{}", fmt::join(names, ", "))
                << ")\nRun with --help for more information.\n";
      return 2;
    }
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
  } catch (const std::bad_alloc&) {
    std::cerr << "pneumid" << (current.empty() ? "" : " " + current)
              << ": error: out of memory: the problem is too large for this machine (a sample time "
                 "much shorter than the model's time scale, long horizons or delays, or a long "
                 "record); choose a longer sample time or shorter data\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "pneumid" << (current.empty() ? "" : " " + current) << ": error: " << e.what()
              << "\n";
    return 1;
  }
  return 0;
}
