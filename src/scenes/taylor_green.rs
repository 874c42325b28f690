//! Taylor-Green vortex in a periodic unit square (CTVF paper, sec. 4.1), and the same
//! vortex in a periodic box `nz` layers deep (`taylor_green_3d`): uniform along z, it has the
//! same exact solution, so the 3D path of the solver (3D kernel normalisation, neighbour
//! lists, passes, integrator) is measured against it with the same metrics.
//!
//! Exact solution, eqs. (63)-(65), with `b = -8 pi^2 / Re`, U = 1 m/s, L = 1 m:
//! `u = -U e^{bt} cos(2 pi x) sin(2 pi y)`, `v = U e^{bt} sin(2 pi x) cos(2 pi y)`,
//! `p = -U^2 e^{2bt} (cos(4 pi x) + cos(4 pi y)) / 4`. Quintic spline, h/dx = 1, summation
//! density, no artificial viscosity, c0 = 10 U, rho0 = 1.
//!
//! Metrics in `summary.json`:
//! - `l1_velocity_final`: eq. (66) as PySPH computes it, mean | |u_i| - |u_exact(x_i)| |
//!   over mean |u_exact|, at tf;
//! - `l1_velocity_max`: the largest value of the same over the time series;
//! - `l1_velocity_mean`: its time average over [0, tf] (trapezoidal rule on the time
//!   series): the papers' L1 figures are curves, and the value at tf of a curve that
//!   fluctuates by tens of per cent from sample to sample is a fragile way to compare two;
//! - `umax_decay_rel_error`: |max |u| - U e^{b tf}| / (U e^{b tf});
//! - `p_l1_final`: mean |(p - mean p) - (p_e - mean p_e)| over max |p_e| at tf;
//! - `kinetic_energy_rel_error`: |KE - KE_exact| / KE_exact at tf, KE = sum m |u|^2 / 2.

use super::fluid_scheme::{fluid_scheme, scheme_params, FluidConstants};
use super::memory::check_size;
use super::params::{Bound, Params, Spec};
use super::snapshots::{shifting_columns, snapshot_bodies};
use super::stepping::{checkpoint, forward_to_sim, plan};
use super::{common_params, SceneEntry, SceneRun};
use crate::solver::kernel::Kernel;
use crate::solver::math::Vector;
use crate::solver::nnps::Domain;
use crate::solver::output::vtu::Field;
use crate::solver::scheme::FluidScheme;
use crate::solver::simulation::Simulation;
use crate::solver::systems::{Fluid, FluidInit};
use rand::{Rng, SeedableRng};
use std::collections::BTreeMap;
use std::f64::consts::PI;
use std::path::Path;

const U: f64 = 1.0;
const L: f64 = 1.0;
const RHO0: f64 = 1.0;
const C0: f64 = 10.0 * U;

const METRICS: &[&str] = &[
    "l1_velocity_final",
    "l1_velocity_max",
    "l1_velocity_mean",
    "umax_decay_rel_error",
    "p_l1_final",
    "kinetic_energy_rel_error",
];

/// The registry entry of the square.
pub const ENTRY: SceneEntry = entry::<2>(
    "taylor_green",
    "Taylor-Green vortex in a periodic unit square, against the exact solution (CTVF sec. 4.1)",
);

/// The registry entry of the box (3D).
pub const ENTRY_3D: SceneEntry = entry::<3>(
    "taylor_green_3d",
    "The Taylor-Green vortex in a periodic box nz layers deep, uniform along z: the 3D solver against the same exact solution",
);

/// The scene in `D` dimensions: one source, the dimension a parameter.
const fn entry<const D: usize>(name: &'static str, about: &'static str) -> SceneEntry {
    SceneEntry {
        name,
        dim: D,
        about,
        params: params::<D>,
        build: build::<D>,
        check: |p| setup::<D>(p).map(drop),
        metrics: METRICS,
        columns: &[
            "t",
            "u_max",
            "u_max_exact",
            "l1_velocity",
            "decay_rel_error",
            "p_l1",
            "kinetic_energy",
            "kinetic_energy_exact",
            "ipst_iterations",
            "shift_max",
        ],
        outputs: 1,
    }
}

