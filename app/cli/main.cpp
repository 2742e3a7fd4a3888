// mfr — the command-line shell over mfrcore. Every subcommand reads a scene (a model file, an
// .mfrscene, or @sample), writes PNG/JSON, and on bad input prints one line naming the file or
// argument and the reason, exits non-zero and leaves no partial output.
#include <CLI/CLI.hpp>

#include <cstdio>
#include <iostream>
#include <string>

#include "commands.hpp"
#include "mfr/error.hpp"
#include "mfr/host_memory.hpp"

namespace {

int runMfr(int argc, char** argv) {
  CLI::App app{"mfr: multifragment rendering — capture, sort and operate on many fragments per pixel", "mfr"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "mfr " MFR_VERSION);
  mfr::cli::addRender(app);
  mfr::cli::addCompare(app);
  mfr::cli::addInfo(app);
  mfr::cli::addBench(app);
  mfr::cli::addDataset(app);
  mfr::cli::addTrain(app);
  mfr::cli::addEvaluate(app);
  mfr::cli::addAllocations(app);
  mfr::cli::addProbe(app);
  // An empty value ("--stats ''", "--view ''", "--contour ''") is refused: to the commands an empty
  // string meant "not given", so --stats '' wrote no stats without a word.
  const CLI::Validator nonEmpty(
      [](const std::string& value) { return value.empty() ? std::string("an empty value") : std::string(); }, "",
      "non-empty");
  for (CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; }))
    for (CLI::Option* option : sub->get_options([](CLI::Option*) { return true; }))
      if (option->get_type_size() != 0) option->check(nonEmpty);
  // A first word that is no command ("mfr rendr") — CLI11 would only say that a subcommand is
  // required, without naming the word.
  if (argc > 1 && argv[1][0] != '-') {
    std::string commands;
    bool known = false;
    for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; })) {
      commands += (commands.empty() ? "" : ", ") + sub->get_name();
      known = known || sub->get_name() == argv[1];
    }
    if (!known) {
      std::cerr << "mfr: " << argv[1] << ": unknown command (" << commands << "; see mfr --help)\n";
      return 2;
    }
  }
  try {
    // A malformed MFR_MEMORY_LIMIT_MIB is refused before any work (not before --help or --version).
    bool helpOrVersion = false;
    for (int i = 1; i < argc; ++i)
      helpOrVersion = helpOrVersion || std::string(argv[i]) == "-h" || std::string(argv[i]) == "--help" ||
                      std::string(argv[i]) == "--version";
    if (!helpOrVersion) (void)mfr::availableHostMemory();
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::cerr << "mfr: ";
    for (const char* c = e.what(); *c; ++c) std::cerr << (*c == '\n' ? ' ' : *c);  // one line
    std::cerr << " (see mfr --help)\n";
    return 2;
  } catch (const mfr::Error& e) {
    std::cerr << "mfr: " << e.what() << "\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "mfr: internal error: " << e.what() << "\n";
    return 3;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  // What escapes the commands' own handling (the options' set-up: out of memory) is still one line.
  try {
    return runMfr(argc, argv);
  } catch (const std::exception& e) {
    std::cerr << "mfr: internal error: " << e.what() << "\n";
  } catch (...) {
    std::cerr << "mfr: internal error\n";
  }
  return 3;
}
