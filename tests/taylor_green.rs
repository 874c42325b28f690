//! Taylor-Green vortex (CTVF sec. 4.1): error bounds at a small size, `tvf` against PySPH's,
//! the effect of the correction terms at Re = 1000 (figs. 10-11), convergence with
//! resolution (figs. 8-9), thread-count independence and bit-for-bit restart.
//!
//! The bounds below were measured on this code and are stated with the measured value; a
//! change that makes the solution worse than the bound fails here.

use sphrepro::scenes::harness::{self, RunOptions};
use sphrepro::scenes::taylor_green;
use sphrepro::solver::output::summary::Status;
use std::collections::BTreeMap;

fn run(sets: &[&str]) -> BTreeMap<String, f64> {
    let dir = tempfile::tempdir().unwrap();
    let params = taylor_green::params_from(sets).unwrap();
    let opts = RunOptions { quiet: true, ..Default::default() };
    let s = harness::run(&taylor_green::ENTRY, &params, dir.path(), &opts).unwrap();
    assert_eq!(serde_json::to_value(s.status).unwrap(), "completed", "{sets:?}");
    eprintln!("{sets:?}: {:?}", s.metrics);
    s.metrics
}

/// (scheme, pst, rate positions, L1 bound, decay bound) at nx = 32, Re = 100, t = 0.5.
/// Measured values in the comments; the bounds leave about 25 % for platform differences
/// in libm. The rates after the drift (the default) and at the step's start (sec. 3.7)
/// are both guarded.
#[test]
fn small_run_errors_stay_within_measured_bounds() {
    let cases = [
        // measured: L1 = 2.43e-2, decay error = 2.03e-2
        ("edac", "none", "start", 0.030, 0.025),
        // measured: L1 = 6.03e-2, decay error = 1.05e-1
        ("ctvf", "sun", "start", 0.075, 0.13),
        // measured: L1 = 1.97e-2, decay error = 2.15e-2
        ("ctvf", "ipst", "start", 0.025, 0.027),
        // measured: L1 = 2.69e-2, decay error = 1.36e-2
        ("edac", "none", "end", 0.034, 0.017),
        // measured: L1 = 5.76e-2, decay error = 7.98e-2
        ("ctvf", "sun", "end", 0.072, 0.10),
        // measured: L1 = 2.19e-2, decay error = 2.20e-2
        ("ctvf", "ipst", "end", 0.028, 0.028),
    ];
    for (scheme, pst, rates_at, l1_bound, decay_bound) in cases {
        let m = run(&[
            "nx=32",
            "re=100",
            "tf=0.5",
            &format!("scheme={scheme}"),
            &format!("pst={pst}"),
            &format!("rate_positions={rates_at}"),
        ]);
        assert!(
            m["l1_velocity_final"] < l1_bound,
            "{scheme}+{pst} ({rates_at}): L1 {} >= {l1_bound}",
            m["l1_velocity_final"]
        );
        assert!(
            m["umax_decay_rel_error"] < decay_bound,
            "{scheme}+{pst} ({rates_at}): max |u| decay error {} >= {decay_bound}",
            m["umax_decay_rel_error"]
        );
    }
}

/// `tvf` is the scheme PySPH 1.0b2 runs as `pysph run taylor_green --scheme tvf` (Adami et
/// al. 2013: summation density, state equation, background pressure p_b = rho0 c0^2): its L1
/// error follows the peer's, including where that is large. The state equation cannot hold
/// the initial pressure of eq. (65), so both codes start from p = 0 and end tens of per cent
/// off the exact solution, where `edac` ends within 2 %. PySPH's values were measured with
/// `../shared/peers/pysph-taylor-green.sh --scheme tvf`; ours then agreed to
/// 0.2 % (nx = 50), 1.9 % and 3.9 % (nx = 32). A tenth apart still tells the peer's scheme
/// from the others: in the nx = 32 runs `edac` ends at 2.1 % and 9.0 %, `ctvf` with Sun's
/// shifting at 6.5 % and 17.8 %.
#[test]
fn tvf_follows_pysphs_tvf() {
    // (nx, Re, tf, PySPH's L1 at tf)
    let cases = [(50, 100, "2.0", 0.4528), (32, 100, "1.0", 0.3544), (32, 1000, "1.0", 0.3278)];
    for (nx, re, tf, peer) in cases {
        let m = run(&["scheme=tvf", &format!("nx={nx}"), &format!("re={re}"), &format!("tf={tf}")]);
        let l1 = m["l1_velocity_final"];
        assert!((l1 / peer - 1.0).abs() < 0.1, "tvf, nx = {nx}, Re = {re}: L1 {l1} against PySPH's {peer}");
    }
}

