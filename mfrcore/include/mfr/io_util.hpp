#pragma once
// Small file helpers shared by the CLI and writers: atomic writes so that no failure leaves a
// half-written output file behind.
#include <filesystem>
#include <string_view>

namespace mfr {

// Writes bytes to path.tmp-XXXX then renames over path. Throws mfr::Error naming path.
void writeFileAtomically(const std::filesystem::path& path, std::string_view bytes);

// Reads a whole file. Throws mfr::Error naming path when missing or unreadable.
std::string readFile(const std::filesystem::path& path);

}  // namespace mfr
