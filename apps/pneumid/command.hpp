// Sub-command registry of the `pneumid` program. Each apps/pneumid/cmd_*.cpp
// registers itself with a static Registrar, so that adding a command needs no
// change elsewhere:
//
//   static pneumid::cli::Registrar reg("convert", "Convert a model between domains",
//                                      [](CLI::App& app) { ... app.callback(...); });
//
// Callbacks report results on stdout; errors are thrown (pneumid::InvalidArgument,
// pneumid::DataError, CLI::Error, std::exception) and main() prints them on stderr
// as "pneumid <command>: error: <message>" with exit code 1 (2 for usage errors).
// A callback may throw pneumid::cli::ExitCode to end with another status.
//
// Naming: a command's parsed flags are a struct `<Command>Args` (IdentifyArgs,
// ControlArgs, ...); option groups shared by several commands are
// `<Group>Options` with their Add function (DataOptions, ModelOptions,
// RealtimeOptions in *_options.hpp).
#pragma once

#include <functional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

namespace pneumid::cli {

struct CommandInfo {
  std::string name;
  std::string description;
  std::function<void(CLI::App&)> setup;
};

/// All registered commands, sorted by name.
std::vector<CommandInfo>& Commands();

struct Registrar {
  Registrar(std::string name, std::string description, std::function<void(CLI::App&)> setup);
};

/// Thrown by a command to exit with a given status after printing its own message.
struct ExitCode {
  int code;
};

/// True when stderr is a terminal (progress bars are drawn only then, or when forced).
bool StderrIsTerminal();

}  // namespace pneumid::cli
