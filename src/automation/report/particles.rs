//! Particle figures: particles as dots coloured by a field, with a colour bar, the walls'
//! particles in grey, and an optional vector field (e.g. free-surface normals) drawn as
//! arrows.

use super::canvas::{self, Axis, Render, MARGIN, X_LABEL_AREA, Y_LABEL_AREA};
use super::colors::viridis;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;

/// Width in pixels of the colour bar panel right of the particles: the bar, its tick
/// labels and title, and a margin that keeps the title inside the image.
const BAR_PANEL: u32 = 190;
const BAR_WIDTH: u32 = 40;
const BAR_RIGHT_MARGIN: u32 = 25;
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
    /// Axis labels, with units (`x (m)`).
    pub x_label: String,
    /// Axis labels, with units (`y (m)`).
    pub y_label: String,
    /// Wall particles (x, y), drawn in grey under the fluid.
    pub walls: Option<(Vec<f64>, Vec<f64>)>,
    /// The particles of structures in the fluid (x, y), drawn in dark red beside it.
    pub structures: Option<(Vec<f64>, Vec<f64>)>,
    /// The data extent `[x0, x1, y0, y1]` to show (the panels of one figure share one);
    /// `None` fits the particles and walls.
    pub extent: Option<[f64; 4]>,
    /// Colour scale limits; `None` fits the finite values. Values outside are clamped.
    pub range: Option<(f64, f64)>,
    /// Same length scale on both axes (the data ranges are widened to fit the canvas).
    pub aspect_equal: bool,
    /// A vector per particle drawn over the dots as a segment from the particle along
    /// the vector's direction; `None`: no overlay.
    pub arrows: Option<Arrows>,
}

/// A vector point array drawn as arrows of one length (direction only) at the particles
/// where it is non-zero and finite.
#[derive(Clone, Debug)]
pub struct Arrows {
    /// x components, one per particle.
    pub u: Vec<f64>,
    /// y components, one per particle.
    pub v: Vec<f64>,
    /// Arrow length in data units; `None`: one and a half particle spacings (the median
    /// nearest-neighbour distance), and at least [`MIN_ARROW_PX`] pixels.
    pub length: Option<f64>,
}

/// Colour of the arrows (red: distinct from the viridis dots).
const ARROW: RGBColor = RGBColor(215, 48, 39);
/// Colour of the wall particles.
const WALL: RGBColor = RGBColor(150, 150, 150);
/// The colour of a structure's particles in a fluid's figure.
const STRUCTURE: RGBColor = RGBColor(150, 30, 30);
/// The shortest arrow drawn, in pixels: shorter ones cannot be seen.
pub const MIN_ARROW_PX: f64 = 14.0;

impl Arrows {
    /// The arrows `(start, end)` in data units over particles at `x`, `y`, `length` long;
    /// where particles stand closer than `0.6 length`, one arrow per such distance (the
    /// first in particle order), so that arrows do not pile on each other.
    pub(crate) fn layout(&self, x: &[f64], y: &[f64], length: f64) -> Vec<((f64, f64), (f64, f64))> {
        let n = x.len().min(y.len()).min(self.u.len()).min(self.v.len());
        let gap = 0.6 * length;
        let mut taken: std::collections::HashMap<(i64, i64), Vec<(f64, f64)>> =
            std::collections::HashMap::new();
        let mut out = Vec::new();
        for i in 0..n {
            let (u, v) = (self.u[i], self.v[i]);
            let norm = u.hypot(v);
            if !(norm > 0.0 && norm.is_finite() && x[i].is_finite() && y[i].is_finite()) {
                continue;
            }
            let cell = ((x[i] / gap).floor() as i64, (y[i] / gap).floor() as i64);
            let near = (-1..=1).any(|a| {
                (-1..=1).any(|b| {
                    taken.get(&(cell.0 + a, cell.1 + b)).is_some_and(|pts| {
                        pts.iter().any(|p| (p.0 - x[i]).hypot(p.1 - y[i]) < gap * (1.0 - 1e-9))
                    })
                })
            });
            if near {
                continue;
            }
            taken.entry(cell).or_default().push((x[i], y[i]));
            out.push(((x[i], y[i]), (x[i] + length * u / norm, y[i] + length * v / norm)));
        }
        out
    }

