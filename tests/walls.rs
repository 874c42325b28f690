//! Walls (Adami et al. 2012, CTVF sec. 3.6): fluid at rest in a tank stays inside with the
//! hydrostatic pressure; the lid-driven cavity at Re = 100 approaches Ghia's profiles, and
//! at Re = 1000 stays free of voids with the pressure gradient of eq. (27).
//! Bounds are the quick-preset values measured on this code (stated), plus 30 %.

use sphrepro::scenes::harness::{self, RunOptions};
use sphrepro::scenes::{cavity, dam_break, free_surface_demo, hydrostatic_tank, SceneEntry};
use std::collections::BTreeMap;

fn run(entry: &SceneEntry, sets: &[&str]) -> BTreeMap<String, f64> {
    let dir = tempfile::tempdir().unwrap();
    let params = entry.params_from_sets(&sets.iter().map(|s| s.to_string()).collect::<Vec<_>>()).unwrap();
    let s =
        harness::run(entry, &params, dir.path(), &RunOptions { quiet: true, ..Default::default() }).unwrap();
    assert_eq!(serde_json::to_value(s.status).unwrap(), "completed", "{sets:?}");
    s.metrics
}

#[test]
fn a_tank_at_rest_keeps_its_fluid_and_its_hydrostatic_pressure() {
    let m = run(&hydrostatic_tank::ENTRY, &["dx=0.05", "tf=1.0", "alpha=0.05"]);
    assert_eq!(m["particles_outside"], 0.0, "fluid crossed a wall");
    // measured: 2.58e-3 of rho g H, and 6.3e-4 sqrt(g H)
    assert!(m["pressure_rel_error"] < 0.0034, "{m:?}");
    assert!(m["max_speed"] < 0.00082, "{m:?}");
}

/// A tank accelerated upward at a = g carries its fluid at rest in its own frame, with the
/// hydrostatic pressure of g + a that the walls' extrapolation (eq. 52, with the wall's
/// acceleration) gives it: its pressure error (against rho0 (g + a) (H - y)) and its
/// spurious speed in the tank's frame stay within twice those of the same tank at rest.
#[test]
fn an_accelerated_tank_holds_the_hydrostatic_pressure_of_g_plus_a() {
    let sets = ["dx=0.1", "tf=0.5"];
    let rest = run(&hydrostatic_tank::ENTRY, &sets);
    let moving = run(&hydrostatic_tank::ENTRY, &[sets[0], sets[1], "tank_acceleration=9.81"]);
    assert_eq!(moving["particles_outside"], 0.0, "fluid crossed a wall");
    for metric in ["pressure_rel_error", "max_speed"] {
        assert!(moving[metric] <= 2.0 * rest[metric], "{metric}: {moving:?} against {rest:?} at rest");
    }
}

#[test]
fn the_cavity_at_re_100_approaches_ghia() {
    let m = run(&cavity::ENTRY, &["nx=30", "re=100", "tf=5.0", "pst=sun"]);
    // measured: ghia_u_rms 2.40e-2, ghia_v_rms 1.28e-2 (units of the lid speed; with BQL,
    // the default before eq. (27) was followed here, 2.28e-2 and 1.51e-2)
    assert!(m["ghia_u_rms"] < 0.031, "{m:?}");
    assert!(m["ghia_v_rms"] < 0.017, "{m:?}");
}

/// Eq. (27) as printed (the cavity's default, `pressure_reference = auto` within walls)
/// keeps the fluid under the lid free of voids at Re = 1000; with the neighbours' mean
/// pressure subtracted (BQL, the Taylor-Green default) voids open there (and at 50x50 the
/// fluid then leaves the cavity at t = 3.2 s). Measured (nx = 30, t = 4 s): the smallest
/// density over the run is 0.857 rho0 without BQL, 0.420 with it.
#[test]
fn the_cavity_at_re_1000_stays_free_of_voids_with_eq_27() {
    let m = run(&cavity::ENTRY, &["nx=30", "re=1000", "tf=4.0"]);
    assert!(m["min_density"] > 0.8, "{m:?}");
    let bql = run(&cavity::ENTRY, &["nx=30", "re=1000", "tf=4.0", "pressure_reference=local_mean"]);
    assert!(bql["min_density"] < 0.6, "{bql:?}");
}

#[test]
fn bad_geometry_is_refused_naming_the_parameter() {
    for (entry, sets, key) in [
        (&hydrostatic_tank::ENTRY, &["dx=0.5"][..], "height"),
        (&hydrostatic_tank::ENTRY, &["dx=-0.1"][..], "dx"),
        (&hydrostatic_tank::ENTRY, &["scheme=edac"][..], "scheme"),
        (&cavity::ENTRY, &["hdx=1.5"][..], "hdx"),
        (&dam_break::ENTRY, &["tank_width=0.5"][..], "tank_width"),
        (&dam_break::ENTRY, &["tank_height=1.0"][..], "tank_height"),
        (&dam_break::ENTRY, &["dx=-0.02"][..], "dx"),
        (&dam_break::ENTRY, &["scheme=edac"][..], "scheme"),
    ] {
        let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
        let err = match entry.params_from_sets(&sets) {
            Err(e) => e,
            Ok(p) => (entry.build)(&p).err().expect("refused"),
        };
        assert!(err.contains(key), "{sets:?}: {err}");
    }
}

