#include "viewer/plots/chart_png.hpp"

#include <vtkAxis.h>
#include <vtkChartLegend.h>
#include <vtkChartMatrix.h>
#include <vtkChartXY.h>
#include <vtkContextScene.h>
#include <vtkContextView.h>
#include <vtkDoubleArray.h>
#include <vtkNew.h>
#include <vtkPlot.h>
#include <vtkPlotPoints.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkStringArray.h>
#include <vtkTable.h>
#include <vtkTextProperty.h>
#include <vtkVector.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "scanner/common/error.hpp"
#include "viewer/plots/legend_place.hpp"
#include "viewer/render/display.hpp"
#include "viewer/render/vtk_scene.hpp"

namespace uwscan::viewer {
namespace {

constexpr float kLineWidthPx = 2.0f;
constexpr float kMarkerSizePx = 11.0f;

// The series' points a chart can draw: positive ones on log axes.
vtkSmartPointer<vtkTable> SeriesTable(const PlotSeries& s, bool log_x, bool log_y) {
  vtkNew<vtkDoubleArray> x, y;
  x->SetName("x");
  y->SetName(s.label.c_str());
  for (std::size_t i = 0; i < std::min(s.x.size(), s.y.size()); ++i) {
    if ((log_x && !(s.x[i] > 0.0)) || (log_y && !(s.y[i] > 0.0))) continue;
    if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
    x->InsertNextValue(s.x[i]);
    y->InsertNextValue(s.y[i]);
  }
  auto table = vtkSmartPointer<vtkTable>::New();
  table->AddColumn(x);
  table->AddColumn(y);
  return table;
}

// lo and hi in data units, on linear and log axes alike.
void FixRange(vtkAxis& axis, double lo, double hi) {
  axis.SetBehavior(vtkAxis::FIXED);
  axis.SetUnscaledRange(lo, hi);
}

// One x value for every point (a single pipeline's point) leaves VTK an empty range, drawn
// without ticks: widen it around the value.
void WidenIfDegenerate(vtkAxis& axis, const std::vector<PlotSeries>& series, bool log) {
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const PlotSeries& s : series) {
    for (const double x : s.x) {
      if (std::isfinite(x) && (!log || x > 0.0)) lo = std::min(lo, x), hi = std::max(hi, x);
    }
  }
  if (!(lo <= hi) || hi - lo > 1e-9 * std::max(1.0, std::abs(hi))) return;
  if (log) return FixRange(axis, lo / 2.0, hi * 2.0);
  const double half = lo == 0.0 ? 1.0 : 0.5 * std::abs(lo);
  FixRange(axis, lo - half, hi + half);
}

void FillChart(vtkChartXY& chart, const PlotSpec& spec) {
  chart.SetTitle(spec.title);
  chart.GetTitleProperties()->SetFontSize(15);
  chart.GetAxis(vtkAxis::BOTTOM)->SetTitle(spec.x_label);
  chart.GetAxis(vtkAxis::LEFT)->SetTitle(spec.y_label);
  chart.GetAxis(vtkAxis::BOTTOM)->SetLogScale(spec.log_x);
  chart.GetAxis(vtkAxis::LEFT)->SetLogScale(spec.log_y);
  int drawn = 0;
  for (const PlotSeries& s : spec.series) {
    vtkSmartPointer<vtkTable> table = SeriesTable(s, spec.log_x, spec.log_y);
    if (table->GetNumberOfRows() == 0) continue;
    // A line of one point is drawn as that point (VTK refuses to paint it and says so).
    const bool line = s.style == SeriesStyle::kLine && table->GetNumberOfRows() >= 2;
    const int type = s.style == SeriesStyle::kBars ? vtkChart::BAR
                     : line                        ? vtkChart::LINE
                                                   : vtkChart::POINTS;
    vtkPlot* plot = chart.AddPlot(type);
    plot->SetInputData(table, 0, 1);
    plot->SetColor(s.colour.r, s.colour.g, s.colour.b, 255);
    plot->SetWidth(kLineWidthPx);
    plot->SetLabel(s.label);
    if (auto* points = vtkPlotPoints::SafeDownCast(plot)) {
      points->SetMarkerStyle(line ? vtkPlotPoints::NONE : vtkPlotPoints::CIRCLE);
      points->SetMarkerSize(kMarkerSizePx);
    }
    ++drawn;
  }
  if (drawn == 0) throw Error("plot '" + spec.title + "': no point to draw");
  if (spec.y_range)
    FixRange(*chart.GetAxis(vtkAxis::LEFT), spec.y_range->first, spec.y_range->second);
  WidenIfDegenerate(*chart.GetAxis(vtkAxis::BOTTOM), spec.series, spec.log_x);
  if (!spec.x_tick_labels.empty()) {
    vtkNew<vtkDoubleArray> positions;
    vtkNew<vtkStringArray> labels;
    for (std::size_t i = 0; i < spec.x_tick_labels.size(); ++i) {
      positions->InsertNextValue(static_cast<double>(i + 1));
      labels->InsertNextValue(spec.x_tick_labels[i]);
    }
    chart.GetAxis(vtkAxis::BOTTOM)->SetCustomTickPositions(positions, labels);
  }
  chart.SetShowLegend(true);
  chart.GetLegend()->SetLabelSize(12);
  // Where it hides least of the data (the fast-and-coarse and slow-and-exact corners of a
  // trade-off plot hold the points; a rate plot's bars fill its bottom).
  const LegendPlace place = PlaceLegend(spec);
  const bool left = place == LegendPlace::kTopLeft || place == LegendPlace::kBottomLeft;
  const bool top = place != LegendPlace::kBottomLeft && place != LegendPlace::kBottomRight;
  chart.GetLegend()->SetHorizontalAlignment(place == LegendPlace::kTopCentre
                                                ? vtkChartLegend::CENTER
                                            : left ? vtkChartLegend::LEFT
                                                   : vtkChartLegend::RIGHT);
  chart.GetLegend()->SetVerticalAlignment(top ? vtkChartLegend::TOP : vtkChartLegend::BOTTOM);
}

}  // namespace

void SavePlotsPng(const std::vector<PlotSpec>& plots, const std::filesystem::path& png_path,
                  int width_px, int height_px) {
  if (plots.empty()) throw Error(png_path.string() + ": no plot to draw");
  if (width_px < 64 || height_px < 64 || width_px > 8192 || height_px > 8192) {
    throw Error(png_path.string() + ": picture size must be in [64, 8192] pixels");
  }
  RequireDisplay();
  vtkNew<vtkContextView> view;
  view->GetRenderer()->SetBackground(1.0, 1.0, 1.0);
  vtkRenderWindow* window = view->GetRenderWindow();
  window->SetOffScreenRendering(1);
  window->SetMultiSamples(0);
  window->SetSize(width_px, height_px);
  vtkNew<vtkChartMatrix> matrix;
  matrix->SetSize(vtkVector2i(static_cast<int>(plots.size()), 1));
  // Room at the left for the y axis's title beside its tick labels (VTK's default cut it off),
  // and as much between charts side by side: the right one's y labels met the left one's x labels.
  matrix->SetBorders(90, 50, 20, 30);
  matrix->SetGutterX(90.0f);
  for (std::size_t i = 0; i < plots.size(); ++i) {
    vtkNew<vtkChartXY> chart;
    matrix->SetChart(vtkVector2i(static_cast<int>(i), 0), chart);
    FillChart(*chart, plots[i]);
  }
  view->GetScene()->AddItem(matrix);
  window->Render();
  internal::WriteWindowPng(*window, png_path);
}

}  // namespace uwscan::viewer
