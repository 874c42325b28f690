//! The manuscript: Markdown that follows the papers. One part per paper, in the papers'
//! order; within a part, the paper's sections with its figures and tables under the paper's
//! own numbers, then what the paper does not show. Each item: the paper's caption in our
//! words, our figure or table, the paper's claims with their computed verdicts, and a
//! discussion. A summary table of every claim and its verdict comes first.
//!
//! The text holds nothing that changes from run to run (no date, no time, no commit), so
//! that the same results give the same bytes.

use super::files::write_atomic;
use std::fmt::Write as _;
use std::path::Path;

/// A whole reproduction report.
#[derive(Clone, Debug, Default)]
pub struct Manuscript {
    /// Document title (level-1 heading).
    pub title: String,
    /// Paragraphs before the summary.
    pub intro: String,
    /// The summary table: headers, then one row per claim.
    pub summary: Option<(Vec<String>, Vec<Vec<String>>)>,
    /// What the results cover, after the summary: a paragraph, then a table's headers and
    /// rows.
    pub coverage: Option<(String, Vec<String>, Vec<Vec<String>>)>,
    /// One part per paper (level-2 heading).
    pub parts: Vec<Part>,
}

/// The part of one paper.
#[derive(Clone, Debug, Default)]
pub struct Part {
    /// Heading.
    pub title: String,
    /// Paragraphs before its sections.
    pub text: String,
    /// Its sections (level-3 headings): the paper's, then "beyond the paper".
    pub sections: Vec<Section>,
}

/// One section (level-3 heading).
#[derive(Clone, Debug, Default)]
pub struct Section {
    /// Section heading.
    pub title: String,
    /// Paragraphs before the items.
    pub text: String,
    /// Figures and tables, in order.
    pub items: Vec<Item>,
}

/// One figure or table of a problem (level-4 heading): the paper's number (or our title),
/// the paper's caption, what we drew, the verdicts on the paper's claims, a discussion.
#[derive(Clone, Debug, Default)]
pub struct Item {
    /// Heading: the paper's number (`Fig. 14a`) or, beyond the paper, a title.
    pub heading: String,
    /// The paper's caption in our words (empty beyond the paper).
    pub paper_caption: String,
    /// What we drew, in order.
    pub blocks: Vec<Block>,
    /// The verdicts on the paper's claims, one paragraph each.
    pub verdicts: Vec<String>,
    /// Discussion (Markdown).
    pub discussion: String,
}

