//! The solver is one source for 2D and 3D: a periodic cube of fluid at rest, uniform
//! pressure, stays at rest with every scheme (the 3D path of kernels, neighbour lists,
//! passes and integrator, exercised end to end).

use sphrepro::solver::kernel::{Kernel, KernelKind};
use sphrepro::solver::math::Vector;
use sphrepro::solver::nnps::Domain;
use sphrepro::solver::particles::{Fluid, FluidInit};
use sphrepro::solver::scheme::{FluidSettings, Pst, SchemeName};
use sphrepro::solver::simulation::{Simulation, TimeSettings};

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
        let fluid = Fluid::new("fluid", dx, init.clone(), s.transport.is_some()).unwrap();
        let time = TimeSettings { cfl: 0.25, c0: 10.0, u_ref: 1.0, blowup_factor: 10.0 };
        let mut sim =
            Simulation::new(Domain::periodic([0.0; 3], [1.0; 3]), kernel, fluid, None, s, time).unwrap();
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
