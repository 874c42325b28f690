//! The free-surface detection of CTVF sec. 3.4 on static shapes (figs. 1-2): a ring of
//! fluid, a patch resting on a wall, and the dam-break column in its tank. Nothing moves:
//! the run is one short step; the snapshot carries the normals and the surface flags.
//!
//! Metrics: `surface_particles` (found on the surface), `interior_surface_particles`
//! (found on the surface but not in the outer layer: must be 0), `outer_layer_missed`
//! (outer-layer particles not found).

use super::fluid_scheme::{fluid_scheme, free_surface_params, scheme_params, FluidConstants};
use super::geometry::{box_walls, lattice};
use super::memory::check_size;
use super::params::{Bound, Params, Spec};
use super::snapshots::{snapshot_bodies, surface_fields};
use super::stepping::{checkpoint, forward_to_sim, plan, simulation};
use super::walls::{fluid_at_rest, wall_from};
use super::{common_params, SceneEntry, SceneRun};
use crate::solver::kernel::Kernel;
use crate::solver::math::Vector;
use crate::solver::nnps::Domain;
use crate::solver::scheme::{DensityModel, FluidScheme};
use crate::solver::simulation::Simulation;
use std::collections::BTreeMap;
use std::path::Path;

const RHO0: f64 = 1000.0;

/// The registry entry.
pub const ENTRY: SceneEntry = SceneEntry {
    name: "free_surface_demo",
    dim: 2,
    about: "Free-surface particles and normals on a ring, a patch on a wall and a column (CTVF sec. 3.4)",
    params,
    build,
    check: |p| setup(p).map(drop),
    metrics: &["surface_particles", "interior_surface_particles", "outer_layer_missed"],
    columns: &["t", "surface_particles", "interior_surface_particles"],
    outputs: 0,
};

/// Whether a particle belongs to the shape's outer layer (the particles a surface detection
/// must flag).
type OuterLayer = Box<dyn Fn(&Vector<2>) -> bool>;

fn params() -> Vec<Spec> {
    let mut v = vec![
        Spec::choice("shape", &["ring", "patch", "column"], "ring", "what to detect the surface of"),
        Spec::float("dx", 0.05, Bound::Positive, "particle spacing (m)"),
    ];
    v.extend(scheme_params("none"));
    v.extend(free_surface_params());
    v.extend(common_params(1e-4));
    v
}

struct Demo {
    sim: Simulation<2>,
    /// Whether each particle (by id) is in the outer layer of its shape.
    outer: Vec<bool>,
}

/// The kernel, smoothing length and scheme, once every parameter check that needs no
/// particle has passed.
fn setup(p: &Params) -> Result<(Kernel, f64, FluidScheme), String> {
    let dx = p.float("dx");
    if dx > 0.1 {
        return Err(format!("scene `free_surface_demo`: `dx` = {dx} leaves too few particles (at most 0.1)"));
    }
    // The largest shape's lattice (2 x 2 around the ring) and a tank's walls.
    check_size::<2>("free_surface_demo", "dx", dx, 4.0 / (dx * dx) + 30.0 / dx)?;
    let constants = FluidConstants {
        rho0: RHO0,
        c0: 10.0,
        u_ref: 1.0,
        dx,
        nu: None,
        alpha: None,
        density: DensityModel::Continuity,
        gravity: [0.0; 3],
        free_surface: true,
    };
    fluid_scheme::<2>("free_surface_demo", p, &constants)
}

fn build(p: &Params) -> Result<Box<dyn SceneRun>, String> {
    let dx = p.float("dx");
    let (kernel, h, scheme) = setup(p)?;
    let (x, walls, outer): (Vec<Vector<2>>, Vec<(Vector<2>, Vector<2>)>, OuterLayer) = match p.str("shape") {
        "ring" => (
            lattice(-1.0, 1.0, -1.0, 1.0, dx)
                .into_iter()
                .filter(|x| (0.5..1.0).contains(&x.norm()))
                .collect(),
            Vec::new(),
            Box::new(move |x: &Vector<2>| x.norm() > 1.0 - dx || x.norm() < 0.5 + dx),
        ),
        "patch" => (
            lattice(0.0, 1.0, 0.0, 0.3, dx),
            box_walls(1.0, 0.3, dx, 3, false).into_iter().filter(|(x, _)| x[1] < 0.0).collect(),
            Box::new(move |x: &Vector<2>| x[1] > 0.3 - dx || x[0] < dx || x[0] > 1.0 - dx),
        ),
        _ => (
            lattice(0.0, 1.0, 0.0, 2.0, dx),
            box_walls(4.0, 3.0, dx, 3, false),
            Box::new(move |x: &Vector<2>| x[1] > 2.0 - dx || x[0] > 1.0 - dx),
        ),
    };
    let outer: Vec<bool> = x.iter().map(outer).collect();
    let fluid = fluid_at_rest(x, dx, RHO0, h, scheme, |_| 0.0)?;
    let wall =
        (!walls.is_empty()).then(|| wall_from(&walls, |_| Vector::zeros(), dx, RHO0, 10.0)).transpose()?;
    let domain = Domain::bounded([-2.0, -2.0], [5.0, 4.0]);
    let bodies = std::iter::once(fluid.into()).chain(wall.map(Into::into));
    let sim = simulation("free_surface_demo", p, domain, kernel, bodies)?;
    Ok(Box::new(Demo { sim, outer }))
}

impl Demo {
    fn counts(&self) -> (usize, usize, usize) {
        let f = self.sim.fluid();
        let fs = self.sim.surface().expect("free surface declared");
        let (mut found, mut interior, mut missed) = (0, 0, 0);
        for k in 0..f.len() {
            let outer = self.outer[f.id[k] as usize];
            found += fs.surface[k] as usize;
            interior += (fs.surface[k] && !outer) as usize;
            missed += (!fs.surface[k] && outer) as usize;
        }
        (found, interior, missed)
    }
}

impl SceneRun for Demo {
    forward_to_sim!();
    fn plan(&self) -> String {
        plan(&self.sim, "static shape")
    }
    fn sample(&mut self) -> Vec<(&'static str, f64)> {
        let (found, interior, _) = self.counts();
        vec![
            ("t", self.sim.time()),
            ("surface_particles", found as f64),
            ("interior_surface_particles", interior as f64),
        ]
    }
    fn snapshot(&self, dir: &Path, index: usize) -> std::io::Result<Vec<(String, String)>> {
        snapshot_bodies(&self.sim, dir, index, surface_fields(&self.sim))
    }
    fn metrics(&self) -> BTreeMap<String, f64> {
        let (found, interior, missed) = self.counts();
        BTreeMap::from([
            ("surface_particles".to_string(), found as f64),
            ("interior_surface_particles".to_string(), interior as f64),
            ("outer_layer_missed".to_string(), missed as f64),
        ])
    }
    checkpoint!();
}
