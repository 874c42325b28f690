//! ParaView snapshots of a scene's bodies: a fluid (each of its parts apart), walls and
//! elastic solids, with the shifting's and the free surface's fields.

use crate::solver::math::Vector;
use crate::solver::output::vtu::{write_vtu, Field};
use crate::solver::simulation::Simulation;
use crate::solver::systems::{Body, ElasticSolid, Fluid, Wall};
use std::path::Path;

/// A `D`-vector as the three components ParaView reads (zeros beyond `D`).
fn pad<const D: usize>(v: &Vector<D>) -> [f64; 3] {
    std::array::from_fn(|k| if k < D { v[k] } else { 0.0 })
}

/// Writes a fluid snapshot with velocity, speed, pressure, density, id and the `extra`
/// fields (one value per particle of the fluid); of the particles whose original index is in
/// `ids` only, if given (one part of the fluid).
pub fn write_fluid<const D: usize>(
    path: &Path,
    f: &Fluid<D>,
    extra: &[Field],
    ids: Option<&std::ops::Range<u32>>,
) -> std::io::Result<()> {
    let mut fields = vec![
        Field::Vector("velocity", f.u.iter().map(pad).collect()),
        Field::Scalar("speed", f.u.iter().map(|u| u.norm()).collect()),
        Field::Scalar("pressure", f.p.clone()),
        Field::Scalar("density", f.rho.clone()),
        Field::Int("id", f.id.iter().map(|&i| i as i64).collect()),
    ];
    fields.extend(extra.iter().cloned());
    let x: Vec<[f64; 3]> = f.x.iter().map(pad).collect();
    match ids {
        None => write_vtu(path, &x, &fields),
        Some(ids) => {
            let keep: Vec<usize> = (0..f.len()).filter(|&k| ids.contains(&f.id[k])).collect();
            let fields: Vec<Field> = fields.iter().map(|field| field.select(&keep)).collect();
            write_vtu(path, &keep.iter().map(|&k| x[k]).collect::<Vec<_>>(), &fields)
        }
    }
}

/// The shifting's time-series columns, every scene alike: IPST's moves in the last step
/// (0 without IPST) and the largest shifting speed |u~ - u| (0 without shifting).
pub fn shifting_columns<const D: usize>(sim: &Simulation<D>) -> [(&'static str, f64); 2] {
    let shift_max = sim.shift_speeds().map_or(0.0, |s| s.into_iter().fold(0.0, f64::max));
    [("ipst_iterations", sim.last_ipst_iterations() as f64), ("shift_max", shift_max)]
}

/// Where the scheme moves the particles with a transport velocity u~ (CTVF eq. 33): u~ and
/// the shifting speed of the coming step, |u~ - u| (see [`Simulation::shift_speeds`]), as
/// snapshot fields; nothing otherwise.
pub fn shifting_fields<const D: usize>(sim: &Simulation<D>) -> Vec<Field<'static>> {
    if !sim.has_fluid() {
        return Vec::new();
    }
    match (&sim.fluid().u_hat, sim.shift_speeds()) {
        (Some(u_hat), Some(shift)) => vec![
            Field::Vector("transport_velocity", u_hat.iter().map(pad).collect()),
            Field::Scalar("shift_speed", shift),
        ],
        _ => Vec::new(),
    }
}

/// Free-surface snapshot fields of `sim`: normal, surface and near-surface flags.
pub fn surface_fields<const D: usize>(sim: &Simulation<D>) -> Vec<Field<'static>> {
    let Some(fs) = sim.surface() else { return Vec::new() };
    vec![
        Field::Vector("normal", fs.normal.iter().map(pad).collect()),
        Field::Int("free_surface", fs.surface.iter().map(|&s| s as i64).collect()),
        Field::Int("near_surface", fs.near.iter().map(|&s| s as i64).collect()),
    ]
}

/// Writes a wall snapshot: prescribed velocity, extrapolated pressure and density, normal.
pub fn write_wall<const D: usize>(path: &Path, w: &Wall<D>) -> std::io::Result<()> {
    let u: Vec<Vector<D>> = (0..w.len()).map(|i| w.velocity(i)).collect();
    write_vtu(
        path,
        &w.x.iter().map(pad).collect::<Vec<_>>(),
        &[
            Field::Vector("velocity", u.iter().map(pad).collect()),
            Field::Scalar("speed", u.iter().map(|u| u.norm()).collect()),
            Field::Scalar("pressure", w.boundary.ghost.iter().map(|g| g.p).collect()),
            Field::Scalar("density", w.boundary.rho.clone()),
            Field::Vector("normal", w.normal.iter().map(pad).collect()),
        ],
    )
}

