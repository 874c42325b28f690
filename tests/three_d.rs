//! The solver is one source for 2D and 3D: a periodic cube of fluid at rest, uniform
//! pressure, stays at rest with every scheme (the 3D path of kernels, neighbour lists,
//! passes and integrator, exercised end to end).

use sphrepro::solver::kernel::{Kernel, KernelKind};
use sphrepro::solver::math::Vector;
use sphrepro::solver::nnps::Domain;
use sphrepro::solver::scheme::{FluidSettings, Pst, SchemeName};
use sphrepro::solver::simulation::{Simulation, TimeSettings};
use sphrepro::solver::systems::{Fluid, FluidInit};

#[test]
fn a_periodic_cube_at_rest_stays_at_rest_in_3d() {
    let n = 10;
    let dx = 1.0 / n as f64;
    let mut init = FluidInit::<3>::default();
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                init.x.push(Vector::<3>::new(
                    (i as f64 + 0.5) * dx,
                    (j as f64 + 0.5) * dx,
                    (k as f64 + 0.5) * dx,
                ));
                init.u.push(Vector::zeros());
                init.m.push(dx * dx * dx);
                init.rho.push(1.0);
                init.p.push(1.0);
            }
        }
    }
    let kernel = Kernel::new(KernelKind::QuinticSpline, 3);
    for (scheme, pst) in
        [(SchemeName::Edac, Pst::None), (SchemeName::Ctvf, Pst::Sun), (SchemeName::Ctvf, Pst::Ipst)]
    {
        let settings =
            FluidSettings { pst, ..FluidSettings::internal_flow(1.0, 10.0, 1.0, dx, kernel.w(dx, dx), 0.01) };
        let s = scheme.fluid_scheme(&settings);
        let fluid = Fluid::new("fluid", dx, init.clone(), s).unwrap();
        let domain = Domain::periodic([0.0; 3], [1.0; 3]);
        let mut sim =
            Simulation::builder(domain, kernel).body(fluid).time(TimeSettings::new(0.25)).build().unwrap();
        for _ in 0..20 {
            sim.step(f64::INFINITY).unwrap();
        }
        let f = sim.fluid();
        let u_max = f.u.iter().map(|u| u.norm()).fold(0.0, f64::max);
        let rho_dev = f.rho.iter().map(|r| (r - f.rho[0]).abs()).fold(0.0, f64::max);
        assert!(u_max < 1e-10, "{scheme:?}+{pst:?}: a uniform fluid moved: {u_max}");
        assert!(rho_dev < 1e-10, "{scheme:?}+{pst:?}: densities differ by {rho_dev}");
    }
}

/// `taylor_green_3d` (the vortex in a periodic box six layers deep, uniform along z), run
/// as `taylor_green` at the same resolution.
fn taylor_green_pair(extra: &[&str]) -> (Simulation<3>, Simulation<2>) {
    use sphrepro::scenes::taylor_green::{simulation, ENTRY, ENTRY_3D};
    let sets: Vec<String> = extra.iter().map(|s| s.to_string()).collect();
    let mut sets3 = sets.clone();
    sets3.push("nz=6".into());
    let sim3 = simulation::<3>(&ENTRY_3D.params_from_sets(&sets3).unwrap()).unwrap();
    let sim2 = simulation::<2>(&ENTRY.params_from_sets(&sets).unwrap()).unwrap();
    (sim3, sim2)
}

/// Eq. (66) as PySPH computes it, over the particles of `f` at time `t` (Re = 100).
fn l1_velocity<const D: usize>(f: &Fluid<D>, t: f64) -> f64 {
    let (mut err, mut norm) = (0.0, 0.0);
    for (x, u) in f.x.iter().zip(&f.u) {
        let ue = sphrepro::scenes::taylor_green::exact(x, t, 100.0).0.norm();
        err += (u.norm() - ue).abs();
        norm += ue;
    }
    err / norm
}

/// At t = 0 the 3D passes give the exact acceleration of the vortex, -grad p / rho + nu
/// lap u, as closely as the 2D ones do (the bound of the 2D test, 2 %, and within 10 % of
/// the 2D error), and nothing along z.
#[test]
fn taylor_green_in_a_box_starts_with_the_exact_acceleration() {
    use std::f64::consts::PI;
    let b = -8.0 * PI * PI / 100.0;
    for scheme in ["edac", "ctvf"] {
        let (sim3, sim2) = taylor_green_pair(&["nx=50", &format!("scheme={scheme}"), "pst=sun"]);
        let rel = |x: &[Vector<3>], du: &[Vector<3>]| {
            let (mut err, mut norm) = (0.0, 0.0);
            for (x, du) in x.iter().zip(du) {
                let u = sphrepro::scenes::taylor_green::exact(x, 0.0, 100.0).0;
                let e = Vector::<3>::new(-PI * (4.0 * PI * x[0]).sin(), -PI * (4.0 * PI * x[1]).sin(), 0.0)
                    + u * b;
                err += (du - e).norm();
                norm += e.norm();
            }
            err / norm
        };
        let e3 = rel(&sim3.fluid().x, &sim3.fluid_rates().du);
        let pad = |v: &[Vector<2>]| v.iter().map(|v| Vector::<3>::new(v[0], v[1], 0.0)).collect::<Vec<_>>();
        let e2 = rel(&pad(&sim2.fluid().x), &pad(&sim2.fluid_rates().du));
        let z = sim3.fluid_rates().du.iter().map(|a| a[2].abs()).fold(0.0, f64::max);
        eprintln!("{scheme}: relative L1 error of du/dt at t = 0: 3D {e3:.4e}, 2D {e2:.4e}; largest |du_z/dt| {z:.2e}");
        assert!(e3 < 0.02, "{scheme}: {e3}");
        assert!((e3 / e2 - 1.0).abs() < 0.1, "{scheme}: 3D {e3} against 2D {e2}");
        assert!(z < 1e-9, "{scheme}: du_z/dt = {z}");
    }
}

/// To t = 0.5 s at 20 x 20 (x 6) the box follows the square: its L1 error is within 30 % of
/// the square's, and its z-velocity stays small. It does not stay zero: seeded by rounding,
/// the exact lattice loses its order along z as it does in the plane (see the problem
/// `taylor_green_lattice`), by about 1e-5 U here with SPST.
#[test]
fn taylor_green_in_a_box_follows_the_square() {
    let (mut sim3, mut sim2) = taylor_green_pair(&["nx=20", "scheme=ctvf", "pst=sun"]);
    assert_eq!(sim3.fluid().len(), 20 * 20 * 6);
    let t_end = 0.5;
    while sim3.time() < t_end - 1e-12 {
        sim3.step(t_end - sim3.time()).unwrap();
    }
    while sim2.time() < t_end - 1e-12 {
        sim2.step(t_end - sim2.time()).unwrap();
    }
    assert_eq!(sim3.steps(), sim2.steps(), "the same time steps");
    let (e3, e2) = (l1_velocity(sim3.fluid(), sim3.time()), l1_velocity(sim2.fluid(), sim2.time()));
    let w = sim3.fluid().u.iter().map(|u| u[2].abs()).fold(0.0, f64::max);
    eprintln!("L1 at t = 0.5: 3D {e3:.4e}, 2D {e2:.4e}; largest |w| {w:.2e}");
    assert!((e3 / e2 - 1.0).abs() < 0.3, "3D {e3} against 2D {e2}");
    assert!(w < 1e-3, "|w| = {w}");
}
