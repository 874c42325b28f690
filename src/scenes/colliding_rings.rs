//! 2D colliding rubber rings (CTVF paper, sec. 4.6, figs. 24-28; first in SPH by Swegle et
//! al., then Monaghan 2000 and Gray, Monaghan & Swift 2001): two equal rings of inner radius
//! r_min = 0.03 m and outer radius r_max = 0.04 m, E = 1.0e7 Pa, rho0 = 1200 kg/m^3,
//! nu = 0.3975 (and 0.47 in figs. 25-26), dx = 0.001 m, Monaghan's artificial viscosity
//! with alpha = 1, run to t = 0.016 s (the paper's timing run, sec. 5). Quintic spline,
//! h = `hdx` dx (h = dx as the paper's other solids; the authors' PySPH script uses
//! h = 1.3 dx). No gravity.
//!
//! **Speed.** The paper's "initial speed of the rings v0 = 0.12 c0" is read as the
//! *closing* speed: each ring moves at v0 / 2 = 0.06 c0 towards the other. Gray et al. 2001
//! (after Monaghan 2000) give each ring 0.059 c0, so that the rings approach at 0.118 c0
//! (about 0.12 c0); the CTVF authors' PySPH script sets the left ring to 0.059 c0 and the
//! right one to -0.059 c0. `v0_over_c0` is that closing speed over c0 (eq. 8's c0 of the
//! material), whatever nu.
//!
//! **Geometry.** Each ring is made of particles on concentric circles (a ring lattice) of
//! radii r_k = r_min + (k + 1/2) dx, k = 0 .. round((r_max - r_min) / dx) - 1, with
//! N_k = round(2 pi r_k / dx) particles at angles 2 pi j / N_k (j = 0 at the far side from
//! the other ring, then anticlockwise), each of mass rho0 2 pi r_k dx / N_k (the annulus'
//! area shared out, so the ring's mass is exact). The centres lie on the x axis at
//! -/+ `separation` / 2; the default separation of 0.082 m (outer surfaces 2 mm apart) is
//! the authors' PySPH set-up (centres at -/+ 0.041 m). Both rings are ONE
//! [`ElasticSolid`] body (left ring first, then the right one): when they touch they
//! interact through the same SPH equations as the particles of one ring, as in Gray et al.
//! 2001 and PySPH's example; there is no contact law.
//!
//! **Points A and B** (fig. 27, whose drawing our text of the paper lacks): A is the
//! particle of the left ring's outermost circle nearest its top (angle pi/2 from its
//! centre, outer surface), B its mirror image on the right ring. Fig. 28 draws x and y of A
//! (and B) against t; by the set-up's symmetry `bx = -ax` and `by = ay` while the run is
//! symmetric.
//!
//! Metrics:
//! - `clusters_max` and `max_gap`: the numerical-fracture detector ([`fracture`]) over the
//!   whole body (both rings) at every time-series row and at the end: the largest number of
//!   clusters (particles closer than 1.5 dx connected) and the largest nearest-neighbour
//!   distance, in dx. Two whole rings apart are 2 clusters; rings in contact are 1; more
//!   than 2 is fracture.
//! - `rebound_speed_ratio`: `-U(tf) / U(0)`, with U the x velocity of the left ring's
//!   centre of mass (`sum m u_x / sum m` over its particles; U(0) = v0 / 2). 1: the ring
//!   leaves at the speed it came with (elastic rebound); 0: it stopped; -1: it has not
//!   collided yet (a run shorter than the approach). Once the rings have separated U is
//!   constant (no external force), so at tf it is the rebound speed of a run long enough.
//! - `energy_rel_error`: the largest `|E(t) - E(0)| / E(0)` over every step, with
//!   `E = sum_a m_a |u_a|^2 / 2 + sum_a V_a (p_a^2 / (2 K) + s_a : s_a / (4 G))`, the kinetic
//!   energy plus the elastic strain energy of plane strain from the stress (V_a = m_a /
//!   rho_a; K the bulk and G the shear modulus, eq. 4 and eq. 8; s the in-plane deviatoric
//!   stress, its zz component not tracked). Monaghan's artificial viscosity dissipates
//!   energy by design, so this measures the viscous loss plus any error of time stepping
//!   and shifting, not an error of conservation alone.
//!
//! `timeseries.csv`: `t, ax, ay, bx, by, u_left, energy, clusters, max_gap`: the points A
//! and B, U of the left ring, E, and the detector.

