#pragma once
// Name → method. Adding a method: its file pair in methods/, its shader folder, one line in
// registry.cpp.
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "mfr/methods/method.hpp"

namespace mfr {

struct RegistryEntry {
  std::string name;
  std::function<std::unique_ptr<Method>()> create;
};

const std::vector<RegistryEntry>& methodRegistry();
// Throws mfr::Error("--method <name>", "unknown method (available: …)").
std::unique_ptr<Method> createMethod(const std::string& name);

}  // namespace mfr
