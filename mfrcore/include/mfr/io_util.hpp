#pragma once
// Small file helpers shared by the CLI and writers: atomic writes so that no failure leaves a
// half-written output file behind.
#include <filesystem>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace mfr {

// Writes bytes to path.tmp-XXXX then renames over path; a symbolic link's file is written, and the
// link kept. Throws mfr::Error naming path (and first checkOutputPath's refusals). An interrupt or
// termination signal (SIGINT, SIGTERM, SIGHUP) that arrives meanwhile is held until the write is
// done (TerminationSignalsHeld), so that it leaves no temporary behind.
void writeFileAtomically(const std::filesystem::path& path, std::string_view bytes);
// Several outputs of one command, all or none: every temporary is written before any is renamed,
// so a second output that fails (disk full) leaves no first one behind (a bug hunt: mfr render's
// PNG stayed when its --stats failed), and a signal waits for the last rename, so that it leaves
// neither a temporary nor a new PNG beside an old JSON. Throws as writeFileAtomically.
void writeFilesAtomically(const std::vector<std::pair<std::filesystem::path, std::string>>& files);
// Whether an output could be written there, before anything is: its folder exists and takes a new
// file (one is created and removed), the path is not something other than a regular file (a
// folder, a device such as /dev/full, a pipe), which a rename would replace, and not a link to no
// file. Commands with several outputs check them all first, so that a bad second
// path leaves no first file behind. Throws mfr::Error naming path.
void checkOutputPath(const std::filesystem::path& path);

// Whether two names are one file: the same inode where both exist (hard and symbolic links), else
// the same absolute path with links and "." / ".." resolved as far as the path exists.
bool sameFile(const std::string& a, const std::string& b);

// A file a command reads or writes, named by its option (e.g. "--json", "scene", "image A").
struct CommandFile {
  enum class Role {
    kInput,           // a file read
    kScene,           // a file read, or a built-in scene ("@sample"): no file
    kOutput,          // written when given (empty: not given)
    kRequiredOutput,  // written; empty is an error
  };
  std::string option;
  std::string path;
  Role role = Role::kInput;
};
// Before any work: each output's folder exists and its name is no folder (checkOutputPath), a
// required output is not empty, and no output is the same file as an input or another output (a
// relative and an absolute name, links and hard links included) — a command never writes over a
// file named on its command line, nor one file twice. Throws mfr::Error naming the later option.
// mfr's commands and mfrview's scripted runs.
void checkCommandFiles(const std::vector<CommandFile>& files);

// While one lives, SIGINT, SIGTERM and SIGHUP are caught and remembered instead of acted on (one
// the process ignores stays ignored); the last one alive puts the previous handlers back and
// raises each that arrived, so the process then ends as it would have (or runs its own handler).
// Process-wide, whichever thread the signal reaches; nests and may be used from several threads.
// Not for long work: Ctrl-C waits for it.
class TerminationSignalsHeld {
 public:
  TerminationSignalsHeld();
  ~TerminationSignalsHeld();
  TerminationSignalsHeld(const TerminationSignalsHeld&) = delete;
  TerminationSignalsHeld& operator=(const TerminationSignalsHeld&) = delete;
};

// Reads a whole regular file. Throws mfr::Error naming path when missing, not a regular file (a
// device, a pipe) or unreadable.
std::string readFile(const std::filesystem::path& path);

}  // namespace mfr
