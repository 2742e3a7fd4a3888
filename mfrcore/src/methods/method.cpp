#include "mfr/methods/method.hpp"

#include <cmath>
#include <sstream>

#include "mfr/error.hpp"

namespace mfr {

Params::Params(const std::vector<ParamSpec>& specs, const std::map<std::string, std::string>& values,
               const std::string& method) {
  for (const ParamSpec& s : specs) values_[s.name] = s.defaultValue;
  for (const auto& [name, value] : values) {
    const ParamSpec* spec = nullptr;
    for (const ParamSpec& s : specs)
      if (s.name == name) spec = &s;
    if (!spec) {
      std::string list;
      for (const ParamSpec& s : specs) list += (list.empty() ? "" : ", ") + s.name;
      throw Error("--param " + name,
                  "not a parameter of " + method + (list.empty() ? " (it has none)" : " (has: " + list + ")"));
    }
    const std::string where = "--param " + name + "=" + value;
    switch (spec->type) {
      case ParamSpec::Type::Int:
      case ParamSpec::Type::Float: {
        std::istringstream in(value);
        double v = 0;
        char extra = 0;
        if (!(in >> v) || (in >> extra) || !std::isfinite(v)) throw Error(where, "expected a number");
        // Digits only, as the command line's whole-number options: "k=1e2", "k=8.0", "k= 8" were
        // taken (k = 100, 8, 8) where "k=1.5" was refused (a bug hunt).
        const std::size_t digits = value.starts_with('-') ? 1 : 0;
        if (spec->type == ParamSpec::Type::Int &&
            (value.size() == digits || value.find_first_not_of("0123456789", digits) != std::string::npos))
          throw Error(where, "expected an integer (digits only)");
        if (v < spec->min || v > spec->max) {
          std::ostringstream r;
          r << "out of range [" << spec->min << ", " << spec->max << "]";
          throw Error(where, r.str());
        }
        break;
      }
      case ParamSpec::Type::Bool:
        if (value != "true" && value != "false" && value != "1" && value != "0" && value != "on" && value != "off")
          throw Error(where, "expected true or false");
        break;
      case ParamSpec::Type::Text:
        if (value.find('\n') != std::string::npos) throw Error(where, "expected one line");
        break;
      case ParamSpec::Type::Choice: {
        bool ok = false;
        std::string list;
        for (const std::string& c : spec->choices) {
          ok = ok || c == value;
          list += (list.empty() ? "" : ", ") + c;
        }
        if (!ok) throw Error(where, "expected one of: " + list);
        break;
      }
    }
    values_[name] = value;
  }
}

std::string defaultValueFor(const ParamSpec& spec, const std::string& operation) {
  if (operation != "hybrid" && (spec.name == "tail" || spec.name == "exact_tail") && spec.defaultValue == "true")
    return "false";
  return spec.defaultValue;
}

long long Params::integer(const std::string& name) const {
  return std::llround(std::stod(text(name)));
}
double Params::real(const std::string& name) const {
  return std::stod(text(name));
}
bool Params::flag(const std::string& name) const {
  const std::string& v = text(name);
  return v == "true" || v == "1" || v == "on";
}
const std::string& Params::text(const std::string& name) const {
  const auto it = values_.find(name);
  if (it == values_.end()) throw Error("parameter " + name, "not declared by the method");
  return it->second;
}

const gl::Program& ResolveProgramCache::get(const std::string& methodFolder, const Operation& op,
                                            const gl::Defines& extra, const std::string& passFile) {
  std::string key = passFile + ";" + op.glslFile;
  for (const auto& [k, v] : extra) key += ";" + k + "=" + v;
  auto it = programs_.find(key);
  if (it == programs_.end()) {
    gl::Defines defines = extra;
    defines["MFR_OP_FILE"] = "\"" + op.glslFile + "\"";
    it = programs_
             .emplace(key, gl::Program({{GL_VERTEX_SHADER, "common/fullscreen.vert"},
                                        {GL_FRAGMENT_SHADER, "methods/" + methodFolder + "/" + passFile}},
                                       defines))
             .first;
  }
  return it->second;
}

}  // namespace mfr