/// CTVF sec. 3.4 (figs. 1-2): on a ring and on a patch resting on a wall, the particles
/// found on the free surface are in the outer layer, none inside. Measured: ring (dx =
/// 0.05, 948 particles) 156 found; patch (198 particles) 26 found, the 4 outer particles
/// not found being the side particles touching the wall (the wall lies in their cone).
#[test]
fn free_surface_particles_are_the_outer_layer() {
    for (shape, found, missed) in [("ring", 156.0, 52.0), ("patch", 26.0, 4.0), ("column", 55.0, 4.0)] {
        let m = run(&free_surface_demo::ENTRY, &[&format!("shape={shape}"), "dx=0.05"]);
        assert_eq!(m["interior_surface_particles"], 0.0, "{shape}: {m:?}");
        assert_eq!(m["surface_particles"], found, "{shape}: {m:?}");
        assert_eq!(m["outer_layer_missed"], missed, "{shape}: {m:?}");
    }
}

/// The dam break at a coarse spacing keeps every particle in the tank and follows
/// Koshizuka & Oka's toe. Measured (dx = 0.05, t = 1 s): toe RMS 0.122 L, deepest
/// particle 0.10 dx beyond a wall surface.
#[test]
fn the_dam_break_front_follows_koshizuka_and_no_particle_is_lost() {
    let m = run(&dam_break::ENTRY, &["dx=0.05", "tf=1.0"]);
    assert_eq!(m["particles_lost"], 0.0, "{m:?}");
    assert!(m["max_penetration"] < 0.14, "{m:?}");
    assert!(m["toe_rms"] < 0.16, "{m:?}");
}

/// Every scene's time series carries the shifting columns: with IPST in the dam break, the
/// moves of the last step and the largest |u~ - u|, zero together while the lattice is
/// still uniform enough to meet eq. (39) at once (measured: until t = 0.2 s), both non-zero
/// once the column has moved; the snapshots carry the shifting speed of each particle.
#[test]
fn the_dam_break_records_what_the_shifting_does() {
    let dir = tempfile::tempdir().unwrap();
    let sets: Vec<String> = ["dx=0.1", "tf=0.4", "pst=ipst"].iter().map(|s| s.to_string()).collect();
    let params = dam_break::ENTRY.params_from_sets(&sets).unwrap();
    harness::run(&dam_break::ENTRY, &params, dir.path(), &RunOptions { quiet: true, ..Default::default() })
        .unwrap();
    let ts = std::fs::read_to_string(dir.path().join("timeseries.csv")).unwrap();
    let header: Vec<&str> = ts.lines().next().unwrap().split(',').collect();
    let col =
        |name: &str| header.iter().position(|h| *h == name).unwrap_or_else(|| panic!("{name}: {header:?}"));
    let (iters, shift) = (col("ipst_iterations"), col("shift_max"));
    let rows: Vec<Vec<f64>> =
        ts.lines().skip(1).map(|l| l.split(',').map(|v| v.parse().unwrap()).collect()).collect();
    assert!(rows.iter().any(|r| r[iters] >= 1.0 && r[shift] > 0.0), "{ts}");
    assert!(rows.iter().all(|r| (r[iters] == 0.0) == (r[shift] == 0.0)), "{ts}");
    let fluid = |p: &std::path::PathBuf| p.file_name().unwrap().to_string_lossy().starts_with("fluid_");
    let snapshots = std::fs::read_dir(dir.path().join("vtu")).unwrap().map(|e| e.unwrap().path());
    let last = snapshots.filter(fluid).max().unwrap();
    assert!(std::fs::read_to_string(last).unwrap().contains("Name=\"shift_speed\""));
}

/// A checkpoint written before a parameter existed (here `wall_pressure`, which such runs
/// did not record) resumes when the parameter holds its default, the value those runs had:
/// its cache key is the same, so must its checkpoint be.
#[test]
fn a_checkpoint_from_before_a_parameter_existed_resumes() {
    let sets: Vec<String> = ["nx=10", "tf=0.3"].iter().map(|s| s.to_string()).collect();
    let params = cavity::ENTRY.params_from_sets(&sets).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let stop = RunOptions { quiet: true, stop_after_steps: Some(20), ..Default::default() };
    assert!(harness::run(&cavity::ENTRY, &params, dir.path(), &stop).is_err());
    let path = dir.path().join("checkpoint.json");
    let mut ckpt: serde_json::Value = serde_json::from_slice(&std::fs::read(&path).unwrap()).unwrap();
    let recorded = ckpt["params"].as_object_mut().unwrap();
    assert_eq!(recorded.remove("wall_pressure").unwrap(), "extrapolated");
    std::fs::write(&path, serde_json::to_vec(&ckpt).unwrap()).unwrap();
    let quiet = RunOptions { quiet: true, ..Default::default() };
    let resumed = harness::run(&cavity::ENTRY, &params, dir.path(), &quiet).unwrap();
    let whole = harness::run(&cavity::ENTRY, &params, tempfile::tempdir().unwrap().path(), &quiet).unwrap();
    assert_eq!(resumed.steps, whole.steps);
    assert_eq!(resumed.metrics, whole.metrics, "resumed, not rerun from scratch into other numbers");
}
