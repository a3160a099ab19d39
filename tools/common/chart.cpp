#include "common/chart.hpp"

#include "common/atomic_file.hpp"
#include "common/stb_wrapper.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <utility>

namespace statsim::tools::chart {
namespace {

constexpr Color kText{35, 35, 35};
constexpr Color kFrame{70, 70, 70};
constexpr Color kGrid{226, 226, 226};
constexpr Color kMinorGrid{242, 242, 242};
constexpr Color kWhite{255, 255, 255};

// stb_easy_font metrics, in its pixel units: capitals span y in [0, 7], descenders reach 9.
constexpr double kCapHeight = 7.0;

struct Pt {
  double x = 0.0;
  double y = 0.0;
};

struct Rect {
  double x0 = 0.0;
  double y0 = 0.0;
  double x1 = 0.0;
  double y1 = 0.0;
  double width() const { return x1 - x0; }
  double height() const { return y1 - y0; }
  bool contains(Pt p) const { return p.x >= x0 && p.x <= x1 && p.y >= y0 && p.y <= y1; }
  bool contains(const Rect& r) const { return r.x0 >= x0 && r.x1 <= x1 && r.y0 >= y0 && r.y1 <= y1; }
  bool intersects(const Rect& r) const { return r.x0 < x1 && r.x1 > x0 && r.y0 < y1 && r.y1 > y0; }
  Rect inflated(double d) const { return {x0 - d, y0 - d, x1 + d, y1 + d}; }
};

double clamp01(double v)
{
  return v < 0.0 ? 0.0 : (v > 1.0 ? 1.0 : v);
}

// ---------------------------------------------------------------------------------------------
// Text: stb_easy_font produces axis-aligned quads that we rasterise with box-filter coverage.
// ---------------------------------------------------------------------------------------------

// Only printable ASCII is in the font.
std::vector<char> font_string(const std::string& s)
{
  std::vector<char> out;
  out.reserve(s.size() + 1);
  for (char c : s) {
    out.push_back(c >= 32 && c <= 126 ? c : (c == '\n' || c == '\t' ? ' ' : '?'));
  }
  out.push_back('\0');
  return out;
}

// Width in pixels of the ink of `s` at `scale` (without the trailing advance).
double text_width(const std::string& s, double scale)
{
  if (s.empty()) {
    return 0.0;
  }
  std::vector<char> buf = font_string(s);
  return (stb_easy_font_width(buf.data()) - 1) * scale;
}

double text_height(double scale)
{
  return kCapHeight * scale;
}

enum class HAlign { left, center, right };
enum class VAlign { top, middle, bottom };

// ---------------------------------------------------------------------------------------------
// Canvas: an RGB float image plus a coverage mask. Shapes are accumulated into the mask (max of
// coverages, so overlapping pieces of one shape do not darken) and then painted in one colour.
// ---------------------------------------------------------------------------------------------
class Canvas {
public:
  Canvas(int width, int height)
      : w_(width),
        h_(height),
        rgb_(static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 3, 255.0f),
        mask_(static_cast<std::size_t>(width) * static_cast<std::size_t>(height), 0.0f)
  {
    reset_clip();
    clear_dirty();
  }

  void set_clip(const Rect& r)
  {
    cx0_ = std::max(0, static_cast<int>(std::floor(r.x0)));
    cy0_ = std::max(0, static_cast<int>(std::floor(r.y0)));
    cx1_ = std::min(w_, static_cast<int>(std::ceil(r.x1)));
    cy1_ = std::min(h_, static_cast<int>(std::ceil(r.y1)));
  }
  void reset_clip() { set_clip({0.0, 0.0, static_cast<double>(w_), static_cast<double>(h_)}); }

  // Paints the accumulated mask in `c` with `opacity`, then clears the mask.
  void paint(Color c, double opacity = 1.0)
  {
    if (dx0_ >= dx1_ || dy0_ >= dy1_) {
      return;
    }
    const float cr = c.r;
    const float cg = c.g;
    const float cb = c.b;
    const float op = static_cast<float>(clamp01(opacity));
    for (int y = dy0_; y < dy1_; ++y) {
      for (int x = dx0_; x < dx1_; ++x) {
        const std::size_t i = index(x, y);
        const float a = mask_[i] * op;
        mask_[i] = 0.0f;
        if (a <= 0.0f) {
          continue;
        }
        float* p = &rgb_[i * 3];
        p[0] += (cr - p[0]) * a;
        p[1] += (cg - p[1]) * a;
        p[2] += (cb - p[2]) * a;
      }
    }
    clear_dirty();
  }

  // Axis-aligned rectangle with fractional coverage at its edges.
  void rect(double x0, double y0, double x1, double y1)
  {
    if (x1 < x0) {
      std::swap(x0, x1);
    }
    if (y1 < y0) {
      std::swap(y0, y1);
    }
    const int ix0 = static_cast<int>(std::floor(x0));
    const int iy0 = static_cast<int>(std::floor(y0));
    const int ix1 = static_cast<int>(std::ceil(x1));
    const int iy1 = static_cast<int>(std::ceil(y1));
    for (int y = iy0; y < iy1; ++y) {
      const double cy = std::min(y1, y + 1.0) - std::max(y0, static_cast<double>(y));
      for (int x = ix0; x < ix1; ++x) {
        const double cx = std::min(x1, x + 1.0) - std::max(x0, static_cast<double>(x));
        cover(x, y, cx * cy);
      }
    }
  }

