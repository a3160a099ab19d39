#pragma once
/// @file
/// Where to draw a shape's mesh for a body: the transform from the mesh's own coordinates (the
/// file the table was gathered from) to the world, from the body's pose and the table's mesh
/// frame.
///
/// A table's body frame is the mesh's principal axes about its centre of mass. The table records
/// where the mesh sits in it (`SignatureView::mesh_frame`: a mesh point m is the body point
/// R (m - c), R row by row, then c, m); a table without it (or a runtime whose signatures have no
/// such field) has body frame = mesh frame. A body at position x with orientation q then shows
/// mesh point m at
///   world = x + q R (m - c) = (q R) m + (x - q R c).

#include "statsim/math.hpp"

#include <type_traits>
#include <utility>

namespace statsim {

namespace detail {
template <class View, class = void>
struct view_has_mesh_frame : std::false_type {};
template <class View>
struct view_has_mesh_frame<View, std::void_t<decltype(std::declval<const View&>().mesh_frame)>> : std::true_type {};

/// The table's mesh frame (R row by row, then c), or null when it has none.
template <class View>
const Scalar* mesh_frame_of(const View& view)
{
  if constexpr (view_has_mesh_frame<View>::value) {
    return view.mesh_frame;
  } else {
    (void)view;
    return nullptr;
  }
}

template <class View, class = void>
struct view_has_scale : std::false_type {};
template <class View>
struct view_has_scale<View, std::void_t<decltype(std::declval<const View&>().scale)>> : std::true_type {};

/// The shape's size over the table's (`SignatureView::scale`), 1 for views without it.
template <class View>
Scalar scale_of(const View& view)
{
  if constexpr (view_has_scale<View>::value) {
    return view.scale;
  } else {
    (void)view;
    return 1;
  }
}
}  // namespace detail

/// The affine map from mesh coordinates (m) to world coordinates (m) of a 3D body at `position`
/// (its centre of mass, m) and `orientation` (body to world, unit), for the shape whose table is
/// `view` (a `SignatureView<3>`): apply it to the mesh's vertices, or hand it to a renderer as
/// the model matrix; a shape of another size (`scaled_view`) scales the mesh about c. Setting-up
/// and drawing code: not used by a step.
template <class View>
Eigen::Transform<Scalar, 3, Eigen::Affine> mesh_to_world(const View& view, const Vector3& position,
                                                       const Quaternion& orientation)
{
  const Eigen::Matrix<Scalar, 3, 3> q = orientation.toRotationMatrix();
  Eigen::Matrix<Scalar, 3, 3> r = Eigen::Matrix<Scalar, 3, 3>::Identity();
  Vector3 c = Vector3::Zero();
  if (const Scalar* f = detail::mesh_frame_of(view)) {
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) r(i, j) = f[3 * i + j];
    c = Vector3(f[9], f[10], f[11]);
  }
  const Scalar s = detail::scale_of(view);
  if (s != 1) r *= s;  // a body point s R (m - c)
  Eigen::Transform<Scalar, 3, Eigen::Affine> t;
  t.linear() = q * r;
  t.translation() = position - t.linear() * c;
  return t;
}

/// The 2D map (a body at `position`, m, with `orientation`): a mesh point m (a polygon vertex)
/// is drawn at the world point `mesh_to_world(...) * m`.
template <class View>
Eigen::Transform<Scalar, 2, Eigen::Affine> mesh_to_world(const View& view, const Vector2& position,
                                                       const Rot2& orientation)
{
  Eigen::Matrix<Scalar, 2, 2> q;
  q << orientation.c, -orientation.s, orientation.s, orientation.c;
  Eigen::Matrix<Scalar, 2, 2> r = Eigen::Matrix<Scalar, 2, 2>::Identity();
  Vector2 c = Vector2::Zero();
  if (const Scalar* f = detail::mesh_frame_of(view)) {
    r << f[0], f[1], f[2], f[3];
    c = Vector2(f[4], f[5]);
  }
  const Scalar s = detail::scale_of(view);
  if (s != 1) r *= s;
  Eigen::Transform<Scalar, 2, Eigen::Affine> t;
  t.linear() = q * r;
  t.translation() = position - t.linear() * c;
  return t;
}

/// As above, for a body of a world (`Body<D>`).
template <class View, class BodyT>
auto mesh_to_world(const View& view, const BodyT& body) -> decltype(mesh_to_world(view, body.position, body.orientation))
{
  return mesh_to_world(view, body.position, body.orientation);
}

}  // namespace statsim
