// tinygltf's implementation (Debian libtinygltf-dev is header-only), compiled once, without its
// image loading and writing (the exported files carry no textures: see CMakeLists.txt).
#define TINYGLTF_IMPLEMENTATION
#include "export/tinygltf.hpp"