  // A line segment of the given width with round caps.
  void segment(Pt a, Pt b, double width)
  {
    const double r = 0.5 * width;
    const int ix0 = static_cast<int>(std::floor(std::min(a.x, b.x) - r - 1.0));
    const int ix1 = static_cast<int>(std::ceil(std::max(a.x, b.x) + r + 1.0));
    const int iy0 = static_cast<int>(std::floor(std::min(a.y, b.y) - r - 1.0));
    const int iy1 = static_cast<int>(std::ceil(std::max(a.y, b.y) + r + 1.0));
    const double dx = b.x - a.x;
    const double dy = b.y - a.y;
    const double len2 = dx * dx + dy * dy;
    // Thin lines keep their weight by lowering the opacity instead of the width.
    const double weight = std::min(1.0, width);
    const double reff = std::max(r, 0.5);
    for (int y = std::max(iy0, cy0_); y < std::min(iy1, cy1_); ++y) {
      for (int x = std::max(ix0, cx0_); x < std::min(ix1, cx1_); ++x) {
        const double px = x + 0.5 - a.x;
        const double py = y + 0.5 - a.y;
        double t = len2 > 0.0 ? (px * dx + py * dy) / len2 : 0.0;
        t = t < 0.0 ? 0.0 : (t > 1.0 ? 1.0 : t);
        const double ex = px - t * dx;
        const double ey = py - t * dy;
        const double d = std::sqrt(ex * ex + ey * ey);
        cover(x, y, weight * clamp01(reff + 0.5 - d));
      }
    }
  }

  void polyline(const std::vector<Pt>& pts, double width, bool dashed)
  {
    if (pts.size() == 1) {
      segment(pts[0], pts[0], width);
      return;
    }
    if (!dashed) {
      for (std::size_t i = 1; i < pts.size(); ++i) {
        segment(pts[i - 1], pts[i], width);
      }
      return;
    }
    const double on = 3.0 * width + 5.0;
    const double off = 1.5 * width + 4.0;
    bool drawing = true;
    double left = on;  // length remaining in the current dash or gap
    for (std::size_t i = 1; i < pts.size(); ++i) {
      Pt a = pts[i - 1];
      const Pt b = pts[i];
      double len = std::hypot(b.x - a.x, b.y - a.y);
      while (len > 0.0) {
        const double step = std::min(left, len);
        const double f = step / len;
        const Pt m{a.x + (b.x - a.x) * f, a.y + (b.y - a.y) * f};
        if (drawing) {
          segment(a, m, width);
        }
        a = m;
        len -= step;
        left -= step;
        if (left <= 1e-9) {
          drawing = !drawing;
          left = drawing ? on : off;
        }
      }
    }
  }

  void disc(Pt c, double radius)
  {
    const int ix0 = static_cast<int>(std::floor(c.x - radius - 1.0));
    const int ix1 = static_cast<int>(std::ceil(c.x + radius + 1.0));
    const int iy0 = static_cast<int>(std::floor(c.y - radius - 1.0));
    const int iy1 = static_cast<int>(std::ceil(c.y + radius + 1.0));
    for (int y = iy0; y < iy1; ++y) {
      for (int x = ix0; x < ix1; ++x) {
        const double d = std::hypot(x + 0.5 - c.x, y + 0.5 - c.y);
        cover(x, y, clamp01(radius + 0.5 - d));
      }
    }
  }

  // A filled polygon (even-odd rule), 4x4 supersampled. Meant for small shapes (markers).
  void polygon(const std::vector<Pt>& pts)
  {
    if (pts.size() < 3) {
      return;
    }
    double x0 = pts[0].x;
    double x1 = pts[0].x;
    double y0 = pts[0].y;
    double y1 = pts[0].y;
    for (const Pt& p : pts) {
      x0 = std::min(x0, p.x);
      x1 = std::max(x1, p.x);
      y0 = std::min(y0, p.y);
      y1 = std::max(y1, p.y);
    }
    constexpr int kSub = 4;
    for (int y = static_cast<int>(std::floor(y0)); y < static_cast<int>(std::ceil(y1)); ++y) {
      for (int x = static_cast<int>(std::floor(x0)); x < static_cast<int>(std::ceil(x1)); ++x) {
        int inside = 0;
        for (int sy = 0; sy < kSub; ++sy) {
          for (int sx = 0; sx < kSub; ++sx) {
            const double px = x + (sx + 0.5) / kSub;
            const double py = y + (sy + 0.5) / kSub;
            bool in = false;
            for (std::size_t i = 0, j = pts.size() - 1; i < pts.size(); j = i++) {
              if ((pts[i].y > py) != (pts[j].y > py) &&
                  px < (pts[j].x - pts[i].x) * (py - pts[i].y) / (pts[j].y - pts[i].y) + pts[i].x) {
                in = !in;
              }
            }
            inside += in ? 1 : 0;
          }
        }
        cover(x, y, static_cast<double>(inside) / (kSub * kSub));
      }
    }
  }

  // Text whose unrotated layout box has its top-left corner at (x, y). With `vertical`, the text
  // is rotated a quarter turn counter-clockwise (reading upwards) about that corner, so it
  // occupies [x, x + height] x [y - width, y].
  void text(const std::string& s, double x, double y, double scale, bool vertical)
  {
    if (s.empty()) {
      return;
    }
    std::vector<char> buf = font_string(s);
    std::vector<char> verts(buf.size() * 1024 + 64);
    const int quads = stb_easy_font_print(0.0f, 0.0f, buf.data(), nullptr, verts.data(),
                                          static_cast<int>(verts.size()));
    for (int q = 0; q < quads; ++q) {
      float qx0 = std::numeric_limits<float>::max();
      float qy0 = qx0;
      float qx1 = -qx0;
      float qy1 = -qx0;
      for (int v = 0; v < 4; ++v) {
        float vx = 0.0f;
        float vy = 0.0f;
        const char* vp = verts.data() + (static_cast<std::size_t>(q) * 4 + static_cast<std::size_t>(v)) * 16;
        std::memcpy(&vx, vp, sizeof vx);
        std::memcpy(&vy, vp + 4, sizeof vy);
        qx0 = std::min(qx0, vx);
        qx1 = std::max(qx1, vx);
        qy0 = std::min(qy0, vy);
        qy1 = std::max(qy1, vy);
      }
      if (!vertical) {
        rect(x + qx0 * scale, y + qy0 * scale, x + qx1 * scale, y + qy1 * scale);
      } else {
        rect(x + qy0 * scale, y - qx1 * scale, x + qy1 * scale, y - qx0 * scale);
      }
    }
  }

