//! Line figures: curves against a common x axis, linear or logarithmic.

use super::canvas::{self, densify, Axis, Render};
use super::colors::{palette, REFERENCE};
use super::glyph::Glyph;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

/// One curve of a [`LineFigure`].
#[derive(Clone, Debug)]
pub struct Series {
    /// Legend entry.
    pub label: String,
    /// Abscissae.
    pub x: Vec<f64>,
    /// Ordinates (same length as `x`; extra values are ignored).
    pub y: Vec<f64>,
    /// How the curve is drawn.
    pub style: SeriesStyle,
}

/// How a [`Series`] is drawn. Colours come from a fixed palette by series index, except
/// [`SeriesStyle::Dashed`], reserved for reference / exact curves and drawn black.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SeriesStyle {
    /// Solid line.
    Line,
    /// Black dashed line: a reference or exact solution.
    Dashed,
    /// Markers only.
    Points,
    /// Solid line with markers at the data points.
    LinePoints,
    /// Black markers: published reference points (squares; a second set triangles, a third
    /// diamonds).
    Reference,
}

/// A figure of curves y(x).
#[derive(Clone, Debug)]
pub struct LineFigure {
    /// Title above the chart.
    pub title: String,
    /// x axis label, with units.
    pub x_label: String,
    /// y axis label, with units.
    pub y_label: String,
    /// Logarithmic x axis (non-positive x values are skipped).
    pub log_x: bool,
    /// Logarithmic y axis (non-positive y values are skipped).
    pub log_y: bool,
    /// The curves, drawn in order.
    pub series: Vec<Series>,
    /// The data ranges to show, `[x0, x1, y0, y1]` (the panels of one figure share them);
    /// `None` fits the curves.
    pub extent: Option<[f64; 4]>,
}

/// Writes `fig` to `<stem>.png` and `<stem>.svg` (900 x 600 pixels): labelled axes,
/// ranges fitted to the data with margins, a legend in the emptiest corner. Points that
/// cannot be drawn (non-finite, or non-positive on a log axis) break the curve.
pub fn line_figure(fig: &LineFigure, stem: &Path) -> Result<(), String> {
    canvas::save(fig, stem)
}

impl LineFigure {
    /// Drawable runs of each series: maximal stretches of points the axes accept.
    fn runs(&self, x: &Axis, y: &Axis) -> Vec<Vec<Vec<(f64, f64)>>> {
        self.series
            .iter()
            .map(|s| {
                let mut runs = vec![Vec::new()];
                for (&a, &b) in s.x.iter().zip(&s.y) {
                    if x.accepts(a) && y.accepts(b) {
                        runs.last_mut().unwrap().push((a, b));
                    } else if !runs.last().unwrap().is_empty() {
                        runs.push(Vec::new());
                    }
                }
                runs.retain(|r| !r.is_empty());
                runs
            })
            .collect()
    }
}

impl Render for LineFigure {
    fn title(&self) -> &str {
        &self.title
    }

    fn size(&self) -> (u32, u32) {
        (900, 600)
    }

