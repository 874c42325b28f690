//! The automation framework: everything above the scenes that turns runs into papers.
//!
//! - [`registry`]: problems from `problems/*.toml`, checked and expanded into cases;
//! - [`papers`]: the papers reproduced, in the manuscript's order;
//! - [`cache`] and [`lock`]: one folder per case keyed by a sha2 digest, one runner per case;
//!   [`results`]: the committed results, a read-only second layer of the cache, and their
//!   export;
//! - [`reads`]: what the figures and tables read from a case's folder, which a committed
//!   result must hold to be done;
//! - [`runner`]: a job pool of `simulate` subprocesses; [`estimate`]: what the cases would
//!   cost, from a short run of each, before they run;
//! - [`slurm`]: the same cases as job arrays on a Slurm cluster;
//! - [`check`]: bounds for CI and case states; [`baseline`]: the quick preset's results
//!   committed as regression baselines, compared metric by metric, rewritten by `bless`;
//! - [`study`]: the figures and tables a problem declares, the speed-accuracy trade and
//!   stability maps, the verdicts on the paper's claims, and the manuscript;
//! - [`report`]: figures, tables and the manuscript built from run results;
//! - [`commands`]: the commands behind the CLI.
//!
//! It uses the scenes' declared parameters and the `summary.json` / `timeseries.csv` /
//! `.vtu` formats, nothing else from `solver`.

pub mod baseline;
pub mod cache;
pub mod check;
pub mod commands;
pub mod estimate;
pub mod lock;
pub mod papers;
pub mod reads;
pub mod registry;
pub mod report;
pub mod results;
pub mod runner;
pub mod slurm;
pub mod study;

#[cfg(test)]
mod tests {
    /// STYLE 6.9: the solver never imports the scenes or the automation half.
    #[test]
    fn solver_does_not_depend_on_scenes_or_automation() {
        fn walk(dir: &std::path::Path, bad: &mut Vec<String>) {
            for e in std::fs::read_dir(dir).unwrap().flatten() {
                let p = e.path();
                if p.is_dir() {
                    walk(&p, bad);
                } else if p.extension().is_some_and(|x| x == "rs") {
                    let s = std::fs::read_to_string(&p).unwrap();
                    if s.contains("crate::scenes") || s.contains("crate::automation") {
                        bad.push(p.display().to_string());
                    }
                }
            }
        }
        let mut bad = Vec::new();
        walk(&std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("src/solver"), &mut bad);
        assert!(bad.is_empty(), "solver files importing scenes/automation: {bad:?}");
    }
}
