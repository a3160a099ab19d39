// PNG charts for the host tools: line and scatter series, shaded bands, reference lines,
// linear or log10 axes, ticks with labels, titles and a legend.
//
// Usage:
//   chart::Chart c;
//   c.title = "Time per step";
//   c.x = {"bodies", chart::Scale::log10};
//   c.y = {"seconds", chart::Scale::log10};
//   chart::Series s;
//   s.name = "statsim";  s.x = {...};  s.y = {...};  s.marker = chart::Marker::circle;
//   c.series.push_back(s);
//   chart::write_png(c, "out/time.png");
//
// Text is drawn with stb_easy_font (ASCII only: other bytes print as '?'); PNG encoding is done
// by stb_image_write. Shapes are anti-aliased.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace statsim::tools::chart {

/// An 8-bit sRGB colour.
struct Color {
  std::uint8_t r = 0;
  std::uint8_t g = 0;
  std::uint8_t b = 0;
};

/// The i-th colour of the default palette (Okabe-Ito, colour-blind friendly; cycles after 8).
Color palette(std::size_t i);

/// How an axis maps values to positions. On a log10 axis, values <= 0 are not drawn.
enum class Scale { linear, log10 };

/// Point marker shapes.
enum class Marker { none, circle, square, diamond, triangle };

/// Where the legend goes, inside the plot area. `automatic` tries a 9x9 grid of places and
/// picks the one hiding the least data (markers and labels count most, bands least), preferring
/// corners, then places near the sides; `hidden` draws none.
enum class LegendPosition { automatic, top_right, top_left, bottom_right, bottom_left, hidden };

/// One data series, drawn as a polyline through its points and/or as markers.
/// A point whose x or y is not finite (or not positive on a log axis) is skipped and breaks the
/// polyline there.
struct Series {
  std::string name;                 ///< Legend text; an empty name keeps it out of the legend.
  std::vector<double> x;            ///< Abscissae (same length as y).
  std::vector<double> y;            ///< Ordinates.
  std::optional<Color> color;       ///< Default: palette(index of the series in Chart::series).
  bool line = true;                 ///< Connect the points in the given order.
  bool dashed = false;              ///< Dashed instead of solid line.
  double line_width = 2.0;          ///< Line width in pixels.
  Marker marker = Marker::none;     ///< Marker drawn at every point.
  double marker_size = 4.0;         ///< Marker radius in pixels.
  std::vector<std::string> labels;  ///< Optional text next to each point (empty, or one per
                                    ///< point; empty strings are skipped). Placed so that
                                    ///< labels avoid each other where possible.
};

/// A shaded region between two curves lower(x) and upper(x), e.g. a min/max range.
/// Points are sorted by x; non-finite points are skipped.
struct Band {
  std::string name;             ///< Legend text; empty keeps it out of the legend.
  std::vector<double> x;        ///< Abscissae.
  std::vector<double> lower;    ///< One bound per x.
  std::vector<double> upper;    ///< The other bound per x.
  std::optional<Color> color;   ///< Default: palette(index of the band in Chart::bands).
  double opacity = 0.22;        ///< Fill opacity in [0, 1].
};

/// A horizontal (y = value) or vertical (x = value) line across the whole plot, with an
/// optional label drawn next to it inside the plot.
struct ReferenceLine {
  enum class Orientation { horizontal, vertical };
  Orientation orientation = Orientation::horizontal;
  double value = 0.0;
  std::string label;
  Color color{110, 110, 110};
  bool dashed = true;
  double line_width = 1.5;
};

/// One axis: title, scale and optional fixed limits (default: fitted to the data with a small
/// margin; on a log axis, limits must be positive).
struct Axis {
  std::string title;
  Scale scale = Scale::linear;
  std::optional<double> min;
  std::optional<double> max;
};

/// A complete chart description. Everything is drawn in this order: grid, bands, reference
/// lines, series lines, markers, point labels, frame and ticks, titles, legend.
struct Chart {
  std::string title;
  Axis x;
  Axis y;
  std::vector<Band> bands;
  std::vector<Series> series;
  std::vector<ReferenceLine> reference_lines;
  LegendPosition legend = LegendPosition::automatic;
  bool grid = true;         ///< Light grid lines at the major ticks (and minor ones on log axes).
  int width = 1100;         ///< Image size in pixels.
  int height = 700;
  double text_scale = 2.0;  ///< Size of tick labels, axis titles and legend text (stb_easy_font
                            ///< pixel units; its capitals are 7 units tall).
  double title_scale = 3.0; ///< Size of the chart title (reduced if the title would not fit).
  double label_scale = 1.5; ///< Size of point and reference-line labels.
};

/// An RGB image, 3 bytes per pixel, rows top to bottom.
struct Image {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> rgb;
};

/// Draws the chart. Throws std::invalid_argument for inconsistent input (mismatched vector
/// lengths, a non-positive fixed limit on a log axis, min >= max, an image under 200x150).
Image render(const Chart& chart);

/// Encodes an image as PNG bytes. Throws std::runtime_error if encoding fails.
std::string encode_png(const Image& image);

/// Renders the chart and writes it as a PNG file, atomically (temporary file, then rename), so
/// a failed run leaves no partial file. Throws std::invalid_argument (see render()) or
/// std::runtime_error (I/O).
void write_png(const Chart& chart, const std::filesystem::path& path);

}  // namespace statsim::tools::chart
