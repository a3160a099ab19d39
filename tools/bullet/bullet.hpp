// Bullet 3 (Debian libbullet-dev, double-precision build) for the host tools, with its warnings
// silenced: include Bullet only through this header. The runtime never includes it.
//
// The double-precision libraries (*-float64, BT_USE_DOUBLE_PRECISION) are the only Bullet build
// linked: the float and double builds export the same symbols and cannot share the `statsim`
// executable. On x86-64 Linux neither build uses Bullet's SSE paths (btScalar.h enables them only
// for MSVC and Apple), so the choice changes only the width of the numbers.
#pragma once

#ifndef BT_USE_DOUBLE_PRECISION
#error "the host tools use Bullet's double-precision libraries: compile with -DBT_USE_DOUBLE_PRECISION"
#endif

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
#include <LinearMath/btConvexHullComputer.h>
#include <BulletCollision/NarrowPhaseCollision/btGjkEpaPenetrationDepthSolver.h>
#include <BulletCollision/NarrowPhaseCollision/btGjkPairDetector.h>
#include <BulletCollision/NarrowPhaseCollision/btPointCollector.h>
#include <BulletCollision/NarrowPhaseCollision/btVoronoiSimplexSolver.h>
#pragma GCC diagnostic pop

#include <Eigen/Core>

namespace statsim::tools::bullet {

inline btVector3 to_bt(const Eigen::Vector3d& v)
{
  return btVector3(v.x(), v.y(), v.z());
}

inline Eigen::Vector3d to_eigen(const btVector3& v)
{
  return Eigen::Vector3d(v.x(), v.y(), v.z());
}

}  // namespace statsim::tools::bullet
