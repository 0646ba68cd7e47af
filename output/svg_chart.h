// A small x-y chart as a standalone SVG 1.1 document, for the numerical
// studies (work-precision on log-log axes, stability maps with the theory's
// line drawn over the simulated points). The standard library only.
//
// Each series is drawn as a polyline, markers, or both, in its own colour,
// and named in a legend. Axes may be linear or logarithmic (base 10, with a
// tick at each decade); a log axis drops points <= 0 and says how many it
// dropped in a <desc> element. Non-finite points are dropped likewise.
//
// Elements a reader (or a test) can find: the chart is <svg class="chart">,
// each series a <g class="series" id="series-N"> (N from 0, in order) holding
// a <polyline> and/or <circle> markers whose coordinates are pixels, and
// each axis label a <text class="axis-label">.
//
// Several charts can share one document as panels of a grid (ChartGrid):
// each panel is a nested <svg class="chart" id="panel-K"> whose element ids
// start with "panel-K-" (so "panel-K-series-N").
#ifndef VMHAPTICS_OUTPUT_SVG_CHART_H_
#define VMHAPTICS_OUTPUT_SVG_CHART_H_

#include <cmath>
#include <string>
#include <vector>

namespace vmh::output {

struct ChartSeries {
  std::string label;        // legend text
  std::vector<double> x;    // same length as y
  std::vector<double> y;
  std::string color;        // CSS colour; empty: the next of a fixed palette
  bool line = true;         // a polyline through the points, in order
  bool markers = true;      // a dot at each point
  bool dashed = false;      // dashed polyline (e.g. a theoretical bound)
};

// How a series is drawn beyond its colour, for series that may coincide
// (e.g. two integrators of the same order): a stroke-dasharray of its own
// (empty: "6 4" when dashed, else solid), the polyline's width, the markers'
// radius, and hollow markers (a ring in the series' colour, no fill) so that
// a series drawn under this one shows through. The legend's sample shows the
// same. (Apart from ChartSeries so that its brace-initialisations stay whole.)
struct SeriesLook {
  std::string dash;
  double line_width = 1.5;
  double marker_radius = 3.0;
  bool hollow = false;
};

struct ChartAxis {
  std::string label;        // with its unit, e.g. "wall time (s)"
  bool log = false;         // base-10 logarithmic
  double min = std::nan("");  // NaN: from the data (padded, or whole decades)
  double max = std::nan("");
};

// A shaded interval of x over the plot area's whole height, drawn under the
// grid and the series (e.g. the time window a study judges).
struct ChartBand {
  double x0 = 0.0;  // data units, either order
  double x1 = 0.0;
  std::string color = "#e0e0e0";
};

struct Chart {
  std::string title;
  // a second line under the title, smaller and in its own colour (e.g. an
  // outcome); empty: none, and the title's margin stays as it was
  std::string subtitle;
  std::string subtitle_color = "#555555";
  ChartAxis x;
  ChartAxis y;
  std::vector<ChartSeries> series;
  // looks[i] for series i; a series past its end: the defaults
  std::vector<SeriesLook> looks;
  std::vector<ChartBand> bands;
  int width_px = 640;
  int height_px = 420;
};

// The chart as an SVG document. Throws std::invalid_argument if a series has
// x and y of different lengths.
std::string chart_svg(const Chart& chart);

// Charts side by side, `columns` to a row in order, each in a cell as large
// as the largest panel, under a title and lines of notes.
struct ChartGrid {
  std::string title;
  std::vector<std::string> notes;
  int columns = 1;
  std::vector<Chart> panels;
};

// The grid as one SVG document (<svg class="chart-grid">). Throws
// std::invalid_argument as chart_svg does, naming the panel.
std::string chart_grid_svg(const ChartGrid& grid);

}  // namespace vmh::output

#endif  // VMHAPTICS_OUTPUT_SVG_CHART_H_
