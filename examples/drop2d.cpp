// 2D demo: 100 unit squares and 100 L-shapes dropped onto the ground, simulated with their
// signatures from the committed tables (tables/square2d.hpp, tables/lshape2d.hpp). Prints a
// summary and writes a PNG of the final frame. Bodies touch at their hulls (the tables' body-body
// data, `BodyContacts::hulls`), so they pile as polygons do instead of resting on one another's
// collision spheres; --spheres gives the paper's model.
//
//   drop2d [--n N] [--png FILE] [--seed S] [--frames FILE.csv] [--every K] [--spheres]
//     --n       bodies of each shape (default 100, at most 500)
//     --png     picture of the final frame (default drop2d.png; "-" for none)
//     --seed    seed of the initial states and of the world (default 1)
//     --frames  per-frame transforms, every K-th step (default 6), in the demos' CSV format
//               (tools/scenes/frames.hpp): x, y with y up, z = 0, the turn as a quaternion about z
//     --spheres body-body contacts at the collision spheres (the paper's model)
#include "scenes/frames.hpp"
#include "statsim/world2.hpp"
#include "tables/lshape2d.hpp"
#include "tables/square2d.hpp"

#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wconversion"
#pragma GCC diagnostic ignored "-Wsign-conversion"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#pragma GCC diagnostic ignored "-Wshadow"
#endif
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb/stb_easy_font.h>
#include <stb/stb_image_write.h>
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

using namespace statsim;

namespace {
constexpr std::uint32_t capacity = 1000;
World2<capacity> world;

// Outlines of the two shapes (the same polygons the tables were gathered from), in metres.
const Vector2 square_outline[] = {{-0.5f, -0.5f}, {0.5f, -0.5f}, {0.5f, 0.5f}, {-0.5f, 0.5f}};
const Vector2 lshape_corners[] = {{0, 0}, {1, 0}, {1, 0.25f}, {0.25f, 0.25f}, {0.25f, 1}, {0, 1}};

struct Outline {
  std::vector<Vector2> points;  // body frame: centred on the centroid
};

Outline centred(const Vector2* p, int n)
{
  // Centroid of a simple polygon: sum of (p_i + p_j) cross(p_i, p_j) over 6 A.
  float area = 0;
  Vector2 c(0, 0);
  for (int i = 0; i < n; ++i) {
    const Vector2& a = p[i];
    const Vector2& b = p[(i + 1) % n];
    const float cr = a.x() * b.y() - a.y() * b.x();
    area += cr;
    c += (a + b) * cr;
  }
  c /= 3 * area;
  Outline o;
  for (int i = 0; i < n; ++i) o.points.push_back(p[i] - c);
  return o;
}

// A filled polygon in an RGB image, by even-odd scanlines through pixel centres.
struct Image {
  int w, h;
  std::vector<unsigned char> rgb;
  Image(int width, int height) : w(width), h(height), rgb(std::size_t(width * height * 3), 255) {}
  void fill(const std::vector<Vector2>& poly, const unsigned char colour[3])
  {
    float ymin = 1e9f, ymax = -1e9f;
    for (const Vector2& p : poly) {
      ymin = std::fmin(ymin, p.y());
      ymax = std::fmax(ymax, p.y());
    }
    for (int y = std::max(0, int(ymin)); y <= std::min(h - 1, int(ymax) + 1); ++y) {
      const float sy = float(y) + 0.5f;
      float xs[16];
      int k = 0;
      for (std::size_t i = 0; i < poly.size() && k < 16; ++i) {
        const Vector2& a = poly[i];
        const Vector2& b = poly[(i + 1) % poly.size()];
        if ((a.y() <= sy) != (b.y() <= sy)) xs[k++] = a.x() + (sy - a.y()) / (b.y() - a.y()) * (b.x() - a.x());
      }
      for (int i = 1; i < k; ++i)
        for (int j = i; j > 0 && xs[j - 1] > xs[j]; --j) std::swap(xs[j - 1], xs[j]);
      for (int i = 0; i + 1 < k; i += 2)
        for (int x = std::max(0, int(std::ceil(xs[i] - 0.5f))); x <= std::min(w - 1, int(xs[i + 1] - 0.5f)); ++x)
          std::memcpy(&rgb[std::size_t((y * w + x) * 3)], colour, 3);
    }
  }
  void rect(float x0, float y0, float x1, float y1, const unsigned char colour[3])
  {
    fill({{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}}, colour);
  }
  /// Writes `text` from (x, y) (its top left), `px` pixels per dot of stb_easy_font's glyphs.
  void text(float x, float y, const char* text, float px, const unsigned char colour[3])
  {
    // stb_easy_font writes each dot run as a quad of four vertices of 16 bytes: x, y, z, colour.
    static char quads[16 * 4 * 400];
    const int count = stb_easy_font_print(0, 0, const_cast<char*>(text), nullptr, quads, int(sizeof quads));
    for (int q = 0; q < count; ++q) {
      float corner[2][2];
      std::memcpy(corner[0], quads + q * 64, sizeof corner[0]);
      std::memcpy(corner[1], quads + q * 64 + 32, sizeof corner[1]);
      rect(x + corner[0][0] * px, y + corner[0][1] * px, x + corner[1][0] * px, y + corner[1][1] * px, colour);
    }
  }
};
}  // namespace

