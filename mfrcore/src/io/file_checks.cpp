#include "file_checks.hpp"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string_view>
#include <system_error>
#include <tuple>
#include <unistd.h>

#include "mfr/error.hpp"

namespace mfr::io {

namespace fs = std::filesystem;

void checkReadable(const fs::path& path, const std::string& name, std::string_view kind) {
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);
  if (st.type() == fs::file_type::not_found) throw Error(name, "no such file");
  if (ec) throw Error(name, "cannot access file: " + ec.message());
  if (fs::is_directory(st)) throw Error(name, "is a directory, not a " + std::string(kind) + " file");
  // FIFOs and devices would block or never end.
  if (!fs::is_regular_file(st)) throw Error(name, "not a regular file");
  if (::access(path.c_str(), R_OK) != 0) throw Error(name, std::string("cannot read file: ") + std::strerror(errno));
  std::ifstream probe(path, std::ios::binary);
  if (!probe) throw Error(name, "cannot open file for reading");
  if (fs::file_size(path, ec) == 0 && !ec) throw Error(name, "empty file");
}

namespace {

// The length of the well-formed UTF-8 sequence at s[i] (RFC 3629: no overlong forms, no
// surrogates, nothing above U+10FFFF: what JSON writers accept), or 0.
std::size_t utf8SequenceAt(const std::string& s, std::size_t i) {
  const auto byte = [&](std::size_t k) { return static_cast<unsigned char>(s[i + k]); };
  const unsigned char lead = byte(0);
  if (lead < 0x80) return 1;
  std::size_t length = 0;
  unsigned char low = 0x80, high = 0xBF;  // the second byte's range
  if (lead >= 0xC2 && lead <= 0xDF) {
    length = 2;
  } else if (lead >= 0xE0 && lead <= 0xEF) {
    length = 3;
    if (lead == 0xE0) low = 0xA0;
    if (lead == 0xED) high = 0x9F;
  } else if (lead >= 0xF0 && lead <= 0xF4) {
    length = 4;
    if (lead == 0xF0) low = 0x90;
    if (lead == 0xF4) high = 0x8F;
  } else {
    return 0;
  }
  if (i + length > s.size() || byte(1) < low || byte(1) > high) return 0;
  for (std::size_t k = 2; k < length; ++k)
    if (byte(k) < 0x80 || byte(k) > 0xBF) return 0;
  return length;
}

}  // namespace

std::string utf8Name(const std::string& s) {
  std::string out;
  out.reserve(s.size());
  for (std::size_t i = 0; i < s.size();) {
    if (const std::size_t length = utf8SequenceAt(s, i); length > 0) {
      out.append(s, i, length);
      i += length;
      continue;
    }
    const auto byte = static_cast<unsigned char>(s[i++]);  // Latin-1: U+0080 … U+00FF
    out += static_cast<char>(0xC0 | (byte >> 6));
    out += static_cast<char>(0x80 | (byte & 0x3F));
  }
  return out;
}

FileEnds fileEnds(const std::filesystem::path& path, const std::string* contents, std::size_t headBytes,
                  std::size_t tailBytes) {
  FileEnds ends;
  if (contents != nullptr) {
    ends.head = contents->substr(0, headBytes);
    ends.tail = contents->substr(contents->size() - std::min(contents->size(), tailBytes));
    return ends;
  }
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  const auto size = static_cast<std::size_t>(std::max<std::streamoff>(in.tellg(), 0));
  in.seekg(0);
  ends.head.resize(std::min(size, headBytes));
  in.read(ends.head.data(), static_cast<std::streamsize>(ends.head.size()));
  in.seekg(static_cast<std::streamoff>(size - std::min(size, tailBytes)));
  ends.tail.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  return ends;
}

void checkVtkXmlFileEnd(const std::filesystem::path& path, const std::string* contents, const std::string& name) {
  const auto [head, tail] = fileEnds(path, contents, 1024, 256);
  if (head.find("<VTKFile") == std::string::npos) return;  // not VTK XML at all: VTK's reader says so
  const std::size_t last = tail.find_last_not_of(" \t\r\n");
  constexpr std::string_view kEnd = "</VTKFile>";
  if (last == std::string::npos || last + 1 < kEnd.size() ||
      tail.compare(last + 1 - kEnd.size(), kEnd.size(), kEnd) != 0)
    throw Error(name, "truncated: a VTK XML file ends with </VTKFile>, and this one does not");
}

std::vector<std::string> vtkXmlTags(const std::filesystem::path& path, const std::string* contents) {
  std::vector<std::string> tags;
  std::string tag;
  bool inTag = false, appended = false;
  // Comments and CDATA sections are no tags: a DataArray commented out declares nothing (a review).
  std::string_view closing;  // "-->" or "]]>" while inside one; the last bytes seen
  std::string recent;
  const auto take = [&](const char* bytes, std::size_t count) {
    for (std::size_t i = 0; i < count && !appended; ++i) {
      const char c = bytes[i];
      if (!closing.empty()) {
        recent.push_back(c);
        if (recent.size() > 3) recent.erase(0, recent.size() - 3);
        if (recent == closing) closing = {};
        continue;
      }
      if (!inTag) {
        inTag = c == '<';
      } else if (c != '>') {
        if (tag.size() < (1u << 16)) tag += c;
        if (tag == "!--" || tag == "![CDATA[") {
          closing = tag == "!--" ? std::string_view("-->") : std::string_view("]]>");
          recent.clear();
          tag.clear();
          inTag = false;
        }
      } else {
        appended = tag.rfind("AppendedData", 0) == 0;
        if (!appended) tags.push_back(std::move(tag));
        tag.clear();
        inTag = false;
      }
    }
  };
  if (contents != nullptr) {
    take(contents->data(), contents->size());
    return tags;
  }
  std::ifstream in(path, std::ios::binary);
  std::string chunk(1 << 16, '\0');
  while (!appended && in) {
    in.read(chunk.data(), static_cast<std::streamsize>(chunk.size()));
    take(chunk.data(), static_cast<std::size_t>(in.gcount()));
  }
  return tags;
}