  Image image() const
  {
    Image img;
    img.width = w_;
    img.height = h_;
    img.rgb.resize(rgb_.size());
    for (std::size_t i = 0; i < rgb_.size(); ++i) {
      const float v = std::min(255.0f, std::max(0.0f, rgb_[i]));
      img.rgb[i] = static_cast<std::uint8_t>(std::lround(v));
    }
    return img;
  }

private:
  std::size_t index(int x, int y) const
  {
    return static_cast<std::size_t>(y) * static_cast<std::size_t>(w_) + static_cast<std::size_t>(x);
  }

  void cover(int x, int y, double a)
  {
    if (x < cx0_ || x >= cx1_ || y < cy0_ || y >= cy1_ || a <= 0.0) {
      return;
    }
    float& m = mask_[index(x, y)];
    m = std::max(m, static_cast<float>(std::min(a, 1.0)));
    dx0_ = std::min(dx0_, x);
    dy0_ = std::min(dy0_, y);
    dx1_ = std::max(dx1_, x + 1);
    dy1_ = std::max(dy1_, y + 1);
  }

  void clear_dirty()
  {
    dx0_ = w_;
    dy0_ = h_;
    dx1_ = 0;
    dy1_ = 0;
  }

  int w_;
  int h_;
  std::vector<float> rgb_;
  std::vector<float> mask_;
  int cx0_ = 0, cy0_ = 0, cx1_ = 0, cy1_ = 0;  // clip rectangle, half-open
  int dx0_ = 0, dy0_ = 0, dx1_ = 0, dy1_ = 0;  // dirty part of the mask, half-open
};

// The layout box of `s` anchored at (x, y) by the given alignment.
Rect text_box(const std::string& s, double x, double y, double scale, HAlign h, VAlign v)
{
  const double w = text_width(s, scale);
  const double ht = text_height(scale);
  const double left = h == HAlign::left ? x : (h == HAlign::center ? x - 0.5 * w : x - w);
  const double top = v == VAlign::top ? y : (v == VAlign::middle ? y - 0.5 * ht : y - ht);
  return {left, top, left + w, top + ht};
}

void draw_text(Canvas& cv, const std::string& s, double x, double y, double scale, HAlign h,
               VAlign v, Color c)
{
  const Rect box = text_box(s, x, y, scale, h, v);
  cv.text(s, box.x0, box.y0, scale, false);
  cv.paint(c);
}

// ---------------------------------------------------------------------------------------------
// Axes: ranges, ticks, value-to-pixel mapping.
// ---------------------------------------------------------------------------------------------
struct Tick {
  double value = 0.0;   // in data units
  bool major = true;
  std::string label;    // empty: no label
};

struct AxisMap {
  Scale scale = Scale::linear;
  double t0 = 0.0;  // transformed limits
  double t1 = 1.0;
  double p0 = 0.0;  // pixel positions of t0 and t1
  double p1 = 1.0;

