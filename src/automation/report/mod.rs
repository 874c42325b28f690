//! Figures, tables and the manuscript: the presentation layer of a reproduction.
//!
//! Every figure function writes `<stem>.png` and `<stem>.svg` from one drawing routine
//! (see `canvas`), with the DejaVu Sans font embedded in the binary (see `font`), so
//! rendering needs nothing from the system. Tables are written as `<stem>.csv` and
//! `<stem>.md`; [`write_manuscript`] assembles Markdown that embeds the figures and
//! inlines the tables.
//!
//! All functions return `Err(String)` naming the offending path and create parent
//! directories as needed.

mod canvas;
mod colors;
mod files;
mod font;
mod glyph;
mod line;
mod manuscript;
mod map;
mod order;
mod pareto;
mod particles;
mod table;

pub use line::{line_figure, LineFigure, Series, SeriesStyle};
pub use manuscript::{write_manuscript, Block, Item, Manuscript, Part, Section};
pub use map::{outcome_map, Outcome, OutcomeMap};
pub use order::observed_order;
pub use pareto::{pareto_figure, pareto_front, ParetoFigure};
pub use particles::{particle_figure, Arrows, ScatterField};
pub use table::{write_table, Table};

#[cfg(test)]
pub(crate) mod testutil;
