//! Shared figure machinery: axes (linear, logarithmic, categorical), tick formatting,
//! the chart frame, legends, markers, and saving one drawing to both PNG and SVG.

use super::colors::REFERENCE;
use super::files::{create_parent, with_suffix};
use super::font::{ensure_registered, FAMILY};
use plotters::coord::ranged1d::{DefaultFormatting, KeyPointHint, Ranged};
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;
use std::ops::Range;
use std::path::Path;

/// Outer margin of every chart, in pixels.
pub(crate) const MARGIN: u32 = 15;
/// Height of the area below the plot holding x tick labels and the x axis label.
pub(crate) const X_LABEL_AREA: u32 = 60;
/// Width of the area left of the plot holding y tick labels and the y axis label.
pub(crate) const Y_LABEL_AREA: u32 = 85;
/// Font sizes (pixels) of the title, axis labels and tick labels / legend entries.
pub(crate) const TITLE_SIZE: u32 = 26;
pub(crate) const DESC_SIZE: u32 = 19;
pub(crate) const TICK_SIZE: u32 = 16;

/// Relative padding added on each side of the data range.
const PAD: f64 = 0.05;

/// Text style of the embedded font at `size` pixels.
pub(crate) fn text(size: u32) -> TextStyle<'static> {
    (FAMILY, size).into_font().into()
}

/// A chart axis. The plotted coordinate is always the data value itself; the axis
/// decides where it lands, which ticks exist and how they are written.
#[derive(Clone, Debug)]
pub(crate) enum Axis {
    /// Linear axis over `lo..hi`.
    Linear(f64, f64),
    /// Logarithmic axis over `lo..hi` (both positive).
    Log(f64, f64),
    /// One slot per name; slot `i` is centred on the value `i`.
    Category(Vec<String>),
}

impl Axis {
    /// An axis covering the finite values (positive ones on a log axis) with padding.
    pub(crate) fn fit(values: impl IntoIterator<Item = f64>, log: bool) -> Axis {
        let (lo, hi) = values
            .into_iter()
            .filter(|v| v.is_finite() && (!log || *v > 0.0))
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| (a.min(v), b.max(v)));
        if log {
            let (lo, hi) = if lo > hi { (0.1, 10.0) } else { (lo, hi) };
            let (a, b) = (lo.log10(), hi.log10());
            let pad = if b > a { (b - a) * PAD } else { 0.5 };
            Axis::Log(10f64.powf(a - pad), 10f64.powf(b + pad))
        } else {
            let (lo, hi) = if lo > hi { (0.0, 1.0) } else { (lo, hi) };
            let pad = if hi > lo {
                (hi - lo) * PAD
            } else if lo != 0.0 {
                lo.abs() * 0.1
            } else {
                1.0
            };
            Axis::Linear(lo - pad, hi + pad)
        }
    }

    /// The axis with its upper end moved out by `fraction` of its span (of its decades on a
    /// log axis): room for the labels written to the right of the points near it.
    pub(crate) fn widened_right(self, fraction: f64) -> Axis {
        match self {
            Axis::Linear(lo, hi) => Axis::Linear(lo, hi + (hi - lo) * fraction),
            Axis::Log(lo, hi) => Axis::Log(lo, hi * (hi / lo).powf(fraction)),
            c => c,
        }
    }

    /// Whether `v` can be drawn on this axis (finite, and positive on a log axis).
    pub(crate) fn accepts(&self, v: f64) -> bool {
        v.is_finite() && !(matches!(self, Axis::Log(..)) && v <= 0.0)
    }

    /// Position of `v` along the axis as a fraction of its length (0 at `lo`).
    pub(crate) fn fraction(&self, v: f64) -> f64 {
        match self {
            Axis::Linear(lo, hi) => (v - lo) / (hi - lo),
            Axis::Log(lo, hi) => (v / lo).ln() / (hi / lo).ln(),
            Axis::Category(names) => (v + 0.5) / names.len().max(1) as f64,
        }
    }

    /// Tick label for the value `v`.
    pub(crate) fn format(&self, v: f64) -> String {
        match self {
            // A tick computed as lo + k * step can miss zero by rounding (-5.551e-17).
            Axis::Linear(lo, hi) if v.abs() < 1e-9 * (hi - lo).abs() => fmt_num(0.0),
            Axis::Linear(..) => fmt_num(v),
            Axis::Log(..) => fmt_log(v),
            Axis::Category(names) => {
                let i = v.round();
                if (v - i).abs() < 1e-6 && i >= 0.0 && (i as usize) < names.len() {
                    names[i as usize].clone()
                } else {
                    String::new()
                }
            }
        }
    }

    /// How many tick labels to ask the mesh for.
    fn label_count(&self) -> usize {
        match self {
            Axis::Category(names) => names.len().max(1),
            _ => 8,
        }
    }
}