    fn render<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> Result<(), String> {
        let (x, y) = match self.extent {
            Some([x0, x1, y0, y1]) => (Axis::fit([x0, x1], self.log_x), Axis::fit([y0, y1], self.log_y)),
            None => {
                let xs = self.series.iter().flat_map(|s| s.x.iter().copied());
                let ys = self.series.iter().flat_map(|s| s.y.iter().copied());
                (Axis::fit(xs, self.log_x), Axis::fit(ys, self.log_y))
            }
        };
        let runs = self.runs(&x, &y);
        let mut chart = canvas::chart(area, x.clone(), y.clone())?;
        canvas::mesh(&mut chart, &self.x_label, &self.y_label, true)?;

        let mut colour_index = 0;
        // Solid curves drawn widest first, each later one narrower (down to 2 px): a curve
        // that lies on an earlier one shows inside it rather than hiding it.
        let solid = self
            .series
            .iter()
            .filter(|s| !matches!(s.style, SeriesStyle::Dashed | SeriesStyle::Reference))
            .count();
        let width = |i: usize| 2 + (2 * (solid.saturating_sub(1 + i))).min(6) as u32;
        // Each set of published points its own marker: squares, then triangles, diamonds.
        let mut reference_index = 0;
        for (s, runs) in self.series.iter().zip(&runs) {
            let dashed = s.style == SeriesStyle::Dashed;
            let reference = s.style == SeriesStyle::Reference;
            let color = if dashed || reference {
                REFERENCE
            } else {
                colour_index += 1;
                palette(colour_index - 1)
            };
            let line = color.stroke_width(if dashed || reference { 2 } else { width(colour_index - 1) });
            let with_line = !matches!(s.style, SeriesStyle::Points | SeriesStyle::Reference);
            let with_marks =
                matches!(s.style, SeriesStyle::Points | SeriesStyle::LinePoints | SeriesStyle::Reference);
            let mark = if reference {
                reference_index += 1;
                [2, 1, 3, 4][(reference_index - 1) % 4]
            } else {
                0
            };
            for (k, run) in runs.iter().enumerate() {
                let anno = if dashed {
                    chart.draw_series(DashedLineSeries::new(run.iter().copied(), 10, 6, line))
                } else if with_line {
                    chart.draw_series(LineSeries::new(run.iter().copied(), line))
                } else {
                    chart.draw_series(run.iter().map(|&p| Glyph::marker(mark, p, 4, color.filled())))
                }
                .map_err(|e| e.to_string())?;
                if k == 0 {
                    let sample_line = with_line.then_some((line, dashed));
                    let sample_mark = with_marks.then_some((mark, 4, color.filled()));
                    anno.label(s.label.clone()).legend(move |p| Glyph::sample(p, sample_line, sample_mark));
                }
                if with_marks && with_line {
                    chart
                        .draw_series(run.iter().map(|&p| Glyph::marker(mark, p, 4, color.filled())))
                        .map_err(|e| e.to_string())?;
                }
            }
        }
        let pts: Vec<(f64, f64)> = runs.iter().flatten().flat_map(|r| densify(&x, &y, r)).collect();
        let labelled = runs.iter().filter(|r| !r.is_empty()).count();
        if labelled > 0 {
            canvas::legend(&mut chart, labelled, &pts)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::automation::report::testutil::check_figure;

    fn convergence(log: bool) -> LineFigure {
        let h: Vec<f64> = (0..6).map(|i| 0.1 / 2f64.powi(i)).collect();
        LineFigure {
            title: "L2 error vs h <TVF>".into(),
            x_label: "h [m]".into(),
            y_label: "L2 velocity error [m/s]".into(),
            log_x: log,
            log_y: log,
            extent: None,
            series: vec![
                Series {
                    label: "EDAC".into(),
                    x: h.clone(),
                    y: h.iter().map(|h| 2.0 * h * h).collect(),
                    style: SeriesStyle::LinePoints,
                },
                Series {
                    label: "TVF (one zero error)".into(),
                    x: h.clone(),
                    y: vec![0.05, 0.02, 0.0, 1e-3, 3e-4, 1e-4],
                    style: SeriesStyle::Points,
                },
                Series {
                    label: "CTVF".into(),
                    x: h.clone(),
                    y: h.iter().map(|h| 0.5 * h).collect(),
                    style: SeriesStyle::Line,
                },
                Series {
                    label: "second order".into(),
                    x: h.clone(),
                    y: h.iter().map(|h| h * h).collect(),
                    style: SeriesStyle::Dashed,
                },
            ],
        }
    }

    #[test]
    fn log_log_figure_with_zero_error() {
        let dir = tempfile::tempdir().unwrap();
        let stem = dir.path().join("sub/dir/convergence");
        line_figure(&convergence(true), &stem).unwrap();
        let svg = check_figure(
            &stem,
            (900, 600),
            &["L2 error vs h &lt;TVF&gt;", "EDAC", "CTVF", "second order", "h [m]"],
        );
        assert!(svg.contains("1e-3") || svg.contains("1e-4"), "log tick labels");
    }

    #[test]
    fn linear_figure_with_nan_and_empty_series() {
        let dir = tempfile::tempdir().unwrap();
        let stem = dir.path().join("decay");
        let t: Vec<f64> = (0..50).map(|i| i as f64 * 0.1).collect();
        let mut fig = LineFigure {
            title: "Kinetic energy decay".into(),
            x_label: "t [s]".into(),
            y_label: "E_k / E_k(0)".into(),
            log_x: false,
            log_y: false,
            extent: None,
            series: vec![
                Series {
                    label: "exact".into(),
                    x: t.clone(),
                    y: t.iter().map(|t| (-0.8 * t).exp()).collect(),
                    style: SeriesStyle::Dashed,
                },
                Series {
                    label: "simulated".into(),
                    x: t.clone(),
                    y: t.iter()
                        .map(|t| if *t > 3.0 && *t < 3.3 { f64::NAN } else { (-0.82 * t).exp() })
                        .collect(),
                    style: SeriesStyle::Line,
                },
                Series { label: "nothing".into(), x: vec![], y: vec![], style: SeriesStyle::Line },
            ],
        };
        line_figure(&fig, &stem).unwrap();
        check_figure(&stem, (900, 600), &["Kinetic energy decay", "exact", "simulated"]);
        fig.series.clear();
        line_figure(&fig, &stem).unwrap();
    }
}
