//! The manuscript: Markdown assembling text, figures and tables side by side with what
//! the paper reports.

use super::files::write_atomic;
use std::fmt::Write as _;
use std::path::Path;

/// A whole reproduction report.
#[derive(Clone, Debug)]
pub struct Manuscript {
    /// Document title (level-1 heading).
    pub title: String,
    /// Paragraphs before the first section.
    pub intro: String,
    /// The sections, in order.
    pub sections: Vec<Section>,
}

/// One section (level-2 heading).
#[derive(Clone, Debug)]
pub struct Section {
    /// Section heading.
    pub title: String,
    /// Paragraphs before the items.
    pub text: String,
    /// Figures, tables and further text, in order.
    pub items: Vec<Item>,
}

/// Content of a section.
#[derive(Clone, Debug)]
pub enum Item {
    /// An image with the comparison to the paper.
    Figure {
        /// Image path relative to the manuscript file.
        path: String,
        /// Caption (also the image's alt text).
        caption: String,
        /// What the paper shows.
        paper: String,
        /// What this reproduction got, with numbers.
        ours: String,
    },
    /// A table written by [`write_table`](super::write_table), inlined from its `.md` file.
    Table {
        /// Markdown file path relative to the manuscript file.
        md_path: String,
        /// Caption line written above the table.
        caption: String,
    },
    /// A paragraph.
    Text(String),
}

/// Writes `m` as Markdown to `path` (atomically: temporary file, then rename). Figures
/// and tables are numbered; each figure is `![caption](path)`, a caption line and a
/// line `**Paper:** ... **Here:** ...`; tables are read from their `.md` files
/// (relative to `path`'s directory) and inlined under a caption line.
pub fn write_manuscript(m: &Manuscript, path: &Path) -> Result<(), String> {
    let base = path.parent().unwrap_or(Path::new(""));
    let mut out = format!("# {}\n\n", m.title);
    push_text(&mut out, &m.intro);
    let (mut figures, mut tables) = (0, 0);
    for s in &m.sections {
        let _ = write!(out, "## {}\n\n", s.title);
        push_text(&mut out, &s.text);
        for item in &s.items {
            match item {
                Item::Figure { path: img, caption, paper, ours } => {
                    figures += 1;
                    let alt = caption.replace(['[', ']', '\n'], " ");
                    let _ = write!(out, "![{alt}]({})\n\n", img.replace(' ', "%20"));
                    let _ = write!(out, "**Figure {figures}.** {caption}\n\n");
                    let _ = write!(out, "**Paper:** {paper} **Here:** {ours}\n\n");
                }
                Item::Table { md_path, caption } => {
                    tables += 1;
                    let file = base.join(md_path);
                    let md =
                        std::fs::read_to_string(&file).map_err(|e| format!("{}: {e}", file.display()))?;
                    let _ = write!(out, "**Table {tables}.** {caption}\n\n{}\n\n", md.trim_end());
                }
                Item::Text(t) => push_text(&mut out, t),
            }
        }
    }
    write_atomic(path, out.as_bytes())
}

fn push_text(out: &mut String, text: &str) {
    let t = text.trim();
    if !t.is_empty() {
        out.push_str(t);
        out.push_str("\n\n");
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::automation::report::{write_table, Table};

    #[test]
    fn embeds_figures_and_inlines_tables() {
        let dir = tempfile::tempdir().unwrap();
        let t = Table {
            title: "orders".into(),
            headers: vec!["scheme".into(), "order".into()],
            rows: vec![vec!["EDAC".into(), "1.98".into()], vec!["TVF".into(), "1.91".into()]],
        };
        write_table(&t, &dir.path().join("paper/tables/orders")).unwrap();
        let m = Manuscript {
            title: "Reproduction of CTVF".into(),
            intro: "We rerun every test case.".into(),
            sections: vec![Section {
                title: "Taylor-Green vortex".into(),
                text: "Periodic box, Re = 100.".into(),
                items: vec![
                    Item::Figure {
                        path: "figures/tg_decay.png".into(),
                        caption: "Kinetic energy decay".into(),
                        paper: "all schemes follow the exact decay.".into(),
                        ours: "max deviation 1.2 % (CTVF).".into(),
                    },
                    Item::Table { md_path: "tables/orders.md".into(), caption: "Observed orders".into() },
                    Item::Text("CTVF is the most accurate.".into()),
                    Item::Figure {
                        path: "figures/tg_pareto.svg".into(),
                        caption: "Cost vs accuracy".into(),
                        paper: "not shown.".into(),
                        ours: "CTVF on the front for nx >= 50.".into(),
                    },
                ],
            }],
        };
        let path = dir.path().join("paper/manuscript.md");
        write_manuscript(&m, &path).unwrap();
        let md = std::fs::read_to_string(&path).unwrap();
        assert!(md.starts_with("# Reproduction of CTVF\n"));
        assert!(md.contains("![Kinetic energy decay](figures/tg_decay.png)"));
        assert!(md.contains("![Cost vs accuracy](figures/tg_pareto.svg)"));
        assert!(md.contains(
            "**Paper:** all schemes follow the exact decay. **Here:** max deviation 1.2 % (CTVF)."
        ));
        assert!(md.contains("**Table 1.** Observed orders"));
        assert!(md.contains("| scheme | order |\n|---|---|\n| EDAC | 1.98 |\n| TVF | 1.91 |"));
        assert!(md.contains("**Figure 2.** Cost vs accuracy"));
        let leftovers: Vec<_> =
            std::fs::read_dir(dir.path().join("paper")).unwrap().map(|e| e.unwrap().file_name()).collect();
        assert_eq!(leftovers.len(), 2, "{leftovers:?}"); // manuscript.md and tables/

        let missing = Manuscript {
            sections: vec![Section {
                title: "s".into(),
                text: String::new(),
                items: vec![Item::Table { md_path: "nope.md".into(), caption: "c".into() }],
            }],
            ..m
        };
        let e = write_manuscript(&missing, &path).unwrap_err();
        assert!(e.contains("nope.md"), "{e}");
    }
}