fn params<const D: usize>() -> Vec<Spec> {
    let mut v = vec![
        Spec::int("nx", 50, 1, "particles per side"),
        Spec::float("re", 100.0, Bound::Positive, "Reynolds number U L / nu"),
        // At most dx / 2 each way: a particle never passes its neighbour's lattice site.
        Spec::float("perturb", 0.0, Bound::NonNegative, "random initial displacement, as a fraction of dx")
            .at_most(1.0),
        Spec::int("seed", 1, 0, "seed of the initial perturbation"),
    ];
    if D == 3 {
        v.push(Spec::int(
            "nz",
            6,
            1,
            "particle layers along z (the box is nz dx deep, at least two kernel supports)",
        ));
    }
    v.extend(scheme_params("sun"));
    v.extend(common_params(2.0));
    v
}

/// The exact velocity and pressure at `x` and time `t`, eqs. (63)-(65) (no motion along
/// a third axis).
pub fn exact<const D: usize>(x: &Vector<D>, t: f64, re: f64) -> (Vector<D>, f64) {
    let b = -8.0 * PI * PI / re;
    let e = U * (b * t).exp();
    let (sx, cx) = (2.0 * PI * x[0]).sin_cos();
    let (sy, cy) = (2.0 * PI * x[1]).sin_cos();
    let mut u = Vector::<D>::zeros();
    u[0] = -e * cx * sy;
    u[1] = e * sx * cy;
    let p = -e * e * ((4.0 * PI * x[0]).cos() + (4.0 * PI * x[1]).cos()) / 4.0;
    (u, p)
}

struct TaylorGreen<const D: usize> {
    sim: Simulation<D>,
    /// The domain, for the plan.
    setting: String,
    re: f64,
    l1: L1History,
}

/// The L1 error over the samples taken so far: its largest value and its time integral.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
struct L1History {
    max: f64,
    /// Trapezoidal integral over [0, t] of the last sample,
    integral: f64,
    /// that sample `(t, L1)`.
    last: Option<(f64, f64)>,
}

impl L1History {
    /// The history with the sample `(t, l1)` appended.
    fn with(self, t: f64, l1: f64) -> Self {
        let integral = match self.last {
            Some((t0, l0)) => self.integral + 0.5 * (t - t0) * (l0 + l1),
            None => 0.0,
        };
        Self { max: self.max.max(l1), integral, last: Some((t, l1)) }
    }

    /// The time average over [0, t] once the value `l1` at `t` is included (`l1` itself at
    /// t = 0).
    fn mean_with(self, t: f64, l1: f64) -> f64 {
        let h = if self.last.is_some_and(|(t0, _)| t0 >= t) { self } else { self.with(t, l1) };
        if t > 0.0 {
            h.integral / t
        } else {
            l1
        }
    }
}

fn build<const D: usize>(p: &Params) -> Result<Box<dyn SceneRun>, String> {
    let sim = simulation::<D>(p)?;
    let setting = match D {
        2 => "periodic unit square".to_string(),
        _ => format!("periodic box, {} layers deep", p.int("nz")),
    };
    Ok(Box::new(TaylorGreen { sim, setting, re: p.float("re"), l1: L1History::default() }))
}

/// What the particles are made from, once every parameter check that needs none of them
/// has passed.
struct Setup<const D: usize> {
    nx: usize,
    nz: usize,
    dx: f64,
    re: f64,
    kernel: Kernel,
    h: f64,
    scheme: FluidScheme,
    domain: Domain<D>,
}

/// The scene's name in `D` dimensions, for its errors.
const fn name<const D: usize>() -> &'static str {
    if D == 3 {
        ENTRY_3D.name
    } else {
        ENTRY.name
    }
}

fn setup<const D: usize>(p: &Params) -> Result<Setup<D>, String> {
    let scene = name::<D>();
    let nx = p.int("nx") as usize;
    let re = p.float("re");
    let dx = L / nx as f64;
    let nz = if D == 3 { p.int("nz") as usize } else { 1 };
    let size = if D == 3 { format!("{nx} (`nz` = {nz})") } else { nx.to_string() };
    check_size::<D>(scene, "nx", size, (nx as f64).powi(2) * nz as f64)?;
    let constants = FluidConstants::internal_flow(RHO0, C0, U, L, re, dx);
    let (kernel, h, scheme) = fluid_scheme::<D>(scene, p, &constants)?;
    let depth = nz as f64 * dx;
    let domain = Domain::periodic([0.0; D], std::array::from_fn(|k| if k < 2 { L } else { depth }));
    // The box must hold two kernel supports along each axis for its periodic images to be
    // distinct; along the third, that is a matter of `nz`.
    let radius = kernel.support() * h;
    if domain.short_periodic_axis(radius) == Some(2) {
        return Err(format!(
            "scene `{scene}`: `nz` = {nz}: the box ({depth:.4} deep) must be at least two kernel supports ({:.4}) deep",
            2.0 * radius
        ));
    }
    domain.check_periodic(radius).map_err(|e| format!("scene `{scene}`: {e}"))?;
    Ok(Setup { nx, nz, dx, re, kernel, h, scheme, domain })
}

