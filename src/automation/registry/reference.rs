//! The published points a `profile` figure is drawn against: a CSV file in
//! `reference_data/`, read and checked when the problem file is loaded.

use super::model::{valid_name, Reference};
use super::schema::{Loc, ReferenceFile, Span};
use std::path::{Path, PathBuf};

/// The folder of published curves for the problem file at `path`: `reference_data/` next
/// to the problems folder (`problems/x.toml` -> `reference_data/`).
pub fn reference_dir(path: &Path) -> PathBuf {
    let problems = path.parent().unwrap_or(Path::new(""));
    match problems.parent() {
        Some(root) => root.join("reference_data"),
        None => problems.join("..").join("reference_data"),
    }
}

/// Reads and checks the published points of a `profile` figure: the file exists under
/// `reference_data/`, has both columns, and every value is a number.
pub(super) fn read(loc: &Loc, span: Span, key: &str, r: &ReferenceFile) -> Result<Reference, String> {
    let key = format!("{key}.reference");
    if !valid_name(&r.file) || r.file.starts_with('.') {
        return Err(loc.err(
            span,
            &format!("{key}.file"),
            format!("`{}` must be a file name in reference_data/ (letters, digits, `.`, `_`, `-`)", r.file),
        ));
    }
    let path = reference_dir(loc.path).join(&r.file);
    let mut rd = csv::Reader::from_path(&path)
        .map_err(|e| loc.err(span.clone(), &format!("{key}.file"), format!("{}: {e}", path.display())))?;
    let headers = rd
        .headers()
        .map_err(|e| loc.err(span.clone(), &format!("{key}.file"), format!("{}: {e}", path.display())))?
        .clone();
    let col = |which: &str, name: &str| {
        headers.iter().position(|h| h.trim() == name).ok_or_else(|| {
            loc.err(
                span.clone(),
                &format!("{key}.{which}"),
                format!(
                    "{} has no column `{name}`; its columns: {}",
                    path.display(),
                    headers.iter().collect::<Vec<_>>().join(", ")
                ),
            )
        })
    };
    let (ix, iy) = (col("x", &r.x)?, col("y", &r.y)?);
    let selected: Vec<(usize, &str)> = r
        .rows
        .iter()
        .map(|(c, v)| Ok((col(&format!("rows.{c}"), c)?, v.as_str())))
        .collect::<Result<_, String>>()?;
    let scale = match r.y_scale {
        Some(f) if !(f.is_finite() && f != 0.0) => {
            return Err(loc.err(
                span,
                &format!("{key}.y_scale"),
                format!("{f} must be a finite non-zero factor"),
            ))
        }
        f => f.unwrap_or(1.0),
    };
    let (mut x, mut y) = (Vec::new(), Vec::new());
    for (i, rec) in rd.records().enumerate() {
        let row = i + 2; // the header is line 1
        let rec = rec
            .map_err(|e| loc.err(span.clone(), &format!("{key}.file"), format!("{}: {e}", path.display())))?;
        if !selected.iter().all(|&(j, v)| rec.get(j).map(str::trim) == Some(v)) {
            continue;
        }
        let num = |j: usize, name: &str| -> Result<f64, String> {
            let s = rec.get(j).unwrap_or("").trim();
            s.parse::<f64>().map_err(|_| {
                loc.err(
                    span.clone(),
                    &format!("{key}.file"),
                    format!("{}:{row}: column `{name}`: `{s}` is not a number", path.display()),
                )
            })
        };
        x.push(num(ix, &r.x)?);
        y.push(num(iy, &r.y)? * scale);
    }
    if x.is_empty() {
        let which = if selected.is_empty() { "" } else { " with the values of `rows`" };
        return Err(loc.err(span, &format!("{key}.file"), format!("{}: no rows{which}", path.display())));
    }
    Ok(Reference {
        label: r.label.clone().unwrap_or_else(|| r.file.trim_end_matches(".csv").to_string()),
        path,
        x_column: r.x.clone(),
        y_column: r.y.clone(),
        x,
        y,
    })
}

