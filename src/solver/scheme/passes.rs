//! The parallel loops. Each pass is a gather over the neighbours of every particle of one
//! body, writing only that particle's own row: a plain rayon loop with no locks or atomics,
//! and a neighbour order fixed by the cell list, so results are bit-for-bit identical for
//! any number of threads.

use super::{DensityModel, FluidScheme, PressureGradient, PressureModel, Shifting};
use crate::solver::equations::{
    artificial_viscosity, continuity, edac, momentum, shifting, viscosity, Pair, Point,
};
use crate::solver::kernel::Kernel;
use crate::solver::math::Vector;
use crate::solver::nnps::{CellList, Domain};
use crate::solver::particles::{Fluid, FluidRates};
use rayon::prelude::*;

/// Particles per rayon task: large enough that scheduling is noise.
const MIN_LEN: usize = 128;

#[inline(always)]
fn pair<const D: usize>(k: &Kernel, h: f64, xij: Vector<D>, r2: f64) -> Pair<D> {
    let (w, f) = k.w_and_grad_factor(r2.sqrt(), h);
    Pair {
        xij,
        r2,
        h,
        wij: w,
        dwij: xij * f,
    }
}

#[inline(always)]
fn point<const D: usize>(f: &Fluid<D>, u_hat: &[Vector<D>], i: usize) -> Point<D> {
    Point {
        u: f.u[i],
        u_hat: u_hat[i],
        m: f.m[i],
        rho: f.rho[i],
        p: f.p[i],
    }
}

/// Scratch state of the fluid passes that must survive between steps without allocating:
/// the IPST work arrays and their own cell list.
#[derive(Clone, Debug)]
pub struct FluidPasses<const D: usize> {
    ipst_cells: Option<CellList<D>>,
    x_shift: Vec<Vector<D>>,
    dr: Vec<Vector<D>>,
    chi: Vec<f64>,
    /// IPST iterations taken in the last step (for logs and benchmarks).
    pub last_ipst_iterations: usize,
}

impl<const D: usize> FluidPasses<D> {
    /// Work space for `scheme` (the IPST arrays only when IPST is declared).
    pub fn new(scheme: &FluidScheme, domain: Domain<D>, radius: f64) -> Self {
        let ipst = matches!(
            scheme.transport.map(|t| t.shifting),
            Some(Shifting::Ipst { .. })
        );
        Self {
            ipst_cells: ipst.then(|| CellList::new(domain, radius)),
            x_shift: Vec::new(),
            dr: Vec::new(),
            chi: Vec::new(),
            last_ipst_iterations: 0,
        }
    }

    /// Summation density, `rho_a = sum_b m_b W_ab`.
    pub fn summation_density(fluid: &mut Fluid<D>, cells: &CellList<D>, k: &Kernel) {
        let h = fluid.h;
        let (x, m) = (&fluid.x, &fluid.m);
        fluid
            .rho
            .par_iter_mut()
            .enumerate()
            .with_min_len(MIN_LEN)
            .for_each(|(i, rho)| {
                let mut s = 0.0;
                cells.for_each_neighbour(x, &x[i], |j, _, r2| {
                    s += m[j] * k.w(r2.sqrt(), h);
                });
                *rho = s;
            });
    }

    /// Pass A: the density and pressure rates (eqs. 25 and 26), then their explicit
    /// update over `dt` (eqs. 56-57); or the state equation (8).
    pub fn update_density_and_pressure(
        fluid: &mut Fluid<D>,
        cells: &CellList<D>,
        k: &Kernel,
        s: &FluidScheme,
        rates: &mut FluidRates<D>,
        dt: f64,
    ) {
        let continuity_on = s.density == DensityModel::Continuity;
        let corr = s.transport.map(|t| t.corrections);
        match s.pressure {
            PressureModel::StateEquation { c0, rho0 } => {
                if continuity_on {
                    Self::density_rate(
                        fluid,
                        cells,
                        k,
                        corr.is_some_and(|c| c.continuity),
                        &mut rates.drho,
                    );
                    apply(&mut fluid.rho, &rates.drho, dt);
                }
                let c2 = c0 * c0;
                fluid
                    .p
                    .par_iter_mut()
                    .zip(&fluid.rho)
                    .for_each(|(p, &rho)| *p = c2 * (rho - rho0));
            }
            PressureModel::Edac { cs, nu } => {
                let cs2 = cs * cs;
                let pressure_corr = corr.is_some_and(|c| c.pressure);
                let continuity_corr = corr.is_some_and(|c| c.continuity);
                let h = fluid.h;
                let f: &Fluid<D> = fluid;
                let u_hat = f.u_hat();
                let rate = |i: usize| -> (f64, f64) {
                    let a = point(f, u_hat, i);
                    let (mut dp, mut drho) = (0.0, 0.0);
                    cells.for_each_neighbour(&f.x, &f.x[i], |j, xij, r2| {
                        let ab = pair(k, h, xij, r2);
                        let b = point(f, u_hat, j);
                        dp += edac::compressibility(&a, &b, &ab, cs2)
                            + edac::diffusion(&a, &b, &ab, nu);
                        if pressure_corr {
                            dp += edac::transport_correction(&a, &b, &ab);
                        }
                        if continuity_on {
                            drho += continuity::transport_divergence(&a, &b, &ab);
                            if continuity_corr {
                                drho += continuity::correction(&a, &b, &ab);
                            }
                        }
                    });
                    (dp, drho)
                };
                if continuity_on {
                    rates
                        .dp
                        .par_iter_mut()
                        .zip(rates.drho.par_iter_mut())
                        .enumerate()
                        .with_min_len(MIN_LEN)
                        .for_each(|(i, (dp, drho))| (*dp, *drho) = rate(i));
                    apply(&mut fluid.rho, &rates.drho, dt);
                } else {
                    rates
                        .dp
                        .par_iter_mut()
                        .enumerate()
                        .with_min_len(MIN_LEN)
                        .for_each(|(i, dp)| *dp = rate(i).0);
                }
                apply(&mut fluid.p, &rates.dp, dt);
            }
        }
    }

