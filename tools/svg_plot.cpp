// SVG plots of the demo's report (tools/svg_plot.h).
#include "tools/svg_plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace ps11 {
namespace {

std::string num(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.1f", v);
    return buf;
}

std::string tick(double v) {
    char buf[32];
    const double a = std::fabs(v);
    std::snprintf(buf, sizeof buf, a >= 100 || v == 0 ? "%.0f" : a >= 10 ? "%.1f" : a >= 1 ? "%.2f" : "%.3g", v);
    return buf;
}

// The frame of a plot: the data range mapped into the drawing area, axes with ticks, labels.
struct Frame {
    PlotAxes axes;
    double x0 = 0, x1 = 1, y0 = 0, y1 = 1;
    static constexpr int kLeft = 58, kTop = 28, kBottom = 44;
    int right = 16;     // room right of the data (a scatter's labels need more)
    bool padX = false;  // widen the x range (scatter points off the frame's edge)

    double tx(double x) const {
        double a = axes.logX ? std::log10(std::max(x, 1e-9)) : x, lo = axes.logX ? std::log10(x0) : x0,
               hi = axes.logX ? std::log10(x1) : x1;
        return kLeft + (a - lo) / (hi - lo) * (axes.width - kLeft - right);
    }
    double ty(double y) const { return axes.height - kBottom - (y - y0) / (y1 - y0) * (axes.height - kTop - kBottom); }

    void fit(const std::vector<double>& xs, const std::vector<double>& ys) {
        if (xs.empty()) return;
        x0 = *std::min_element(xs.begin(), xs.end()), x1 = *std::max_element(xs.begin(), xs.end());
        y0 = std::min(0.0, *std::min_element(ys.begin(), ys.end())), y1 = *std::max_element(ys.begin(), ys.end());
        if (axes.logX) {
            x0 = std::max(x0 / 1.3, 1e-6), x1 = x1 * 1.3;
        } else if (padX || x1 == x0) {
            const double pad = (x1 - x0) * 0.08 + (x1 == x0 ? std::max(1.0, std::fabs(x0) * 0.1) : 0);
            x0 -= pad, x1 += pad;
        }
        y1 += (y1 - y0) * 0.12 + (y1 == y0 ? 1 : 0);
    }

    std::string open() const {
        std::string s = "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" + std::to_string(axes.width) + "\" height=\"" +
                        std::to_string(axes.height) + "\" viewBox=\"0 0 " + std::to_string(axes.width) + " " +
                        std::to_string(axes.height) + "\" font-family=\"sans-serif\" font-size=\"11\">\n";
        s += "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
        s += "<text x=\"" + std::to_string(axes.width / 2) + "\" y=\"16\" text-anchor=\"middle\" font-size=\"13\">" +
             htmlEscape(axes.title) + "</text>\n";
        const double left = kLeft, rightEdge = axes.width - right, top = kTop, bottom = axes.height - kBottom;
        s += "<path d=\"M" + num(left) + " " + num(top) + " V" + num(bottom) + " H" + num(rightEdge) +
             "\" stroke=\"#444\" fill=\"none\"/>\n";
        for (int i = 0; i <= 4; ++i) {
            const double fy = y0 + (y1 - y0) * i / 4, py = ty(fy);
            s += "<line x1=\"" + num(left) + "\" x2=\"" + num(rightEdge) + "\" y1=\"" + num(py) + "\" y2=\"" + num(py) +
                 "\" stroke=\"#eee\"/><text x=\"" + num(left - 4) + "\" y=\"" + num(py + 4) +
                 "\" text-anchor=\"end\">" + tick(fy) + "</text>\n";
            const double fx = axes.logX ? std::pow(10.0, std::log10(x0) + (std::log10(x1) - std::log10(x0)) * i / 4)
                                        : x0 + (x1 - x0) * i / 4;
            s += "<text x=\"" + num(tx(fx)) + "\" y=\"" + num(bottom + 14) + "\" text-anchor=\"middle\">" + tick(fx) +
                 "</text>\n";
        }
        s += "<text x=\"" + num((left + rightEdge) / 2) + "\" y=\"" + num(bottom + 32) + "\" text-anchor=\"middle\">" +
             htmlEscape(axes.xLabel) + "</text>\n";
        s += "<text transform=\"translate(14 " + num((top + bottom) / 2) + ") rotate(-90)\" text-anchor=\"middle\">" +
             htmlEscape(axes.yLabel) + "</text>\n";
        return s;
    }
};

}  // namespace

std::string htmlEscape(const std::string& text) {
    std::string out;
    out.reserve(text.size());
    for (char c : text) {
        switch (c) {
            case '&': out += "&amp;"; break;
            case '<': out += "&lt;"; break;
            case '>': out += "&gt;"; break;
            case '"': out += "&quot;"; break;
            case '\'': out += "&#39;"; break;
            default: out += c;
        }
    }
    return out;
}