impl Ranged for Axis {
    type FormatOption = DefaultFormatting;
    type ValueType = f64;

    fn map(&self, v: &f64, limit: (i32, i32)) -> i32 {
        let f = self.fraction(*v);
        let f = if f.is_finite() { f.clamp(-10.0, 10.0) } else { 0.0 };
        limit.0 + ((limit.1 - limit.0) as f64 * f).round() as i32
    }

    fn key_points<H: KeyPointHint>(&self, hint: H) -> Vec<f64> {
        let light = hint.weight().allow_light_points() && hint.max_num_points() > hint.bold_points();
        match self {
            Axis::Linear(lo, hi) => RangedCoordf64::from(*lo..*hi).key_points(hint),
            Axis::Log(lo, hi) => log_ticks(*lo, *hi, hint.bold_points().max(2), light)
                .unwrap_or_else(|| RangedCoordf64::from(*lo..*hi).key_points(hint)),
            Axis::Category(names) if !light => (0..names.len()).map(|i| i as f64).collect(),
            Axis::Category(_) => Vec::new(),
        }
    }

    fn range(&self) -> Range<f64> {
        match self {
            Axis::Linear(lo, hi) | Axis::Log(lo, hi) => *lo..*hi,
            Axis::Category(names) => -0.5..names.len() as f64 - 0.5,
        }
    }
}

/// Ticks of a log axis: whole decades (thinned to at most `max`), or 1-2-5 multiples on
/// a range under two decades; with `light`, also the 2..9 multiples for minor grid
/// lines. `None` when fewer than two such ticks fit (the caller falls back to linear).
fn log_ticks(lo: f64, hi: f64, max: usize, light: bool) -> Option<Vec<f64>> {
    let (a, b) = (lo.log10().floor() as i32, hi.log10().ceil() as i32);
    let inside = |v: &f64| *v >= lo * (1.0 - 1e-9) && *v <= hi * (1.0 + 1e-9);
    let multiples = |ms: &[f64]| -> Vec<f64> {
        (a..=b).flat_map(|k| ms.iter().map(move |m| m * 10f64.powi(k))).filter(inside).collect()
    };
    let decades = multiples(&[1.0]);
    if decades.len() >= 2 {
        let step = decades.len().div_ceil(max);
        if light && step == 1 {
            return Some(multiples(&[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0]));
        }
        return Some(decades.into_iter().step_by(step).collect());
    }
    let fine = multiples(&[1.0, 2.0, 5.0]);
    (fine.len() >= 2 && fine.len() <= max.max(3)).then_some(fine)
}

/// A number for a tick label: about five significant digits, no trailing zeros,
/// scientific notation (`1.5e-5`) outside `[1e-3, 1e5)`.
pub(crate) fn fmt_num(v: f64) -> String {
    let a = v.abs();
    if a == 0.0 || !a.is_finite() {
        return if a == 0.0 { "0".into() } else { format!("{v}") };
    }
    if (1e-3..1e5).contains(&a) {
        let decimals = (4 - a.log10().floor() as i32).clamp(0, 8) as usize;
        let s = format!("{v:.decimals$}");
        let s = if s.contains('.') { s.trim_end_matches('0').trim_end_matches('.').to_string() } else { s };
        return if s == "-0" { "0".into() } else { s };
    }
    let s = format!("{v:.3e}");
    match s.split_once('e') {
        Some((m, e)) => {
            let m = m.trim_end_matches('0').trim_end_matches('.');
            format!("{m}e{e}")
        }
        None => s,
    }
}

