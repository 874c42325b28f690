//! The manuscript from every problem's items and verdicts: one part per paper, in the
//! papers' order ([`papers::PAPERS`]); in it the paper's sections (by their numbers), each
//! with the figures and tables the paper numbers (in the paper's order, whichever problem
//! draws them) after the descriptions of the problems the section holds; then one
//! "beyond the paper" section per problem for what the paper does not show. A summary table
//! of every claim and its verdict comes first.

use super::{ProblemReport, ReportItem, Verdict};
use crate::automation::papers;
use crate::automation::registry::Problem;
use crate::automation::report::{Manuscript, Part, Section};

/// The title and the opening paragraphs.
#[derive(Clone, Debug)]
pub struct Header {
    /// The title.
    pub title: String,
    /// The paragraphs before the summary.
    pub intro: String,
    /// The coverage table of the cases (headers, rows), with the estimated cost of those
    /// without a result.
    pub cases: Option<(Vec<String>, Vec<Vec<String>>)>,
}

/// A problem's description for the manuscript, with where it comes from.
fn problem_text(p: &Problem) -> String {
    format!(
        "{}\n\n*Problem `{}` (`problems/{}.toml`), `{}` preset: {} case(s).*",
        p.description.trim(),
        p.name,
        p.name,
        p.preset,
        p.cases.len()
    )
}

/// The section a numbered item belongs to.
fn section_of<'a>(p: &'a Problem, it: &'a ReportItem) -> Option<&'a str> {
    it.info.number.as_ref()?;
    it.info.section.as_deref().or(p.section.as_deref())
}

/// The manuscript of `reports` (every problem, in load order) under `header`.
pub fn manuscript(header: Header, reports: &[(&Problem, &ProblemReport)]) -> Manuscript {
    let mut parts = Vec::new();
    let mut summary = Vec::new();
    let mut keys: Vec<&str> = reports.iter().map(|(p, _)| p.paper.as_str()).collect();
    keys.sort_by_key(|k| papers::order(k));
    keys.dedup();
    for key in keys {
        let paper = papers::find(key).ok();
        let short = paper.map_or(key, |p| p.short);
        let mine: Vec<&(&Problem, &ProblemReport)> = reports.iter().filter(|(p, _)| p.paper == key).collect();
        // The paper's sections, by number; each with its numbered items, in the paper's order.
        let mut heads: Vec<&str> =
            mine.iter().flat_map(|(p, r)| r.items.iter().filter_map(move |it| section_of(p, it))).collect();
        heads.sort_by_key(|h| papers::section_key(h));
        heads.dedup();
        let mut sections = Vec::new();
        let mut described: Vec<&str> = Vec::new();
        for head in heads {
            let mut items: Vec<(&ReportItem, usize)> = Vec::new();
            let mut text = Vec::new();
            for (k, (p, r)) in mine.iter().enumerate() {
                let here: Vec<&ReportItem> =
                    r.items.iter().filter(|it| section_of(p, it) == Some(head)).collect();
                if here.is_empty() {
                    continue;
                }
                // A problem is described in its own section, or in the first that shows it.
                let home =
                    p.section.as_deref().filter(|s| r.items.iter().any(|it| section_of(p, it) == Some(*s)));
                if !described.contains(&p.name.as_str()) && home.is_none_or(|h| h == head) {
                    text.push(problem_text(p));
                    described.push(&p.name);
                }
                items.extend(here.into_iter().map(|it| (it, k)));
            }
            items.sort_by(|a, b| {
                let ka = papers::number_key(a.0.info.number.as_deref().unwrap_or(""));
                let kb = papers::number_key(b.0.info.number.as_deref().unwrap_or(""));
                ka.cmp(&kb).then(a.1.cmp(&b.1))
            });
            sections.push(Section {
                title: head.to_string(),
                text: text.join("\n\n"),
                items: items.into_iter().map(|(it, _)| it.item.clone()).collect(),
            });
        }
        // Beyond the paper: one section per problem with unnumbered items, ordered by the
        // paper's section the problem belongs to, then by name.
        let mut beyond: Vec<&&(&Problem, &ProblemReport)> =
            mine.iter().filter(|(_, r)| r.items.iter().any(|it| it.info.number.is_none())).collect();
        beyond.sort_by_key(|(p, _)| {
            (
                p.section.as_deref().map(papers::section_key).unwrap_or((vec![u32::MAX], String::new())),
                p.name.clone(),
            )
        });
        for (p, r) in beyond {
            let text = if described.contains(&p.name.as_str()) {
                let at = p.section.as_deref().unwrap_or("above");
                format!("*More of problem `{}` (described in {at}).*", p.name)
            } else {
                problem_text(p)
            };
            sections.push(Section {
                title: format!("Beyond the paper: {}", p.title),
                text,
                items: r
                    .items
                    .iter()
                    .filter(|it| it.info.number.is_none())
                    .map(|it| it.item.clone())
                    .collect(),
            });
        }
        // The summary rows: numbered items in the paper's order, then the rest.
        // (paper order, number order), problem index, cells
        type Row = ((u8, (u8, u32, String)), usize, Vec<String>);
        let mut rows: Vec<Row> = Vec::new();
        for (k, (p, r)) in mine.iter().enumerate() {
            for v in &r.verdicts {
                let it = r.items.iter().find(|it| it.id == v.claim.figure);
                let number = it.and_then(|it| it.info.number.clone());
                let name = match (&number, it) {
                    (Some(n), _) => format!("{short} {n}"),
                    (None, Some(it)) => format!("{short}, beyond: {}", it.item.heading),
                    (None, None) => format!("{short}: {}", v.claim.figure),
                };
                let order = match &number {
                    Some(n) => (0, papers::number_key(n)),
                    None => (1, (0, 0, p.name.clone())),
                };
                rows.push((order, k, vec![name, v.claim.claim.trim().to_string(), v.short()]));
            }
        }
        rows.sort_by(|a, b| a.0.cmp(&b.0).then(a.1.cmp(&b.1)));
        summary.extend(rows.into_iter().map(|r| r.2));
        parts.push(Part {
            title: paper.map_or_else(|| key.to_string(), |p| p.title.to_string()),
            text: String::new(),
            sections,
        });
    }
    let coverage = header.cases.map(|(h, rows)| {
        let count = |v: Verdict| {
            reports.iter().flat_map(|(_, r)| &r.verdicts).filter(|c| c.own.verdict == v).count()
        };
        let text = format!(
            "Of the {} claims above, {} are reproduced, {} not reproduced and {} not run at their own preset. \
             The cases of every problem, with a result or without one; the cost of those without is the sum of \
             estimates measured from a short run of each case (`sphrepro reproduce --dry-run`, on one thread; \
             they run low where a step grows dearer during a run).",
            reports.iter().map(|(_, r)| r.verdicts.len()).sum::<usize>(),
            count(Verdict::Reproduced),
            count(Verdict::NotReproduced),
            count(Verdict::NotRun)
        );
        (text, h, rows)
    });
    Manuscript {
        title: header.title,
        intro: header.intro,
        coverage,
        summary: (!summary.is_empty())
            .then(|| (vec!["figure or table".into(), "the paper's claim".into(), "verdict".into()], summary)),
        parts,
    }
}