  bool valid(double v) const { return std::isfinite(v) && (scale == Scale::linear || v > 0.0); }
  double transform(double v) const { return scale == Scale::log10 ? std::log10(v) : v; }
  double px(double v) const { return p0 + (transform(v) - t0) / (t1 - t0) * (p1 - p0); }
  bool in_range(double v) const
  {
    const double t = transform(v);
    const double eps = 1e-9 * (t1 - t0);
    return t >= t0 - eps && t <= t1 + eps;
  }
};

std::string format_number(double v, int decimals)
{
  char buf[64];
  if (v == 0.0 || std::fabs(v) < 1e-300) {
    return "0";
  }
  const double a = std::fabs(v);
  if (a >= 1e7 || a < 1e-5) {
    std::snprintf(buf, sizeof buf, "%.3g", v);
  } else {
    std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  }
  std::string s = buf;
  if (s == "-0") {
    s = "0";
  }
  return s;
}

// "1e-7", "0.001", "20", "1e9": compact labels for powers of ten (times 1..9).
std::string format_log_value(double mantissa, int exponent)
{
  char buf[64];
  const double v = mantissa * std::pow(10.0, exponent);
  if (exponent >= -4 && exponent <= 6) {
    std::snprintf(buf, sizeof buf, "%.*f", exponent < 0 ? -exponent : 0, v);
  } else {
    std::snprintf(buf, sizeof buf, "%.0fe%d", mantissa, exponent);
  }
  return buf;
}

std::vector<Tick> linear_ticks(double lo, double hi, double target_count)
{
  std::vector<Tick> ticks;
  const double span = hi - lo;
  if (!(span > 0.0)) {
    return ticks;
  }
  const double raw = span / std::max(1.0, target_count);
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  const double norm = raw / mag;
  const double step = (norm < 1.5 ? 1.0 : norm < 3.0 ? 2.0 : norm < 7.0 ? 5.0 : 10.0) * mag;
  const int decimals = std::max(0, std::min(12, static_cast<int>(-std::floor(std::log10(step) + 1e-9))));
  const double first = std::ceil(lo / step - 1e-9);
  const double last = std::floor(hi / step + 1e-9);
  for (double k = first; k <= last && ticks.size() < 200; k += 1.0) {
    const double v = k * step;
    ticks.push_back({v, true, format_number(std::fabs(v) < 1e-12 * step ? 0.0 : v, decimals)});
  }
  return ticks;
}

// Ticks of a log10 axis whose transformed range is [t0, t1].
std::vector<Tick> log_ticks(double t0, double t1, double target_count)
{
  std::vector<Tick> ticks;
  const int k0 = static_cast<int>(std::floor(t0)) - 1;
  const int k1 = static_cast<int>(std::ceil(t1)) + 1;
  auto inside = [&](double t) { return t >= t0 - 1e-9 && t <= t1 + 1e-9; };
  int majors = 0;
  for (int k = k0; k <= k1; ++k) {
    majors += inside(k) ? 1 : 0;
  }
  const int every = std::max(1, static_cast<int>(std::ceil(majors / std::max(1.0, target_count))));
  // With fewer than two decades shown, label 2x and 5x too (or every minor tick if needed).
  const bool label_25 = majors < 2;
  const bool label_all = label_25 && (t1 - t0) < std::log10(5.0);
  for (int k = k0; k <= k1; ++k) {
    for (int m = 1; m <= 9; ++m) {
      const double t = k + std::log10(static_cast<double>(m));
      if (!inside(t)) {
        continue;
      }
      Tick tick;
      tick.value = m * std::pow(10.0, k);
      tick.major = m == 1;
      bool labelled = m == 1 ? ((k % every + every) % every == 0)
                             : (label_all || (label_25 && (m == 2 || m == 5)));
      if (m == 1 && every > 1 && majors <= 1) {
        labelled = true;
      }
      if (labelled) {
        tick.label = format_log_value(m, k);
      }
      ticks.push_back(tick);
    }
  }
  // Very short ranges inside one decade may contain no tick at all: fall back to linear ticks.
  if (ticks.size() < 2) {
    ticks.clear();
    for (const Tick& t : linear_ticks(std::pow(10.0, t0), std::pow(10.0, t1), 4.0)) {
      if (t.value > 0.0) {
        ticks.push_back(t);
      }
    }
  }
  return ticks;
}

std::vector<Tick> make_ticks(const AxisMap& m, double target_count)
{
  return m.scale == Scale::log10 ? log_ticks(m.t0, m.t1, target_count)
                                 : linear_ticks(m.t0, m.t1, target_count);
}

// Fits the transformed range of an axis to the values it shows.
void fit_range(AxisMap& m, const Axis& axis, const std::vector<double>& values, const char* which)
{
  const bool log = axis.scale == Scale::log10;
  for (const std::optional<double>& lim : {axis.min, axis.max}) {
    if (lim && (!std::isfinite(*lim) || (log && *lim <= 0.0))) {
      throw std::invalid_argument(std::string("chart: the ") + which +
                                  " axis limit must be finite" + (log ? " and positive" : ""));
    }
  }
  double lo = std::numeric_limits<double>::infinity();
  double hi = -lo;
  for (double v : values) {
    if (m.valid(v)) {
      lo = std::min(lo, m.transform(v));
      hi = std::max(hi, m.transform(v));
    }
  }
  if (!(lo <= hi)) {
    lo = 0.0;
    hi = 1.0;
  }
  if (hi - lo < 1e-12 * std::max(1.0, std::fabs(lo))) {
    const double d = log ? 0.5 : (lo == 0.0 ? 1.0 : 0.1 * std::fabs(lo));
    lo -= d;
    hi += d;
  }
  const double pad = 0.04 * (hi - lo);
  m.t0 = axis.min ? m.transform(*axis.min) : lo - pad;
  m.t1 = axis.max ? m.transform(*axis.max) : hi + pad;
  if (axis.min && !axis.max && m.t1 <= m.t0) {
    m.t1 = m.t0 + (log ? 1.0 : std::max(1.0, std::fabs(m.t0)));
  }
  if (axis.max && !axis.min && m.t1 <= m.t0) {
    m.t0 = m.t1 - (log ? 1.0 : std::max(1.0, std::fabs(m.t1)));
  }
  if (!(m.t1 > m.t0)) {
    throw std::invalid_argument(std::string("chart: the ") + which + " axis minimum must be below its maximum");
  }
}

// ---------------------------------------------------------------------------------------------
// Markers and legend.
// ---------------------------------------------------------------------------------------------
void mark(Canvas& cv, Marker marker, Pt c, double r)
{
  switch (marker) {
    case Marker::none:
      break;
    case Marker::circle:
      cv.disc(c, r);
      break;
    case Marker::square:
      cv.rect(c.x - 0.85 * r, c.y - 0.85 * r, c.x + 0.85 * r, c.y + 0.85 * r);
      break;
    case Marker::diamond:
      cv.polygon({{c.x, c.y - 1.25 * r}, {c.x + 1.25 * r, c.y}, {c.x, c.y + 1.25 * r}, {c.x - 1.25 * r, c.y}});
      break;
    case Marker::triangle:
      cv.polygon({{c.x, c.y - 1.3 * r}, {c.x + 1.15 * r, c.y + 0.75 * r}, {c.x - 1.15 * r, c.y + 0.75 * r}});
      break;
  }
}

struct LegendEntry {
  std::string text;
  Color color;
  bool is_band = false;
  double opacity = 1.0;
  bool line = false;
  bool dashed = false;
  double line_width = 2.0;
  Marker marker = Marker::none;
  double marker_size = 4.0;
};

// Weighted samples of where data is drawn, to place the legend where it hides the least.
// Hiding a marker or a label is much worse than covering a stretch of line or band.
struct Ink {
  struct Sample {
    Pt p;
    double weight;
  };
  std::vector<Sample> samples;
  void segment(Pt a, Pt b, double weight = 1.0)
  {
    const double len = std::hypot(b.x - a.x, b.y - a.y);
    const int n = std::max(1, static_cast<int>(len / 4.0));
    for (int i = 0; i <= n; ++i) {
      const double f = static_cast<double>(i) / n;
      samples.push_back({{a.x + (b.x - a.x) * f, a.y + (b.y - a.y) * f}, weight});
    }
  }
  void area(const Rect& r, double weight)
  {
    for (double y = r.y0; y <= r.y1; y += 4.0) {
      for (double x = r.x0; x <= r.x1; x += 4.0) {
        samples.push_back({{x, y}, weight});
      }
    }
  }
  void point(Pt p, double weight) { samples.push_back({p, weight}); }
  double count(const Rect& r) const
  {
    double total = 0.0;
    for (const Sample& s : samples) {
      total += r.contains(s.p) ? s.weight : 0.0;
    }
    return total;
  }
};

Color series_color(const Series& s, std::size_t i)
{
  return s.color ? *s.color : palette(i);
}

Color band_color(const Band& b, std::size_t i)
{
  return b.color ? *b.color : palette(i);
}

void check_lengths(const Chart& c)
{
  for (const Series& s : c.series) {
    if (s.x.size() != s.y.size()) {
      throw std::invalid_argument("chart: series '" + s.name + "' has " + std::to_string(s.x.size()) +
                                  " x values but " + std::to_string(s.y.size()) + " y values");
    }
    if (!s.labels.empty() && s.labels.size() != s.x.size()) {
      throw std::invalid_argument("chart: series '" + s.name + "' needs one label per point");
    }
  }
  for (const Band& b : c.bands) {
    if (b.x.size() != b.lower.size() || b.x.size() != b.upper.size()) {
      throw std::invalid_argument("chart: band '" + b.name + "' has vectors of different lengths");
    }
  }
  if (c.width < 200 || c.height < 150 || c.width > 20000 || c.height > 20000) {
    throw std::invalid_argument("chart: image size must be between 200x150 and 20000x20000");
  }
  if (!(c.text_scale > 0.0) || !(c.title_scale > 0.0) || !(c.label_scale > 0.0)) {
    throw std::invalid_argument("chart: text scales must be positive");
  }
}

}  // namespace

Color palette(std::size_t i)
{
  // Okabe & Ito (2008), reordered so the first colours are the most distinct on white.
  static constexpr std::array<Color, 8> colors{{{0, 114, 178},
                                                {213, 94, 0},
                                                {0, 158, 115},
                                                {204, 121, 167},
                                                {230, 159, 0},
                                                {86, 180, 233},
                                                {100, 100, 100},
                                                {240, 228, 66}}};
  return colors[i % colors.size()];
}

Image render(const Chart& chart)
{
  check_lengths(chart);
  const double W = chart.width;
  const double H = chart.height;
  const double ts = chart.text_scale;
  const double ls = chart.label_scale;

  // ---- ranges ---------------------------------------------------------------------------------
  AxisMap xm;
  AxisMap ym;
  xm.scale = chart.x.scale;
  ym.scale = chart.y.scale;
  {
    std::vector<double> xs;
    std::vector<double> ys;
    for (const Series& s : chart.series) {
      for (std::size_t i = 0; i < s.x.size(); ++i) {
        if (xm.valid(s.x[i]) && ym.valid(s.y[i])) {
          xs.push_back(s.x[i]);
          ys.push_back(s.y[i]);
        }
      }
    }
    for (const Band& b : chart.bands) {
      for (std::size_t i = 0; i < b.x.size(); ++i) {
        if (xm.valid(b.x[i]) && ym.valid(b.lower[i]) && ym.valid(b.upper[i])) {
          xs.push_back(b.x[i]);
          ys.push_back(b.lower[i]);
          ys.push_back(b.upper[i]);
        }
      }
    }
    for (const ReferenceLine& r : chart.reference_lines) {
      (r.orientation == ReferenceLine::Orientation::horizontal ? ys : xs).push_back(r.value);
    }
    fit_range(xm, chart.x, xs, "x");
    fit_range(ym, chart.y, ys, "y");
  }

  // ---- layout -----------------------------------------------------------------------------------
  const double pad = 18.0;
  const double tick_len = 6.0;
  const double gap = 7.0;
  const double title_h = chart.title.empty() ? 0.0 : text_height(chart.title_scale) + 20.0;
  const double xtitle_h = chart.x.title.empty() ? 0.0 : text_height(ts) + 16.0;
  const double ytitle_w = chart.y.title.empty() ? 0.0 : text_height(ts) + 16.0;
  const double tick_h = text_height(ts);

  // Tick density depends on the plot size, which depends on the label widths: guess, then fix.
  std::vector<Tick> xticks = make_ticks(xm, (W - 250.0) / 110.0);
  std::vector<Tick> yticks = make_ticks(ym, (H - 180.0) / 60.0);
  double ylabel_w = 0.0;
  for (const Tick& t : yticks) {
    ylabel_w = std::max(ylabel_w, text_width(t.label, ts));
  }
  double last_xlabel_w = 0.0;
  for (const Tick& t : xticks) {
    if (!t.label.empty()) {
      last_xlabel_w = text_width(t.label, ts);
    }
  }
  const double left = std::round(pad + ytitle_w + ylabel_w + gap + tick_len);
  const double right = std::round(W - std::max(pad + 10.0, 0.5 * last_xlabel_w + pad));
  const double top = std::round(pad + title_h + 0.5 * tick_h);
  const double bottom = std::round(H - pad - xtitle_h - tick_h - gap - tick_len);
  if (right - left < 60.0 || bottom - top < 40.0) {
    throw std::invalid_argument("chart: the image is too small for its labels");
  }
  xm.p0 = left;
  xm.p1 = right;
  ym.p0 = bottom;
  ym.p1 = top;
  const Rect plot{left, top, right, bottom};

  Canvas cv(chart.width, chart.height);
  Ink ink;
  auto snap = [](double p) { return std::floor(p) + 0.5; };

  // ---- grid -----------------------------------------------------------------------------------
  if (chart.grid) {
    for (int pass = 0; pass < 2; ++pass) {
      const bool major = pass == 1;
      for (const Tick& t : xticks) {
        if (t.major == major && xm.in_range(t.value)) {
          const double p = snap(xm.px(t.value));
          cv.rect(p - 0.5, top, p + 0.5, bottom);
        }
      }
      for (const Tick& t : yticks) {
        if (t.major == major && ym.in_range(t.value)) {
          const double p = snap(ym.px(t.value));
          cv.rect(left, p - 0.5, right, p + 0.5);
        }
      }
      cv.paint(major ? kGrid : kMinorGrid);
    }
  }

  cv.set_clip(plot);

  // ---- bands ----------------------------------------------------------------------------------
  for (std::size_t bi = 0; bi < chart.bands.size(); ++bi) {
    const Band& b = chart.bands[bi];
    struct BP {
      double x, lo, hi;
    };
    std::vector<BP> pts;
    for (std::size_t i = 0; i < b.x.size(); ++i) {
      if (xm.valid(b.x[i]) && ym.valid(b.lower[i]) && ym.valid(b.upper[i])) {
        pts.push_back({xm.px(b.x[i]), ym.px(b.lower[i]), ym.px(b.upper[i])});
      }
    }
    std::stable_sort(pts.begin(), pts.end(), [](const BP& a, const BP& c) { return a.x < c.x; });
    for (std::size_t i = 1; i < pts.size(); ++i) {
      const BP& a = pts[i - 1];
      const BP& c = pts[i];
      if (!(c.x > a.x)) {
        continue;
      }
      // Every pixel column whose centre lies in [a.x, c.x) belongs to this piece only.
      const int col0 = static_cast<int>(std::ceil(a.x - 0.5));
      const int col1 = static_cast<int>(std::ceil(c.x - 0.5));
      for (int col = col0; col < col1; ++col) {
        const double f = (col + 0.5 - a.x) / (c.x - a.x);
        const double y0 = a.lo + (c.lo - a.lo) * f;
        const double y1 = a.hi + (c.hi - a.hi) * f;
        cv.rect(col, std::min(y0, y1), col + 1.0, std::max(y0, y1));
        if (col % 4 == 0) {
          ink.segment({col + 0.5, y0}, {col + 0.5, y1}, 0.25);
        }
      }
    }
    cv.paint(band_color(b, bi), b.opacity);
  }

  // ---- reference lines --------------------------------------------------------------------------
  struct PendingLabel {
    std::string text;
    Rect box;
    Color color;
  };
  std::vector<PendingLabel> ref_labels;
  std::vector<Rect> taken;  // label boxes already placed
  for (const ReferenceLine& r : chart.reference_lines) {
    const bool horizontal = r.orientation == ReferenceLine::Orientation::horizontal;
    const AxisMap& m = horizontal ? ym : xm;
    if (!m.valid(r.value) || !m.in_range(r.value)) {
      continue;
    }
    const double p = snap(m.px(r.value));
    const Pt a = horizontal ? Pt{left, p} : Pt{p, bottom};
    const Pt b = horizontal ? Pt{right, p} : Pt{p, top};
    cv.polyline({a, b}, r.line_width, r.dashed);
    cv.paint(r.color);
    ink.segment(a, b);
    if (!r.label.empty()) {
      Rect box;
      if (horizontal) {
        box = text_box(r.label, right - 8.0, p - 5.0, ls, HAlign::right, VAlign::bottom);
        if (box.y0 < top + 3.0) {
          box = text_box(r.label, right - 8.0, p + 5.0, ls, HAlign::right, VAlign::top);
        }
      } else {
        box = text_box(r.label, p + 5.0, top + 8.0, ls, HAlign::left, VAlign::top);
        if (box.x1 > right - 3.0) {
          box = text_box(r.label, p - 5.0, top + 8.0, ls, HAlign::right, VAlign::top);
        }
      }
      ref_labels.push_back({r.label, box, r.color});
      taken.push_back(box.inflated(3.0));
      ink.area(box, 3.0);
    }
  }

  // ---- series: lines, then markers --------------------------------------------------------------
  std::vector<std::vector<Pt>> series_pts(chart.series.size());
  for (std::size_t si = 0; si < chart.series.size(); ++si) {
    const Series& s = chart.series[si];
    std::vector<Pt>& all = series_pts[si];
    all.assign(s.x.size(), Pt{std::numeric_limits<double>::quiet_NaN(), 0.0});
    std::vector<Pt> run;
    auto flush = [&]() {
      if (s.line && run.size() >= 2) {
        cv.polyline(run, s.line_width, s.dashed);
        for (std::size_t i = 1; i < run.size(); ++i) {
          ink.segment(run[i - 1], run[i]);
        }
      }
      run.clear();
    };
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      if (xm.valid(s.x[i]) && ym.valid(s.y[i])) {
        all[i] = {xm.px(s.x[i]), ym.px(s.y[i])};
        run.push_back(all[i]);
      } else {
        flush();
      }
    }
    flush();
    cv.paint(series_color(s, si));
  }
  for (std::size_t si = 0; si < chart.series.size(); ++si) {
    const Series& s = chart.series[si];
    if (s.marker == Marker::none) {
      continue;
    }
    for (const Pt& p : series_pts[si]) {
      if (std::isfinite(p.x)) {
        // A white halo keeps markers readable on top of lines and bands.
        mark(cv, s.marker, p, s.marker_size + 1.5);
      }
    }
    cv.paint(kWhite, 0.9);
    for (const Pt& p : series_pts[si]) {
      if (std::isfinite(p.x)) {
        mark(cv, s.marker, p, s.marker_size);
        ink.point(p, 100.0);
        taken.push_back({p.x - s.marker_size, p.y - s.marker_size, p.x + s.marker_size, p.y + s.marker_size});
      }
    }
    cv.paint(series_color(s, si));
  }

