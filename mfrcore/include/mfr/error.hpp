#pragma once
// One exception type for every user-facing failure. Its message is a single line that names the
// file or argument at fault and the reason, e.g. "model.stl: truncated binary STL (84 of 684 bytes)".
#include <stdexcept>
#include <string>

namespace mfr {

class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message) : std::runtime_error(message) {}
  // "<what>: <reason>" — what is a file path, an argument name or a component.
  Error(const std::string& what, const std::string& reason) : std::runtime_error(what + ": " + reason) {}
};

// Thrown when a named field is not there: by loadVolume for a LoadOptions::field the file does not
// have (or a format without named fields), by colorByField for a field the mesh does not have. Its
// message lists the fields there are.
class FieldNotFound : public Error {
 public:
  using Error::Error;
};

}  // namespace mfr