    fn density_rate(
        fluid: &Fluid<D>,
        cells: &CellList<D>,
        k: &Kernel,
        corrected: bool,
        drho: &mut [f64],
    ) {
        let h = fluid.h;
        let u_hat = fluid.u_hat();
        drho.par_iter_mut()
            .enumerate()
            .with_min_len(MIN_LEN)
            .for_each(|(i, out)| {
                let a = point(fluid, u_hat, i);
                let mut s = 0.0;
                cells.for_each_neighbour(&fluid.x, &fluid.x[i], |j, xij, r2| {
                    let ab = pair(k, h, xij, r2);
                    let b = point(fluid, u_hat, j);
                    s += continuity::transport_divergence(&a, &b, &ab);
                    if corrected {
                        s += continuity::correction(&a, &b, &ab);
                    }
                });
                *out = s;
            });
    }

    /// Pass B: the acceleration (eq. 27 or its Adami form) and, for the shifting
    /// techniques that are sums over neighbours, the homogenisation acceleration.
    /// `dt` is the step the homogenisation will be applied over (eq. 36 divides by it).
    pub fn accelerations(
        fluid: &Fluid<D>,
        cells: &CellList<D>,
        k: &Kernel,
        s: &FluidScheme,
        rates: &mut FluidRates<D>,
        dt: f64,
    ) {
        let h = fluid.h;
        let u_hat = fluid.u_hat();
        let mut g = Vector::<D>::zeros();
        for d in 0..D.min(3) {
            g[d] = s.gravity[d];
        }
        let shifting = s.transport.map(|t| t.shifting);
        let corr = s.transport.map(|t| t.corrections);
        let momentum_corr = corr.is_some_and(|c| c.momentum);
        let transport = s.transport.is_some();
        let sun_prefactor = match shifting {
            // -(Ma c0) 2h / dt, eq. (36)
            Some(Shifting::Sun2019 { ma_c0, .. }) => -ma_c0 * 2.0 * h / dt,
            _ => 0.0,
        };
        let rate = |i: usize| -> (Vector<D>, Vector<D>) {
            let a = point(fluid, u_hat, i);
            let mut acc = Vector::<D>::zeros();
            let mut ac = Vector::<D>::zeros();
            // BQL: the reference weights and the neighbour-mean pressure, combined at the end.
            let (mut c_ref, mut p_sum, mut n_nb) = (Vector::<D>::zeros(), 0.0, 0usize);
            cells.for_each_neighbour(&fluid.x, &fluid.x[i], |j, xij, r2| {
                let ab = pair(k, h, xij, r2);
                let b = point(fluid, u_hat, j);
                let (grad, bql) = match s.pressure_gradient {
                    PressureGradient::Symmetric { bql } => {
                        (momentum::pressure_gradient(&a, &b, &ab), bql)
                    }
                    PressureGradient::Adami { bql } => {
                        (momentum::pressure_gradient_adami(&a, &b, &ab), bql)
                    }
                };
                acc += grad;
                if bql {
                    c_ref += match s.pressure_gradient {
                        PressureGradient::Symmetric { .. } => {
                            momentum::pressure_reference_weight(&a, &b, &ab)
                        }
                        PressureGradient::Adami { .. } => momentum::adami_weight(&a, &b, &ab),
                    };
                    p_sum += b.p;
                    n_nb += 1;
                }
                if let Some(nu) = s.viscosity {
                    acc += viscosity::morris(&a, &b, &ab, nu);
                }
                if let Some((alpha, c)) = s.artificial_viscosity {
                    acc += artificial_viscosity::monaghan(&a, &b, &ab, alpha, c);
                }
                if transport {
                    acc += momentum::artificial_stress(&a, &b, &ab);
                    if momentum_corr {
                        acc += momentum::transport_divergence_correction(&a, &b, &ab);
                    }
                    match shifting {
                        Some(Shifting::BackgroundPressure { pb }) => {
                            ac += shifting::background_pressure(&a, &b, &ab, pb)
                        }
                        Some(Shifting::Sun2019 { w_dx, r, n, .. }) => {
                            ac += shifting::sun2019(&b, &ab, w_dx, r, n)
                        }
                        _ => {}
                    }
                }
            });
            if n_nb > 0 {
                // BQL: the gradient with the neighbour-mean pressure as reference; the
                // mean is constant over the sum, so it is applied once here.
                acc += c_ref * (p_sum / n_nb as f64);
            }
            if matches!(shifting, Some(Shifting::Sun2019 { .. })) {
                ac *= sun_prefactor;
            }
            (acc + g, ac)
        };
        if transport {
            rates
                .du
                .par_iter_mut()
                .zip(rates.a_c.par_iter_mut())
                .enumerate()
                .with_min_len(MIN_LEN)
                .for_each(|(i, (du, ac))| {
                    let (d, c) = rate(i);
                    *du = d;
                    // IPST fills a_c in its own pass.
                    if !matches!(shifting, Some(Shifting::Ipst { .. })) {
                        *ac = c;
                    }
                });
        } else {
            rates
                .du
                .par_iter_mut()
                .enumerate()
                .with_min_len(MIN_LEN)
                .for_each(|(i, du)| *du = rate(i).0);
        }
    }