/// A log-axis tick: decades as `1e-3` outside 0.01..1000, plain numbers otherwise.
pub(crate) fn fmt_log(v: f64) -> String {
    if v > 0.0 && v.is_finite() {
        let k = v.log10().round() as i32;
        if (v / 10f64.powi(k) - 1.0).abs() < 1e-9 && !(-2..=3).contains(&k) {
            return format!("1e{k}");
        }
    }
    fmt_num(v)
}

/// A figure that can draw itself on any backend.
pub(crate) trait Render {
    /// Title drawn above the chart.
    fn title(&self) -> &str;
    /// Canvas size in pixels.
    fn size(&self) -> (u32, u32);
    /// Draws into the area below the title.
    fn render<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> Result<(), String>;
}

/// Draws `fig` on a white canvas with its title, into `<stem>.png` and `<stem>.svg`.
pub(crate) fn save<F: Render>(fig: &F, stem: &Path) -> Result<(), String> {
    ensure_registered();
    let png = with_suffix(stem, ".png");
    let svg = with_suffix(stem, ".svg");
    create_parent(&png)?;
    let named = |p: &Path, e: String| format!("{}: {e}", p.display());
    draw_on(fig, BitMapBackend::new(&png, fig.size())).map_err(|e| named(&png, e))?;
    draw_on(fig, SVGBackend::new(&svg, fig.size())).map_err(|e| named(&svg, e))
}

fn draw_on<F: Render, DB: DrawingBackend>(fig: &F, backend: DB) -> Result<(), String> {
    let root = backend.into_drawing_area();
    root.fill(&WHITE).map_err(|e| e.to_string())?;
    let area = root.titled(fig.title(), text(title_size(&root, fig.title()))).map_err(|e| e.to_string())?;
    fig.render(&area)?;
    root.present().map_err(|e| e.to_string())
}

/// The title's font size: [`TITLE_SIZE`], or smaller (down to [`TICK_SIZE`]) so that a
/// long title fits the canvas with margins instead of being cut at its edges.
fn title_size<DB: DrawingBackend>(root: &DrawingArea<DB, Shift>, title: &str) -> u32 {
    // Two margins on each side: the font's estimate runs a few per cent short.
    let room = root.dim_in_pixel().0.saturating_sub(4 * MARGIN);
    let width = root.estimate_text_size(title, &text(TITLE_SIZE)).map_or(0, |(w, _)| w);
    if width <= room {
        TITLE_SIZE
    } else {
        (TITLE_SIZE * room / width).max(TICK_SIZE)
    }
}

/// The chart type every figure draws on.
pub(crate) type Chart<'a, DB> = ChartContext<'a, DB, Cartesian2d<Axis, Axis>>;

/// The room the y axis takes for category `names`: they need more than numbers (e.g.
/// `ctvf/ipst/none`), about 0.6 em per character, plus the axis description.
pub(crate) fn y_label_area(names: &[String]) -> u32 {
    let chars = names.iter().map(|n| n.chars().count()).max().unwrap_or(0) as u32;
    Y_LABEL_AREA.max(chars * TICK_SIZE * 6 / 10 + DESC_SIZE + 25)
}

/// A chart frame in `area`: margins, label areas and the axes, nothing drawn yet.
pub(crate) fn chart<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    x: Axis,
    y: Axis,
) -> Result<Chart<'_, DB>, String> {
    let y_area = match &y {
        Axis::Category(names) => y_label_area(names),
        _ => Y_LABEL_AREA,
    };
    ChartBuilder::on(area)
        .margin(MARGIN)
        .x_label_area_size(X_LABEL_AREA)
        .y_label_area_size(y_area)
        .build_cartesian_2d(x, y)
        .map_err(|e| e.to_string())
}

