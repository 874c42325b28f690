//! The simulation's tests: the stages in order, the schedules bit for bit, the
//! fluid-structure interface.

use super::*;
use crate::solver::integrator::{self, RatePositions};
use crate::solver::interactions::fluid_boundary::Boundaries;
use crate::solver::kernel::KernelKind;
use crate::solver::passes::{rates, FluidPasses};
use crate::solver::schedule::Wavefront;
use crate::solver::scheme::{
    Corrections, FluidSettings, Pst, SchemeName, Shifting, SolidSchemeName, SolidSettings, Transport,
};
use crate::solver::systems::{FluidInit, FluidWork, SolidInit, SolidMaterial};

/// The work of the first fluid of `sim`.
fn fluid_work<const D: usize>(sim: &mut Simulation<D>) -> &mut FluidWork<D> {
    let f = sim.first_fluid().expect("a fluid");
    sim.work[f].as_fluid_mut().expect("a fluid's work")
}

/// A Taylor-Green-like vortex on a perturbed 16x16 lattice in a periodic unit box,
/// CTVF with IPST, with the rates taken at `rates_at`.
fn vortex(rates_at: RatePositions) -> Simulation<2> {
    vortex_with(rates_at, Pst::Ipst)
}

fn vortex_with(rates_at: RatePositions, pst: Pst) -> Simulation<2> {
    vortex_sized(16, SchemeName::Ctvf, pst, rates_at)
}

/// The vortex on an `n` x `n` lattice with `scheme`.
fn vortex_sized(n: usize, scheme: SchemeName, pst: Pst, rates_at: RatePositions) -> Simulation<2> {
    vortex_of(n, KernelKind::QuinticSpline, scheme, pst, rates_at)
}

/// The same with the kernel `kind`.
fn vortex_of(
    n: usize,
    kind: KernelKind,
    scheme: SchemeName,
    pst: Pst,
    rates_at: RatePositions,
) -> Simulation<2> {
    let dx = 1.0 / n as f64;
    let mut init = FluidInit::<2>::default();
    for j in 0..n {
        for i in 0..n {
            let wobble = 0.1 * dx * ((7 * i + 3 * j) as f64).sin();
            let x = Vector::<2>::new((i as f64 + 0.5) * dx + wobble, (j as f64 + 0.5) * dx - wobble);
            let (a, b) = (2.0 * std::f64::consts::PI * x[0], 2.0 * std::f64::consts::PI * x[1]);
            init.x.push(x);
            init.u.push(Vector::<2>::new(-a.cos() * b.sin(), a.sin() * b.cos()));
            init.m.push(dx * dx);
            init.rho.push(1.0);
            init.p.push(0.0);
        }
    }
    let kernel = Kernel::new(kind, 2);
    let settings =
        FluidSettings { pst, ..FluidSettings::internal_flow(1.0, 10.0, 1.0, dx, kernel.w(dx, dx), 0.01) };
    let fluid = Fluid::new("fluid", dx, init, scheme.fluid_scheme(&settings)).unwrap();
    let time = TimeSettings { rate_positions: rates_at, ..TimeSettings::new(0.25) };
    Simulation::builder(Domain::periodic([0.0; 2], [1.0; 2]), kernel).body(fluid).time(time).build().unwrap()
}

