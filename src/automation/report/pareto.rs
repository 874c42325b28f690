//! Cost-accuracy figures with their Pareto front.

use super::canvas::{self, Axis, Render};
use super::colors::{palette, REFERENCE};
use super::glyph::Glyph;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::path::Path;

/// Points of several groups (e.g. schemes) in a plane where both coordinates are costs
/// (e.g. run time and error).
#[derive(Clone, Debug)]
pub struct ParetoFigure {
    /// Title above the chart.
    pub title: String,
    /// x axis label, with units.
    pub x_label: String,
    /// y axis label, with units.
    pub y_label: String,
    /// `(group, point label, x, y)`: the group picks colour and marker and names the
    /// legend entry; the point label is written beside the point.
    pub points: Vec<(String, String, f64, f64)>,
    /// Logarithmic x axis (non-positive x values are skipped).
    pub log_x: bool,
    /// Logarithmic y axis (non-positive y values are skipped).
    pub log_y: bool,
}

/// Indices of the non-dominated points when minimising both coordinates, sorted by x
/// (then y). A point is dominated if another is no worse in both coordinates and better
/// The share of the horizontal axis added on the right for the points' labels.
const LABEL_ROOM: f64 = 0.12;

/// in one; points with a NaN coordinate are never on the front; exact duplicates both are.
pub fn pareto_front(points: &[(f64, f64)]) -> Vec<usize> {
    let dominates = |a: (f64, f64), b: (f64, f64)| a.0 <= b.0 && a.1 <= b.1 && (a.0 < b.0 || a.1 < b.1);
    let mut front: Vec<usize> = (0..points.len())
        .filter(|&i| !points[i].0.is_nan() && !points[i].1.is_nan())
        .filter(|&i| !points.iter().any(|&q| dominates(q, points[i])))
        .collect();
    front.sort_by(|&a, &b| points[a].0.total_cmp(&points[b].0).then(points[a].1.total_cmp(&points[b].1)));
    front
}

/// Writes `p` to `<stem>.png` and `<stem>.svg` (900 x 650 pixels): one colour and marker
/// per group, point labels, and the Pareto front of the drawable points as a black step
/// line with its points circled.
pub fn pareto_figure(p: &ParetoFigure, stem: &Path) -> Result<(), String> {
    canvas::save(p, stem)
}

impl Render for ParetoFigure {
    fn title(&self) -> &str {
        &self.title
    }

    fn size(&self) -> (u32, u32) {
        (900, 650)
    }

    fn render<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> Result<(), String> {
        // Each point's resolution is written to its right: room for the rightmost one's.
        let x = Axis::fit(self.points.iter().map(|p| p.2), self.log_x).widened_right(LABEL_ROOM);
        let y = Axis::fit(self.points.iter().map(|p| p.3), self.log_y);
        let shown: Vec<&(String, String, f64, f64)> =
            self.points.iter().filter(|p| x.accepts(p.2) && y.accepts(p.3)).collect();
        let mut groups: Vec<&str> = Vec::new();
        for p in &self.points {
            if !groups.contains(&p.0.as_str()) {
                groups.push(&p.0);
            }
        }
        let mut chart = canvas::chart(area, x, y)?;
        canvas::mesh(&mut chart, &self.x_label, &self.y_label, true)?;

        let xy: Vec<(f64, f64)> = shown.iter().map(|p| (p.2, p.3)).collect();
        let front: Vec<(f64, f64)> = pareto_front(&xy).into_iter().map(|i| xy[i]).collect();
        let mut steps = Vec::with_capacity(2 * front.len());
        for (k, &(fx, fy)) in front.iter().enumerate() {
            if k > 0 {
                steps.push((fx, front[k - 1].1));
            }
            steps.push((fx, fy));
        }
        let ink = REFERENCE.stroke_width(2);
        chart
            .draw_series(DashedLineSeries::new(steps.clone(), 8, 5, ink))
            .map_err(|e| e.to_string())?
            .label("Pareto front")
            .legend(move |(px, py)| {
                EmptyElement::at((px, py))
                    + PathElement::new(vec![(0, 0), (24, 0)], ink)
                    + Circle::new((12, 0), 7, REFERENCE.stroke_width(1))
            });
        chart
            .draw_series(front.iter().map(|&c| Circle::new(c, 10, REFERENCE.stroke_width(2))))
            .map_err(|e| e.to_string())?;

        let beside = canvas::text(canvas::TICK_SIZE - 3).pos(Pos::new(HPos::Left, VPos::Bottom));
        for (g, name) in groups.iter().enumerate() {
            let color = palette(g);
            let mine: Vec<_> = shown.iter().filter(|p| p.0 == *name).collect();
            chart
                .draw_series(mine.iter().map(|p| Glyph::marker(g, (p.2, p.3), 6, color.filled())))
                .map_err(|e| e.to_string())?
                .label(*name)
                .legend(move |p| Glyph::sample(p, None, Some((g, 6, color.filled()))));
            let labels = mine
                .iter()
                .map(|p| EmptyElement::at((p.2, p.3)) + Text::new(p.1.clone(), (8, -6), beside.clone()));
            chart.draw_series(labels).map_err(|e| e.to_string())?;
        }
        // Keep the legend off the points and the front line between them.
        let spec = chart.as_coord_spec();
        let mut avoid = canvas::densify(spec.x_spec(), spec.y_spec(), &steps);
        avoid.extend_from_slice(&xy);
        canvas::legend(&mut chart, groups.len() + 1, &avoid)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::automation::report::testutil::check_figure;

    #[test]
    fn front_of_hand_made_points() {
        let pts = [
            (3.0, 1.0), // 0 front
            (1.0, 5.0), // 1 front
            (2.0, 2.0), // 2 front
            (2.5, 2.5), // 3 dominated by 2
            (1.0, 6.0), // 4 dominated by 1 (same x, worse y)
            (4.0, 1.0), // 5 dominated by 0 (same y, worse x)
            (f64::NAN, 0.0),
            (2.0, 2.0), // 7 duplicate of 2: also non-dominated
        ];
        assert_eq!(pareto_front(&pts), vec![1, 2, 7, 0]);
        assert_eq!(pareto_front(&[]), Vec::<usize>::new());
        assert_eq!(pareto_front(&[(1.0, 1.0)]), vec![0]);
    }

    #[test]
    fn cost_error_figure() {
        let dir = tempfile::tempdir().unwrap();
        let stem = dir.path().join("pareto");
        let mut points = Vec::new();
        for (s, c, e) in [("EDAC", 1.0, 1.0), ("TVF", 1.6, 0.5), ("CTVF", 2.0, 0.3)] {
            for nx in [25.0, 50.0, 100.0] {
                points.push((s.to_string(), format!("nx={nx}"), c * nx * nx * 1e-4, e / (nx * nx)));
            }
        }
        points.push(("TVF".into(), "nx=0".into(), 0.0, 1e-3));
        let p = ParetoFigure {
            title: "Cost vs accuracy".into(),
            x_label: "wall time [s]".into(),
            y_label: "L2 error [m/s]".into(),
            points,
            log_x: true,
            log_y: true,
        };
        pareto_figure(&p, &stem).unwrap();
        check_figure(
            &stem,
            (900, 650),
            &["Cost vs accuracy", "EDAC", "TVF", "CTVF", "Pareto front", "nx=50"],
        );
    }
}
