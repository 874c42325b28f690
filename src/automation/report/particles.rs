//! Particle figures: particles as dots coloured by a field, with a colour bar.

use super::canvas::{self, Axis, Render, MARGIN, X_LABEL_AREA, Y_LABEL_AREA};
use super::colors::viridis;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

/// Width in pixels of the colour bar panel right of the particles.
const BAR_PANEL: u32 = 150;
const BAR_SAMPLES: usize = 128;

/// Particle positions and one scalar value per particle.
#[derive(Clone, Debug)]
pub struct ScatterField {
    /// Title above the chart.
    pub title: String,
    /// Particle x coordinates.
    pub x: Vec<f64>,
    /// Particle y coordinates.
    pub y: Vec<f64>,
    /// The value that colours each particle.
    pub value: Vec<f64>,
    /// Colour bar label, with units.
    pub value_label: String,
    /// Colour scale limits; `None` fits the finite values. Values outside are clamped.
    pub range: Option<(f64, f64)>,
    /// Same length scale on both axes (the data ranges are widened to fit the canvas).
    pub aspect_equal: bool,
}

/// Writes `f` to `<stem>.png` and `<stem>.svg` (900 x 720 pixels): particles as small
/// filled circles coloured by value on a viridis-like map, and a labelled colour bar.
/// Particles with a NaN value are grey; non-finite positions are skipped.
pub fn particle_figure(f: &ScatterField, stem: &Path) -> Result<(), String> {
    canvas::save(f, stem)
}

impl ScatterField {
    fn value_range(&self) -> (f64, f64) {
        let (lo, hi) = self.range.unwrap_or_else(|| {
            self.value
                .iter()
                .filter(|v| v.is_finite())
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| (a.min(v), b.max(v)))
        });
        if !(lo.is_finite() && hi.is_finite()) || lo > hi {
            (0.0, 1.0)
        } else if lo == hi {
            (lo - 0.5, hi + 0.5)
        } else {
            (lo, hi)
        }
    }

    /// Axes fitted to the positions; with `aspect_equal`, widened so one data unit has
    /// the same length in pixels on both axes of a `w` x `h` plotting area.
    fn axes(&self, w: f64, h: f64) -> (Axis, Axis) {
        let (x, y) = (Axis::fit(self.x.iter().copied(), false), Axis::fit(self.y.iter().copied(), false));
        if !self.aspect_equal {
            return (x, y);
        }
        let (xr, yr) = (x.range(), y.range());
        let per_px = ((xr.end - xr.start) / w).max((yr.end - yr.start) / h);
        let widen = |r: std::ops::Range<f64>, px: f64| {
            let (c, half) = ((r.start + r.end) / 2.0, per_px * px / 2.0);
            Axis::Linear(c - half, c + half)
        };
        (widen(xr, w), widen(yr, h))
    }
}

impl Render for ScatterField {
    fn title(&self) -> &str {
        &self.title
    }

    fn size(&self) -> (u32, u32) {
        (900, 720)
    }

    fn render<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> Result<(), String> {
        let (w, h) = area.dim_in_pixel();
        let (main, bar) = area.split_horizontally(w.saturating_sub(BAR_PANEL));
        let pw = (w - BAR_PANEL).saturating_sub(2 * MARGIN + Y_LABEL_AREA).max(1) as f64;
        let ph = h.saturating_sub(2 * MARGIN + X_LABEL_AREA).max(1) as f64;
        let (x, y) = self.axes(pw, ph);
        let (lo, hi) = self.value_range();
        let mut chart = canvas::chart(&main, x, y)?;
        canvas::mesh(&mut chart, "x", "y", false)?;

        let n = self.x.len().min(self.y.len()).min(self.value.len());
        // Dots about a third of the mean spacing, as if the particles filled the plot.
        let r = ((pw * ph / n.max(1) as f64).sqrt() * 0.35).clamp(1.0, 6.0).round() as i32;
        let dots = (0..n).filter(|&i| self.x[i].is_finite() && self.y[i].is_finite()).map(|i| {
            let c = viridis((self.value[i] - lo) / (hi - lo));
            Circle::new((self.x[i], self.y[i]), r, c.filled())
        });
        chart.draw_series(dots).map_err(|e| e.to_string())?;
        colour_bar(&bar, lo, hi, &self.value_label)
    }
}