/// A fluid split into two named bodies (its lower and upper halves, each added as a body
/// of its own) steps as the whole does, bit for bit, on one and two threads: both parts
/// are one fluid to the passes, so every sum runs over the same neighbours in the same
/// order. Each part keeps its name and its particles.
#[test]
fn a_fluid_split_into_two_bodies_steps_as_one() {
    let whole = vortex_sized(32, SchemeName::Ctvf, Pst::Ipst, RatePositions::End);
    let f = whole.fluid();
    let half = f.len() / 2;
    let init_part = |range: std::ops::Range<usize>| FluidInit {
        x: f.by_id(&f.x)[range.clone()].to_vec(),
        u: f.by_id(&f.u)[range.clone()].to_vec(),
        m: f.by_id(&f.m)[range.clone()].to_vec(),
        rho: vec![1.0; range.len()],
        p: vec![0.0; range.len()],
    };
    let (lower, upper) = (init_part(0..half), init_part(half..f.len()));
    let physics = {
        let mut s = f.physics;
        if let Some(Transport { shifting: Shifting::Ipst { chi_ref, .. }, .. }) = s.transport.as_mut() {
            *chi_ref = f64::NAN;
        }
        s
    };
    let (h, kernel, domain, time) = (f.h, whole.kernel, whole.domain, whole.time_settings);
    let run = |split: bool, threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| {
            let builder = Simulation::builder(domain, kernel).time(time);
            let mut sim = if split {
                builder
                    .body(Fluid::new("lower", h, lower.clone(), physics).unwrap())
                    .body(Fluid::new("upper", h, upper.clone(), physics).unwrap())
            } else {
                let mut all = lower.clone();
                for (a, b) in [(&mut all.x, &upper.x), (&mut all.u, &upper.u)] {
                    a.extend_from_slice(b);
                }
                all.m.extend_from_slice(&upper.m);
                all.rho.extend_from_slice(&upper.rho);
                all.p.extend_from_slice(&upper.p);
                builder.body(Fluid::new("fluid", h, all, physics).unwrap())
            }
            .build()
            .unwrap();
            for _ in 0..20 {
                sim.step(f64::INFINITY).unwrap();
            }
            let f = sim.fluid();
            let r = sim.fluid_rates();
            let mut bits: Vec<u64> =
                [&f.rho, &f.p].iter().flat_map(|v| f.by_id(v)).map(|x| x.to_bits()).collect();
            for v in [&f.x, &f.u, &r.du, &r.a_c] {
                bits.extend(f.by_id(v).iter().flat_map(|x| x.iter().map(|c| c.to_bits())));
            }
            let parts: Vec<(String, std::ops::Range<u32>)> =
                f.parts.iter().map(|p| (p.name.clone(), p.ids.clone())).collect();
            (bits, parts)
        })
    };
    let (one, parts_one) = run(false, 1);
    assert_eq!(parts_one, [("fluid".to_string(), 0..1024)]);
    for threads in [1, 2] {
        let (two, parts) = run(true, threads);
        assert!(one == two, "{threads} threads: the split fluid differs from the whole");
        assert_eq!(parts, [("lower".to_string(), 0..512), ("upper".to_string(), 512..1024)]);
    }
}

/// Bodies are named once; a pair switched off must name two bodies.
#[test]
fn bodies_are_named_once_and_pairs_switched_off_by_name() {
    let sim = vortex(RatePositions::End);
    let f = sim.fluid().clone();
    let builder = || Simulation::builder(sim.domain, sim.kernel);
    let twice = builder().body(f.clone()).body(f.clone()).build().err().unwrap();
    assert_eq!(twice, "two bodies are named `fluid`");
    let unknown = builder().body(f.clone()).without("fluid", "lid").build().err().unwrap();
    assert_eq!(unknown, "no body is named `lid` (bodies: fluid)");
    let itself = builder().body(f).without("fluid", "fluid").build().err().unwrap();
    assert!(itself.contains("are one body"), "{itself}");
    assert_eq!(
        Simulation::<2>::builder(sim.domain, sim.kernel).build().err().unwrap(),
        "a simulation needs a fluid or a solid body"
    );
}