    /// IPST (eqs. 37-41): move copies of the particles by `U_max dt sum V_b n_ab W_ab` until
    /// `|max chi - chi_ref| <= tol chi_ref` (eq. 39, chi of eq. 40) or `max_iter` moves,
    /// then set `(du/dt)_c = 2 (r^M - r^0) / dt^2` (eq. 41). The particles themselves are not
    /// moved: the kick of the next step applies the displacement through u~.
    pub fn ipst(
        &mut self,
        fluid: &Fluid<D>,
        domain: &Domain<D>,
        k: &Kernel,
        s: &FluidScheme,
        rates: &mut FluidRates<D>,
        dt: f64,
    ) {
        let Some(Shifting::Ipst {
            u_max,
            tol,
            max_iter,
            chi_ref,
        }) = s.transport.map(|t| t.shifting)
        else {
            return;
        };
        let cells = self.ipst_cells.as_mut().expect("IPST work space");
        let n = fluid.len();
        let h = fluid.h;
        self.x_shift.clear();
        self.x_shift.extend_from_slice(&fluid.x);
        self.dr.resize(n, Vector::zeros());
        self.chi.resize(n, 0.0);
        let u_hat = fluid.u_hat();
        let mut iterations = 0;
        while iterations < max_iter {
            cells.update(&self.x_shift);
            let xs = &self.x_shift;
            let c: &CellList<D> = cells;
            self.dr
                .par_iter_mut()
                .zip(self.chi.par_iter_mut())
                .enumerate()
                .with_min_len(MIN_LEN)
                .for_each(|(i, (dr, chi))| {
                    let (mut d, mut x) = (Vector::<D>::zeros(), 0.0);
                    c.for_each_neighbour(xs, &xs[i], |j, xij, r2| {
                        let ab = pair(k, h, xij, r2);
                        let b = point(fluid, u_hat, j);
                        d += shifting::ipst_displacement(&b, &ab);
                        x += shifting::ipst_chi(&ab);
                    });
                    *dr = d * (u_max * dt);
                    *chi = x;
                });
            let chi_max = self.chi.iter().fold(f64::MIN, |m, &v| m.max(v));
            if (chi_max - chi_ref).abs() <= tol * chi_ref {
                break;
            }
            for (x, dr) in self.x_shift.iter_mut().zip(&self.dr) {
                *x += dr;
                domain.wrap(x);
            }
            iterations += 1;
        }
        self.last_ipst_iterations = iterations;
        let f = 2.0 / (dt * dt);
        let (x0, xs) = (&fluid.x, &self.x_shift);
        rates
            .a_c
            .par_iter_mut()
            .enumerate()
            .with_min_len(MIN_LEN)
            .for_each(|(i, ac)| {
                *ac = domain.delta(&xs[i], &x0[i]) * f;
            });
    }
}

/// chi_ref of eq. (39): the mean of `chi = h^2 sum W` over the initial configuration for
/// internal flows (the authors' internal-flow choice: a perturbed lattice has no single
/// value), the maximum with a free surface (CTVF sec. 3.3.2).
pub fn ipst_chi_reference<const D: usize>(
    fluid: &Fluid<D>,
    cells: &CellList<D>,
    k: &Kernel,
    free_surface: bool,
) -> f64 {
    let h = fluid.h;
    let chi: Vec<f64> = (0..fluid.len())
        .map(|i| {
            let mut s = 0.0;
            cells.for_each_neighbour(&fluid.x, &fluid.x[i], |_, _, r2| {
                s += h * h * k.w(r2.sqrt(), h)
            });
            s
        })
        .collect();
    if free_surface {
        chi.iter().fold(f64::MIN, |m, &v| m.max(v))
    } else {
        chi.iter().sum::<f64>() / chi.len() as f64
    }
}

fn apply(v: &mut [f64], rate: &[f64], dt: f64) {
    v.par_iter_mut().zip(rate).for_each(|(v, r)| *v += dt * r);
}