/// Draws the axes, tick labels, axis labels and (with `grid`) light grid lines.
pub(crate) fn mesh<DB: DrawingBackend>(
    chart: &mut Chart<'_, DB>,
    x_label: &str,
    y_label: &str,
    grid: bool,
) -> Result<(), String> {
    let xa = chart.as_coord_spec().x_spec().clone();
    let ya = chart.as_coord_spec().y_spec().clone();
    let xf = |v: &f64| xa.format(*v);
    let yf = |v: &f64| ya.format(*v);
    let mut m = chart.configure_mesh();
    m.x_desc(x_label)
        .y_desc(y_label)
        .x_labels(xa.label_count())
        .y_labels(ya.label_count())
        .x_label_formatter(&xf)
        .y_label_formatter(&yf)
        .label_style(text(TICK_SIZE))
        .axis_desc_style(text(DESC_SIZE))
        .bold_line_style(BLACK.mix(0.15))
        .light_line_style(BLACK.mix(0.05));
    if !grid {
        m.disable_mesh();
    }
    m.draw().map_err(|e| e.to_string())
}

/// Draws the legend of the labelled series in the corner holding the fewest of `pts`
/// (data points in chart coordinates), so it hides as little data as possible.
pub(crate) fn legend<'a, DB: DrawingBackend + 'a>(
    chart: &mut Chart<'a, DB>,
    entries: usize,
    pts: &[(f64, f64)],
) -> Result<(), String> {
    let corner = {
        let spec = chart.as_coord_spec();
        emptiest_corner(spec.x_spec(), spec.y_spec(), entries, pts)
    };
    chart
        .configure_series_labels()
        .position(corner)
        .margin(12)
        .label_font(text(TICK_SIZE))
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK.mix(0.4))
        .draw()
        .map_err(|e| e.to_string())
}

/// The corner whose legend-sized box contains the fewest points.
fn emptiest_corner(x: &Axis, y: &Axis, entries: usize, pts: &[(f64, f64)]) -> SeriesLabelPosition {
    let (w, h) = (0.4, (0.07 * entries as f64 + 0.06).min(0.6));
    let corners = [
        (SeriesLabelPosition::UpperRight, 1.0 - w, 1.0 - h),
        (SeriesLabelPosition::UpperLeft, 0.0, 1.0 - h),
        (SeriesLabelPosition::LowerRight, 1.0 - w, 0.0),
        (SeriesLabelPosition::LowerLeft, 0.0, 0.0),
    ];
    let count = |fx: f64, fy: f64| {
        pts.iter()
            .filter(|(px, py)| {
                let (u, v) = (x.fraction(*px), y.fraction(*py));
                u >= fx && u <= fx + w && v >= fy && v <= fy + h
            })
            .count()
    };
    let mut best = (SeriesLabelPosition::UpperRight, usize::MAX);
    for (pos, fx, fy) in corners {
        let n = count(fx, fy);
        if n < best.1 {
            best = (pos, n);
        }
    }
    best.0
}

/// Points along the polyline through `pts`, densified so that a line crossing a corner
/// counts as occupying it even without a vertex there.
pub(crate) fn densify(x: &Axis, y: &Axis, pts: &[(f64, f64)]) -> Vec<(f64, f64)> {
    let inv = |a: &Axis, f: f64| match a {
        Axis::Log(lo, hi) => lo * (hi / lo).powf(f),
        _ => {
            let r = a.range();
            r.start + (r.end - r.start) * f
        }
    };
    let mut out = Vec::with_capacity(pts.len() * 8);
    for w in pts.windows(2) {
        let (a, b) = (w[0], w[1]);
        let (ax, ay, bx, by) = (x.fraction(a.0), y.fraction(a.1), x.fraction(b.0), y.fraction(b.1));
        for k in 0..8 {
            let t = k as f64 / 8.0;
            out.push((inv(x, ax + (bx - ax) * t), inv(y, ay + (by - ay) * t)));
        }
    }
    out.extend(pts.last().copied());
    out
}