/// Eq. (55) with eqs. (36) and (41): the shifting techniques divide (du/dt)_c by the step
/// it is evaluated for, so a shorter step (the last before an end time) keeps the
/// shifting velocity `dt/2 (du/dt)_c` of that step, not its own `dt'/2 (du/dt)_c`.
#[test]
fn a_shortened_step_keeps_the_shifting_velocity() {
    for pst in [Pst::Sun, Pst::Ipst] {
        let mut sim = vortex_with(RatePositions::End, pst);
        for _ in 0..5 {
            sim.step(f64::INFINITY).unwrap();
        }
        let dt = sim.nominal_dt();
        assert_eq!(sim.fluid_rates().a_c_dt, Some(dt), "{pst:?}: scaled for the nominal step");
        let (f, r) = (sim.fluid().clone(), sim.fluid_rates().clone());
        let short = 0.25 * dt;
        sim.step(short).unwrap();
        let (u, du, ac) = (f.by_id(&f.u), f.by_id(&r.du), f.by_id(&r.a_c));
        let after = sim.fluid();
        let u_hat = after.by_id(after.u_hat.as_ref().unwrap());
        let mut largest_shift: f64 = 0.0;
        for i in 0..u.len() {
            let expected = u[i] + du[i] * (0.5 * short) + ac[i] * (0.5 * dt);
            assert!(
                (u_hat[i] - expected).norm() <= 1e-14 * expected.norm().max(1.0),
                "{pst:?}: particle {i}"
            );
            largest_shift = largest_shift.max((ac[i] * (0.5 * dt)).norm());
        }
        assert!(largest_shift > 1e-6, "{pst:?}: the test needs a shifting velocity ({largest_shift:e})");
    }
}

/// Sec. 3.7: the pressure and density of step n+1 come from the rates at the start
/// positions x^n with the half-step velocities; `RatePositions::End` takes them after the
/// drift, so its pressure differs.
#[test]
fn the_rates_are_taken_where_rate_positions_says() {
    for (rates_at, at_start) in [(RatePositions::Start, true), (RatePositions::End, false)] {
        let mut sim = vortex(rates_at);
        for _ in 0..20 {
            sim.step(f64::INFINITY).unwrap();
        }
        // By hand: the half kick and u~ (eqs. 54-55), then pass A on the start lists.
        let dt = sim.nominal_dt();
        let (mut probe, mut r) = (sim.fluid().clone(), sim.fluid_rates().clone());
        let Fluid { u, u_hat, .. } = &mut probe;
        integrator::kick_transport(u, u_hat.as_deref_mut(), &r.du, &r.a_c, r.a_c_dt, dt);
        let f = sim.first_fluid().unwrap();
        let Some(Coupling::FluidFluid(own)) = sim.couplings.iter().find(|c| c.bodies() == (f, f)) else {
            panic!()
        };
        let work = sim.work[f].as_fluid().unwrap();
        let boundaries = Boundaries::new(&sim.couplings, work.boundary_couplings(), &sim.state.bodies);
        rates::density_and_pressure_rates(&mut FluidPasses::new(), &probe, &own.list, boundaries, &mut r);
        rates::update_density_and_pressure(&mut probe, &r, dt);
        sim.step(f64::INFINITY).unwrap();
        let bits = |f: &Fluid<2>| f.by_id(&f.p).iter().map(|p| p.to_bits()).collect::<Vec<_>>();
        let same = bits(&probe) == bits(sim.fluid());
        assert_eq!(same, at_start, "{rates_at:?}");
    }
}

/// Each number of threads tunes its own schedule: once a run has kept one on two
/// threads, its steps on one thread go through the trials of both orders again, and its
/// steps back on two threads keep what two threads kept.
#[test]
fn each_thread_count_tunes_its_own_schedule() {
    let pool = |t: usize| rayon::ThreadPoolBuilder::new().num_threads(t).build().unwrap();
    let (one, two) = (pool(1), pool(2));
    let mut sim = vortex_sized(128, SchemeName::Edac, Pst::None, RatePositions::End);
    let steps = |sim: &mut Simulation<2>, n: usize| {
        let mut ran = Vec::new();
        for _ in 0..n {
            sim.step(f64::INFINITY).unwrap();
            ran.push(sim.last_schedule());
        }
        ran
    };
    two.install(|| steps(&mut sim, TUNING_STEPS));
    let kept = fluid_work(&mut sim).tuners[0].1.chosen().expect("two threads kept a schedule");
    let on_one = one.install(|| steps(&mut sim, TUNING_STEPS));
    assert!(on_one.contains(&Schedule::Sweeps) && on_one.contains(&Schedule::Wavefront), "{on_one:?}");
    assert_eq!(fluid_work(&mut sim).tuners.iter().map(|t| t.0).collect::<Vec<_>>(), [2, 1]);
    assert!(fluid_work(&mut sim).tuners[1].1.chosen().is_some(), "one thread kept a schedule");
    assert_eq!(two.install(|| steps(&mut sim, 3)), [kept; 3]);
}

