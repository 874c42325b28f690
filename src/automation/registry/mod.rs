//! The problem registry: reads `problems/*.toml`, checks every entry against the scene's
//! declared parameters and metrics, and expands parameter grids into named cases for a
//! preset. Every error names the file, the line and the key; nothing runs unless every
//! problem file is valid. The schema is documented in `docs/problems.md`.
//!
//! - `schema`: the TOML schema, as written (serde structs with their spans);
//! - `model`: the resolved problem the rest of the crate uses ([`Problem`], [`Case`],
//!   [`Figure`], [`Table`], [`Bound`], [`Claim`], [`Select`]);
//! - `load`: reading a file or a folder of them ([`load_dir`], [`load`], [`parse`]);
//! - `expand`: presets and grids expanded into named cases;
//! - `checks`: figures, tables, bounds and claims checked against the scene and the cases;
//! - `reference`: the published points a `profile` figure is drawn against.

mod checks;
mod expand;
mod load;
mod model;
mod reference;
mod schema;

pub use load::{load, load_dir, parse};
pub use model::{
    glob_matches, BaselineRule, Bound, Case, Claim, ClaimTest, Figure, FigureKind, ItemInfo, Problem,
    Reference, Select, Table, Test, DEFAULT_PRESET,
};
pub use reference::reference_dir;

#[cfg(test)]
mod testutil;
