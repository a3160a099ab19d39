// tiny_gltf.h (Debian libtinygltf-dev) with its warnings silenced: include it through this header.
// tinygltf_impl.cpp includes it once with TINYGLTF_IMPLEMENTATION defined.
#pragma once
#include "common/third_party_begin.hpp"
#include <tiny_gltf.h>
#include "common/third_party_end.hpp"
