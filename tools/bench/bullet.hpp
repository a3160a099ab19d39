// Bullet 3 for the benchmark, warnings silenced: include Bullet only through this header.
//
// The benchmark uses Bullet's double-precision build (Debian's *-float64 libraries,
// BT_USE_DOUBLE_PRECISION) because tools/ref3d links it into the same `statsim` executable: the
// float and double builds export the same symbols and cannot share a process. On x86-64 Linux
// neither build uses Bullet's SSE paths (btScalar.h enables them only for MSVC and Apple), so the
// difference is the width of the numbers. tools/ref3d/bullet.hpp is used when present (one
// wrapper for the project), else the same includes here.
#pragma once

#ifndef BT_USE_DOUBLE_PRECISION
#error "tools/bench uses Bullet's double-precision libraries: compile with -DBT_USE_DOUBLE_PRECISION"
#endif

#if __has_include("ref3d/bullet.hpp")
#include "ref3d/bullet.hpp"
#else
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wall"
#pragma GCC diagnostic ignored "-Wextra"
#pragma GCC diagnostic ignored "-Wpedantic"
#pragma GCC diagnostic ignored "-Wshadow"
#pragma GCC diagnostic ignored "-Wconversion"
#pragma GCC diagnostic ignored "-Wsign-conversion"
#pragma GCC diagnostic ignored "-Wfloat-conversion"
#pragma GCC diagnostic ignored "-Wunused-parameter"
#pragma GCC diagnostic ignored "-Wunused-variable"
#pragma GCC diagnostic ignored "-Wunused-but-set-variable"
#pragma GCC diagnostic ignored "-Wdeprecated-copy"
#pragma GCC diagnostic ignored "-Wclass-memaccess"
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#pragma GCC diagnostic ignored "-Wold-style-cast"
#pragma GCC diagnostic ignored "-Woverloaded-virtual"
#include <btBulletCollisionCommon.h>
#include <btBulletDynamicsCommon.h>
#include <BulletCollision/Gimpact/btGImpactCollisionAlgorithm.h>
#include <BulletCollision/Gimpact/btGImpactShape.h>
#pragma GCC diagnostic pop
#endif