use super::common::{plan, restore_sim, simulation, snapshot_bodies};
use super::params::{Bound, Params, Spec};
use super::solid_common::{
    check_count, forward_stepwise, solid_params, solid_setup, SolidDefaults, SolidSetup,
};
use super::{common_params, SceneEntry, SceneRun};
use crate::solver::fracture;
use crate::solver::math::Vector;
use crate::solver::nnps::Domain;
use crate::solver::simulation::Simulation;
use crate::solver::systems::{ElasticSolid, SolidInit, SolidMaterial};
use std::collections::BTreeMap;
use std::f64::consts::PI;
use std::path::Path;

/// Particles closer than this many initial spacings are connected in the fracture detector.
pub const LINK: f64 = 1.5;

/// The body's name.
const RINGS: &str = "rings";

/// The registry entry.
pub const ENTRY: SceneEntry = SceneEntry {
    name: "colliding_rings",
    dim: 2,
    about: "Two rubber rings colliding head on and rebounding (CTVF sec. 4.6)",
    params,
    build,
    check: |p| setup(p).map(drop),
    metrics: &["clusters_max", "max_gap", "rebound_speed_ratio", "energy_rel_error"],
    columns: &["t", "ax", "ay", "bx", "by", "u_left", "energy", "clusters", "max_gap"],
    outputs: 0,
};

fn params() -> Vec<Spec> {
    let mut v = vec![
        Spec::float(
            "v0_over_c0",
            0.12,
            Bound::Positive,
            "closing speed of the rings over c0 (each ring moves at half of it), v0 of sec. 4.6",
        ),
        Spec::float("inner_radius", 0.03, Bound::Positive, "ring inner radius r_min (m)"),
        Spec::float("outer_radius", 0.04, Bound::Positive, "ring outer radius r_max (m)"),
        Spec::float(
            "separation",
            0.082,
            Bound::Positive,
            "distance between the rings' centres (m); more than 2 r_max",
        ),
    ];
    v.extend(solid_params(&SolidDefaults {
        dx: 0.001,
        youngs_modulus: 1.0e7,
        poisson_ratio: 0.3975,
        density: 1200.0,
        yield_stress: None,
        alpha: 1.0,
        pst: "sun",
    }));
    v.extend(common_params(0.016));
    v
}

/// What the parameters make, once every check that needs no particle has passed.
struct Setup {
    solid: SolidSetup,
    /// Circles per ring.
    circles: usize,
    /// The speed of each ring (m/s).
    v_ring: f64,
}

fn setup(p: &Params) -> Result<Setup, String> {
    let scene = "colliding_rings";
    let (ri, ro, sep) = (p.float("inner_radius"), p.float("outer_radius"), p.float("separation"));
    if p.float("v0_over_c0") >= 1.0 {
        return Err(format!(
            "scene `{scene}`: parameter `v0_over_c0` = {:?}: must be below 1: the rings would approach at the speed of sound",
            p.float("v0_over_c0")
        ));
    }
    if ro <= ri {
        return Err(format!(
            "scene `{scene}`: parameter `outer_radius` = {ro:?}: must exceed `inner_radius` = {ri:?}"
        ));
    }
    let c0 = SolidMaterial::new(p.float("youngs_modulus"), p.float("poisson_ratio"), p.float("density"))
        .map(|m| m.c0())
        .unwrap_or(0.0);
    let v0 = p.float("v0_over_c0") * c0;
    let solid = solid_setup(scene, p, (v0, "`v0_over_c0`"), v0, [0.0; 3])?;
    let dx = solid.dx;
    if sep <= 2.0 * ro {
        return Err(format!(
            "scene `{scene}`: parameter `separation` = {sep:?}: the rings overlap; it must exceed 2 `outer_radius` = {:?}",
            2.0 * ro
        ));
    }
    if sep > 100.0 * ro {
        return Err(format!(
            "scene `{scene}`: parameter `separation` = {sep:?}: the rings would not meet; it must not exceed 100 `outer_radius` = {:?}",
            100.0 * ro
        ));
    }
    let circles = ((ro - ri) / dx).round();
    let what = format!("the rings (`inner_radius` = {ri:?}, `outer_radius` = {ro:?}) at `dx` = {dx:?}");
    if circles < 2.0 {
        return Err(format!("scene `{scene}`: {what} are fewer than 2 particles thick"));
    }
    check_count(scene, &what, 2.0 * PI * (ro * ro - ri * ri) / (dx * dx))?;
    Ok(Setup { solid, circles: circles as usize, v_ring: 0.5 * v0 })
}