/// A body of four tiles (64 x 64), the fewest a wave runs in, on two threads: two
/// regions of two tiles, each region's first passes waiting on the other's last
/// listing. One step equals the sweeps' bit for bit. Under Miri, which checks the
/// tiles' shared access, 28 x 28 with the cubic spline in smaller chunks, 20 minutes:
/// `MIRIFLAGS="-Zmiri-tree-borrows -Zmiri-ignore-leaks -Zmiri-deterministic-floats"`
/// (Miri otherwise adds random rounding errors to `sin` and `cos`, so that two set-ups
/// of one body differ).
#[test]
fn four_tiles_on_two_threads_step_as_the_sweeps() {
    // Under Miri the cubic spline's narrower support makes four tiles of fewer particles.
    let (n, kernel) =
        if cfg!(miri) { (28, KernelKind::CubicSpline) } else { (64, KernelKind::QuinticSpline) };
    let run = |schedule: Schedule| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap();
        pool.install(|| {
            let mut sim = vortex_of(n, kernel, SchemeName::Edac, Pst::None, RatePositions::End);
            fluid_work(&mut sim).wave = Wavefront::with_min_tiles(4);
            sim.set_schedule(schedule);
            sim.step(f64::INFINITY).unwrap();
            assert_eq!(sim.wavefront_steps(), u64::from(schedule == Schedule::Wavefront));
            if schedule == Schedule::Wavefront {
                assert_eq!(fluid_work(&mut sim).wave.tiles(), 4);
            }
            let (f, r) = (sim.fluid(), sim.fluid_rates());
            let mut bits: Vec<u64> = f.p.iter().chain(&f.rho).map(|x| x.to_bits()).collect();
            bits.extend(r.du.iter().chain(&f.u).flat_map(|v| v.iter().map(|c| c.to_bits())));
            bits
        })
    };
    assert_eq!(run(Schedule::Wavefront), run(Schedule::Sweeps));
}

/// The wavefront step sums what the sweeps sum, in the same order: the same state, bit
/// for bit, for `edac`, `ctvf`+`sun` and `ctvf`+`ipst`, on one, two and three threads
/// (each its wave over a region of the tiles), and when the tuner changes the order
/// from block to block. Tiles of three chunks cut the 128 x 128 body into ten, so that
/// the first and last meet across the periodic edge, and the regions' ends meet, and the
/// list's storage is handed from tile to tile.
#[test]
fn the_wavefront_step_is_the_sweeps_bit_for_bit() {
    let cases = [(SchemeName::Edac, Pst::None), (SchemeName::Ctvf, Pst::Sun), (SchemeName::Ctvf, Pst::Ipst)];
    for (scheme, pst) in cases {
        let run = |schedule: Schedule, threads: usize, steps: usize| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            pool.install(|| {
                let mut sim = vortex_sized(128, scheme, pst, RatePositions::End);
                sim.set_schedule(schedule);
                for _ in 0..steps {
                    sim.step(f64::INFINITY).unwrap();
                }
                let (waves, tiles) = match schedule {
                    Schedule::Sweeps => (0..1, None),
                    // The tuner's blocks of sweeps and of tiles.
                    Schedule::Tuned => (1..steps, None),
                    Schedule::Wavefront => (steps..steps + 1, Some(10)),
                };
                let ran = sim.wavefront_steps() as usize;
                assert!(waves.contains(&ran), "{scheme:?} {pst:?} {schedule:?}: {ran} steps tiled");
                if let Some(tiles) = tiles {
                    assert_eq!(fluid_work(&mut sim).wave.tiles(), tiles, "{scheme:?} {pst:?} {schedule:?}");
                }
                let (f, r) = (sim.fluid(), sim.fluid_rates());
                let vectors = [&f.x, &f.u, &r.du, &r.a_c];
                let mut bits: Vec<u64> =
                    [&f.rho, &f.p, &r.dp].iter().flat_map(|v| v.iter().map(|x| x.to_bits())).collect();
                bits.extend(
                    vectors.iter().flat_map(|v| v.iter().flat_map(|x| x.iter().map(|c| c.to_bits()))),
                );
                bits
            })
        };
        let sweeps = run(Schedule::Sweeps, 1, 4);
        for threads in 1..=3 {
            assert_eq!(run(Schedule::Wavefront, threads, 4), sweeps, "{scheme:?} {pst:?}, {threads} threads");
        }
        let steps = TUNING_STEPS + 2;
        assert_eq!(
            run(Schedule::Tuned, 2, steps),
            run(Schedule::Sweeps, 1, steps),
            "{scheme:?} {pst:?}, tuned"
        );
    }
}