/// Draws a key (colour swatch + name per entry) stacked from the top of `area`; for
/// legends that must sit outside the plot.
pub(crate) fn key<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    entries: &[(&str, RGBColor)],
    top: i32,
) -> Result<(), String> {
    let line = TICK_SIZE as i32 + 12;
    for (i, (name, color)) in entries.iter().enumerate() {
        let y = top + i as i32 * line;
        area.draw(&Rectangle::new([(10, y), (30, y + 18)], color.filled()))
            .and_then(|_| area.draw(&Rectangle::new([(10, y), (30, y + 18)], REFERENCE.mix(0.5))))
            .and_then(|_| area.draw(&Text::new(name.to_string(), (38, y + 1), text(TICK_SIZE))))
            .map_err(|e| e.to_string())?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A title wider than the canvas is set smaller so that it fits; a short one keeps the
    /// title size.
    #[test]
    fn a_long_title_is_set_smaller_to_fit() {
        ensure_registered();
        let mut buf = vec![0u8; 900 * 600 * 3];
        let root = BitMapBackend::with_buffer(&mut buf, (900, 600)).into_drawing_area();
        assert_eq!(title_size(&root, "Taylor-Green, Re = 100"), TITLE_SIZE);
        let long = "Taylor-Green, Re = 100, CTVF with SPST: kernels, accuracy against cost: \
                    l1_velocity_mean against wall time (s)";
        let size = title_size(&root, long);
        assert!(size < TITLE_SIZE);
        let (w, _) = root.estimate_text_size(long, &text(size)).unwrap();
        assert!(w <= 900 - 4 * MARGIN + 2, "{w} pixels at {size}");
    }

    #[test]
    fn tick_formatting() {
        assert_eq!(fmt_num(0.0), "0");
        assert_eq!(fmt_num(0.30000000000000004), "0.3");
        assert_eq!(fmt_num(-2.5), "-2.5");
        assert_eq!(fmt_num(12000.0), "12000");
        assert_eq!(fmt_num(1.5e-5), "1.5e-5");
        assert_eq!(fmt_num(2e6), "2e6");
        assert_eq!(fmt_num(0.0015), "0.0015");
        assert_eq!(fmt_log(1e-3), "1e-3");
        assert_eq!(fmt_log(1e-5), "1e-5");
        assert_eq!(fmt_log(1e4), "1e4");
        assert_eq!(fmt_log(0.01), "0.01");
        assert_eq!(fmt_log(100.0), "100");
        assert_eq!(fmt_log(2e-4), "2e-4");
        assert_eq!(Axis::Linear(-0.45, 1.05).format(-5.551115123125783e-17), "0");
        assert_eq!(Axis::Linear(-1e-12, 1e-12).format(1e-13), "1e-13");
    }

    #[test]
    fn log_ticks_are_decades_or_125() {
        assert_eq!(log_ticks(1e-4, 2e-1, 8, false).unwrap(), vec![1e-4, 1e-3, 1e-2, 1e-1]);
        let thin = log_ticks(1e-12, 1.0, 5, false).unwrap();
        assert!(thin.len() <= 5 && thin.len() >= 3, "{thin:?}");
        let narrow = log_ticks(0.15, 0.9, 8, false).unwrap();
        assert_eq!(narrow, vec![0.2, 0.5]);
        assert!(log_ticks(0.31, 0.45, 8, false).is_none());
        let minor = log_ticks(1e-3, 1e-1, 8, true).unwrap();
        assert_eq!(minor.len(), 19);
    }

    #[test]
    fn fit_pads_and_skips_nonpositive_on_log() {
        match Axis::fit([0.0, -1.0, 1e-3, 1e-1], true) {
            Axis::Log(lo, hi) => assert!(lo < 1e-3 && lo > 5e-4 && hi > 1e-1 && hi < 2e-1),
            a => panic!("{a:?}"),
        }
        match Axis::fit([2.0, 2.0], false) {
            Axis::Linear(lo, hi) => assert!(lo < 2.0 && hi > 2.0),
            a => panic!("{a:?}"),
        }
        assert!(matches!(Axis::fit([], true), Axis::Log(..)));
    }
}