/// A vertical colour bar spanning `lo..hi` with ticks and `label`, aligned with the
/// plotting area of the neighbouring chart.
fn colour_bar<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    lo: f64,
    hi: f64,
    label: &str,
) -> Result<(), String> {
    let mut bar = ChartBuilder::on(area)
        .margin(MARGIN)
        .margin_right(0)
        .x_label_area_size(X_LABEL_AREA)
        .right_y_label_area_size(BAR_PANEL - 40 - MARGIN)
        .build_cartesian_2d(Axis::Linear(0.0, 1.0), Axis::Linear(lo, hi))
        .map_err(|e| e.to_string())?;
    let step = (hi - lo) / BAR_SAMPLES as f64;
    let cells = (0..BAR_SAMPLES).map(|k| {
        let v = lo + step * k as f64;
        let c = viridis((k as f64 + 0.5) / BAR_SAMPLES as f64);
        Rectangle::new([(0.0, v), (1.0, v + step)], c.filled())
    });
    bar.draw_series(cells).map_err(|e| e.to_string())?;
    let fmt = |v: &f64| canvas::fmt_num(*v);
    bar.configure_mesh()
        .disable_mesh()
        .disable_x_axis()
        .y_labels(8)
        .y_label_formatter(&fmt)
        .y_desc(label)
        .label_style(canvas::text(canvas::TICK_SIZE))
        .axis_desc_style(canvas::text(canvas::DESC_SIZE))
        .draw()
        .map_err(|e| e.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::automation::report::testutil::check_figure;

    #[test]
    fn taylor_green_pressure_field() {
        let dir = tempfile::tempdir().unwrap();
        let stem = dir.path().join("tg_pressure");
        let n = 40;
        let (mut x, mut y, mut p) = (vec![], vec![], vec![]);
        for i in 0..n {
            for j in 0..n {
                let (a, b) = ((i as f64 + 0.5) / n as f64, (j as f64 + 0.5) / n as f64);
                x.push(a);
                y.push(b * 0.5);
                let tau = std::f64::consts::TAU;
                p.push(-0.25 * ((2.0 * tau * a).cos() + (2.0 * tau * b).cos()));
            }
        }
        p[3] = f64::NAN;
        let f = ScatterField {
            title: "Taylor-Green pressure, t = 2 s".into(),
            x,
            y,
            value: p,
            value_label: "p [Pa]".into(),
            range: None,
            aspect_equal: true,
        };
        particle_figure(&f, &stem).unwrap();
        check_figure(&stem, (900, 720), &["Taylor-Green pressure, t = 2 s", "p [Pa]"]);
        let (x, y) = f.axes(600.0, 300.0);
        let (xr, yr) = (x.range(), y.range());
        let ratio = ((xr.end - xr.start) / 600.0) / ((yr.end - yr.start) / 300.0);
        assert!((ratio - 1.0).abs() < 1e-12);
    }

    #[test]
    fn constant_and_empty_fields() {
        let dir = tempfile::tempdir().unwrap();
        let f = ScatterField {
            title: "constant".into(),
            x: vec![0.0, 1.0],
            y: vec![0.0, 0.0],
            value: vec![3.0, 3.0],
            value_label: "rho [kg/m^3]".into(),
            range: Some((2.0, 4.0)),
            aspect_equal: false,
        };
        particle_figure(&f, &dir.path().join("c")).unwrap();
        let empty = ScatterField { x: vec![], y: vec![], value: vec![], range: None, ..f };
        particle_figure(&empty, &dir.path().join("e")).unwrap();
        assert_eq!(empty.value_range(), (0.0, 1.0));
    }
}
