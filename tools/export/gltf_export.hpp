// A frame file (render/frames.hpp) as a binary glTF 2.0 file (.glb) that Blender and web viewers
// open:
//  - one mesh per shape and body colour (the shapes of `statsim render`, in the body frame; no
//    normals, so viewers shade them flat, as the glTF specification asks when normals are absent),
//    materials from render::body_colour (the same palette as the pictures);
//  - a root node "statsim world (z up)" turning the z-up world into glTF's y-up (-90 deg about x),
//    with one child node "body I" per body, placed at the body's first pose;
//  - one animation "frames": per body a translation and a rotation channel (LINEAR), keyframes at
//    the file's frame times (s, shared input accessor), values as in the file (rotation as glTF's
//    x, y, z, w). A body absent from a frame keeps its previous pose.
// Bodies of shape "sphere" get the node scale of their radius.
#pragma once

#include "render/frames.hpp"
#include "render/render.hpp"

#include <string>
#include <vector>

namespace statsim::tools::exporter {

/// Writes `frames` to `path` as binary glTF; `shapes[i]` is the mesh of shape index i. Returns
/// false with `error` on bad input (no frames, times not increasing) or an unwritable file.
bool export_glb(const render::Frames& frames, const std::vector<const render::RenderShape*>& shapes,
                const std::string& path, std::string& error);

}  // namespace statsim::tools::exporter

