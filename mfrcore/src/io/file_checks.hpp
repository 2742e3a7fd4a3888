#pragma once
// Checks shared by the model and volume loaders: a file is looked at before any library reads it,
// so that missing, unreadable, empty or special files get one line naming them, never a hang.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <new>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "mfr/error.hpp"
#include "mfr/io/load.hpp"

namespace mfr::io {

// Throws mfr::Error(name, reason) unless path is a readable, non-empty regular file. `kind` is
// what the caller expected ("model", "volume") and appears in the directory message.
void checkReadable(const std::filesystem::path& path, const std::string& name, std::string_view kind);

// The first headBytes and the last tailBytes of `contents` when given (a file decompressed in
// memory), else of the file at path: what the end checks below and the IFC check look at.
struct FileEnds {
  std::string head, tail;
};
FileEnds fileEnds(const std::filesystem::path& path, const std::string* contents, std::size_t headBytes,
                  std::size_t tailBytes);

// A VTK XML file (.vti, .vtp) ends with </VTKFile>: VTK's XML readers read a file cut inside its
// raw, base64 or inline data without an error, and the missing samples came out as zeros or
// garbage with exit 0 (a bug hunt). Reads the end of `contents` when given, else of the file at
// path. Throws mfr::Error(name, "truncated: …").
void checkVtkXmlFileEnd(const std::filesystem::path& path, const std::string* contents, const std::string& name);

// The tags of a VTK XML file (the text between < and >, each cut at 64 KiB) before its
// <AppendedData: what its elements declare, read in one pass without keeping the data between
// them. From `contents` when given, else from the file at path.
std::vector<std::string> vtkXmlTags(const std::filesystem::path& path, const std::string* contents);
// Whether a tag (vtkXmlTags) opens or closes element `element`: its name, then the end, a space or '/'.
bool isVtkXmlElement(std::string_view tag, std::string_view element);
// The value of attribute `key` of a tag (quoted with " or '), empty when it has none.
std::string vtkXmlAttribute(std::string_view tag, std::string_view key);
// What a DataArray declares that VTK's XML readers allocate or seek to before they read a value:
// NumberOfComponents in [1, maxComponents] (2^32 − 1 spun in vtkXMLReader::CreateArray, 2^31 − 1
// took 12 GB: fuzzing), NumberOfTuples in [0, maxTuples], an appended array's offset a whole
// number below the file's size (−1 read garbage, "nan" the first array, exit 0: fuzzing). Throws
// mfr::Error(name, "DataArray 'NAME' …").
void checkVtkXmlDataArray(std::string_view tag, long long maxComponents, long long maxTuples, std::uintmax_t fileBytes,
                          const std::string& name);

// A library's (possibly multi-line) message as one line: newlines and tabs become spaces, runs of
// spaces collapse, trailing spaces go.
std::string oneLine(std::string s);
// A name read from a file as valid UTF-8: unchanged when it is; else every byte that does not
// begin a valid UTF-8 sequence is read as Latin-1 (Windows tools write "Terraindæk" so), so that
// JSON, Qt and messages show the name instead of failing on it.
std::string utf8Name(const std::string& s);

// Runs load() and turns whatever it throws into one mfr::Error line that starts with the file's
// name: library messages are folded into one line, bad_alloc and unknown exceptions named;
// LoadCancelled passes through.
template <class Load>
auto withFileErrors(const std::string& name, Load&& load) -> decltype(load()) {
  try {
    return load();
  } catch (const LoadCancelled&) {
    throw;
  } catch (const FieldNotFound& e) {  // kept apart: a scene file reports it at its 'field' key
    std::string message = oneLine(e.what());
    // The name as the folded message shows it: a name that is not UTF-8 was named twice, raw and
    // folded ("bad\xff.ply: bad?.ply: …", a bug hunt).
    if (const std::string shown = oneLine(name); message.rfind(shown, 0) != 0) message = shown + ": " + message;
    throw FieldNotFound(message);
  } catch (const Error& e) {
    std::string message = oneLine(e.what());
    if (const std::string shown = oneLine(name); message.rfind(shown, 0) != 0) message = shown + ": " + message;
    throw Error(message);
  } catch (const std::bad_alloc&) {
    throw Error(oneLine(name), "out of memory while loading");
  } catch (const std::exception& e) {
    throw Error(oneLine(name), oneLine(e.what()));
  } catch (...) {
    throw Error(oneLine(name), "unknown error while loading");
  }
}

}  // namespace mfr::io
