//! Reading a case's snapshots for particle figures: the series files (`fluid.pvd`,
//! `wall.pvd`), the snapshot nearest a time, and the points and point arrays of one `.vtu`
//! (ASCII, as the solver writes them), also from its gzip-compressed copy (`NAME.vtu.gz`,
//! as the committed results keep them).

use std::io::Read as _;
use std::path::{Path, PathBuf};

/// The snapshots listed in series file `name` (`fluid.pvd`) of `dir`: (time, file), in
/// file order.
pub(crate) fn pvd_entries(dir: &Path, name: &str) -> Result<Vec<(f64, String)>, String> {
    let pvd = dir.join(name);
    let s = std::fs::read_to_string(&pvd).map_err(|e| format!("{}: {e}", pvd.display()))?;
    let list: Vec<(f64, String)> = s
        .lines()
        .filter_map(|l| {
            let f = l.split("file=\"").nth(1)?.split('"').next()?;
            let t: f64 = l.split("timestep=\"").nth(1)?.split('"').next()?.parse().ok()?;
            Some((t, f.to_string()))
        })
        .collect();
    if list.is_empty() {
        return Err(format!("{}: no snapshot listed", pvd.display()));
    }
    Ok(list)
}

/// The series a particle figure draws in case folder `dir`: `fluid.pvd` when the case has a
/// fluid, else the first other body's series by name (a solid's, e.g. `plate.pvd`), never
/// the walls'. Errors when the folder has no series.
pub(crate) fn drawn_series(dir: &Path) -> Result<String, String> {
    if dir.join("fluid.pvd").exists() {
        return Ok("fluid.pvd".into());
    }
    let names = snapshot_series(dir)?;
    names
        .into_iter()
        .find(|n| n != "wall.pvd")
        .ok_or_else(|| format!("{}: no snapshot series (*.pvd)", dir.display()))
}

/// The entry nearest `time` (the first of equally near ones), or the last one.
pub(crate) fn pick_snapshot(list: &[(f64, String)], time: Option<f64>) -> &(f64, String) {
    match time {
        None => list.last().expect("non-empty"),
        Some(t) => {
            list.iter().fold(&list[0], |best, e| if (e.0 - t).abs() < (best.0 - t).abs() { e } else { best })
        }
    }
}

/// A series file listing `entries` (time, file), as the solver writes them.
pub(crate) fn pvd_text(entries: &[(f64, String)]) -> String {
    let mut s = String::from(
        "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n<Collection>\n",
    );
    for (t, f) in entries {
        s += &format!("<DataSet timestep=\"{t:e}\" part=\"0\" file=\"{f}\"/>\n");
    }
    s + "</Collection>\n</VTKFile>\n"
}

/// The file a series lists as `file` under `dir`, or its gzip-compressed copy: its path and
/// its text; `None` when neither exists.
pub(crate) fn read_vtu(dir: &Path, file: &str) -> Result<Option<(PathBuf, String)>, String> {
    let path = dir.join(file);
    if path.exists() {
        let text = std::fs::read_to_string(&path).map_err(|e| format!("{}: {e}", path.display()))?;
        return Ok(Some((path, text)));
    }
    let gz = dir.join(format!("{file}.gz"));
    if gz.exists() {
        let f = std::fs::File::open(&gz).map_err(|e| format!("{}: {e}", gz.display()))?;
        let mut text = String::new();
        flate2::read::GzDecoder::new(f)
            .read_to_string(&mut text)
            .map_err(|e| format!("{}: {e}", gz.display()))?;
        return Ok(Some((gz, text)));
    }
    Ok(None)
}

/// The text of the first `<DataArray ...>` after `from` whose tag contains `tag_has`.
fn data_array<'a>(xml: &'a str, from: usize, tag_has: &str) -> Option<&'a str> {
    let mut at = from;
    loop {
        let i = at + xml[at..].find("<DataArray")?;
        let close = i + xml[i..].find('>')?;
        if xml[i..close].contains(tag_has) {
            let end = close + xml[close..].find("</DataArray>")?;
            return Some(&xml[close + 1..end]);
        }
        at = close;
    }
}

fn numbers(s: &str) -> Vec<f64> {
    s.split_whitespace().filter_map(|x| x.parse().ok()).collect()
}

/// One `.vtu` read: its points and a way to its point arrays.
pub(crate) struct Vtu {
    path: PathBuf,
    xml: String,
    /// Point x coordinates.
    pub x: Vec<f64>,
    /// Point y coordinates.
    pub y: Vec<f64>,
}

impl Vtu {
    /// Parses the text of `path`.
    pub(crate) fn parse(path: PathBuf, xml: String) -> Result<Self, String> {
        let pts_at = xml.find("<Points>").ok_or_else(|| format!("{}: no <Points>", path.display()))?;
        let pts = data_array(&xml, pts_at, "DataArray")
            .map(numbers)
            .ok_or_else(|| format!("{}: unreadable <Points>", path.display()))?;
        let x = pts.iter().step_by(3).copied().collect();
        let y = pts.iter().skip(1).step_by(3).copied().collect();
        Ok(Self { path, xml, x, y })
    }

    /// Point array `name`.
    pub(crate) fn array(&self, name: &str) -> Result<Vec<f64>, String> {
        data_array(&self.xml, 0, &format!("Name=\"{name}\""))
            .map(numbers)
            .ok_or_else(|| format!("{}: no point array `{name}`", self.path.display()))
    }

