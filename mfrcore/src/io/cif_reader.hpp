#pragma once
// CIF 1.1 syntax into gemmi's document model (private to mfrcore/io). gemmi's own CIF parser is
// built on PEGTL, which Debian's gemmi-dev neither ships (the "+ds" source drops the bundled copy)
// nor depends on; gemmi's mmCIF interpretation (make_structure) works on the document this fills.
#include <string>

#include <gemmi/cifdoc.hpp>

namespace mfr::io {

// The blocks, items, loops and save frames of `text`, values kept raw as gemmi keeps them (quotes
// and text-field semicolons included; gemmi::cif::as_string strips them). Follows the rules of
// gemmi's grammar (cif.hpp): case-insensitive reserved words, quoted strings ending at a quote
// followed by white space, text fields between lines starting with ';', comments from '#'.
// Throws mfr::Error(name, "line N: reason") for a syntax error, an unterminated string or text
// field, a tag without a value, or a loop whose value count is not a multiple of its tag count.
gemmi::cif::Document readCif(const std::string& text, const std::string& name);

}  // namespace mfr::io