bool isVtkXmlElement(std::string_view tag, std::string_view element) {
  return tag.substr(0, element.size()) == element &&
         (tag.size() == element.size() || std::isspace(static_cast<unsigned char>(tag[element.size()])) ||
          tag[element.size()] == '/');
}

std::string vtkXmlAttribute(std::string_view tag, std::string_view key) {
  for (std::size_t at = tag.find(key); at != std::string_view::npos; at = tag.find(key, at + 1)) {
    const bool word = at > 0 && std::isspace(static_cast<unsigned char>(tag[at - 1]));
    std::size_t i = at + key.size();
    while (i < tag.size() && std::isspace(static_cast<unsigned char>(tag[i]))) ++i;
    if (!word || i >= tag.size() || tag[i] != '=') continue;
    ++i;
    while (i < tag.size() && std::isspace(static_cast<unsigned char>(tag[i]))) ++i;
    if (i >= tag.size() || (tag[i] != '"' && tag[i] != '\'')) continue;
    const std::size_t end = tag.find(tag[i], i + 1);
    if (end == std::string_view::npos) return {};
    return std::string(tag.substr(i + 1, end - i - 1));
  }
  return {};
}

void checkVtkXmlDataArray(std::string_view tag, long long maxComponents, long long maxTuples, std::uintmax_t fileBytes,
                          const std::string& name) {
  // A whole number as VTK reads one (istream >>: surrounding spaces, a '+', "3.0"). A '-', a
  // fraction, an exponent or other garbage after the digits is refused, though VTK would read the
  // digits before it ("3.5" and "3x" as 3, "1e3" as 1): such a file is damaged (review 28).
  const auto whole = [](const std::string& text, long long& value) {
    std::size_t first = text.find_first_not_of(" \t\r\n");
    const std::size_t last = text.find_last_not_of(" \t\r\n");
    if (first == std::string::npos) return false;
    if (text[first] == '+') ++first;
    const char* const end = text.data() + last + 1;
    const auto [digitsEnd, ec] = std::from_chars(text.data() + first, end, value);
    if (ec != std::errc() || text[first] == '-' || text[first] == '+') return false;
    if (digitsEnd == end) return true;
    // "3.0", "3.": a point and zeros only.
    return *digitsEnd == '.' && std::all_of(digitsEnd + 1, end, [](char c) { return c == '0'; });
  };
  const auto array = [&] {
    const std::string named = vtkXmlAttribute(tag, "Name");
    return named.empty() ? std::string("an unnamed DataArray's ") : "DataArray '" + named + "' ";
  };
  for (const auto& [key, least, most] :
       {std::tuple<const char*, long long, long long>{"NumberOfComponents", 1, maxComponents},
        std::tuple<const char*, long long, long long>{"NumberOfTuples", 0, maxTuples}}) {
    const std::string text = vtkXmlAttribute(tag, key);
    if (text.empty()) continue;
    long long count = 0;
    if (!whole(text, count) || count < least || count > most)
      throw Error(name, array() + key + "=\"" + text.substr(0, 24) + "\" is not a count in [" + std::to_string(least) +
                            ", " + std::to_string(most) + "]");
  }
  if (vtkXmlAttribute(tag, "format") != "appended") return;
  const std::string text = vtkXmlAttribute(tag, "offset");
  long long offset = 0;
  if (!whole(text, offset) || static_cast<std::uintmax_t>(offset) >= fileBytes)
    throw Error(name, array() + "offset=\"" + text.substr(0, 24) + "\" is not a place in the file's " +
                          std::to_string(fileBytes) + " bytes");
}

std::string oneLine(std::string s) {
  // Libraries quote bytes of a corrupt file in their messages (VTK: "Unsupported data type: "
  // and four bytes of garbage): control characters and bytes that are not UTF-8 become '?'.
  for (std::size_t i = 0; i < s.size();) {
    const auto lead = static_cast<unsigned char>(s[i]);
    const std::size_t length = utf8SequenceAt(s, i);
    if (length == 0) {
      s[i++] = '?';
      continue;
    }
    if (length == 1 && (lead < 0x20 || lead == 0x7F)) s[i] = lead == '\n' || lead == '\r' || lead == '\t' ? ' ' : '?';
    i += length;
  }
  s.erase(std::unique(s.begin(), s.end(), [](char a, char b) { return a == ' ' && b == ' '; }), s.end());
  while (!s.empty() && s.back() == ' ') s.pop_back();
  return s;
}

}  // namespace mfr::io