/// A fluid and a free elastic block in a periodic box (no walls, no gravity, schemes
/// whose own forces are pairwise: no CTVF momentum correction, no reference pressure):
/// the fluid's force on the block and the block's on the fluid cancel, so the total
/// momentum stays at its start to round-off over a hundred steps, with the block on
/// three sub-steps a step and on none.
#[test]
fn momentum_crosses_the_fluid_structure_interface_without_loss() {
    use crate::solver::scheme::{Corrections, PressureReference, SolidSchemeName, SolidSettings};
    use crate::solver::systems::{BoundaryMaterial, SolidInit, SolidMaterial};
    for substeps in [Substeps::Fixed(3), Substeps::Fixed(1)] {
        let n = 24;
        let dx = 1.0 / n as f64;
        let kernel = Kernel::new(KernelKind::QuinticSpline, 2);
        let (mut fluid, mut block) = (FluidInit::<2>::default(), SolidInit::<2>::default());
        for j in 0..n {
            for i in 0..n {
                let x = Vector::<2>::new((i as f64 + 0.5) * dx, (j as f64 + 0.5) * dx);
                if (9..15).contains(&i) && (9..15).contains(&j) {
                    block.x.push(x);
                    block.u.push(Vector::zeros());
                    block.m.push(dx * dx);
                    block.rho.push(1.0);
                    block.fixed.push(false);
                } else {
                    let wave = 0.1 * (2.0 * std::f64::consts::PI * x[1]).sin();
                    fluid.x.push(x);
                    fluid.u.push(Vector::<2>::new(0.3 + wave, 0.1));
                    fluid.m.push(dx * dx);
                    fluid.rho.push(1.0);
                    fluid.p.push(0.0);
                }
            }
        }
        let settings = FluidSettings {
            pst: Pst::Sun,
            corrections: Corrections::NONE,
            pressure_reference: PressureReference::None,
            ..FluidSettings::internal_flow(1.0, 10.0, 1.0, dx, kernel.w(dx, dx), 0.01)
        };
        let fluid = Fluid::new("water", dx, fluid, SchemeName::Ctvf.fluid_scheme(&settings)).unwrap();
        let solid_settings = SolidSettings::for_tests(Pst::Sun, kernel.w(dx, dx));
        let material = SolidMaterial::new(300.0, 0.3, 1.0).unwrap();
        let boundary = BoundaryMaterial {
            rho0: 1.0,
            c0: 10.0,
            density: Default::default(),
            pressure: Default::default(),
            viscosity: Default::default(),
        };
        let physics = SolidSchemeName::Ctvf.solid_scheme(&solid_settings).unwrap();
        let block =
            ElasticSolid::new("block", dx, block, material, physics).unwrap().facing_fluid(boundary).unwrap();
        let time = TimeSettings { solid_substeps: substeps, ..TimeSettings::new(0.25) };
        let mut sim = Simulation::builder(Domain::periodic([0.0; 2], [1.0; 2]), kernel)
            .body(fluid)
            .body(block)
            .time(time)
            .build()
            .unwrap();
        assert_eq!(
            sim.step_sizes().1,
            match substeps {
                Substeps::Fixed(n) => n,
                Substeps::Auto => 0,
            }
        );
        let momentum = |sim: &Simulation<2>| {
            let f = sim.fluid();
            let (s, _) = sim.solid("block").unwrap();
            let p: Vector<2> = f.u.iter().zip(&f.m).chain(s.u.iter().zip(&s.m)).map(|(u, m)| u * *m).sum();
            let scale: f64 =
                f.u.iter().zip(&f.m).chain(s.u.iter().zip(&s.m)).map(|(u, m)| u.norm() * m).sum();
            (p, scale)
        };
        let (p0, scale) = momentum(&sim);
        for _ in 0..100 {
            sim.step(f64::INFINITY).unwrap();
        }
        let (s, _) = sim.solid("block").unwrap();
        let block_p: Vector<2> = s.u.iter().zip(&s.m).map(|(u, m)| u * *m).sum();
        assert!(
            block_p[0] > 0.05 * p0[0] * 36.0 / 540.0,
            "{substeps:?}: the flow pushes the block: {block_p:?}"
        );
        let (p, _) = momentum(&sim);
        assert!((p - p0).norm() < 1e-13 * scale, "{substeps:?}: momentum {p0:?} -> {p:?} (scale {scale})");
    }
}

