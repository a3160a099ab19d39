// The stb headers used by `statsim render` for its pictures and captions (Debian libstb-dev),
// with their warnings silenced so that -Wall -Wextra -Wconversion ... -Werror builds stay clean.
//
// Include this from exactly one .cpp file (render/render.cpp): it compiles stb_image_write's
// implementation into that file with internal linkage (STB_IMAGE_WRITE_STATIC), so it cannot
// clash with another copy elsewhere in the program. stb_easy_font is all static functions.
#pragma once

#include "common/third_party_begin.hpp"

#ifndef STB_IMAGE_WRITE_STATIC
#define STB_IMAGE_WRITE_STATIC
#endif
#ifndef STB_IMAGE_WRITE_IMPLEMENTATION
#define STB_IMAGE_WRITE_IMPLEMENTATION
#endif
#include <stb/stb_image_write.h>
#include <stb/stb_easy_font.h>
#include "common/third_party_end.hpp"