/// One ring's particles on concentric circles (the module's docs), centred at `(cx, 0)`,
/// angles measured from the far side (`side` = -1: the left ring, whose far side is -x):
/// positions and masses, and the index of the outermost circle's particle nearest the top.
pub fn ring_lattice(
    cx: f64,
    side: f64,
    ri: f64,
    dx: f64,
    circles: usize,
    rho0: f64,
) -> (Vec<Vector<2>>, Vec<f64>, usize) {
    let (mut x, mut m, mut top) = (Vec::new(), Vec::new(), 0);
    for k in 0..circles {
        let r = ri + (k as f64 + 0.5) * dx;
        let n = ((2.0 * PI * r / dx).round() as usize).max(3);
        let mut best = f64::INFINITY;
        for j in 0..n {
            let theta = 2.0 * PI * j as f64 / n as f64;
            // Angle from the far side, anticlockwise seen from the ring's outside: the two
            // rings are mirror images of each other.
            let p = Vector::<2>::new(cx + side * r * theta.cos(), r * theta.sin());
            if k + 1 == circles && (theta - 0.5 * PI).abs() < best {
                best = (theta - 0.5 * PI).abs();
                top = x.len();
            }
            x.push(p);
            m.push(rho0 * 2.0 * PI * r * dx / n as f64);
        }
    }
    (x, m, top)
}

/// Kinetic plus elastic strain energy (plane strain, from the stress) of `s` (module docs).
pub fn energy(s: &ElasticSolid<2>) -> f64 {
    let (k, g) = (s.material.bulk_modulus(), s.material.shear_modulus());
    (0..s.len())
        .map(|i| {
            let v = s.m[i] / s.rho[i];
            0.5 * s.m[i] * s.u[i].norm_squared()
                + v * (s.p[i] * s.p[i] / (2.0 * k) + s.s[i].norm_squared() / (4.0 * g))
        })
        .sum()
}

struct Rings {
    sim: Simulation<2>,
    dx: f64,
    /// Particles of the left ring: `0..n_left`.
    n_left: usize,
    /// Points A and B.
    a: usize,
    b: usize,
    /// U(0) and E(0).
    u0: f64,
    e0: f64,
    energy_err: f64,
    /// The fracture detector's worst over the run.
    fracture: fracture::Worst,
}

fn build(p: &Params) -> Result<Box<dyn SceneRun>, String> {
    Ok(Box::new(rings(p)?))
}

