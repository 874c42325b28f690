//! Tables written as CSV (for tools) and GitHub Markdown (for the manuscript).

use super::files::with_suffix;
use super::files::write_atomic;
use std::path::Path;

/// A table of preformatted cells.
#[derive(Clone, Debug)]
pub struct Table {
    /// What the table holds; written as an HTML comment atop the Markdown file (the
    /// manuscript supplies the visible caption).
    pub title: String,
    /// Column headers.
    pub headers: Vec<String>,
    /// Rows of cells; short rows are padded with empty cells.
    pub rows: Vec<Vec<String>>,
}

/// Writes `<stem>.csv` and `<stem>.md` (each atomically). Fails, naming the path, if a
/// row has more cells than there are headers.
pub fn write_table(t: &Table, stem: &Path) -> Result<(), String> {
    let csv_path = with_suffix(stem, ".csv");
    let md_path = with_suffix(stem, ".md");
    let width = t.headers.len();
    if let Some(i) = t.rows.iter().position(|r| r.len() > width) {
        return Err(format!(
            "{}: row {i} has {} cells but the table has {width} columns",
            csv_path.display(),
            t.rows[i].len()
        ));
    }
    let padded = |r: &Vec<String>| -> Vec<String> {
        let mut r = r.clone();
        r.resize(width, String::new());
        r
    };
    let mut w = csv::Writer::from_writer(Vec::new());
    let named = |e: csv::Error| format!("{}: {e}", csv_path.display());
    w.write_record(&t.headers).map_err(named)?;
    for r in &t.rows {
        w.write_record(padded(r)).map_err(named)?;
    }
    let bytes = w.into_inner().map_err(|e| format!("{}: {e}", csv_path.display()))?;
    write_atomic(&csv_path, &bytes)?;
    write_atomic(&md_path, markdown(t, width, padded).as_bytes())
}

fn markdown(t: &Table, width: usize, padded: impl Fn(&Vec<String>) -> Vec<String>) -> String {
    let cell = |c: &str| c.replace('|', "\\|").replace(['\r', '\n'], " ");
    let line =
        |cells: &[String]| format!("| {} |\n", cells.iter().map(|c| cell(c)).collect::<Vec<_>>().join(" | "));
    let mut md = format!("<!-- {} -->\n", t.title.replace("--", "- -"));
    md += &line(&t.headers);
    md += &format!("|{}\n", "---|".repeat(width));
    for r in &t.rows {
        md += &line(&padded(r));
    }
    md
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> Table {
        Table {
            title: "Convergence of EDAC".into(),
            headers: vec!["nx".into(), "L2 error".into(), "order".into()],
            rows: vec![
                vec!["25".into(), "1.2e-2".into(), "".into()],
                vec!["50".into(), "3.1e-3".into(), "1.95".into()],
                vec!["100".into(), "a|b, \"quoted\"".into()],
            ],
        }
    }

    #[test]
    fn csv_and_markdown_round_trip() {
        let dir = tempfile::tempdir().unwrap();
        let stem = dir.path().join("tables/conv");
        let t = sample();
        write_table(&t, &stem).unwrap();

        let mut r = csv::Reader::from_path(dir.path().join("tables/conv.csv")).unwrap();
        assert_eq!(r.headers().unwrap().iter().collect::<Vec<_>>(), t.headers);
        let rows: Vec<Vec<String>> =
            r.records().map(|rec| rec.unwrap().iter().map(String::from).collect()).collect();
        assert_eq!(rows.len(), 3);
        assert_eq!(rows[0], t.rows[0]);
        assert_eq!(rows[1], t.rows[1]);
        assert_eq!(rows[2], vec!["100", "a|b, \"quoted\"", ""]);

        let md = std::fs::read_to_string(dir.path().join("tables/conv.md")).unwrap();
        let table_lines: Vec<&str> = md.lines().filter(|l| l.starts_with('|')).collect();
        assert_eq!(table_lines.len(), 2 + 3);
        assert_eq!(table_lines[0], "| nx | L2 error | order |");
        assert_eq!(table_lines[1], "|---|---|---|");
        assert_eq!(table_lines[4], "| 100 | a\\|b, \"quoted\" |  |");
        assert!(md.contains("Convergence of EDAC"));
    }

    #[test]
    fn too_long_row_is_an_error_naming_the_file() {
        let dir = tempfile::tempdir().unwrap();
        let mut t = sample();
        t.rows.push(vec!["1".into(), "2".into(), "3".into(), "4".into()]);
        let e = write_table(&t, &dir.path().join("bad")).unwrap_err();
        assert!(e.contains("bad.csv") && e.contains("row 3"), "{e}");
    }
}
