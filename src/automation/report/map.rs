//! Outcome maps: a categorical grid (e.g. scheme x parameter) of run outcomes.

use super::canvas::{self, Axis, Render, MARGIN, TICK_SIZE};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::path::Path;

/// Width in pixels of the key panel right of the grid.
const KEY_PANEL: u32 = 170;

/// What became of one run.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Outcome {
    /// Ran to the end within tolerance (green).
    Stable,
    /// Ran to the end but outside tolerance (orange).
    Inaccurate,
    /// Blew up or produced non-finite values (red).
    Diverged,
    /// No result (grey); also drawn for grid cells not listed.
    Missing,
}

impl Outcome {
    const ALL: [Outcome; 4] = [Outcome::Stable, Outcome::Inaccurate, Outcome::Diverged, Outcome::Missing];

    fn color(self) -> RGBColor {
        match self {
            Outcome::Stable => RGBColor(77, 175, 74),
            Outcome::Inaccurate => RGBColor(255, 152, 0),
            Outcome::Diverged => RGBColor(215, 25, 28),
            Outcome::Missing => RGBColor(190, 190, 190),
        }
    }

    /// The key's word, `above` for a case beyond the map's bound.
    fn name(self, above: &str) -> &str {
        match self {
            Outcome::Stable => "stable",
            Outcome::Inaccurate => above,
            Outcome::Diverged => "diverged",
            Outcome::Missing => "missing",
        }
    }
}

/// A grid of outcomes: columns are `x_ticks`, rows are `y_ticks` (first row on top).
#[derive(Clone, Debug)]
pub struct OutcomeMap {
    /// Title above the chart.
    pub title: String,
    /// Label under the columns (e.g. the swept parameter).
    pub x_label: String,
    /// Label beside the rows (e.g. "scheme").
    pub y_label: String,
    /// Column names.
    pub x_ticks: Vec<String>,
    /// Row names.
    pub y_ticks: Vec<String>,
    /// `(column, row, outcome, short text)`; cells out of the grid are ignored.
    pub cells: Vec<(usize, usize, Outcome, Option<String>)>,
    /// The key's word for [`Outcome::Inaccurate`] (e.g. "fractured").
    pub above: String,
}

/// Writes `m` to `<stem>.png` and `<stem>.svg`: coloured cells (green stable, orange
/// inaccurate, red diverged, grey missing) with their optional text, and a key. The
/// canvas grows with the grid.
pub fn outcome_map(m: &OutcomeMap, stem: &Path) -> Result<(), String> {
    canvas::save(m, stem)
}

impl Render for OutcomeMap {
    fn title(&self) -> &str {
        &self.title
    }

    fn size(&self) -> (u32, u32) {
        let (nx, ny) = (self.x_ticks.len() as u32, self.y_ticks.len() as u32);
        // The row names' room grows with the longest, so that the cells keep theirs.
        let labels = canvas::y_label_area(&self.y_ticks).max(230) + 100;
        ((labels + KEY_PANEL + 100 * nx).clamp(700, 2400), (180 + 56 * ny).clamp(360, 1600))
    }

    fn render<DB: DrawingBackend>(&self, area: &DrawingArea<DB, Shift>) -> Result<(), String> {
        let (nx, ny) = (self.x_ticks.len(), self.y_ticks.len());
        // Row 0 on top: the y axis lists the names bottom-up.
        let rows: Vec<String> = self.y_ticks.iter().rev().cloned().collect();
        let row = |j: usize| (ny - 1 - j) as f64;
        let (w, _) = area.dim_in_pixel();
        let (grid, key) = area.split_horizontally(w.saturating_sub(KEY_PANEL));
        let mut chart = canvas::chart(&grid, Axis::Category(self.x_ticks.clone()), Axis::Category(rows))?;
        canvas::mesh(&mut chart, &self.x_label, &self.y_label, false)?;

        let mut outcome = vec![Outcome::Missing; nx * ny];
        for &(i, j, o, _) in self.cells.iter().filter(|c| c.0 < nx && c.1 < ny) {
            outcome[j * nx + i] = o;
        }
        let cell = |i: usize, j: usize| [(i as f64 - 0.5, row(j) - 0.5), (i as f64 + 0.5, row(j) + 0.5)];
        let all = (0..ny).flat_map(|j| (0..nx).map(move |i| (i, j)));
        let fill = |(i, j): (usize, usize)| Rectangle::new(cell(i, j), outcome[j * nx + i].color().filled());
        chart.draw_series(all.clone().map(fill)).map_err(|e| e.to_string())?;
        let border = |(i, j): (usize, usize)| Rectangle::new(cell(i, j), WHITE.stroke_width(3));
        chart.draw_series(all.map(border)).map_err(|e| e.to_string())?;

        let centre = Pos::new(HPos::Center, VPos::Center);
        let labels = self.cells.iter().filter(|c| c.0 < nx && c.1 < ny).filter_map(|(i, j, o, t)| {
            let ink: &'static RGBColor = if *o == Outcome::Diverged { &WHITE } else { &BLACK };
            let style = canvas::text(TICK_SIZE - 2).pos(centre).color(ink);
            t.as_ref().map(|t| Text::new(t.clone(), (*i as f64, row(*j)), style))
        });
        chart.draw_series(labels).map_err(|e| e.to_string())?;

        let entries: Vec<(&str, RGBColor)> =
            Outcome::ALL.iter().map(|o| (o.name(&self.above), o.color())).collect();
        canvas::key(&key, &entries, MARGIN as i32 + 10)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::automation::report::testutil::check_figure;

    #[test]
    fn scheme_by_resolution_map() {
        let dir = tempfile::tempdir().unwrap();
        let stem = dir.path().join("stability");
        let m = OutcomeMap {
            title: "Stability, Taylor-Green Re = 100".into(),
            x_label: "particles per side".into(),
            y_label: "scheme".into(),
            x_ticks: vec!["25".into(), "50".into(), "100".into(), "200".into()],
            y_ticks: vec!["EDAC".into(), "TVF".into(), "CTVF".into()],
            cells: vec![
                (0, 0, Outcome::Stable, Some("2.1e-2".into())),
                (1, 0, Outcome::Stable, Some("5.3e-3".into())),
                (2, 0, Outcome::Inaccurate, Some("t=1.2".into())),
                (0, 1, Outcome::Diverged, Some("t=0.4".into())),
                (1, 1, Outcome::Missing, None),
                (3, 2, Outcome::Stable, None),
                (9, 9, Outcome::Stable, None),
            ],
            above: "fractured".into(),
        };
        outcome_map(&m, &stem).unwrap();
        let size = m.size();
        assert_eq!(size, (330 + 170 + 400, 360));
        check_figure(
            &stem,
            size,
            &[
                "Stability, Taylor-Green Re = 100",
                "stable",
                "fractured",
                "diverged",
                "missing",
                "CTVF",
                "200",
                "t=0.4",
            ],
        );
    }
}