/// Part of an item's body.
#[derive(Clone, Debug)]
pub enum Block {
    /// An image, its caption and what the results say about it.
    Image {
        /// Image path relative to the manuscript file.
        path: String,
        /// Caption (also the image's alt text).
        caption: String,
        /// What the results show, with numbers.
        ours: String,
    },
    /// A figure that could not be drawn: why.
    Missing {
        /// Caption of the figure that would be here.
        caption: String,
        /// Why it is not.
        why: String,
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

/// Writes `m` as Markdown to `path` (atomically: temporary file, then rename). Tables are
/// read from their `.md` files (relative to `path`'s directory) and inlined under their
/// caption line.
pub fn write_manuscript(m: &Manuscript, path: &Path) -> Result<(), String> {
    let base = path.parent().unwrap_or(Path::new(""));
    let mut out = format!("# {}\n\n", m.title);
    push_text(&mut out, &m.intro);
    if let Some((headers, rows)) = &m.summary {
        out += "## Summary of the verdicts\n\n";
        out += &markdown_table(headers, rows);
        out += "\n";
    }
    if let Some((text, headers, rows)) = &m.coverage {
        out += "## What the results cover\n\n";
        push_text(&mut out, text);
        out += &markdown_table(headers, rows);
        out += "\n";
    }
    for part in &m.parts {
        let _ = write!(out, "## {}\n\n", part.title);
        push_text(&mut out, &part.text);
        for s in &part.sections {
            let _ = write!(out, "### {}\n\n", s.title);
            push_text(&mut out, &s.text);
            for item in &s.items {
                write_item(&mut out, item, base)?;
            }
        }
    }
    let text = format!("{}\n", out.trim_end());
    write_atomic(path, text.as_bytes())
}

fn write_item(out: &mut String, item: &Item, base: &Path) -> Result<(), String> {
    let _ = write!(out, "#### {}\n\n", item.heading);
    if !item.paper_caption.trim().is_empty() {
        let _ = write!(out, "*In the paper:* {}\n\n", item.paper_caption.trim());
    }
    for b in &item.blocks {
        match b {
            Block::Image { path: img, caption, ours } => {
                let alt = caption.replace(['[', ']', '\n'], " ");
                let _ = write!(out, "![{alt}]({})\n\n", img.replace(' ', "%20"));
                let _ = write!(out, "*Ours:* {}", caption.trim());
                if !ours.trim().is_empty() {
                    let _ = write!(out, " {}", ours.trim());
                }
                out.push_str("\n\n");
            }
            Block::Missing { caption, why } => {
                let _ = write!(
                    out,
                    "*Ours:* {} *(Not drawn: {}.)*\n\n",
                    caption.trim(),
                    why.trim_end_matches('.')
                );
            }
            Block::Table { md_path, caption } => {
                let file = base.join(md_path);
                let md = std::fs::read_to_string(&file).map_err(|e| format!("{}: {e}", file.display()))?;
                let _ = write!(out, "*Table:* {}\n\n{}\n\n", caption.trim(), md.trim_end());
            }
            Block::Text(t) => push_text(out, t),
        }
    }
    for v in &item.verdicts {
        push_text(out, v);
    }
    push_text(out, &item.discussion);
    Ok(())
}

/// A GitHub Markdown table of preformatted cells.
pub(crate) fn markdown_table(headers: &[String], rows: &[Vec<String>]) -> String {
    let cell = |c: &str| c.replace('|', "\\|").replace(['\r', '\n'], " ");
    let line =
        |cells: &[String]| format!("| {} |\n", cells.iter().map(|c| cell(c)).collect::<Vec<_>>().join(" | "));
    let mut md = line(headers);
    md += &format!("|{}\n", "---|".repeat(headers.len()));
    for r in rows {
        let mut r = r.clone();
        r.resize(headers.len(), String::new());
        md += &line(&r);
    }
    md
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
    fn parts_sections_and_items_in_order() {
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
            summary: Some((
                vec!["item".into(), "claim".into(), "verdict".into()],
                vec![vec!["Fig. 6a".into(), "decays as exact".into(), "reproduced".into()]],
            )),
            coverage: Some((
                "The cases.".into(),
                vec!["problem".into(), "cases".into()],
                vec![vec!["`tg`".into(), "3".into()]],
            )),
            parts: vec![Part {
                title: "The CTVF paper".into(),
                text: String::new(),
                sections: vec![Section {
                    title: "4.1 Taylor-Green vortex".into(),
                    text: "Periodic box, Re = 100.".into(),
                    items: vec![
                        Item {
                            heading: "Fig. 6a".into(),
                            paper_caption: "Decay of max |u|, SPST, Re = 100.".into(),
                            blocks: vec![
                                Block::Image {
                                    path: "figures/tg_decay.png".into(),
                                    caption: "Kinetic energy decay".into(),
                                    ours: "max deviation 1.2 %.".into(),
                                },
                                Block::Table {
                                    md_path: "tables/orders.md".into(),
                                    caption: "Observed orders".into(),
                                },
                            ],
                            verdicts: vec!["**Verdict: reproduced**".into()],
                            discussion: "CTVF is the most accurate.".into(),
                        },
                        Item {
                            heading: "Cost".into(),
                            blocks: vec![Block::Missing {
                                caption: "Cost vs accuracy".into(),
                                why: "no result".into(),
                            }],
                            ..Item::default()
                        },
                    ],
                }],
            }],
        };
        let path = dir.path().join("paper/manuscript.md");
        write_manuscript(&m, &path).unwrap();
        let md = std::fs::read_to_string(&path).unwrap();
        assert!(md.starts_with("# Reproduction of CTVF\n\nWe rerun"), "{md}");
        assert!(md.contains(
            "## Summary of the verdicts\n\n| item | claim | verdict |\n|---|---|---|\n| Fig. 6a |"
        ));
        let order = [
            "## What the results cover\n\nThe cases.\n\n| problem | cases |\n|---|---|\n| `tg` | 3 |",
            "## The CTVF paper",
            "### 4.1 Taylor-Green",
            "#### Fig. 6a",
            "*In the paper:* Decay",
            "![Kinetic energy decay](figures/tg_decay.png)",
            "*Ours:* Kinetic energy decay max deviation",
            "*Table:* Observed orders",
            "| EDAC | 1.98 |",
            "**Verdict: reproduced**",
            "CTVF is the most accurate.",
            "#### Cost",
            "*(Not drawn: no result.)*",
        ];
        let mut at = 0;
        for o in order {
            let i = md[at..].find(o).unwrap_or_else(|| panic!("{o} after {at}: {md}"));
            at += i;
        }
        assert!(md.ends_with(".)*\n"), "{md:?}");

        let missing = Manuscript {
            parts: vec![Part {
                sections: vec![Section {
                    items: vec![Item {
                        blocks: vec![Block::Table { md_path: "nope.md".into(), caption: "c".into() }],
                        ..Item::default()
                    }],
                    ..Section::default()
                }],
                ..Part::default()
            }],
            ..m
        };
        let e = write_manuscript(&missing, &path).unwrap_err();
        assert!(e.contains("nope.md"), "{e}");
    }
}