int main(int argc, char** argv)
{
  long n = 100;
  const char* png = "drop2d.png";
  unsigned long long seed = 1;
  const char* frames = nullptr;
  int every = 6;
  bool spheres = false;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--n") && i + 1 < argc) n = std::strtol(argv[++i], nullptr, 10);
    else if (!std::strcmp(argv[i], "--png") && i + 1 < argc) png = argv[++i];
    else if (!std::strcmp(argv[i], "--seed") && i + 1 < argc) seed = std::strtoull(argv[++i], nullptr, 10);
    else if (!std::strcmp(argv[i], "--frames") && i + 1 < argc) frames = argv[++i];
    else if (!std::strcmp(argv[i], "--every") && i + 1 < argc) every = std::max(1, int(std::strtol(argv[++i], nullptr, 10)));
    else if (!std::strcmp(argv[i], "--spheres")) spheres = true;
    else {
      std::fprintf(stderr, "usage: drop2d [--n N] [--png FILE|-] [--seed S] [--frames FILE.csv] [--every K] [--spheres]\n");
      return 2;
    }
  }
  if (n < 1 || 2 * n > long(capacity)) {
    std::fprintf(stderr, "drop2d: --n must be 1..%u\n", capacity / 2);
    return 2;
  }

  WorldDef2 def;
  def.seed = seed;
  if (spheres) def.body_contacts = BodyContacts::collision_spheres;  // else the default: hulls
  bool set_up = world.configure(def) == Status::ok;
  const SignatureView<2> signatures[2] = {tables::square2d.view(), tables::lshape2d.view()};
  const Outline outlines[2] = {centred(square_outline, 4), centred(lshape_corners, 6)};
  ShapeId shapes[2];
  for (int s = 0; s < 2; ++s) {
    const Added<ShapeId> added = world.add_shape(signatures[s]);
    set_up = set_up && added.ok();
    shapes[s] = added.id;
  }
  const float half_width = 2.0f * std::sqrt(float(n));  // walls far enough out for a low pile
  set_up = set_up && world.add_plane(Vector2(0, 1), 0).ok() && world.add_plane(Vector2(1, 0), -half_width).ok() &&
           world.add_plane(Vector2(-1, 0), -half_width).ok();
  if (!set_up) {
    std::fprintf(stderr, "drop2d: world set-up failed\n");
    return 1;
  }

  Pcg32 rng(seed, 1000);
  for (long i = 0; i < 2 * n; ++i) {
    BodyDef2 b;
    b.shape = shapes[i % 2];
    b.mass = 1;  // kg, both shapes alike, as the committed picture was made (the tables' masses differ)
    const float x = rng.uniform(-0.6f * half_width, 0.6f * half_width);
    const float y = rng.uniform(1, 1 + 0.15f * float(n));
    const float angle = rng.uniform(-3.14159265f, 3.14159265f);
    const float vx = rng.uniform(-1, 1);
    const float spin = rng.uniform(-4, 4);
    b.position = Vector2(x, y);
    b.orientation = Rot2::from_angle(angle);
    b.linear_velocity = Vector2(vx, 0);
    b.angular_velocity = spin;
    const Status st = world.add_body(b).status;
    if (st != Status::ok) {
      std::fprintf(stderr, "drop2d: add_body: %s\n", to_string(st));
      return 1;
    }
  }

  std::FILE* csv = nullptr;
  if (frames) {
    csv = std::fopen(frames, "w");
    if (!csv) {
      std::fprintf(stderr, "drop2d: cannot write %s\n", frames);
      return 1;
    }
    statsim::tools::scenes::write_frames_header(csv);
  }
  const float dt = 1.0f / 60;
  const int max_steps = 60 * 40;
  int steps = 0;
  double seconds = 0;
  while (steps < max_steps && world.count(MotionState::asleep) < world.body_count()) {
    const auto t0 = std::chrono::steady_clock::now();
    const StepResult r = world.step(dt);
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (csv && steps % every == 0) statsim::tools::scenes::write_frame(csv, world, steps, double(steps + 1) * double(dt));
    ++steps;
    if (r.overflow) std::fprintf(stderr, "drop2d: pair buffer overflow (%u dropped)\n", r.pairs_dropped);
  }
  if (csv) std::fclose(csv);

  std::printf("drop2d: %ld squares and %ld L-shapes, %d steps of 1/60 s, %.4f ms per step, contacts at the %s\n", n,
              n, steps, 1e3 * seconds / steps, spheres ? "collision spheres" : "hulls");
  std::printf("  asleep %u of %u, energy guard acted %llu times\n", world.count(MotionState::asleep),
              world.body_count(), static_cast<unsigned long long>(world.energy_clamp_count()));
  for (int s = 0; s < 2; ++s) {
    const SignatureView<2>& sig = signatures[s];
    std::vector<int> hist(sig.rest.count + 1, 0);
    for (std::uint32_t i = 0; i < world.body_count(); ++i) {
      const Body2& b = world.body(i);
      if (b.shape != shapes[s].index) continue;
      ++hist[b.rest_pose == no_rest_pose ? sig.rest.count : b.rest_pose];
    }
    std::printf("  %s rest poses:", sig.name);
    for (std::uint32_t p = 0; p < sig.rest.count; ++p)
      std::printf(" [%u: up (%+.2f %+.2f), table %.0f%%] %d", p, double(sig.rest.normal(p).x()),
                  double(sig.rest.normal(p).y()), 100.0 * double(sig.rest.frequencies[p]), hist[p]);
    std::printf(" [none: on other bodies or moving] %d\n", hist[sig.rest.count]);
  }

  if (std::strcmp(png, "-") != 0) {
    const float scale = 40;  // pixels per metre
    float top = 1;
    for (std::uint32_t i = 0; i < world.body_count(); ++i) top = std::fmax(top, world.body(i).position.y() + 1);
    const int w = int(2 * half_width * scale), h = int((top + 0.5f) * scale);
    Image img(w, h);
    const unsigned char ground[3] = {90, 90, 90}, colours[2][3] = {{31, 119, 180}, {214, 96, 39}};
    img.fill({{0, float(h) - 0.5f * scale}, {float(w), float(h) - 0.5f * scale}, {float(w), float(h)}, {0, float(h)}},
             ground);
    for (std::uint32_t i = 0; i < world.body_count(); ++i) {
      const Body2& b = world.body(i);
      const int s = b.shape == shapes[0].index ? 0 : 1;
      std::vector<Vector2> poly;
      for (const Vector2& p : outlines[s].points) {
        const Vector2 q = b.orientation * p + b.position;  // world, metres; y up
        poly.emplace_back((q.x() + half_width) * scale, float(h) - (q.y() + 0.5f) * scale);
      }
      img.fill(poly, colours[s]);
    }
    // The legend, top left: each shape in its colour, named.
    const unsigned char frame[3] = {200, 200, 200}, white[3] = {255, 255, 255}, ink[3] = {40, 40, 40};
    img.rect(6, 6, 166, 82, frame);
    img.rect(7, 7, 165, 81, white);
    const char* names[2] = {"square", "L-shape"};
    for (int s = 0; s < 2; ++s) {
      std::vector<Vector2> icon;
      const float cx = 30, cy = 26 + 34 * float(s);
      for (const Vector2& p : outlines[s].points) icon.emplace_back(cx + 20 * p.x(), cy - 20 * p.y());
      img.fill(icon, colours[s]);
      img.text(60, cy - 7, names[s], 2, ink);
    }
    if (!stbi_write_png(png, w, h, 3, img.rgb.data(), w * 3)) {
      std::fprintf(stderr, "drop2d: cannot write %s\n", png);
      return 1;
    }
    std::printf("  final frame: %s (%dx%d)\n", png, w, h);
  }
  return 0;
}
