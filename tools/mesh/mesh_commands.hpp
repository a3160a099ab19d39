#pragma once
/// @file
/// The `statsim mesh ...` subcommands. Each command is also a function returning the exit code
/// (0 on success), so tests can call it directly; errors go to `err` as one line, and a command
/// that fails leaves no output file (outputs are written to a temporary file, then renamed).

#include <array>
#include <iosfwd>
#include <string>

namespace statsim::tools {

/// `mesh info FILE [--density RHO] [--units U | --scale S]`: counts, volume, mass, centre of mass,
/// inertia, principal moments and axes, bounding radius, of the mesh scaled by `scale` (metres
/// per file unit); refused, as by `statsim gather`, when it spans less than 1 cm or more than
/// 10 m and `units_given` is false.
int mesh_info(const std::string& file, double density, std::ostream& out, std::ostream& err, double scale = 1.0,
              bool units_given = false);

/// `mesh decimate --in A.obj --out B.obj --vertices N`.
int mesh_decimate(const std::string& in, const std::string& out_file, int vertices, std::ostream& out,
                  std::ostream& err);

/// `mesh spheres --in A.obj --count K --out F.txt [--resolution R]`.
int mesh_spheres(const std::string& in, const std::string& out_file, int count, int resolution, std::ostream& out,
                 std::ostream& err);

/// `mesh box --size X,Y,Z --out F.obj`.
int mesh_box(const std::array<double, 3>& size, const std::string& out_file, std::ostream& out, std::ostream& err);

/// `mesh wedge --legs A,B --depth D --out F.obj`: a right triangular prism (shapes.hpp).
int mesh_wedge(double leg_x, double leg_y, double depth, const std::string& out_file, std::ostream& out,
               std::ostream& err);

/// `mesh nut --across-corners A --thickness T --hole D --hole-segments N --out F.obj`: a hexagonal
/// nut (shapes.hpp).
int mesh_nut(double across_corners, double thickness, double hole_diameter, int hole_segments,
             const std::string& out_file, std::ostream& out, std::ostream& err);

/// `mesh lshape --out F.obj` (the fixed dimensions of shapes.hpp).
int mesh_lshape(const std::string& out_file, std::ostream& out, std::ostream& err);

}  // namespace statsim::tools
