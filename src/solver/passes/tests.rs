//! The passes against what they stand for: the compiled plans against the run-time plan,
//! the list's kernel values against the kernel, the reference pressure against a level.

use super::accelerations::accel_sums;
use super::rates::rate_sums;
use super::*;
use crate::solver::interactions::fluid_fluid::{AccelTerms, RateTerms};
use crate::solver::interactions::lists::build_kernel_list;
use crate::solver::kernel::{Kernel, KernelKind};
use crate::solver::nnps::{CellList, Domain};
use crate::solver::scheme::plan::{self, with_accelerations_plan, with_rates_plan};
use crate::solver::scheme::{
    Corrections, DensityModel, FluidSettings, PressureReference, Pst, SchemeName, SurfacePressure,
};
use crate::solver::systems::{FluidInit, FluidRates};

/// Every plan the named schemes take on an internal flow (viscous) and a free surface
/// (artificial viscosity) has loops of its own: none falls back to run-time checks.
#[test]
fn named_schemes_run_compiled_plans() {
    let internal = crate::solver::scheme::tests::internal_flow_settings();
    let free_surface = FluidSettings {
        nu: None,
        alpha: Some(0.05),
        density: DensityModel::Continuity,
        free_surface: Some(SurfacePressure::Evolve),
        ..internal
    };
    let (mut accel, mut rates) = (Vec::new(), Vec::new());
    for pst in [Pst::Sun, Pst::Ipst, Pst::None] {
        for corrections in [Corrections::ALL, Corrections::NONE] {
            // Within walls (the cavity) ctvf's `auto` reference is eq. (27) without BQL.
            for (flow, walls, names) in [
                (internal, false, &[SchemeName::Edac, SchemeName::Tvf, SchemeName::Ctvf][..]),
                (internal, true, &[SchemeName::Edac, SchemeName::Tvf, SchemeName::Ctvf][..]),
                (free_surface, true, &[SchemeName::Ctvf][..]),
            ] {
                for name in names {
                    let mut scheme = name.fluid_scheme(&FluidSettings { pst, corrections, ..flow });
                    scheme.resolve_reference(walls);
                    let case = format!("{name:?} {pst:?} {corrections:?}");
                    let b = AccelTerms::new(&scheme).plan;
                    assert!(plan::ACCELERATIONS.contains(&b), "{case}: pass B plan {b:#b}");
                    accel.push(b);
                    let a = RateTerms::new(&scheme).plan;
                    // Pass A runs for EDAC or the continuity equation (not tvf's state equation).
                    if a != 0 {
                        assert!(plan::RATES.contains(&a), "{case}: pass A plan {a:#b}");
                        rates.push(a);
                    }
                }
            }
        }
    }
    for plans in [&mut accel, &mut rates] {
        plans.sort();
        plans.dedup();
    }
    assert_eq!(accel.len(), plan::ACCELERATIONS.len(), "every compiled plan is one a named scheme takes");
    assert_eq!(rates.len(), plan::RATES.len(), "every compiled plan is one a named scheme takes");
}

/// A perturbed periodic lattice of 12x12 particles with varied fields (and u~ != u),
/// with its neighbour list.
fn perturbed_lattice() -> (Fluid<2>, KernelList<2>) {
    let (n, dx) = (12, 1.0 / 12.0);
    let h = dx;
    let wave = |k: usize, s: f64| (s * (k as f64 + 1.0)).sin();
    let x: Vec<Vector<2>> = (0..n * n)
        .map(|k| {
            Vector::<2>::new(
                ((k % n) as f64 + 0.5 + 0.2 * wave(k, 1.3)) * dx,
                ((k / n) as f64 + 0.5 + 0.2 * wave(k, 2.1)) * dx,
            )
        })
        .collect();
    let init = FluidInit {
        u: (0..n * n).map(|k| Vector::<2>::new(wave(k, 0.7), wave(k, 1.9))).collect(),
        m: vec![dx * dx; n * n],
        rho: (0..n * n).map(|k| 1.0 + 0.05 * wave(k, 3.1)).collect(),
        p: (0..n * n).map(|k| 2.0 * wave(k, 0.4)).collect(),
        x,
    };
    let physics = SchemeName::Ctvf.fluid_scheme(&crate::solver::scheme::tests::internal_flow_settings());
    let mut fluid = Fluid::new("f", h, init, physics).unwrap();
    for (k, uh) in fluid.u_hat.as_mut().unwrap().iter_mut().enumerate() {
        *uh += Vector::<2>::new(0.1 * wave(k, 2.7), 0.1 * wave(k, 0.3));
    }
    let kernel = Kernel::new(KernelKind::QuinticSpline, 2);
    let mut cells = CellList::new(Domain::periodic([0.0; 2], [1.0; 2]), kernel.support() * h);
    cells.update(&fluid.x);
    let mut nl = KernelList::new();
    build_kernel_list(&mut nl, &cells, &fluid.x, fluid.h, &kernel);
    (fluid, nl)
}