/// Writes an elastic solid's snapshot: velocity, speed, pressure, density, deviatoric
/// stress (its components and von Mises' `sqrt(3 J2)`), the fixed flag, and its free
/// surface if detected.
pub fn write_solid<const D: usize>(
    path: &Path,
    s: &ElasticSolid<D>,
    surface: Option<&crate::solver::passes::free_surface::SurfaceFields<D>>,
) -> std::io::Result<()> {
    write_solids(path, &[(s, surface)])
}

/// Writes the snapshot of several elastic solids in one file, as [`write_solid`] writes one,
/// their particles in the order given; with more than one, a `body` array numbers them
/// (0, 1, ...). A free-surface flag is written where every solid has detected its surface.
pub fn write_solids<const D: usize>(
    path: &Path,
    solids: &[(&ElasticSolid<D>, Option<&crate::solver::passes::free_surface::SurfaceFields<D>>)],
) -> std::io::Result<()> {
    use crate::solver::equations::solid::j2;
    let each = |f: &dyn Fn(&ElasticSolid<D>) -> Vec<f64>| {
        solids.iter().flat_map(|(s, _)| f(s)).collect::<Vec<f64>>()
    };
    let vectors = |f: &dyn Fn(&ElasticSolid<D>) -> Vec<[f64; 3]>| {
        solids.iter().flat_map(|(s, _)| f(s)).collect::<Vec<[f64; 3]>>()
    };
    let ints = |f: &dyn Fn(usize, &ElasticSolid<D>) -> Vec<i64>| {
        solids.iter().enumerate().flat_map(|(k, (s, _))| f(k, s)).collect::<Vec<i64>>()
    };
    let mut fields = vec![
        Field::Vector("velocity", vectors(&|s| s.u.iter().map(pad).collect())),
        Field::Scalar("speed", each(&|s| s.u.iter().map(|u| u.norm()).collect())),
        Field::Scalar("pressure", each(&|s| s.p.clone())),
        Field::Scalar("density", each(&|s| s.rho.clone())),
        Field::Scalar("von_mises", each(&|s| s.s.iter().map(|m| (3.0 * j2(m)).sqrt()).collect())),
        Field::Int("fixed", ints(&|_, s| s.fixed.iter().map(|&f| f as i64).collect())),
    ];
    for (name, (i, j)) in [("s00", (0, 0)), ("s01", (0, 1)), ("s11", (1, 1))] {
        if i < D && j < D {
            fields.push(Field::Scalar(name, each(&|s| s.s.iter().map(|m| m[(i, j)]).collect())));
        }
    }
    if solids.iter().all(|(_, fs)| fs.is_some()) {
        let flags = solids.iter().flat_map(|(_, fs)| fs.expect("detected").surface.iter().map(|&f| f as i64));
        fields.push(Field::Int("free_surface", flags.collect()));
    }
    if solids.len() > 1 {
        fields.push(Field::Int("body", ints(&|k, s| vec![k as i64; s.len()])));
    }
    write_vtu(path, &vectors(&|s| s.x.iter().map(pad).collect()), &fields)
}

/// Writes the snapshots of every body of `sim` (each part of the fluid with `extra` fields)
/// for output number `index`; returns the (body, file) pairs.
pub fn snapshot_bodies<const D: usize>(
    sim: &Simulation<D>,
    dir: &Path,
    index: usize,
    extra: Vec<Field>,
) -> std::io::Result<Vec<(String, String)>> {
    let mut fields = shifting_fields(sim);
    fields.extend(extra);
    let mut files = Vec::new();
    for body in sim.bodies() {
        match body {
            Body::Fluid(f) => {
                let whole = f.parts.len() == 1;
                for part in &f.parts {
                    let name = format!("{}_{index:05}.vtu", part.name);
                    write_fluid(&dir.join(&name), f, &fields, (!whole).then_some(&part.ids))?;
                    files.push((part.name.clone(), name));
                }
            }
            Body::Wall(w) => {
                let name = format!("{}_{index:05}.vtu", w.name);
                write_wall(&dir.join(&name), w)?;
                files.push((w.name.clone(), name));
            }
            Body::ElasticSolid(s) => {
                let name = format!("{}_{index:05}.vtu", s.name);
                write_solid(&dir.join(&name), s, sim.solid_surface(&s.name))?;
                files.push((s.name.clone(), name));
            }
        }
    }
    Ok(files)
}