/// A fluid of `n` x `n` particles at rest from the origin at spacing `dx`, CTVF without
/// shifting or corrections, of sound speed `c0`, under gravity `g` (downward).
fn still_fluid(name: &str, n: (usize, usize), dx: f64, c0: f64, g: f64) -> Fluid<2> {
    let kernel = Kernel::new(KernelKind::QuinticSpline, 2);
    let mut init = FluidInit::<2>::default();
    for j in 0..n.1 {
        for i in 0..n.0 {
            init.x.push(Vector::<2>::new((i as f64 + 0.5) * dx, (j as f64 + 0.5) * dx));
            init.u.push(Vector::zeros());
            init.m.push(dx * dx);
            init.rho.push(1.0);
            init.p.push(0.0);
        }
    }
    let settings = FluidSettings {
        pst: Pst::None,
        corrections: Corrections::NONE,
        gravity: [0.0, -g, 0.0],
        ..FluidSettings::internal_flow(1.0, c0, 1.0, dx, kernel.w(dx, dx), 0.01)
    };
    Fluid::new(name, dx, init, SchemeName::Ctvf.fluid_scheme(&settings)).unwrap()
}

/// Two fluid bodies of different physics in one simulation: they meet only if a
/// multiphase model says how, so the builder refuses them unless kept apart; kept apart,
/// the vortex steps as it does alone, bit for bit (the second fluid, at rest and of a lower
/// sound speed, binds neither the time step nor anything else), and the fluid at rest stays
/// at rest exactly.
#[test]
fn two_fluids_of_different_physics_kept_apart_step_as_each_alone() {
    let alone = vortex_sized(16, SchemeName::Edac, Pst::None, RatePositions::End);
    let vortex = alone.fluid().clone();
    let (kernel, domain, time) = (alone.kernel, alone.domain, alone.time_settings);
    let still = still_fluid("still", (16, 16), 1.0 / 16.0, 5.0, 0.0);
    let both = || Simulation::builder(domain, kernel).time(time).body(vortex.clone()).body(still.clone());
    let e = both().build().err().unwrap();
    assert!(e.contains("bodies `fluid` and `still`") && e.contains("keep them apart"), "{e}");
    let mut sim = both().without("fluid", "still").build().unwrap();
    assert_eq!(sim.fluids().count(), 2);
    let mut alone = alone;
    for _ in 0..20 {
        alone.step(f64::INFINITY).unwrap();
        sim.step(f64::INFINITY).unwrap();
    }
    let bits = |f: &Fluid<2>| {
        let mut b: Vec<u64> = [&f.rho, &f.p].iter().flat_map(|v| f.by_id(v)).map(|x| x.to_bits()).collect();
        b.extend(f.by_id(&f.x).iter().chain(&f.by_id(&f.u)).flat_map(|x| x.iter().map(|c| c.to_bits())));
        b
    };
    assert_eq!(bits(sim.fluid()), bits(alone.fluid()));
    assert_eq!(sim.time().to_bits(), alone.time().to_bits());
    let still = sim.fluids().nth(1).unwrap();
    assert!(still.u.iter().all(|u| *u == Vector::<2>::zeros()), "the fluid at rest moved");
}