#[cfg(test)]
mod tests {
    use super::super::testutil::GOOD;
    use super::super::{parse, FigureKind, Problem};
    use super::*;

    /// A profile figure appended to [`GOOD`], with a reference file in
    /// `ROOT/reference_data/ref.csv` (the problem is `ROOT/problems/x.toml`).
    const PROFILE: &str = r#"
[[figures]]
id = "prof"
kind = "profile"
title = "u on x = 0.5"
where = { pst = "sun" }
file = "centerline_u.csv"
x = "u"
y = "y"
x_label = "u / U (-)"
label = ["nx"]
reference = { file = "ref.csv", x = "Re100", y = "y", label = "Ghia et al. 1982" }
"#;

    fn with_reference(csv: &str) -> tempfile::TempDir {
        let root = tempfile::tempdir().unwrap();
        std::fs::create_dir_all(root.path().join("reference_data")).unwrap();
        std::fs::write(root.path().join("reference_data/ref.csv"), csv).unwrap();
        root
    }

    fn p_in(root: &Path, src: &str) -> Result<Problem, String> {
        parse(&root.join("problems/x.toml"), src, "quick")
    }

    /// `rows` keeps one curve of a file of several; `y_scale` converts its units.
    #[test]
    fn a_reference_selects_its_rows_and_scales_them() {
        let root = with_reference("source,t,v\na,0.0,1.0\nb,0.0,5.0\na,1.0,2.0\n");
        let one = PROFILE.replace(
            r#"x = "Re100", y = "y", label = "Ghia et al. 1982""#,
            r#"x = "t", y = "v", rows = { source = "a" }, y_scale = 1e-4"#,
        );
        let pr = p_in(root.path(), &format!("{GOOD}{one}")).unwrap();
        let f = pr.figures.iter().find(|f| f.id == "prof").unwrap();
        let FigureKind::Profile { references, .. } = &f.kind else { panic!("{:?}", f.kind) };
        assert_eq!((references[0].x.clone(), references[0].y.clone()), (vec![0.0, 1.0], vec![1e-4, 2e-4]));
        let none = one.replace(r#"source = "a""#, r#"source = "c""#);
        assert!(p_in(root.path(), &format!("{GOOD}{none}"))
            .unwrap_err()
            .contains("no rows with the values of `rows`"));
        let bad = one.replace(r#"source = "a""#, r#"kind = "a""#);
        assert!(p_in(root.path(), &format!("{GOOD}{bad}")).unwrap_err().contains("no column `kind`"));
    }

    #[test]
    fn profile_reads_its_reference_points() {
        let root = with_reference("y,Re100,Re400\n0.0,0.0,0.0\n0.5,-0.2,-0.1\n1.0,1.0,1.0\n");
        let pr = p_in(root.path(), &format!("{GOOD}{PROFILE}")).unwrap();
        let f = pr.figures.iter().find(|f| f.id == "prof").unwrap();
        let FigureKind::Profile { file, x, y, references, clip_to_reference: false } = &f.kind else {
            panic!("{:?}", f.kind)
        };
        let r = &references[0];
        assert_eq!((file.as_str(), x.as_str(), y.as_str()), ("centerline_u.csv", "u", "y"));
        assert_eq!(r.x, [0.0, -0.2, 1.0]);
        assert_eq!(r.y, [0.0, 0.5, 1.0]);
        assert_eq!(r.label, "Ghia et al. 1982");
        assert_eq!(r.path, root.path().join("reference_data/ref.csv"));
        assert_eq!(f.x_label.as_deref(), Some("u / U (-)"));
        // Without a reference, and with the default label (the file stem).
        let bare = PROFILE.replace(", label = \"Ghia et al. 1982\"", "");
        let pr = p_in(root.path(), &format!("{GOOD}{bare}")).unwrap();
        let FigureKind::Profile { references, .. } = &pr.figures[1].kind else { panic!() };
        assert_eq!(references[0].label, "ref");
        let none = bare.lines().filter(|l| !l.starts_with("reference")).collect::<Vec<_>>().join("\n");
        let pr = p_in(root.path(), &format!("{GOOD}{none}")).unwrap();
        assert!(
            matches!(&pr.figures[1].kind, FigureKind::Profile { references, .. } if references.is_empty())
        );
        // Two sets of points, and the curves clipped to their range.
        let two = PROFILE.replace(
            "reference = { file = \"ref.csv\", x = \"Re100\", y = \"y\", label = \"Ghia et al. 1982\" }",
            "reference = [{ file = \"ref.csv\", x = \"Re100\", y = \"y\" }, { file = \"ref.csv\", x = \"Re400\", y = \"y\" }]\nx_range = \"reference\"",
        );
        let pr = p_in(root.path(), &format!("{GOOD}{two}")).unwrap();
        let FigureKind::Profile { references, clip_to_reference, .. } = &pr.figures[1].kind else { panic!() };
        assert_eq!((references.len(), references[1].x[1], *clip_to_reference), (2, -0.1, true));
        let e = p_in(
            root.path(),
            &format!("{GOOD}{}", two.replace("x_range = \"reference\"", "x_range = \"all\"")),
        )
        .unwrap_err();
        assert!(e.contains("figures.prof.x_range") && e.contains("`all`"), "{e}");
        // reference_data/ sits next to the problems folder.
        assert_eq!(reference_dir(Path::new("problems/a.toml")), Path::new("reference_data"));
        assert_eq!(reference_dir(Path::new("/r/problems/a.toml")), Path::new("/r/reference_data"));
    }

    #[test]
    fn profile_errors_name_file_line_and_key() {
        let root = with_reference("y,Re100\n0.0,0.0\n1.0,1.0\n");
        let src = format!("{GOOD}{PROFILE}");
        let line = src.lines().position(|l| l.starts_with("reference =")).unwrap() + 1;
        let at = format!("x.toml:{line}: ");
        let e = p_in(root.path(), &src.replace("\"Re100\"", "\"Re1000\"")).unwrap_err();
        assert!(
            e.contains(&at) && e.contains("`figures.prof.reference.x`") && e.contains("no column `Re1000`"),
            "{e}"
        );
        let e = p_in(root.path(), &src.replace("y = \"y\", label", "y = \"z\", label")).unwrap_err();
        assert!(e.contains(&at) && e.contains("`figures.prof.reference.y`") && e.contains("`z`"), "{e}");
        let e = p_in(root.path(), &src.replace("\"ref.csv\"", "\"nope.csv\"")).unwrap_err();
        assert!(
            e.contains(&at) && e.contains("`figures.prof.reference.file`") && e.contains("nope.csv"),
            "{e}"
        );
        let e = p_in(root.path(), &src.replace("\"ref.csv\"", "\"../ref.csv\"")).unwrap_err();
        assert!(e.contains("reference.file") && e.contains("file name"), "{e}");
        let e = p_in(root.path(), &src.replace("Ghia et al. 1982\" }", "G\", colour = 1 }")).unwrap_err();
        assert!(e.contains("colour"), "{e}");
        let bad = with_reference("y,Re100\n0.0,0.0\n0.5,oops\n");
        let e = p_in(bad.path(), &src).unwrap_err();
        assert!(e.contains(&at) && e.contains("ref.csv:3") && e.contains("`oops`"), "{e}");
        let e = p_in(root.path(), &src.replace("file = \"centerline_u.csv\"\n", "")).unwrap_err();
        assert!(e.contains("`figures.prof`") && e.contains("needs `file`"), "{e}");
        let e = p_in(root.path(), &src.replace("y = \"y\"\nx_label", "x_label")).unwrap_err();
        assert!(e.contains("needs `y`"), "{e}");
        let timeseries = src
            .replace("kind = \"profile\"", "kind = \"timeseries\"")
            .replace("y = \"y\"\nx_label", "y = \"u_max\"\nx_label");
        let e = p_in(root.path(), &timeseries).unwrap_err();
        assert!(e.contains("only kind `profile`"), "{e}");
    }
}