  // ---- point labels -----------------------------------------------------------------------------
  for (std::size_t si = 0; si < chart.series.size(); ++si) {
    const Series& s = chart.series[si];
    for (std::size_t i = 0; i < s.labels.size(); ++i) {
      const Pt p = series_pts[si][i];
      if (s.labels[i].empty() || !std::isfinite(p.x)) {
        continue;
      }
      const double o = (s.marker == Marker::none ? 2.0 : s.marker_size) + 3.0;
      const std::array<std::pair<Pt, std::pair<HAlign, VAlign>>, 6> candidates{{
          {{p.x + o, p.y - o}, {HAlign::left, VAlign::bottom}},
          {{p.x + o, p.y + o}, {HAlign::left, VAlign::top}},
          {{p.x - o, p.y - o}, {HAlign::right, VAlign::bottom}},
          {{p.x - o, p.y + o}, {HAlign::right, VAlign::top}},
          {{p.x + o + 2.0, p.y}, {HAlign::left, VAlign::middle}},
          {{p.x - o - 2.0, p.y}, {HAlign::right, VAlign::middle}},
      }};
      std::optional<Rect> chosen;
      std::optional<Rect> fallback;
      for (const auto& cand : candidates) {
        const Rect box = text_box(s.labels[i], cand.first.x, cand.first.y, ls, cand.second.first,
                                  cand.second.second);
        if (!plot.inflated(-2.0).contains(box)) {
          continue;
        }
        if (!fallback) {
          fallback = box;
        }
        const bool clash = std::any_of(taken.begin(), taken.end(),
                                       [&](const Rect& t) { return t.intersects(box.inflated(1.0)); });
        if (!clash) {
          chosen = box;
          break;
        }
      }
      const Rect box = chosen ? *chosen
                              : (fallback ? *fallback
                                          : text_box(s.labels[i], p.x + o, p.y - o, ls, HAlign::left,
                                                     VAlign::bottom));
      cv.text(s.labels[i], box.x0, box.y0, ls, false);
      taken.push_back(box.inflated(2.0));
      ink.area(box, 3.0);
    }
    cv.paint(kText);
  }

