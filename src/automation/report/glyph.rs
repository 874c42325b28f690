//! Point markers and legend samples as one plotters element that does not depend on the
//! backend type (plotters' series need `'static` elements, which rules out `DynElement`
//! over a borrowed backend).

use plotters::element::{Drawable, PointCollection};
use plotters::prelude::*;
use plotters_backend::{BackendCoord, DrawingErrorKind};

/// Width in pixels of a legend line sample.
const SAMPLE: i32 = 24;

/// A marker (circle, triangle, square, diamond, cross: `kind` modulo 5) and/or a short
/// horizontal line, anchored at one coordinate.
pub(crate) struct Glyph<C> {
    at: C,
    line: Option<(ShapeStyle, bool)>,
    mark: Option<(usize, i32, ShapeStyle)>,
    /// Horizontal offset of the marker from the anchor, in pixels.
    dx: i32,
}

impl<C> Glyph<C> {
    /// Marker of shape `kind` and radius `size` pixels centred at `at`.
    pub(crate) fn marker(kind: usize, at: C, size: i32, style: ShapeStyle) -> Self {
        Glyph { at, line: None, mark: Some((kind, size, style)), dx: 0 }
    }

    /// Legend sample starting at `at`: an optional (optionally dashed) line, with an
    /// optional marker in its middle.
    pub(crate) fn sample(
        at: C,
        line: Option<(ShapeStyle, bool)>,
        mark: Option<(usize, i32, ShapeStyle)>,
    ) -> Self {
        Glyph { at, line, mark, dx: SAMPLE / 2 }
    }
}

impl<'a, C> PointCollection<'a, C> for &'a Glyph<C> {
    type Point = &'a C;
    type IntoIter = std::iter::Once<&'a C>;
    fn point_iter(self) -> Self::IntoIter {
        std::iter::once(&self.at)
    }
}

impl<C, DB: DrawingBackend> Drawable<DB> for Glyph<C> {
    fn draw<I: Iterator<Item = BackendCoord>>(
        &self,
        mut points: I,
        backend: &mut DB,
        _: (u32, u32),
    ) -> Result<(), DrawingErrorKind<DB::ErrorType>> {
        let Some((x, y)) = points.next() else {
            return Ok(());
        };
        if let Some((style, dashed)) = self.line {
            let pieces: &[(i32, i32)] = if dashed { &[(0, 6), (9, 15), (18, 24)] } else { &[(0, SAMPLE)] };
            for &(a, b) in pieces {
                backend.draw_line((x + a, y), (x + b, y), &style)?;
            }
        }
        if let Some((kind, s, style)) = self.mark {
            draw_marker(backend, (x + self.dx, y), kind, s, &style)?;
        }
        Ok(())
    }
}

fn draw_marker<DB: DrawingBackend>(
    backend: &mut DB,
    (x, y): BackendCoord,
    kind: usize,
    s: i32,
    style: &ShapeStyle,
) -> Result<(), DrawingErrorKind<DB::ErrorType>> {
    let polygon = |b: &mut DB, pts: Vec<BackendCoord>| {
        if style.filled {
            b.fill_polygon(pts, style)
        } else {
            let mut closed = pts.clone();
            closed.push(pts[0]);
            b.draw_path(closed, style)
        }
    };
    match kind % 5 {
        0 => backend.draw_circle((x, y), s.max(1) as u32, style, style.filled),
        1 => polygon(backend, vec![(x, y - s - 1), (x + s + 1, y + s - 1), (x - s - 1, y + s - 1)]),
        2 => backend.draw_rect((x - s + 1, y - s + 1), (x + s - 1, y + s - 1), style, style.filled),
        3 => polygon(backend, vec![(x, y - s - 1), (x + s + 1, y), (x, y + s + 1), (x - s - 1, y)]),
        _ => {
            let thick = style.stroke_width(2);
            backend.draw_line((x - s, y - s), (x + s, y + s), &thick)?;
            backend.draw_line((x - s, y + s), (x + s, y - s), &thick)
        }
    }
}