    /// How many particles have an arrow to draw (non-zero, finite).
    pub fn count(&self) -> usize {
        self.u
            .iter()
            .zip(&self.v)
            .filter(|(a, b)| a.hypot(**b) > 0.0 && a.is_finite() && b.is_finite())
            .count()
    }
}

/// The polyline of an arrow from `p` to `q`: the shaft, then the two barbs of its head
/// (a third of its length, 25 degrees off the shaft).
fn arrow_path(p: (f64, f64), q: (f64, f64)) -> Vec<(f64, f64)> {
    let (dx, dy) = (q.0 - p.0, q.1 - p.1);
    let barb = |sign: f64| {
        let (c, s) = (25f64.to_radians().cos(), sign * 25f64.to_radians().sin());
        (q.0 - (dx * c - dy * s) / 3.0, q.1 - (dx * s + dy * c) / 3.0)
    };
    vec![p, q, barb(1.0), q, barb(-1.0)]
}

/// The median distance from a particle to its nearest neighbour (1 for fewer than two
/// finite particles), found on a grid of cells no smaller than the mean spacing over the
/// bounding box, so the nearest neighbour of a particle is in its own or an adjacent cell.
pub(crate) fn typical_spacing(x: &[f64], y: &[f64]) -> f64 {
    let pts: Vec<(f64, f64)> =
        x.iter().zip(y).filter(|(a, b)| a.is_finite() && b.is_finite()).map(|(a, b)| (*a, *b)).collect();
    if pts.len() < 2 {
        return 1.0;
    }
    let (x0, x1, y0, y1) = pts
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY, f64::INFINITY, f64::NEG_INFINITY), |(a, b, c, d), p| {
            (a.min(p.0), b.max(p.0), c.min(p.1), d.max(p.1))
        });
    let (wx, wy) = (x1 - x0, y1 - y0);
    let n = pts.len() as f64;
    // Area per particle over the box (a line of particles: length per particle).
    let cell = if wx > 0.0 && wy > 0.0 { (wx * wy / n).sqrt() } else { wx.max(wy) / n };
    if cell <= 0.0 {
        return 1.0; // every particle at one point
    }
    let (nx, ny) = ((wx / cell) as usize + 1, (wy / cell) as usize + 1);
    let key = |p: &(f64, f64)| {
        (((p.0 - x0) / cell) as usize).min(nx - 1) + nx * (((p.1 - y0) / cell) as usize).min(ny - 1)
    };
    let mut cells: std::collections::HashMap<usize, Vec<usize>> = std::collections::HashMap::new();
    for (i, p) in pts.iter().enumerate() {
        cells.entry(key(p)).or_default().push(i);
    }
    let mut nearest: Vec<f64> = pts
        .iter()
        .enumerate()
        .filter_map(|(i, p)| {
            let k = key(p);
            let (cx, cy) = ((k % nx) as i64, (k / nx) as i64);
            let mut best = f64::INFINITY;
            for dy in -1..=1 {
                for dx in -1..=1 {
                    let (a, b) = (cx + dx, cy + dy);
                    if a < 0 || b < 0 || a >= nx as i64 || b >= ny as i64 {
                        continue;
                    }
                    for &j in cells.get(&(a as usize + nx * b as usize)).into_iter().flatten() {
                        let d = (pts[j].0 - p.0).hypot(pts[j].1 - p.1);
                        if j != i && d > 0.0 {
                            best = best.min(d);
                        }
                    }
                }
            }
            best.is_finite().then_some(best)
        })
        .collect();
    if nearest.is_empty() {
        return cell;
    }
    let mid = nearest.len() / 2;
    *nearest.select_nth_unstable_by(mid, f64::total_cmp).1
}

/// Writes `f` to `<stem>.png` and `<stem>.svg` (900 x 720 pixels): particles as small
/// filled circles coloured by value on a viridis-like map, and a labelled colour bar.
/// Particles with a NaN value are grey; non-finite positions are skipped.
pub fn particle_figure(f: &ScatterField, stem: &Path) -> Result<(), String> {
    canvas::save(f, stem)
}

