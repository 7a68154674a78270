#include "apps/cli_util.h"

#include <malloc.h>

#include <exception>
#include <iostream>
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

int RunReportingErrors(const char* command, const std::function<int()>& body) {
  try {
    return body();
  } catch (const std::exception& e) {
    std::cerr << "handlabel " << command << ": error: " << e.what() << "\n";
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