/// A fluid block in free fall (no walls, no pressure: every particle falls at g) that loses
/// its particles below a line at every step, and gains a row above it twice, out of its
/// kernel's reach: the run goes on with the neighbour lists made again each time; every
/// particle of the block falls at u = -g t (to 1e-12), and every new one, which starts
/// without rates (its first half kick takes no gravity), at `g dt / 2` less, dt the step
/// after it came; the count is the count above the line, and the ids stay unique.
#[test]
fn a_fluid_that_loses_and_gains_particles_keeps_falling_freely() {
    let (dx, g) = (0.05, 9.81);
    let block = still_fluid("block", (20, 10), dx, 20.0, g);
    let kernel = Kernel::new(KernelKind::QuinticSpline, 2);
    let domain = Domain::bounded([-1.0, -20.0], [2.0, 2.0]);
    let mut sim = Simulation::builder(domain, kernel).body(block).build().unwrap();
    let (mut removed, mut rows) = (0, Vec::new());
    let mut lag = vec![0.0; 200];
    for step in 0..400 {
        let t0 = sim.time();
        sim.step(f64::INFINITY).unwrap();
        if rows.last().is_some_and(|(at, _)| *at == step) {
            let n = rows.len();
            let dt = sim.time() - t0;
            rows[n - 1].1 = 0.5 * g * dt;
        }
        let above: Vec<bool> = sim.fluid().x.iter().map(|x| x[1] >= 0.0).collect();
        if above.iter().any(|&k| !k) && above.iter().any(|&k| k) {
            removed += sim.retain("block", |i| above[i]).unwrap();
        }
        if step == 100 || step == 250 {
            // A row above the block, out of its kernel's reach, falling with it.
            let f = sim.fluid();
            let (top, u) = (f.x.iter().map(|x| x[1]).fold(f64::MIN, f64::max), f.u[0]);
            let mut row = still_fluid("block", (20, 1), dx, 20.0, g);
            for (x, v) in row.x.iter_mut().zip(&mut row.u) {
                *x += Vector::<2>::new(0.0, top + 4.0 * dx);
                *v = u;
            }
            assert_eq!(sim.extend("block", row).unwrap(), 20);
            rows.push((step + 1, 0.0));
        }
    }
    for (k, (_, l)) in rows.iter().enumerate() {
        lag.extend(std::iter::repeat_n(*l, 20));
        assert!(*l > 0.0, "row {k}");
    }
    let (f, t) = (sim.fluid(), sim.time());
    assert!(removed > 50, "removed {removed}");
    assert_eq!(f.len(), 240 - removed);
    for (u, id) in f.u.iter().zip(&f.id) {
        let expected = -g * t + lag[*id as usize];
        assert!(
            u[0] == 0.0 && (u[1] - expected).abs() < 1e-12 * g * t,
            "{u:?} against {expected} at t = {t}"
        );
    }
    let mut ids = f.id.clone();
    ids.sort_unstable();
    ids.dedup();
    assert_eq!(ids.len(), f.len(), "ids stay unique");
    assert!(sim.retain("block", |_| false).unwrap_err().contains("removing all"));
    assert!(sim.retain("nothing", |_| true).unwrap_err().contains("no body is named `nothing`"));
}