fn rings(p: &Params) -> Result<Rings, String> {
    let Setup { solid: SolidSetup { material, scheme, kernel, dx, h }, circles, v_ring } = setup(p)?;
    let (ri, ro, sep) = (p.float("inner_radius"), p.float("outer_radius"), p.float("separation"));
    let (xl, ml, a) = ring_lattice(-0.5 * sep, -1.0, ri, dx, circles, material.rho0);
    let (xr, mr, b) = ring_lattice(0.5 * sep, 1.0, ri, dx, circles, material.rho0);
    let n_left = xl.len();
    let mut init = SolidInit::<2>::default();
    for (side, xs, ms) in [(1.0, xl, ml), (-1.0, xr, mr)] {
        for (x, m) in xs.into_iter().zip(ms) {
            init.x.push(x);
            init.u.push(Vector::<2>::new(side * v_ring, 0.0));
            init.m.push(m);
            init.rho.push(material.rho0);
            init.fixed.push(false);
        }
    }
    let solid = ElasticSolid::new(RINGS, h, init, material, scheme)?;
    // Room for the rings to travel at twice their speed to tf, and to flatten to twice
    // their size across.
    let reach = 2.0 * v_ring * p.float("tf");
    let (hx, hy) = (0.5 * sep + ro + reach + 10.0 * dx, 2.0 * ro + reach + 10.0 * dx);
    let domain = Domain::bounded([-hx, -hy], [hx, hy]);
    let sim = simulation("colliding_rings", p, domain, kernel, [solid.into()])?;
    let mut run = Rings {
        sim,
        dx,
        n_left,
        a,
        b: n_left + b,
        u0: 0.0,
        e0: 0.0,
        energy_err: 0.0,
        fracture: fracture::Worst::default(),
    };
    run.u0 = run.u_left();
    run.e0 = energy(run.solid());
    Ok(run)
}

impl Rings {
    fn solid(&self) -> &ElasticSolid<2> {
        self.sim.solid(RINGS).expect("the rings").0
    }

    /// U: the x velocity of the left ring's centre of mass.
    fn u_left(&self) -> f64 {
        let s = self.solid();
        let (mu, m) = (0..self.n_left).fold((0.0, 0.0), |(mu, m), i| (mu + s.m[i] * s.u[i][0], m + s.m[i]));
        mu / m
    }

    /// Follows the largest energy change at every step.
    fn after_step(&mut self) {
        let e = energy(self.solid());
        self.energy_err = self.energy_err.max((e - self.e0).abs() / self.e0);
    }

    fn fracture(&mut self) -> fracture::Fracture {
        let x = &self.sim.solid(RINGS).expect("the body").0.x;
        self.fracture.observe(x, self.dx, LINK)
    }
}