impl ScatterField {
    /// The arrows' length in data units: as asked, or one and a half particle spacings and
    /// at least [`MIN_ARROW_PX`] pixels of the plotting area (taken at its size below the
    /// title, about 50 pixels, so that the count below and the drawing agree).
    fn arrow_length(&self, a: &Arrows) -> f64 {
        if let Some(l) = a.length {
            return l;
        }
        let (w, h) = self.size();
        let pw = (w - BAR_PANEL).saturating_sub(2 * MARGIN + Y_LABEL_AREA).max(1) as f64;
        let ph = (h - 50).saturating_sub(2 * MARGIN + X_LABEL_AREA).max(1) as f64;
        let (x, y) = self.axes(pw, ph);
        let (xr, yr) = (x.range(), y.range());
        let per_px = ((xr.end - xr.start) / pw).max((yr.end - yr.start) / ph);
        let n = self.x.len().min(self.y.len());
        (1.5 * typical_spacing(&self.x[..n], &self.y[..n])).max(MIN_ARROW_PX * per_px)
    }

    /// The arrows drawn: `(drawn, particles with a vector)`.
    pub fn arrows_drawn(&self) -> (usize, usize) {
        let Some(a) = &self.arrows else { return (0, 0) };
        (a.layout(&self.x, &self.y, self.arrow_length(a)).len(), a.count())
    }

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
        let (x, y) = match self.extent {
            Some([x0, x1, y0, y1]) => (Axis::fit([x0, x1], false), Axis::fit([y0, y1], false)),
            None => {
                let others = self.walls.iter().chain(self.structures.iter());
                let xs = self.x.iter().chain(others.clone().flat_map(|w| w.0.iter())).copied();
                let ys = self.y.iter().chain(others.flat_map(|w| w.1.iter())).copied();
                (Axis::fit(xs, false), Axis::fit(ys, false))
            }
        };
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
        let (x_range, y_range) = (x.range(), y.range());
        let (lo, hi) = self.value_range();
        // Data units per pixel (the larger of the two axes' when they differ).
        let per_px = {
            let (xr, yr) = (x.range(), y.range());
            ((xr.end - xr.start) / pw).max((yr.end - yr.start) / ph)
        };
        let mut chart = canvas::chart(&main, x, y)?;
        canvas::mesh(&mut chart, &self.x_label, &self.y_label, false)?;

        let n = self.x.len().min(self.y.len()).min(self.value.len());
        // Dots as wide as the particle spacing, so that a fluid reads as one.
        let spacing = typical_spacing(&self.x[..n], &self.y[..n]);
        let r = (0.55 * spacing / per_px).clamp(1.0, 6.0).round() as i32;
        for (points, colour) in [(&self.walls, WALL), (&self.structures, STRUCTURE)] {
            if let Some((px, py)) = points {
                let points = px.iter().zip(py).filter(|(a, b)| a.is_finite() && b.is_finite());
                chart
                    .draw_series(points.map(|(a, b)| Circle::new((*a, *b), r, colour.filled())))
                    .map_err(|e| e.to_string())?;
            }
        }
        // Particles outside the axes (a figure's view) are left out, not piled on its edge.
        let (xr, yr) = (x_range.clone(), y_range.clone());
        let dots = (0..n).filter(|&i| xr.contains(&self.x[i]) && yr.contains(&self.y[i])).map(|i| {
            let c = viridis((self.value[i] - lo) / (hi - lo));
            Circle::new((self.x[i], self.y[i]), r, c.filled())
        });
        chart.draw_series(dots).map_err(|e| e.to_string())?;
        if let Some(a) = &self.arrows {
            let arrows = a.layout(&self.x, &self.y, self.arrow_length(a));
            chart
                .draw_series(
                    arrows
                        .into_iter()
                        .map(|(p, q)| PathElement::new(arrow_path(p, q), ARROW.stroke_width(2))),
                )
                .map_err(|e| e.to_string())?;
        }
        let flag = (0..n).all(|i| !self.value[i].is_finite() || self.value[i] == 0.0 || self.value[i] == 1.0);
        if flag && (lo, hi) == (0.0, 1.0) {
            flag_key(&bar, &self.value_label)
        } else {
            colour_bar(&bar, lo, hi, &self.value_label)
        }
    }
}

/// The key of a field that is a flag (every value 0 or 1): two swatches, the colours the
/// dots take, labelled 0 and 1 (a continuous bar would offer values none takes).
fn flag_key<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>, label: &str) -> Result<(), String> {
    // Swatches at 0.5-1.5 (0) and 2.5-3.5 (1), their labels at the swatches' middles.
    let swatches = [(0.0, 0.5), (1.0, 2.5)]
        .map(|(v, y0)| Rectangle::new([(0.0, y0), (1.0, y0 + 1.0)], viridis(v).filled()));
    let fmt = |v: &f64| {
        if *v == 1.0 {
            "0".to_string()
        } else if *v == 3.0 {
            "1".to_string()
        } else {
            String::new()
        }
    };
    key_panel(area, (0.0, 4.0), swatches, 5, &fmt, label)
}