/// CTVF figs. 10b and 11b: at Re = 1000 the correction terms lower the L1 error, for both
/// shifting techniques.
#[test]
fn corrections_lower_the_error_at_re_1000() {
    for (pst, nx, tf) in [("sun", "nx=40", "tf=1.0"), ("ipst", "nx=32", "tf=1.0")] {
        let with = run(&[nx, "re=1000", tf, &format!("pst={pst}"), "corrections=all"]);
        let without = run(&[nx, "re=1000", tf, &format!("pst={pst}"), "corrections=none"]);
        assert!(
            with["l1_velocity_final"] < without["l1_velocity_final"],
            "{pst}: with corrections {} is not below without {}",
            with["l1_velocity_final"],
            without["l1_velocity_final"]
        );
    }
}

/// CTVF figs. 8-9: at Re = 1000 the error falls as the resolution grows.
#[test]
fn error_falls_with_resolution_at_re_1000() {
    for pst in ["sun", "ipst"] {
        let coarse = run(&["nx=25", "re=1000", "tf=1.0", &format!("pst={pst}")]);
        let fine = run(&["nx=50", "re=1000", "tf=1.0", &format!("pst={pst}")]);
        assert!(
            fine["l1_velocity_final"] < coarse["l1_velocity_final"],
            "{pst}: nx=50 L1 {} is not below nx=25 L1 {}",
            fine["l1_velocity_final"],
            coarse["l1_velocity_final"]
        );
    }
}

/// The same run on one and on two threads gives bit-for-bit identical particles: each
/// particle sums its neighbours in a fixed order, with no atomics.
#[test]
fn one_and_two_threads_give_identical_bits() {
    for sets in [&["nx=32", "tf=0.1", "scheme=ctvf", "pst=ipst"][..], &["nx=32", "tf=0.1", "scheme=edac"][..]]
    {
        let p = taylor_green::params_from(sets).unwrap();
        let state = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            pool.install(|| {
                let mut sim = taylor_green::simulation::<2>(&p).unwrap();
                sim.advance(0.1, 0.1, |_| true).unwrap();
                let f = sim.fluid();
                let bits = |v: &[f64]| f.by_id(v).iter().map(|x| x.to_bits()).collect::<Vec<u64>>();
                let xs: Vec<f64> = f.x.iter().flat_map(|x| [x[0], x[1]]).collect();
                let us: Vec<f64> = f.u.iter().flat_map(|u| [u[0], u[1]]).collect();
                (
                    bits(&f.p),
                    bits(&f.rho),
                    xs.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
                    us.len(),
                    sim.steps(),
                )
            })
        };
        let (one, two) = (state(1), state(2));
        assert_eq!(one.4, two.4, "{sets:?}: step counts");
        assert!(
            one.0 == two.0 && one.1 == two.1,
            "{sets:?}: pressure or density differ between 1 and 2 threads"
        );
        assert!(one.2 == two.2, "{sets:?}: positions differ between 1 and 2 threads");
    }
}