  // Reference-line labels go on top of the data, on a translucent white patch.
  for (const PendingLabel& l : ref_labels) {
    const Rect bg = l.box.inflated(3.0);
    cv.rect(bg.x0, bg.y0, bg.x1, bg.y1);
    cv.paint(kWhite, 0.8);
    cv.text(l.text, l.box.x0, l.box.y0, ls, false);
    cv.paint(l.color);
  }

  cv.reset_clip();

  // ---- frame, ticks and tick labels -------------------------------------------------------------
  cv.rect(left - 1.0, top - 1.0, right + 1.0, top);
  cv.rect(left - 1.0, bottom, right + 1.0, bottom + 1.0);
  cv.rect(left - 1.0, top - 1.0, left, bottom + 1.0);
  cv.rect(right, top - 1.0, right + 1.0, bottom + 1.0);
  for (const Tick& t : xticks) {
    if (xm.in_range(t.value)) {
      const double p = snap(xm.px(t.value));
      cv.rect(p - 0.5, bottom + 1.0, p + 0.5, bottom + 1.0 + (t.major ? tick_len : 0.5 * tick_len));
    }
  }
  for (const Tick& t : yticks) {
    if (ym.in_range(t.value)) {
      const double p = snap(ym.px(t.value));
      cv.rect(left - 1.0 - (t.major ? tick_len : 0.5 * tick_len), p - 0.5, left - 1.0, p + 0.5);
    }
  }
  cv.paint(kFrame);
  for (const Tick& t : xticks) {
    if (!t.label.empty() && xm.in_range(t.value)) {
      cv.text(t.label, text_box(t.label, snap(xm.px(t.value)), bottom + 1.0 + tick_len + gap, ts,
                                HAlign::center, VAlign::top).x0,
              bottom + 1.0 + tick_len + gap, ts, false);
    }
  }
  for (const Tick& t : yticks) {
    if (!t.label.empty() && ym.in_range(t.value)) {
      const Rect box = text_box(t.label, left - 1.0 - tick_len - gap, snap(ym.px(t.value)), ts,
                                HAlign::right, VAlign::middle);
      cv.text(t.label, box.x0, box.y0, ts, false);
    }
  }
  cv.paint(kText);