impl SceneRun for Rings {
    forward_stepwise!();
    fn plan(&self) -> String {
        plan(
            &self.sim,
            &format!(
                "two rings in one body: {} + {} particles, each at {:.4e} m/s towards the other",
                self.n_left,
                self.solid().len() - self.n_left,
                self.u0
            ),
        )
    }
    fn sample(&mut self) -> Vec<(&'static str, f64)> {
        let f = self.fracture();
        let s = self.solid();
        let (a, b) = (s.x[self.a], s.x[self.b]);
        let e = energy(s);
        vec![
            ("t", self.sim.time()),
            ("ax", a[0]),
            ("ay", a[1]),
            ("bx", b[0]),
            ("by", b[1]),
            ("u_left", self.u_left()),
            ("energy", e),
            ("clusters", f.clusters as f64),
            ("max_gap", f.max_gap),
        ]
    }
    fn snapshot(&self, dir: &Path, index: usize) -> std::io::Result<Vec<(String, String)>> {
        snapshot_bodies(&self.sim, dir, index, Vec::new())
    }
    fn metrics(&self) -> BTreeMap<String, f64> {
        // The detector at the end too, whatever the sampling.
        let worst = self.fracture.with(&self.solid().x, self.dx, LINK);
        let mut m = BTreeMap::from(worst.metrics());
        m.extend([
            ("rebound_speed_ratio".to_string(), -self.u_left() / self.u0),
            ("energy_rel_error".to_string(), self.energy_err),
        ]);
        m
    }
    fn save_state(&self) -> serde_json::Value {
        serde_json::json!({
            "sim": &self.sim.state,
            "energy_err": self.energy_err,
            "clusters_max": self.fracture.clusters_max,
            "max_gap": self.fracture.max_gap,
        })
    }
    fn load_state(&mut self, state: serde_json::Value) -> Result<(), String> {
        let get = |k: &str| state[k].clone();
        let err = |e: serde_json::Error| format!("checkpoint: {e}");
        self.energy_err = serde_json::from_value(get("energy_err")).map_err(err)?;
        self.fracture.clusters_max = serde_json::from_value(get("clusters_max")).map_err(err)?;
        self.fracture.max_gap = serde_json::from_value(get("max_gap")).map_err(err)?;
        restore_sim(&mut self.sim, &state)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The ring lattice holds the annulus' mass exactly, its points lie within the annulus,
    /// and the top point is on the outer circle at x = centre (within half a spacing).
    #[test]
    fn the_ring_lattice_fills_the_annulus() {
        let (ri, dx, rho0) = (0.03, 0.001, 1200.0);
        let (x, m, top) = ring_lattice(-0.041, -1.0, ri, dx, 10, rho0);
        let mass: f64 = m.iter().sum();
        let exact = rho0 * PI * (0.04f64.powi(2) - ri * ri);
        assert!((mass - exact).abs() < 1e-12 * exact, "{mass} {exact}");
        for p in &x {
            let r = (p - Vector::<2>::new(-0.041, 0.0)).norm();
            assert!(r > ri && r < 0.04, "{r}");
        }
        assert!(
            (x[top][0] + 0.041).abs() < 0.5 * dx && (x[top][1] - 0.0395).abs() < 1e-3 * dx,
            "{:?}",
            x[top]
        );
    }

    /// The quick resolution (dx = 0.002) with the rings' outer surfaces 1 cm apart
    /// (`separation` = 0.09 m, so that at h = dx their kernels first reach each other after
    /// about 0.5 ms at 0.06 c0 each), run to t = 3 ms, through the first contact: before it
    /// the left ring's centre of mass moves at the set speed v0 / 2 = 0.06 c0 (to 1e-9
    /// relative: the forces within one ring are pairwise and cancel); over the run the body
    /// never falls into more than the two rings (`clusters_max` <= 2), no particle is farther
    /// than 1.5 dx from its nearest neighbour, and the energy (kinetic + strain) stays within
    /// 20 % of the initial (the viscous loss of a collision is a few per cent: a blow-up
    /// or a fracture would exceed it), and the contact has slowed the left ring.
    #[test]
    fn the_quick_rings_approach_at_the_set_speed_and_do_not_fracture() {
        let specs = params();
        let mut p = Params::defaults(&specs);
        for (key, value) in [("dx", "0.002"), ("tf", "0.003"), ("separation", "0.09")] {
            p.set_str("colliding_rings", &specs, key, value).unwrap();
        }
        let mut run = rings(&p).unwrap();
        let c0 = run.solid().material.c0();
        assert!((run.u0 - 0.06 * c0).abs() < 1e-9 * c0, "{} {}", run.u0, 0.06 * c0);
        run.advance(3e-4, 0.003, &mut |_, _| true).unwrap();
        assert!((run.u_left() - 0.06 * c0).abs() < 1e-9 * c0, "before contact: {}", run.u_left());
        while run.sim.time() < 0.003 {
            let before = run.sim.time();
            run.advance(before + 1e-4, 0.003, &mut |_, _| true).unwrap();
            run.sample();
        }
        let m = run.metrics();
        assert!(m["clusters_max"] <= 2.0, "{m:?}");
        assert!(m["max_gap"] < LINK, "{m:?}");
        assert!(m["energy_rel_error"] < 0.2, "{m:?}");
        assert!(run.u_left() < run.u0, "the collision slowed the left ring: {m:?}");
    }

    /// Bad geometry is refused with the key and value named.
    #[test]
    fn bad_geometry_is_refused_by_key() {
        let specs = params();
        for (key, value) in [("separation", "0.05"), ("outer_radius", "0.02"), ("v0_over_c0", "1.5")] {
            let mut p = Params::defaults(&specs);
            p.set_str("colliding_rings", &specs, key, value).unwrap();
            let e = setup(&p).err().unwrap();
            assert!(e.contains(&format!("`{key}` = {value}")), "{e}");
        }
    }
}
