#pragma once
// The budget definitions shared verbatim with the GPU (shaders/budget/*.h), compiled as C++ with
// GLM: the allocation rule, the vkb importance criteria and the dkb features. One definition, so
// the CPU reference, the dataset writer and the shaders cannot drift apart.
#include <cstdint>

#include <glm/glm.hpp>

// Internal linkage per translation unit (the GLSL functions carry no `inline`); a unit that uses
// only some of them must not warn about the rest.
namespace mfr::glsl {
using namespace glm;
using uint = std::uint32_t;
namespace {
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wunused-variable"
#define MFR_OUT(T) T&
#include "budget/allocation.h"
#include "budget/features.h"
#include "budget/importance.h"
#undef MFR_OUT
#pragma GCC diagnostic pop
}  // namespace
}  // namespace mfr::glsl