/// The simulation the scene runs in `D` dimensions, for benchmarks and tests that drive
/// steps directly.
pub fn simulation<const D: usize>(p: &Params) -> Result<Simulation<D>, String> {
    let Setup { nx, nz, dx, re, kernel, h, scheme, domain } = setup::<D>(p)?;
    // Lattice at cell centres, optionally perturbed (seeded), initialised from the exact
    // solution at t = 0 at the perturbed positions.
    let perturb = p.float("perturb");
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(p.int("seed") as u64);
    let mut init = FluidInit::default();
    for k in 0..nz {
        for j in 0..nx {
            for i in 0..nx {
                let mut x = Vector::<D>::zeros();
                x[0] = (i as f64 + 0.5) * dx;
                x[1] = (j as f64 + 0.5) * dx;
                if D == 3 {
                    x[2] = (k as f64 + 0.5) * dx;
                }
                if perturb > 0.0 {
                    for d in 0..D {
                        x[d] += (rng.gen::<f64>() - 0.5) * perturb * dx;
                    }
                    domain.wrap(&mut x);
                }
                let (u, pr) = exact(&x, 0.0, re);
                init.x.push(x);
                init.u.push(u);
                init.p.push(pr);
                init.m.push(RHO0 * dx.powi(D as i32));
                init.rho.push(RHO0);
            }
        }
    }
    let fluid = Fluid::new("fluid", h, init, scheme)?;
    super::stepping::simulation(name::<D>(), p, domain, kernel, [fluid.into()])
}

/// Parameters of this scene from `key=value` strings over the defaults.
pub fn params_from(sets: &[&str]) -> Result<Params, String> {
    ENTRY.params_from_sets(&sets.iter().map(|s| s.to_string()).collect::<Vec<_>>())
}

/// Error norms of the current state against the exact solution.
struct Errors {
    u_max: f64,
    u_max_exact: f64,
    l1: f64,
    p_l1: f64,
    ke: f64,
    ke_exact: f64,
}

impl<const D: usize> TaylorGreen<D> {
    fn errors(&self) -> Errors {
        let f = self.sim.fluid();
        let t = self.sim.time();
        let n = f.len() as f64;
        let (mut err, mut mag_e, mut ke, mut ke_e, mut u_max) = (0.0, 0.0, 0.0, 0.0, 0.0f64);
        let (mut p_mean, mut pe_mean, mut pe_max) = (0.0, 0.0, 0.0f64);
        let mut pe = Vec::with_capacity(f.len());
        // Sequential sums in particle-id order: the metrics do not depend on threads.
        let order = f.by_id(&(0..f.len() as u32).collect::<Vec<_>>());
        for &k in &order {
            let k = k as usize;
            let (ue, pex) = exact(&f.x[k], t, self.re);
            let speed = f.u[k].norm();
            err += (speed - ue.norm()).abs();
            mag_e += ue.norm();
            ke += 0.5 * f.m[k] * speed * speed;
            ke_e += 0.5 * f.m[k] * ue.norm_squared();
            u_max = u_max.max(speed);
            p_mean += f.p[k];
            pe_mean += pex;
            pe_max = pe_max.max(pex.abs());
            pe.push((k, pex));
        }
        p_mean /= n;
        pe_mean /= n;
        let p_err: f64 =
            pe.iter().map(|&(k, pex)| ((f.p[k] - p_mean) - (pex - pe_mean)).abs()).sum::<f64>() / n;
        let b = -8.0 * PI * PI / self.re;
        Errors {
            u_max,
            u_max_exact: U * (b * t).exp(),
            l1: err / mag_e,
            p_l1: p_err / pe_max,
            ke,
            ke_exact: ke_e,
        }
    }
}

