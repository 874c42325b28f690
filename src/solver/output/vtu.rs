//! VTK XML UnstructuredGrid (`.vtu`) snapshots of particles as vertex cells, and the `.pvd`
//! collection that makes them a time series in ParaView.
//!
//! Written by hand rather than with `vtkio`: the format needed here is a few dozen lines of
//! XML with base64-free ASCII arrays, and `vtkio`'s current release is a pre-release.

use std::fmt::Write as _;
use std::io::Write;
use std::path::{Path, PathBuf};

/// One point-data array.
#[derive(Clone, Debug)]
pub enum Field<'a> {
    /// A scalar per particle.
    Scalar(&'a str, Vec<f64>),
    /// A vector per particle (2D vectors are padded to 3 components).
    Vector(&'a str, Vec<[f64; 3]>),
    /// An integer per particle.
    Int(&'a str, Vec<i64>),
}

impl Field<'_> {
    /// The field of the particles `keep` only, in that order.
    pub fn select(&self, keep: &[usize]) -> Self {
        match self {
            Field::Scalar(n, v) => Field::Scalar(n, keep.iter().map(|&k| v[k]).collect()),
            Field::Vector(n, v) => Field::Vector(n, keep.iter().map(|&k| v[k]).collect()),
            Field::Int(n, v) => Field::Int(n, keep.iter().map(|&k| v[k]).collect()),
        }
    }
}

/// Writes one snapshot.
pub fn write_vtu(path: &Path, points: &[[f64; 3]], fields: &[Field]) -> std::io::Result<()> {
    let n = points.len();
    let mut s = String::with_capacity(64 * n * (fields.len() + 2));
    s.push_str("<?xml version=\"1.0\"?>\n<VTKFile type=\"UnstructuredGrid\" version=\"0.1\" byte_order=\"LittleEndian\">\n<UnstructuredGrid>\n");
    let _ = writeln!(s, "<Piece NumberOfPoints=\"{n}\" NumberOfCells=\"{n}\">");
    s.push_str("<PointData>\n");
    for f in fields {
        match f {
            Field::Scalar(name, v) => {
                let _ = writeln!(s, "<DataArray type=\"Float64\" Name=\"{name}\" format=\"ascii\">");
                for x in v {
                    let _ = write!(s, "{x:e} ");
                }
            }
            Field::Vector(name, v) => {
                let _ = writeln!(
                    s,
                    "<DataArray type=\"Float64\" Name=\"{name}\" NumberOfComponents=\"3\" format=\"ascii\">"
                );
                for x in v {
                    let _ = write!(s, "{:e} {:e} {:e} ", x[0], x[1], x[2]);
                }
            }
            Field::Int(name, v) => {
                let _ = writeln!(s, "<DataArray type=\"Int64\" Name=\"{name}\" format=\"ascii\">");
                for x in v {
                    let _ = write!(s, "{x} ");
                }
            }
        }
        s.push_str("\n</DataArray>\n");
    }
    s.push_str(
        "</PointData>\n<Points>\n<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"ascii\">\n",
    );
    for p in points {
        let _ = write!(s, "{:e} {:e} {:e} ", p[0], p[1], p[2]);
    }
    s.push_str("\n</DataArray>\n</Points>\n<Cells>\n<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">\n");
    for i in 0..n {
        let _ = write!(s, "{i} ");
    }
    s.push_str("\n</DataArray>\n<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">\n");
    for i in 1..=n {
        let _ = write!(s, "{i} ");
    }
    s.push_str("\n</DataArray>\n<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">\n");
    for _ in 0..n {
        s.push_str("1 ");
    }
    s.push_str("\n</DataArray>\n</Cells>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>\n");
    let mut f = std::io::BufWriter::new(std::fs::File::create(path)?);
    f.write_all(s.as_bytes())?;
    f.flush()
}

/// A `.pvd` time series, rewritten (atomically) after every snapshot so that it always
/// lists exactly the snapshots on disk.
pub struct Series {
    pvd: PathBuf,
    entries: Vec<(f64, String)>,
}

impl Series {
    /// A series written to `pvd`; snapshot files are named relative to its folder.
    pub fn new(pvd: PathBuf) -> Self {
        Self { pvd, entries: Vec::new() }
    }

    /// A series that already lists `entries` (when a run resumes).
    pub fn with_entries(pvd: PathBuf, entries: Vec<(f64, String)>) -> Self {
        Self { pvd, entries }
    }

    /// The snapshots listed so far: (time, file).
    pub fn entries(&self) -> &[(f64, String)] {
        &self.entries
    }

    /// Adds a snapshot file (relative to the `.pvd`'s folder) at time `t`.
    pub fn push(&mut self, t: f64, file: &str) -> std::io::Result<()> {
        self.entries.push((t, file.to_string()));
        let mut s = String::from(
            "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n<Collection>\n",
        );
        for (t, f) in &self.entries {
            let _ = writeln!(s, "<DataSet timestep=\"{t:e}\" part=\"0\" file=\"{f}\"/>");
        }
        s.push_str("</Collection>\n</VTKFile>\n");
        super::write_atomic(&self.pvd, s.as_bytes())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn vtu_and_pvd_are_well_formed() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("a.vtu");
        write_vtu(
            &p,
            &[[0.0, 0.0, 0.0], [1.0, 0.5, 0.0]],
            &[Field::Scalar("p", vec![1.0, 2.0]), Field::Int("id", vec![0, 1])],
        )
        .unwrap();
        let s = std::fs::read_to_string(&p).unwrap();
        assert!(s.contains("NumberOfPoints=\"2\""));
        assert!(s.contains("Name=\"p\""));
        assert_eq!(s.matches("<DataArray").count(), s.matches("</DataArray>").count());
        let mut series = Series::new(dir.path().join("s.pvd"));
        series.push(0.0, "a.vtu").unwrap();
        series.push(0.5, "b.vtu").unwrap();
        let pvd = std::fs::read_to_string(dir.path().join("s.pvd")).unwrap();
        assert_eq!(pvd.matches("<DataSet").count(), 2);
    }
}
