#pragma once
// Shared command-line plumbing for the subcommands (CLI11 stays inside apps/).

#include <CLI/CLI.hpp>
#include <functional>
#include <string>
#include <vector>

namespace handlabel {

// Parses argv into `app`. Returns -1 when the command should go on, otherwise the exit
// status to return at once: 0 after --help, 2 after a usage error (message printed).
int ParseCommandLine(CLI::App& app, int argc, char** argv);

// Runs `body`, turning exceptions into a one-line message on stderr and status 1.
int RunReportingErrors(const char* command, const std::function<int()>& body);

// One malloc arena for every thread of the process, for commands whose threads each
// run the detector and the fit on their own frames (detect, label jobs without a
// network). Call before the threads start.
void UseOneMallocArena();

// "a,b,,c" -> {"a", "b", "c"}: the comma lists of flags such as --frames, --ignore-views.
std::vector<std::string> SplitCommas(const std::string& text);

}  // namespace handlabel