std::string svgScatter(const PlotAxes& axes, const std::vector<PlotPoint>& points) {
    Frame f{axes};
    f.right = 80, f.padX = true;
    std::vector<double> xs, ys;
    for (const PlotPoint& p : points)
        if (std::isfinite(p.x) && std::isfinite(p.y)) xs.push_back(p.x), ys.push_back(p.y);
    f.fit(xs, ys);
    std::string s = f.open();
    std::vector<const PlotPoint*> front;
    for (const PlotPoint& p : points)
        if (p.marked && std::isfinite(p.x) && std::isfinite(p.y)) front.push_back(&p);
    std::sort(front.begin(), front.end(), [](const PlotPoint* a, const PlotPoint* b) { return a->x < b->x; });
    if (front.size() > 1) {
        std::string d;
        for (const PlotPoint* p : front) d += (d.empty() ? "M" : " L") + num(f.tx(p->x)) + " " + num(f.ty(p->y));
        s += "<path d=\"" + d + "\" stroke=\"#c0392b\" stroke-width=\"1.5\" fill=\"none\"/>\n";
    }
    for (const PlotPoint& p : points) {
        if (!std::isfinite(p.x) || !std::isfinite(p.y)) continue;
        const std::string cx = num(f.tx(p.x)), cy = num(f.ty(p.y));
        s += "<circle cx=\"" + cx + "\" cy=\"" + cy + "\" r=\"4\" fill=\"" + (p.marked ? "#c0392b" : "white") +
             "\" stroke=\"#c0392b\"><title>" + htmlEscape(p.label) + "</title></circle>\n";
        s += "<text x=\"" + num(f.tx(p.x) + 6) + "\" y=\"" + num(f.ty(p.y) - 5) + "\" font-size=\"9\" fill=\"#555\">" +
             htmlEscape(p.label) + "</text>\n";
    }
    return s + "</svg>\n";
}

std::string svgLines(const PlotAxes& axes, const std::vector<PlotSeries>& series) {
    Frame f{axes};
    std::vector<double> xs, ys;
    for (const PlotSeries& l : series)
        for (size_t i = 0; i < l.x.size() && i < l.y.size(); ++i)
            if (std::isfinite(l.x[i]) && std::isfinite(l.y[i])) xs.push_back(l.x[i]), ys.push_back(l.y[i]);
    f.fit(xs, ys);
    std::string s = f.open();
    for (size_t k = 0; k < series.size(); ++k) {
        const PlotSeries& l = series[k];
        std::string d;
        for (size_t i = 0; i < l.x.size() && i < l.y.size(); ++i)
            if (std::isfinite(l.x[i]) && std::isfinite(l.y[i]))
                d += (d.empty() ? "M" : " L") + num(f.tx(l.x[i])) + " " + num(f.ty(l.y[i]));
        s += "<path d=\"" + d + "\" stroke=\"" + l.color + "\" stroke-width=\"1.6\" fill=\"none\"" +
             (l.dashed ? " stroke-dasharray=\"5 3\"" : "") + "/>\n";
        const double ly = Frame::kTop + 8 + 14.0 * double(k), lx = axes.width - f.right - 170;
        s += "<line x1=\"" + num(lx) + "\" x2=\"" + num(lx + 18) + "\" y1=\"" + num(ly) + "\" y2=\"" + num(ly) +
             "\" stroke=\"" + l.color + "\" stroke-width=\"2\"" + (l.dashed ? " stroke-dasharray=\"5 3\"" : "") +
             "/><text x=\"" + num(lx + 22) + "\" y=\"" + num(ly + 4) + "\">" + htmlEscape(l.name) + "</text>\n";
    }
    return s + "</svg>\n";
}

std::string svgGrid(const std::string& title, int columns, int rows, const std::vector<double>& values,
                    const std::string& color, int cell) {
    const int w = columns * cell + 2, h = rows * cell + 22;
    std::string s = "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" + std::to_string(w) + "\" height=\"" +
                    std::to_string(h) + "\" font-family=\"sans-serif\" font-size=\"11\">\n<text x=\"1\" y=\"13\">" +
                    htmlEscape(title) + "</text>\n";
    for (int r = 0; r < rows; ++r)
        for (int c = 0; c < columns; ++c) {
            const size_t i = size_t(r * columns + c);
            const double v = i < values.size() ? std::clamp(values[i], 0.0, 1.0) : 0.0;
            s += "<rect x=\"" + std::to_string(1 + c * cell) + "\" y=\"" + std::to_string(20 + r * cell) +
                 "\" width=\"" + std::to_string(cell - 1) + "\" height=\"" + std::to_string(cell - 1) + "\" fill=\"" +
                 color + "\" fill-opacity=\"" + num(std::max(v, 0.0)) + "\" stroke=\"#ccc\"/>\n";
        }
    return s + "</svg>\n";
}

}  // namespace ps11
