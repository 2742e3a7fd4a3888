#include "mfr/methods/registry.hpp"

#include "abuffer_fixed_array.hpp"
#include "abuffer_linked_list.hpp"
#include "abuffer_sbuffer.hpp"
#include "depth_peeling_front_to_back.hpp"
#include "deep_variable_k_buffer.hpp"
#include "dual_depth_peeling.hpp"
#include "fixed_k_buffer.hpp"
#include "k_peeling.hpp"
#include "kbuffer.hpp"
#include "kbuffer_zmerge.hpp"
#include "kplus_array.hpp"
#include "kplus_dynamic.hpp"
#include "kplus_heap.hpp"
#include "kplus_sbuffer.hpp"
#include "mfr/error.hpp"
#include "moment_based_oit.hpp"
#include "variable_k_importance.hpp"
#include "weighted_blended_oit.hpp"

namespace mfr {

template <class T>
static std::unique_ptr<Method> make() {
  return std::make_unique<T>();
}

// One line per method.
const std::vector<RegistryEntry>& methodRegistry() {
  static const std::vector<RegistryEntry> entries{
      {"abuffer-ll", make<ABufferLinkedList>},
      {"peel-f2b", make<DepthPeelingFrontToBack>},
      {"peel-dual", make<DualDepthPeeling>},
      {"abuffer-array", make<ABufferFixedArray>},
      {"abuffer-sbuffer", make<ABufferSBuffer>},
      {"wboit", make<WeightedBlendedOit>},
      {"mboit", make<MomentBasedOit>},
      {"kbuffer", make<KBufferSorted>},
      {"kplus-array", make<KPlusBufferMaxArray>},
      {"kplus-heap", make<KPlusBufferMaxHeap>},
      {"kpeel", make<KPeeling>},
      {"kplus-sbuffer", make<KPlusBufferSBuffer>},
      {"kplus-dynamic", make<KPlusBufferDynamic>},
      {"fkb", make<FixedKBuffer>},
      {"vkb", make<VariableKBufferImportance>},
      {"dkb", make<DeepVariableKBuffer>},
      {"kbuffer-zmerge", make<KBufferZThicknessMerge>},
  };
  return entries;
}

std::unique_ptr<Method> createMethod(const std::string& name) {
  for (const RegistryEntry& e : methodRegistry())
    if (e.name == name) return e.create();
  if (name == "oracle")  // listed below, but not a GPU method: said so rather than "unknown"
    throw Error("--method oracle",
                "the CPU reference, not a GPU method: it cannot be used here (mfr bench measures "
                "every row against it)");
  std::string list = "oracle";
  for (const RegistryEntry& e : methodRegistry()) list += ", " + e.name;
  throw Error("--method " + name, "unknown method (available: " + list + ")");
}

}  // namespace mfr