/// A vertical colour bar spanning `lo..hi` with ticks and `label`, aligned with the
/// plotting area of the neighbouring chart.
fn colour_bar<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    lo: f64,
    hi: f64,
    label: &str,
) -> Result<(), String> {
    let step = (hi - lo) / BAR_SAMPLES as f64;
    let cells = (0..BAR_SAMPLES).map(|k| {
        let v = lo + step * k as f64;
        let c = viridis((k as f64 + 0.5) / BAR_SAMPLES as f64);
        Rectangle::new([(0.0, v), (1.0, v + step)], c.filled())
    });
    // As the chart axes label their ticks: one computed as lo + k * step that misses zero
    // by rounding reads 0, not -5.551e-17.
    let axis = Axis::Linear(lo, hi);
    key_panel(area, (lo, hi), cells, 8, &|v: &f64| axis.format(*v), label)
}

/// The panel beside a particle chart that keys its colours: `cells` drawn over a vertical
/// axis `lo..hi` aligned with the chart's plotting area, `labels` ticks written by `fmt`,
/// and `label` along it.
fn key_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    (lo, hi): (f64, f64),
    cells: impl IntoIterator<Item = Rectangle<(f64, f64)>>,
    labels: usize,
    fmt: &dyn Fn(&f64) -> String,
    label: &str,
) -> Result<(), String> {
    let mut bar = ChartBuilder::on(area)
        .margin(MARGIN)
        .margin_right(BAR_RIGHT_MARGIN)
        .x_label_area_size(X_LABEL_AREA)
        .right_y_label_area_size(BAR_PANEL - BAR_WIDTH - BAR_RIGHT_MARGIN - MARGIN)
        .build_cartesian_2d(Axis::Linear(0.0, 1.0), Axis::Linear(lo, hi))
        .map_err(|e| e.to_string())?;
    bar.draw_series(cells).map_err(|e| e.to_string())?;
    bar.configure_mesh()
        .disable_mesh()
        .disable_x_axis()
        .y_labels(labels)
        .y_label_formatter(fmt)
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
            x_label: "x (m)".into(),
            y_label: "y (m)".into(),
            walls: None,
            structures: None,
            extent: None,
            range: None,
            aspect_equal: true,
            arrows: None,
        };
        particle_figure(&f, &stem).unwrap();
        check_figure(&stem, (900, 720), &["Taylor-Green pressure, t = 2 s", "p [Pa]", "x (m)", "y (m)"]);
        let (x, y) = f.axes(600.0, 300.0);
        let (xr, yr) = (x.range(), y.range());
        let ratio = ((xr.end - xr.start) / 600.0) / ((yr.end - yr.start) / 300.0);
        assert!((ratio - 1.0).abs() < 1e-12);
    }

    /// A colour bar symmetric about zero labels its middle tick 0, as the chart axes do,
    /// however the tick's value rounds (a pressure field read -5.551e-17 there).
    #[test]
    fn colour_bar_labels_zero_as_zero() {
        let dir = tempfile::tempdir().unwrap();
        let stem = dir.path().join("symmetric");
        for hi in [0.3347, 0.33, 0.7, 3.3] {
            let f = ScatterField {
                title: "symmetric".into(),
                x: vec![0.0, 1.0, 0.5],
                y: vec![0.0, 1.0, 0.5],
                value: vec![-hi, hi, 0.0],
                value_label: "p [Pa]".into(),
                x_label: "x (m)".into(),
                y_label: "y (m)".into(),
                walls: None,
                structures: None,
                extent: None,
                range: None,
                aspect_equal: false,
                arrows: None,
            };
            particle_figure(&f, &stem).unwrap();
            let svg = check_figure(&stem, (900, 720), &["p [Pa]"]);
            let labels: Vec<&str> = svg.lines().map(str::trim).filter(|l| l.parse::<f64>().is_ok()).collect();
            assert!(labels.contains(&"0"), "hi = {hi}: tick labels {labels:?}");
            assert!(labels.iter().all(|l| l.parse::<f64>().unwrap().abs() > 1e-9 || *l == "0"), "{labels:?}");
        }
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
            x_label: "x (m)".into(),
            y_label: "y (m)".into(),
            walls: None,
            structures: None,
            extent: None,
            range: Some((2.0, 4.0)),
            aspect_equal: false,
            arrows: None,
        };
        particle_figure(&f, &dir.path().join("c")).unwrap();
        let empty = ScatterField { x: vec![], y: vec![], value: vec![], range: None, ..f };
        particle_figure(&empty, &dir.path().join("e")).unwrap();
        assert_eq!(empty.value_range(), (0.0, 1.0));
    }

    /// A ring of particles with outward normals on its outer layer, in a box of wall
    /// particles: one red arrow (shaft and head) per non-zero normal, one and a half particle
    /// spacings long, the walls in grey, in both PNG and SVG.
    #[test]
    fn normals_drawn_as_arrows_where_non_zero() {
        let dir = tempfile::tempdir().unwrap();
        let stem = dir.path().join("ring_normals");
        let dx = 0.05;
        let (mut x, mut y, mut fs, mut u, mut v) = (vec![], vec![], vec![], vec![], vec![]);
        for layer in 0..4 {
            let r = 0.5 + layer as f64 * dx;
            let n = (std::f64::consts::TAU * r / dx).round() as usize;
            for k in 0..n {
                let a = std::f64::consts::TAU * k as f64 / n as f64;
                x.push(r * a.cos());
                y.push(r * a.sin());
                let outer = layer == 3;
                fs.push(if outer { 1.0 } else { 0.0 });
                u.push(if outer { 2.0 * a.cos() } else { 0.0 }); // not unit: direction only
                v.push(if outer { 2.0 * a.sin() } else { 0.0 });
            }
        }
        let outer = fs.iter().filter(|f| **f == 1.0).count();
        let spacing = typical_spacing(&x, &y);
        assert!((spacing - dx).abs() < 0.2 * dx, "{spacing}");
        let arrows = Arrows { u, v, length: None };
        let walls: (Vec<f64>, Vec<f64>) = (0..40).map(|i| (-1.0 + i as f64 * dx, -1.0)).unzip();
        let f = ScatterField {
            title: "ring: free surface and normals".into(),
            x,
            y,
            value: fs,
            value_label: "free_surface".into(),
            x_label: "x (m)".into(),
            y_label: "y (m)".into(),
            walls: Some(walls),
            structures: None,
            extent: None,
            range: None,
            aspect_equal: true,
            arrows: Some(arrows),
        };
        let a = f.arrows.as_ref().unwrap();
        let len = f.arrow_length(a);
        assert!((len - 1.5 * spacing).abs() < 1e-12, "{len}");
        let segs = a.layout(&f.x, &f.y, len);
        assert_eq!(segs.len(), outer);
        for ((x0, y0), (x1, y1)) in &segs {
            assert!(((x1 - x0).hypot(y1 - y0) - len).abs() < 1e-12);
            assert!(x1.hypot(*y1) > x0.hypot(*y0)); // outward
        }
        assert_eq!(f.arrows_drawn(), (outer, outer));
        particle_figure(&f, &stem).unwrap();
        let svg = check_figure(&stem, (900, 720), &["ring: free surface and normals", "free_surface"]);
        let red = svg.matches("stroke=\"#D73027\"").count();
        assert_eq!(red, outer, "one arrow per non-zero normal");
        assert!(svg.contains("#969696"), "the walls in grey");
        // Arrows closer than 0.6 of their length are thinned; the count says how many.
        let short = Arrows { length: Some(10.0 * spacing), ..f.arrows.clone().unwrap() };
        assert!(short.layout(&f.x, &f.y, 10.0 * spacing).len() < outer / 4);
        // Without the overlay, no arrow.
        particle_figure(&ScatterField { arrows: None, ..f }, &stem).unwrap();
        let svg = std::fs::read_to_string(stem.with_extension("svg")).unwrap();
        assert_eq!(svg.matches("stroke=\"#D73027\"").count(), 0);
    }

    #[test]
    fn spacing_of_degenerate_sets() {
        assert_eq!(typical_spacing(&[], &[]), 1.0);
        assert_eq!(typical_spacing(&[1.0, 1.0], &[2.0, 2.0]), 1.0);
        let x: Vec<f64> = (0..10).map(|i| i as f64 * 0.1).collect();
        assert!((typical_spacing(&x, &[0.0; 10]) - 0.1).abs() < 1e-12); // a line
    }
}