/// A run stopped mid-way (as by Ctrl-C: a checkpoint is written) and run again resumes and
/// ends bit-for-bit equal to an uninterrupted run: summary metrics, time series, snapshots.
#[test]
fn a_resumed_run_equals_an_uninterrupted_one() {
    let sets = ["nx=24", "tf=0.3", "pst=ipst"];
    let params = taylor_green::params_from(&sets).unwrap();
    let (a, b) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
    let quiet = RunOptions { quiet: true, ..Default::default() };
    let whole = harness::run(&taylor_green::ENTRY, &params, a.path(), &quiet).unwrap();
    let stop = RunOptions { quiet: true, stop_after_steps: Some(137), ..Default::default() };
    assert!(
        harness::run(&taylor_green::ENTRY, &params, b.path(), &stop).is_err(),
        "the stopped run is not done"
    );
    assert!(b.path().join("checkpoint.json").exists());
    let failed: serde_json::Value =
        serde_json::from_slice(&std::fs::read(b.path().join("summary.json")).unwrap()).unwrap();
    assert_eq!(failed["status"], "failed");
    let resumed = harness::run(&taylor_green::ENTRY, &params, b.path(), &quiet).unwrap();
    assert_eq!(whole.steps, resumed.steps);
    assert_eq!(whole.metrics, resumed.metrics);
    for f in ["timeseries.csv", "fluid.pvd", "vtu/fluid_00010.vtu", "vtu/fluid_00005.vtu"] {
        let same = std::fs::read(a.path().join(f)).unwrap() == std::fs::read(b.path().join(f)).unwrap();
        assert!(same, "{f} differs between the resumed and the uninterrupted run");
    }
    assert!(!b.path().join("checkpoint.json").exists(), "a finished run leaves no checkpoint");
}

/// An interrupted run's checkpoint is work a user computed: a run of other parameters in the
/// same folder refuses to discard it unless forced.
#[test]
fn another_case_keeps_off_an_interrupted_run_unless_forced() {
    let dir = tempfile::tempdir().unwrap();
    let quiet = RunOptions { quiet: true, ..Default::default() };
    let stop = RunOptions { quiet: true, stop_after_steps: Some(5), ..Default::default() };
    let first = taylor_green::params_from(&["nx=16", "tf=0.1"]).unwrap();
    assert!(harness::run(&taylor_green::ENTRY, &first, dir.path(), &stop).is_err());
    let checkpoint = std::fs::read(dir.path().join("checkpoint.json")).unwrap();
    let other = taylor_green::params_from(&["nx=16", "tf=0.1", "scheme=edac"]).unwrap();
    let refused = harness::run(&taylor_green::ENTRY, &other, dir.path(), &quiet).unwrap_err();
    assert!(refused.to_string().contains("--force"), "{refused}");
    assert_eq!(std::fs::read(dir.path().join("checkpoint.json")).unwrap(), checkpoint, "kept as it was");
    let forced = RunOptions { force: true, ..quiet };
    assert_eq!(
        harness::run(&taylor_green::ENTRY, &other, dir.path(), &forced).unwrap().status,
        Status::Completed
    );
}

/// `ipst_interval = 5` (the authors' code's default; the paper shifts every step): IPST moves
/// the particles on every fifth step only, and there is no homogenisation acceleration on
/// the others.
#[test]
fn ipst_runs_on_every_interval_th_step_only() {
    // A perturbed lattice and a tolerance it never meets: every IPST step makes all its moves.
    let sets = ["nx=16", "perturb=0.1", "scheme=ctvf", "pst=ipst", "ipst_tol=1e-12", "ipst_max_iter=3"];
    for interval in [1u64, 5] {
        let i = format!("ipst_interval={interval}");
        let params = taylor_green::params_from(&[&sets[..], &[i.as_str()]].concat()).unwrap();
        let mut sim = taylor_green::simulation::<2>(&params).unwrap();
        assert_eq!(sim.last_ipst_iterations(), 3, "the first step shifts");
        for _ in 0..12 {
            sim.step(f64::INFINITY).unwrap();
            // The accelerations just evaluated are for the next step, whose index is the
            // number of steps made.
            let due = sim.steps().is_multiple_of(interval);
            let shifted = sim.fluid_rates().a_c.iter().any(|a| a.norm() > 0.0);
            assert_eq!(sim.last_ipst_iterations(), if due { 3 } else { 0 }, "interval {interval}");
            assert_eq!(shifted, due, "interval {interval}, step {}", sim.steps());
        }
    }
}
