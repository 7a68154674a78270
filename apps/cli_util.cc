#include "apps/cli_util.h"

#include <malloc.h>

#include <exception>
#include <iostream>
#include <new>
#include <sstream>

namespace handlabel {

void UseOneMallocArena() {
  // Each further thread would get an arena of its own, made of mmap'd heaps that glibc
  // unmaps as they empty: the frames a second thread detected and fitted page-faulted
  // their memory afresh, and with another process on one of two cores a detector label
  // job was slower on 2 threads than on 1 (docs/speed.md, "Threads under load"). One
  // arena measured the same on free cores. Not for the network: its two lanes allocate
  // at once, and waiting for the one arena's lock cost 4-7 %.
  mallopt(M_ARENA_MAX, 1);
}

int ParseCommandLine(CLI::App& app, int argc, char** argv) {
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    std::cout << app.help();
    return 0;
  } catch (const CLI::ParseError& e) {
    std::cerr << "handlabel " << app.get_name() << ": " << e.what() << "\n"
              << "Run 'handlabel " << app.get_name() << " --help' for usage.\n";
    return 2;
  }
  return -1;
}

namespace {

// One line: a library's message up to its first line break (LibTorch appends a
// backtrace of 40 lines that tells a user nothing).
std::string FirstLine(const char* text) {
  std::string line(text);
  const size_t end = line.find('\n');
  return end == std::string::npos ? line : line.substr(0, end);
}

}  // namespace

int RunReportingErrors(const char* command, const std::function<int()>& body) {
  try {
    return body();
  } catch (const std::bad_alloc&) {
    std::cerr << "handlabel " << command
              << ": error: out of memory (std::bad_alloc): a count, size or batch given "
                 "in a flag or file needs more memory than this machine has\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "handlabel " << command << ": error: " << FirstLine(e.what()) << "\n";
    return 1;
  }
}

std::vector<std::string> SplitCommas(const std::string& text) {
  std::vector<std::string> items;
  std::stringstream list(text);
  for (std::string item; std::getline(list, item, ',');) {
    if (!item.empty()) items.push_back(item);
  }
  return items;
}

}  // namespace handlabel
