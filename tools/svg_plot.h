// Small self-contained SVG plots for the demo's report (tools/demo_report.h): a scatter of
// points with a highlighted front, and lines over a shared x axis. Text only, no scripts, so
// the page works opened from disk.
#pragma once

#include <string>
#include <vector>

namespace ps11 {

struct PlotPoint {
    double x = 0, y = 0;
    std::string label;   // shown beside the point (and as its tooltip)
    bool marked = false;  // drawn filled and joined by the front line
};

struct PlotSeries {
    std::string name;
    std::string color;  // CSS colour
    std::vector<double> x, y;
    bool dashed = false;
};

struct PlotAxes {
    std::string title, xLabel, yLabel;
    int width = 520, height = 300;
    bool logX = false;
};

// Points (x, y); the marked ones in order of x joined by a line (a Pareto front).
std::string svgScatter(const PlotAxes& axes, const std::vector<PlotPoint>& points);
// Lines over x, with a legend.
std::string svgLines(const PlotAxes& axes, const std::vector<PlotSeries>& series);
// A grid of cells (row-major, values in [0, 1] shaded white to `color`), each cell `cell` px.
std::string svgGrid(const std::string& title, int columns, int rows, const std::vector<double>& values,
                    const std::string& color, int cell = 18);

// Escapes text for HTML and SVG (& < > " ').
std::string htmlEscape(const std::string& text);

}  // namespace ps11
