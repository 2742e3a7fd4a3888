#pragma once
// Loaders whose library can crash, hang or allocate without end on a damaged file (assimp, Open
// CASCADE) run it in a child process (private to mfrcore/io): a crash, a hang or a runaway is then
// one error naming the file, and the process that asked (mfr, or mfrview loading a scene) lives on.
#include <cstdint>
#include <cstring>
#include <functional>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

#include "mfr/io/load.hpp"
#include "mfr/scene/scene.hpp"

namespace mfr::io {

// Who does the work, for messages: "cannot read <format>: <library> crashed (…)".
struct ChildLibrary {
  std::string format;   // "step", "obj", … ("file" when the name has no extension)
  std::string library;  // "the importer (assimp)", "Open CASCADE"
  // Seconds added to the time limit, for work that reports no progress for a time that grows with
  // the file (Open CASCADE's parse).
  int graceSeconds = 0;
};

// The time limit: 120 s, or MFR_IMPORT_TIMEOUT_S (whole seconds, 1 … 86400). Throws
// mfr::Error(name, …) for any other value.
int importSeconds(const std::string& name);

// Runs `work` in a forked child process, under a memory limit (what this process may still take,
// host_memory.hpp) and a time limit (importSeconds) counted from the child's last progress report,
// and returns the bytes it returned. `work` gets a LoadProgress whose reports reach `progress`
// here; cancelling `progress` kills the child and throws LoadCancelled. An mfr::Error that `work`
// throws is thrown here with its message (a FieldNotFound as one); a crash, the time limit, the memory limit or a child
// that ends without a result is an mfr::Error(name, "cannot read <format>: <library> …").
// std::nullopt when no child could be made (the caller then does the work itself, unguarded).
std::optional<std::string> runInChild(const std::string& name, const ChildLibrary& library,
                                      const LoadProgress& progress,
                                      const std::function<std::string(const LoadProgress&)>& work);

// A child's result as bytes, written in the child and read back here (a process of the same
// build): plain values, arrays of them and texts, each length-prefixed. Unpacker throws
// std::logic_error for bytes a Packer did not write.
class Packer {
 public:
  template <typename T>
  void value(const T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    bytes.append(reinterpret_cast<const char*>(&v), sizeof v);
  }
  template <typename T>
  void array(const std::vector<T>& values) {
    static_assert(std::is_trivially_copyable_v<T>);
    value(static_cast<std::uint64_t>(values.size()));
    bytes.append(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(T));
  }
  void text(const std::string& s) {
    value(static_cast<std::uint64_t>(s.size()));
    bytes += s;
  }
  std::string bytes;
};

class Unpacker {
 public:
  explicit Unpacker(const std::string& bytes) : bytes_(bytes) {}
  template <typename T>
  T value() {
    T v{};
    std::memcpy(&v, take(sizeof v), sizeof v);
    return v;
  }
  template <typename T>
  std::vector<T> array() {
    const auto n = value<std::uint64_t>();
    if (n > (bytes_.size() - at_) / sizeof(T)) fail();
    std::vector<T> values(static_cast<std::size_t>(n));
    // An empty vector's data() may be null, which memcpy must not get even for 0 bytes (UBSan).
    if (!values.empty()) std::memcpy(values.data(), take(values.size() * sizeof(T)), values.size() * sizeof(T));
    return values;
  }
  std::string text() {
    const auto n = value<std::uint64_t>();
    if (n > bytes_.size() - at_) fail();
    return {take(static_cast<std::size_t>(n)), static_cast<std::size_t>(n)};
  }
  // What follows what was read (bytes a Packer appended as they are).
  [[nodiscard]] std::string_view rest() const { return std::string_view(bytes_).substr(at_); }
  [[nodiscard]] bool done() const { return at_ == bytes_.size(); }
  [[noreturn]] static void fail() { throw std::logic_error("unpack: bytes a Packer did not write"); }

 private:
  const char* take(std::size_t n) {
    if (n > bytes_.size() - at_) fail();
    const char* p = bytes_.data() + at_;
    at_ += n;
    return p;
  }
  const std::string& bytes_;
  std::size_t at_ = 0;
};

// Objects and a loader's notes as bytes and back, to pass a loader's result out of its child:
// names, meshes (shared meshes stay shared), fields, transforms, materials, visibility. Only for
// bytes packObjects wrote in a process of the same build (std::logic_error for others); the notes
// are appended to `notes` when it is not null.
std::string packObjects(const std::vector<Object>& objects, const std::vector<std::string>& notes = {});
std::vector<Object> unpackObjects(const std::string& bytes, std::vector<std::string>* notes = nullptr);

}  // namespace mfr::io