/// A solid's particles that nothing reaches (farther than the kernel's support from the
/// rest) leave the rest as they are: a spinning block with one such particle at the end of
/// its body, which it loses after ten steps and gains back after twenty, steps bit for bit
/// as the block alone.
#[test]
fn a_solid_losing_and_gaining_a_lone_particle_leaves_the_rest_bit_for_bit() {
    let dx = 0.01;
    let kernel = Kernel::new(KernelKind::QuinticSpline, 2);
    let material = SolidMaterial::new(2.0e6, 0.3975, 1000.0).unwrap();
    let settings = SolidSettings::for_tests(Pst::None, kernel.w(dx, dx));
    let physics = SolidSchemeName::Ctvf.solid_scheme(&settings).unwrap();
    let block = |lone: bool| {
        let mut init = SolidInit::<2>::default();
        for k in 0..64 {
            let x = Vector::<2>::new(((k % 8) as f64 - 3.5) * dx, ((k / 8) as f64 - 3.5) * dx);
            init.x.push(x);
            init.u.push(Vector::<2>::new(-x[1], x[0]) * 50.0);
            init.m.push(material.rho0 * dx * dx);
            init.rho.push(material.rho0);
            init.fixed.push(false);
        }
        if lone {
            init.x.push(Vector::<2>::new(0.5, 0.5));
            init.u.push(Vector::zeros());
            init.m.push(material.rho0 * dx * dx);
            init.rho.push(material.rho0);
            init.fixed.push(false);
        }
        ElasticSolid::new("block", dx, init, material, physics).unwrap()
    };
    let domain = Domain::bounded([-1.0, -1.0], [1.0, 1.0]);
    let build = |lone| Simulation::builder(domain, kernel).body(block(lone)).build().unwrap();
    let (mut alone, mut sim) = (build(false), build(true));
    let bits = |sim: &Simulation<2>| {
        let s = sim.solid("block").unwrap().0;
        let mut b: Vec<u64> = s.p[..64].iter().map(|x| x.to_bits()).collect();
        b.extend(s.x[..64].iter().chain(&s.u[..64]).flat_map(|v| v.iter().map(|c| c.to_bits())));
        b.extend(s.s[..64].iter().flat_map(|m| m.iter().map(|c| c.to_bits())));
        b
    };
    for step in 0..30 {
        alone.step(f64::INFINITY).unwrap();
        sim.step(f64::INFINITY).unwrap();
        if step == 9 {
            assert_eq!(sim.retain("block", |i| i < 64).unwrap(), 1);
        }
        if step == 19 {
            let mut lone = block(true);
            lone.retain(&[vec![false; 64], vec![true]].concat()).unwrap();
            assert_eq!(sim.extend("block", lone).unwrap(), 1);
        }
        assert_eq!(bits(&sim), bits(&alone), "step {step}");
    }
    assert_eq!(sim.solid("block").unwrap().0.len(), 65);
}

/// A load on a fluid (by its particles' original ids, as the fluid sorts them by cell) is a
/// body force on them alone: of two blocks of one fluid at rest, 1 m apart, with no pressure
/// and no gravity, the one loaded moves at `a t` as a whole (to 1e-12) and the other stays
/// at rest; the fluid's step is then no longer fused into tiles.
#[test]
fn a_load_on_a_fluid_accelerates_the_particles_it_names() {
    let dx = 0.05;
    let mut fluid = still_fluid("fluid", (10, 20), dx, 20.0, 0.0);
    for (k, x) in fluid.x.iter_mut().enumerate() {
        if k >= 100 {
            // The upper half of the lattice becomes a second block, 1 m to the right.
            *x += Vector::<2>::new(1.0, -0.5);
        }
    }
    let kernel = Kernel::new(KernelKind::QuinticSpline, 2);
    let domain = Domain::bounded([-1.0, -1.0], [2.5, 2.5]);
    let load = crate::solver::interactions::UniformLoad::new([0.5, 0.25, 0.0], 0..100);
    let mut sim = Simulation::builder(domain, kernel).body(fluid).load("fluid", load).build().unwrap();
    for _ in 0..20 {
        sim.step(f64::INFINITY).unwrap();
    }
    let (f, t) = (sim.fluid(), sim.time());
    assert_eq!(sim.wavefront_steps(), 0);
    for (u, id) in f.u.iter().zip(&f.id) {
        if *id < 100 {
            let a = Vector::<2>::new(0.5, 0.25) * t;
            assert!((u - a).norm() < 1e-12 * a.norm(), "loaded {id}: {u:?} against {a:?}");
        } else {
            assert_eq!(*u, Vector::<2>::zeros(), "unloaded {id}");
        }
    }
}