    /// A scalar field: a point array, or a sum of them with factors
    /// (`2*free_surface+near_surface`).
    pub(crate) fn field(&self, expr: &str) -> Result<Vec<f64>, String> {
        let mut sum: Option<Vec<f64>> = None;
        for term in expr.split('+').map(str::trim) {
            let (k, name) = match term.split_once('*') {
                Some((k, n)) => (
                    k.trim().parse::<f64>().map_err(|_| format!("`{term}` of `{expr}`: not FACTOR*ARRAY"))?,
                    n.trim(),
                ),
                None => (1.0, term),
            };
            let v: Vec<f64> = self.array(name)?.into_iter().map(|x| k * x).collect();
            sum = Some(match sum {
                None => v,
                Some(s) if s.len() == v.len() => s.iter().zip(&v).map(|(a, b)| a + b).collect(),
                Some(_) => {
                    return Err(format!("{}: the arrays of `{expr}` differ in length", self.path.display()))
                }
            });
        }
        sum.ok_or_else(|| format!("{}: no field `{expr}`", self.path.display()))
    }

    /// The x and y components of the 3-component point array `name`.
    pub(crate) fn vectors(&self, name: &str) -> Result<(Vec<f64>, Vec<f64>), String> {
        let v = self.array(name)?;
        if v.len() != 3 * self.x.len() {
            return Err(format!(
                "{}: point array `{name}` has {} values, not 3 per point ({} points)",
                self.path.display(),
                v.len(),
                self.x.len()
            ));
        }
        Ok((v.iter().step_by(3).copied().collect(), v.iter().skip(1).step_by(3).copied().collect()))
    }
}

/// One snapshot of a case read for a particle figure.
pub(crate) struct Snapshot {
    /// Particle x.
    pub x: Vec<f64>,
    /// Particle y.
    pub y: Vec<f64>,
    /// The field that colours them.
    pub value: Vec<f64>,
    /// x and y components of the `arrows` array, if asked for.
    pub arrows: Option<(Vec<f64>, Vec<f64>)>,
    /// The walls' particles at the nearest time (`wall.pvd`), if the case has walls.
    pub walls: Option<(Vec<f64>, Vec<f64>)>,
    /// The particles of the other bodies (structures in the fluid) at the nearest time, when
    /// the drawn series is the fluid's.
    pub structures: Option<(Vec<f64>, Vec<f64>)>,
    /// Its time.
    pub t: f64,
}

/// The snapshot listed in the [`drawn_series`] of `dir` nearest `time` (the last one without a
/// time): points, field `field`, the x, y components of the vector array `arrows`, and the
/// wall particles of the `wall.pvd` snapshot nearest it. `None` when the file the series
/// lists is not there (a committed result keeps only the snapshots its figures draw).
pub(crate) fn snapshot(
    dir: &Path,
    field: &str,
    time: Option<f64>,
    arrows: Option<&str>,
) -> Result<Option<Snapshot>, String> {
    let drawn = drawn_series(dir)?;
    let list = pvd_entries(dir, &drawn)?;
    let (t, file) = pick_snapshot(&list, time).clone();
    let Some((path, xml)) = read_vtu(dir, &file)? else {
        return Ok(None);
    };
    let vtu = Vtu::parse(path, xml)?;
    let value = vtu.field(field)?;
    let arrows = arrows.map(|a| vtu.vectors(a)).transpose()?;
    let walls = points_at(dir, "wall.pvd", t)?;
    let mut structures: Option<Points> = None;
    for name in beside(dir, &drawn)?.into_iter().filter(|n| n != "wall.pvd") {
        if let Some((x, y)) = points_at(dir, &name, t)? {
            let s = structures.get_or_insert_with(Default::default);
            s.0.extend(x);
            s.1.extend(y);
        }
    }
    Ok(Some(Snapshot { x: vtu.x, y: vtu.y, value, arrows, walls, structures, t }))
}

/// Particle positions: x and y.
type Points = (Vec<f64>, Vec<f64>);

/// The particles of series `name` in `dir` at the snapshot nearest `t`; `None` when the
/// case has no such series or the file it lists is not there.
fn points_at(dir: &Path, name: &str, t: f64) -> Result<Option<Points>, String> {
    if !dir.join(name).exists() {
        return Ok(None);
    }
    let list = pvd_entries(dir, name)?;
    let (_, file) = pick_snapshot(&list, Some(t)).clone();
    Ok(match read_vtu(dir, &file)? {
        Some((p, x)) => {
            let v = Vtu::parse(p, x)?;
            Some((v.x, v.y))
        }
        None => None,
    })
}

/// The series drawn beside series `drawn` of case folder `dir` (the snapshots a particle
/// figure reads and an export keeps with it): the walls', and beside a fluid's every other
/// body's (structures in the fluid).
pub(crate) fn beside(dir: &Path, drawn: &str) -> Result<Vec<String>, String> {
    Ok(snapshot_series(dir)?
        .into_iter()
        .filter(|n| n != drawn && (n == "wall.pvd" || drawn == "fluid.pvd"))
        .collect())
}

/// The snapshot series (`*.pvd`) of case folder `dir`, by name.
pub(crate) fn snapshot_series(dir: &Path) -> Result<Vec<String>, String> {
    let rd = std::fs::read_dir(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let mut names: Vec<String> = rd
        .flatten()
        .filter_map(|e| e.file_name().into_string().ok())
        .filter(|n| n.ends_with(".pvd"))
        .collect();
    names.sort();
    Ok(names)
}