  // ---- titles -----------------------------------------------------------------------------------
  if (!chart.x.title.empty()) {
    draw_text(cv, chart.x.title, 0.5 * (left + right), H - pad, ts, HAlign::center, VAlign::bottom, kText);
  }
  if (!chart.y.title.empty()) {
    const double w = text_width(chart.y.title, ts);
    cv.text(chart.y.title, pad, 0.5 * (top + bottom) + 0.5 * w, ts, true);
    cv.paint(kText);
  }
  if (!chart.title.empty()) {
    // Shrink a title that would not fit, and keep it inside the image.
    double scale = chart.title_scale;
    const double room = W - 2.0 * pad;
    const double w = text_width(chart.title, scale);
    if (w > room) {
      scale = std::max(1.0, scale * room / w);
    }
    const double half = 0.5 * text_width(chart.title, scale);
    const double cx = std::min(std::max(0.5 * (left + right), pad + half), W - pad - half);
    draw_text(cv, chart.title, cx, pad, scale, HAlign::center, VAlign::top, kText);
  }

  // ---- legend -----------------------------------------------------------------------------------
  std::vector<LegendEntry> entries;
  for (std::size_t bi = 0; bi < chart.bands.size(); ++bi) {
    const Band& b = chart.bands[bi];
    if (!b.name.empty()) {
      LegendEntry e;
      e.text = b.name;
      e.color = band_color(b, bi);
      e.is_band = true;
      e.opacity = b.opacity;
      entries.push_back(e);
    }
  }
  for (std::size_t si = 0; si < chart.series.size(); ++si) {
    const Series& s = chart.series[si];
    if (!s.name.empty()) {
      LegendEntry e;
      e.text = s.name;
      e.color = series_color(s, si);
      e.line = s.line;
      e.dashed = s.dashed;
      e.line_width = s.line_width;
      e.marker = s.marker;
      e.marker_size = s.marker_size;
      entries.push_back(e);
    }
  }
  if (!entries.empty() && chart.legend != LegendPosition::hidden) {
    const double row_h = std::max(text_height(ts), 12.0) + 9.0;
    const double sample_w = 36.0;
    const double inner = 10.0;
    double text_w = 0.0;
    for (const LegendEntry& e : entries) {
      text_w = std::max(text_w, text_width(e.text, ts));
    }
    const double lw = inner + sample_w + 8.0 + text_w + inner;
    const double lh = inner + row_h * static_cast<double>(entries.size()) - 9.0 + inner;
    const double inset = 10.0;
    // Candidate places on a 9x9 grid over the plot: the one hiding the least ink wins; among
    // (nearly) equal ones, corners first, then places along the sides near the corners.
    auto place = [&](double fx, double fy) -> Rect {
      const double x0 = left + inset + fx * (right - left - 2.0 * inset - lw);
      const double y0 = top + inset + fy * (bottom - top - 2.0 * inset - lh);
      return {std::round(x0), std::round(y0), std::round(x0 + lw), std::round(y0 + lh)};
    };
    Rect box;
    switch (chart.legend) {
      case LegendPosition::top_left: box = place(0.0, 0.0); break;
      case LegendPosition::top_right: box = place(1.0, 0.0); break;
      case LegendPosition::bottom_left: box = place(0.0, 1.0); break;
      case LegendPosition::bottom_right: box = place(1.0, 1.0); break;
      default: {
        double best = std::numeric_limits<double>::infinity();
        constexpr int kSteps = 8;
        for (int pass = 0; pass < 2; ++pass) {  // corners, then everything else
          for (int iy = 0; iy <= kSteps; ++iy) {
            for (int ix = 0; ix <= kSteps; ++ix) {
              const bool is_corner = (ix == 0 || ix == kSteps) && (iy == 0 || iy == kSteps);
              if (is_corner != (pass == 0)) {
                continue;
              }
              const double fx = static_cast<double>(ix) / kSteps;
              const double fy = static_cast<double>(iy) / kSteps;
              const Rect r = place(fx, fy);
              // Prefer the sides of the plot, and along them the corners.
              const double side = std::min(std::min(fx, 1.0 - fx), std::min(fy, 1.0 - fy));
              const double corner = std::max(std::min(fx, 1.0 - fx), std::min(fy, 1.0 - fy));
              const double score = ink.count(r.inflated(4.0)) + 8.0 * side + 2.0 * corner;
              if (score < best) {
                best = score;
                box = r;
              }
            }
          }
        }
      }
    }
    cv.rect(box.x0, box.y0, box.x1, box.y1);
    cv.paint(kWhite, 0.92);
    cv.rect(box.x0, box.y0, box.x1, box.y0 + 1.0);
    cv.rect(box.x0, box.y1 - 1.0, box.x1, box.y1);
    cv.rect(box.x0, box.y0, box.x0 + 1.0, box.y1);
    cv.rect(box.x1 - 1.0, box.y0, box.x1, box.y1);
    cv.paint({170, 170, 170});
    for (std::size_t i = 0; i < entries.size(); ++i) {
      const LegendEntry& e = entries[i];
      const double cy = box.y0 + inner + row_h * static_cast<double>(i) + 0.5 * (row_h - 9.0);
      const double sx0 = box.x0 + inner;
      const double sx1 = sx0 + sample_w;
      if (e.is_band) {
        cv.rect(sx0, cy - 7.0, sx1, cy + 7.0);
        cv.paint(e.color, e.opacity);
      }
      if (e.line) {
        cv.polyline({{sx0, cy}, {sx1, cy}}, e.line_width, e.dashed);
        cv.paint(e.color);
      }
      if (e.marker != Marker::none) {
        mark(cv, e.marker, {0.5 * (sx0 + sx1), cy}, e.marker_size);
        cv.paint(e.color);
      }
      draw_text(cv, e.text, sx1 + 8.0, cy, ts, HAlign::left, VAlign::middle, kText);
    }
  }

  return cv.image();
}

std::string encode_png(const Image& image)
{
  if (image.width <= 0 || image.height <= 0 ||
      image.rgb.size() != static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height) * 3) {
    throw std::runtime_error("encode_png: malformed image");
  }
  std::string out;
  auto sink = [](void* context, void* data, int size) {
    static_cast<std::string*>(context)->append(static_cast<const char*>(data), static_cast<std::size_t>(size));
  };
  const int ok = stbi_write_png_to_func(sink, &out, image.width, image.height, 3, image.rgb.data(),
                                        image.width * 3);
  if (ok == 0 || out.empty()) {
    throw std::runtime_error("encode_png: stb_image_write failed");
  }
  return out;
}

void write_png(const Chart& chart, const std::filesystem::path& path)
{
  write_file_atomic(path, encode_png(render(chart)));
}

}  // namespace statsim::tools::chart
