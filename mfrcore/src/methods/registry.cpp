#include "mfr/methods/registry.hpp"

#include "abuffer_linked_list.hpp"
#include "mfr/error.hpp"

namespace mfr {

template <class T>
static std::unique_ptr<Method> make() {
  return std::make_unique<T>();
}

// One line per method.
const std::vector<RegistryEntry>& methodRegistry() {
  static const std::vector<RegistryEntry> entries{
      {"abuffer-ll", make<ABufferLinkedList>},
  };
  return entries;
}

std::unique_ptr<Method> createMethod(const std::string& name) {
  for (const RegistryEntry& e : methodRegistry())
    if (e.name == name) return e.create();
  std::string list = "oracle";
  for (const RegistryEntry& e : methodRegistry()) list += ", " + e.name;
  throw Error("--method " + name, "unknown method (available: " + list + ")");
}

}  // namespace mfr
