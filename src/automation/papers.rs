//! The papers the problems reproduce, in the order the manuscript takes them: the CTVF
//! paper first, then the chapters of the thesis that builds on it, then the other seed
//! papers. A problem names its paper by key (`paper = "ctvf"`); the manuscript has one part
//! per paper that has a problem, its figures and tables under the paper's own numbers.

/// One paper.
#[derive(Clone, Copy, Debug)]
pub struct Paper {
    /// Key a problem file names it by.
    pub key: &'static str,
    /// Authors, title, where it appeared: the heading of its part of the manuscript.
    pub title: &'static str,
    /// A short name, for the summary table.
    pub short: &'static str,
    /// The seed text it is read from (`../shared/seeds/`), by number.
    pub seed: &'static str,
}

/// Every paper a problem may name, in the manuscript's order.
pub const PAPERS: &[Paper] = &[
    Paper {
        key: "ctvf",
        short: "CTVF",
        title: "Adepu & Ramachandran: a corrected transport-velocity formulation for fluid and \
                structural mechanics with SPH",
        seed: "000",
    },
    Paper {
        key: "thesis_collision",
        short: "Thesis ch. 3",
        title: "Adepu (PhD thesis), chapter 3: collision SPH",
        seed: "003",
    },
    Paper {
        key: "thesis_fsi",
        short: "Thesis ch. 4",
        title: "Adepu (PhD thesis), chapter 4: fluid-structure interaction",
        seed: "003",
    },
    Paper {
        key: "thesis_rigid_fluid",
        short: "Thesis ch. 5",
        title: "Adepu (PhD thesis), chapter 5: rigid-fluid coupling",
        seed: "003",
    },
    Paper {
        key: "thesis_erosion",
        short: "Thesis ch. 6",
        title: "Adepu (PhD thesis), chapter 6: erosion",
        seed: "003",
    },
    Paper {
        key: "adaptive_kernel",
        short: "Adaptive kernel",
        title: "An adaptive approach to remove tensile instability in SPH for weakly compressible fluids",
        seed: "001",
    },
    Paper {
        key: "ale_fictitious_pressure",
        short: "ALE fictitious pressure",
        title: "A fictitious pressure for the transport velocity of ALE-SPH",
        seed: "002",
    },
];

/// The paper of key `key`, or an error listing the keys.
pub fn find(key: &str) -> Result<&'static Paper, String> {
    PAPERS.iter().find(|p| p.key == key).ok_or_else(|| {
        let keys: Vec<_> = PAPERS.iter().map(|p| p.key).collect();
        format!("no paper `{key}`; papers: {}", keys.join(", "))
    })
}

/// The position of paper `key` in [`PAPERS`] (unknown keys last).
pub fn order(key: &str) -> usize {
    PAPERS.iter().position(|p| p.key == key).unwrap_or(PAPERS.len())
}

/// A sort key for a paper's section heading, by its leading number (`4.1 Taylor-Green` before
/// `4.10 ...`, and both after `3.4 ...`); headings without a number sort last, by name.
pub fn section_key(heading: &str) -> (Vec<u32>, String) {
    let lead = heading.split_whitespace().next().unwrap_or("");
    let nums: Option<Vec<u32>> =
        lead.trim_end_matches('.').split('.').map(|x| x.parse().ok()).collect::<Option<Vec<u32>>>();
    match nums {
        Some(n) if !n.is_empty() => (n, heading.to_string()),
        _ => (vec![u32::MAX], heading.to_string()),
    }
}

/// A sort key for a figure or table number in the paper's order: figures by number and
/// panel (`Fig. 2` < `Fig. 10a` < `Fig. 10b` < `Fig. 13 (right)`), then tables by number;
/// anything else last.
pub fn number_key(number: &str) -> (u8, u32, String) {
    let s = number.trim();
    let (kind, rest) = if let Some(r) = s.strip_prefix("Fig.").or_else(|| s.strip_prefix("Figure")) {
        (0, r)
    } else if let Some(r) = s.strip_prefix("Table") {
        (1, r)
    } else {
        return (2, u32::MAX, s.to_string());
    };
    let rest = rest.trim_start();
    let digits: String = rest.chars().take_while(|c| c.is_ascii_digit()).collect();
    match digits.parse() {
        Ok(n) => (kind, n, rest[digits.len()..].trim().to_string()),
        Err(_) => (2, u32::MAX, s.to_string()),
    }
}

/// Whether `number` is one the manuscript can order: `Fig. N...` or `Table N...`.
pub fn valid_number(number: &str) -> bool {
    number_key(number).0 < 2
}

/// The figure a numbered panel belongs to: `Fig. 17` for `Fig. 17a`, `Fig. 13` for
/// `Fig. 13 (right)`.
pub fn figure_of(number: &str) -> String {
    let (kind, n, _) = number_key(number);
    match kind {
        0 => format!("Fig. {n}"),
        1 => format!("Table {n}"),
        _ => number.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_and_sections_sort_in_the_papers_order() {
        let mut v = vec!["Table 1", "Fig. 10b", "Fig. 13 (right)", "Fig. 2", "Fig. 10a", "Fig. 13 (left)"];
        v.sort_by_key(|n| number_key(n));
        assert_eq!(v, ["Fig. 2", "Fig. 10a", "Fig. 10b", "Fig. 13 (left)", "Fig. 13 (right)", "Table 1"]);
        assert_eq!(figure_of("Fig. 17c"), "Fig. 17");
        assert!(valid_number("Fig. 5") && !valid_number("fig5") && !valid_number("Fig. x"));
        let mut s = vec!["4.10 Later", "4.1 Taylor-Green vortex", "3.4 Free surface", "Other"];
        s.sort_by_key(|h| section_key(h));
        assert_eq!(s, ["3.4 Free surface", "4.1 Taylor-Green vortex", "4.10 Later", "Other"]);
        assert_eq!(order("ctvf"), 0);
        assert!(find("nope").unwrap_err().contains("ctvf"));
    }
}