impl<const D: usize> SceneRun for TaylorGreen<D> {
    forward_to_sim!();
    fn plan(&self) -> String {
        plan(&self.sim, &self.setting)
    }
    checkpoint!(l1);
    fn sample(&mut self) -> Vec<(&'static str, f64)> {
        let e = self.errors();
        self.l1 = self.l1.with(self.sim.time(), e.l1);
        let mut row = vec![
            ("t", self.sim.time()),
            ("u_max", e.u_max),
            ("u_max_exact", e.u_max_exact),
            ("l1_velocity", e.l1),
            ("decay_rel_error", (e.u_max - e.u_max_exact).abs() / e.u_max_exact),
            ("p_l1", e.p_l1),
            ("kinetic_energy", e.ke),
            ("kinetic_energy_exact", e.ke_exact),
        ];
        row.extend(shifting_columns(&self.sim));
        row
    }
    fn snapshot(&self, dir: &Path, index: usize) -> std::io::Result<Vec<(String, String)>> {
        let f = self.sim.fluid();
        let t = self.sim.time();
        let p_exact: Vec<f64> = f.x.iter().map(|x| exact(x, t, self.re).1).collect();
        // The pressure level of a periodic weakly compressible flow drifts freely (only
        // differences act); the deviation from the mean is the field to look at.
        let p_mean = f.p.iter().sum::<f64>() / f.len() as f64;
        let p_dev: Vec<f64> = f.p.iter().map(|p| p - p_mean).collect();
        snapshot_bodies(
            &self.sim,
            dir,
            index,
            vec![Field::Scalar("pressure_deviation", p_dev), Field::Scalar("pressure_exact", p_exact)],
        )
    }
    fn metrics(&self) -> BTreeMap<String, f64> {
        let e = self.errors();
        let mut m = BTreeMap::new();
        m.insert("l1_velocity_final".into(), e.l1);
        m.insert("l1_velocity_max".into(), self.l1.max.max(e.l1));
        m.insert("l1_velocity_mean".into(), self.l1.mean_with(self.sim.time(), e.l1));
        m.insert("umax_decay_rel_error".into(), (e.u_max - e.u_max_exact).abs() / e.u_max_exact);
        m.insert("p_l1_final".into(), e.p_l1);
        m.insert("kinetic_energy_rel_error".into(), (e.ke - e.ke_exact).abs() / e.ke_exact);
        m
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// du/dt of the exact solution: -grad p / rho + nu lap u = -pi (sin 4 pi x, sin 4 pi y) + b u.
    fn exact_acceleration(x: &Vector<2>, re: f64) -> Vector<2> {
        let b = -8.0 * PI * PI / re;
        let (u, _) = exact(x, 0.0, re);
        Vector::<2>::new(-PI * (4.0 * PI * x[0]).sin(), -PI * (4.0 * PI * x[1]).sin()) + u * b
    }

    #[test]
    fn initial_acceleration_matches_the_exact_solution() {
        // (tvf is left out: its pressure comes from the summation density, not the exact field.)
        for scheme in ["edac", "ctvf"] {
            let pst = if scheme == "ctvf" { "pst=sun" } else { "pst=none" };
            let p = params_from(&["nx=50", &format!("scheme={scheme}"), pst]).unwrap();
            let sim = simulation::<2>(&p).unwrap();
            let f = sim.fluid();
            let (mut err, mut norm) = (0.0, 0.0);
            for i in 0..f.len() {
                let e = exact_acceleration(&f.x[i], 100.0);
                err += (sim.fluid_rates().du[i] - e).norm();
                norm += e.norm();
            }
            let rel = err / norm;
            eprintln!("{scheme}: relative L1 error of du/dt at t = 0: {rel:.3e}");
            assert!(rel < 0.02, "{scheme}: {rel}");
        }
    }

    #[test]
    fn l1_mean_is_the_trapezoidal_time_average() {
        // L1 = t on [0, 1] then flat at 1 up to t = 2: mean 0.75.
        let h = [(0.0, 0.0), (0.5, 0.5), (1.0, 1.0), (1.5, 1.0)]
            .iter()
            .fold(L1History::default(), |h, &(t, l)| h.with(t, l));
        assert_eq!(h.max, 1.0);
        assert_eq!(h.mean_with(2.0, 1.0), 0.75);
        // The end state already sampled: not counted twice.
        assert_eq!(h.with(2.0, 1.0).mean_with(2.0, 1.0), 0.75);
        assert_eq!(L1History::default().mean_with(0.0, 0.3), 0.3);
    }
}