/// The list's kernel values of every pair: W and `grad W` as the kernel gives them one
/// pair at a time (bit for bit), and the Laplacian factor equal to
/// `x_ab . grad W / (r^2 + 0.01 h^2)` computed from the gradient (to rounding).
#[test]
fn list_kernel_values_are_the_kernels() {
    let (fluid, nl) = perturbed_lattice();
    let k = Kernel::new(crate::solver::kernel::KernelKind::QuinticSpline, 2).scaled(fluid.h);
    let mut pairs = 0;
    for i in 0..fluid.len() {
        nl.for_each(i, &fluid.x, |_, xij, r2, kw| {
            let (w, f) = k.w_and_grad_factor(r2.sqrt());
            assert_eq!((kw.w, kw.grad_factor), (w, f), "pair {i}: {xij:?}");
            let dw = xij * f;
            let lap = xij.dot(&dw) / (r2 + 0.01 * fluid.h * fluid.h);
            assert!((kw.lap - lap).abs() <= 1e-14 * lap.abs().max(1e-300), "{} vs {lap}", kw.lap);
            pairs += usize::from(r2 > 0.0);
        });
    }
    assert!(pairs > 20 * fluid.len(), "{pairs} pairs");
}

/// A reference pressure removes the pressure level from the accelerations: a uniform
/// pressure added to every particle changes them by rounding only with the neighbours'
/// or the fluid's mean as reference, and by its zeroth-order gradient error without.
#[test]
fn a_reference_pressure_removes_the_level() {
    let (mut fluid, nl) = perturbed_lattice();
    let accelerations = |fluid: &Fluid<2>, reference: PressureReference| {
        let settings = FluidSettings {
            pressure_reference: reference,
            ..crate::solver::scheme::tests::internal_flow_settings()
        };
        let mut fluid = fluid.clone();
        fluid.physics = SchemeName::Ctvf.fluid_scheme(&settings);
        let mut rates = FluidRates::of(&fluid);
        accelerations::accelerations(
            &mut FluidPasses::new(),
            &fluid,
            &nl,
            Boundaries::none(),
            None,
            &mut rates,
            1e-3,
        );
        rates.du
    };
    for (reference, removed) in [
        (PressureReference::LocalMean, true),
        (PressureReference::GlobalMean, true),
        (PressureReference::None, false),
    ] {
        let before = accelerations(&fluid, reference);
        fluid.p.iter_mut().for_each(|p| *p += 50.0);
        let after = accelerations(&fluid, reference);
        fluid.p.iter_mut().for_each(|p| *p -= 50.0);
        let scale = before.iter().map(|a| a.norm()).fold(0.0, f64::max);
        let change = before.iter().zip(&after).map(|(b, a)| (a - b).norm()).fold(0.0, f64::max);
        if removed {
            assert!(change < 1e-12 * 50.0 * scale, "{reference:?}: change {change:e}, scale {scale:e}");
        } else {
            assert!(change > 0.1 * scale, "{reference:?}: change {change:e}, scale {scale:e}");
        }
    }
}

/// A compiled plan sums exactly what the run-time plan sums, bit for bit, in both
/// passes: on a perturbed periodic lattice with varied fields, for every compiled plan.
#[test]
fn compiled_plans_equal_the_run_time_plan() {
    let (fluid, nl) = perturbed_lattice();
    let mut passes = FluidPasses::new();
    let src = passes.gather(&fluid, &nl, Boundaries::none());
    let accel = AccelTerms { plan: 0, nu: 0.01, av: (0.1, 10.0), pb: 100.0, sun: (2.0, 0.2, 4) };
    let rates = RateTerms { plan: 0, cs2: 100.0, nu: 0.05 };
    for &p in &plan::ACCELERATIONS {
        let terms = AccelTerms { plan: p, ..accel };
        for i in 0..fluid.len() {
            let compiled = with_accelerations_plan!(p, P => accel_sums::<P, 2>(&terms, &src, i));
            let runtime = accel_sums::<{ plan::RUNTIME }, 2>(&terms, &src, i);
            assert_eq!(
                (compiled.acc, compiled.ac, compiled.c_ref),
                (runtime.acc, runtime.ac, runtime.c_ref),
                "plan {p:#b}"
            );
        }
    }
    for &p in &plan::RATES {
        let terms = RateTerms { plan: p, ..rates };
        for i in 0..fluid.len() {
            let compiled = with_rates_plan!(p, P => rate_sums::<P, 2>(&terms, &src, i));
            assert_eq!(compiled, rate_sums::<{ plan::RUNTIME }, 2>(&terms, &src, i), "plan {p:#b}");
        }
    }
}
