//! The command-line contract of `simulate`: bad input is refused with the key named and
//! nothing written; a blow-up ends `diverged`, never `completed`, and never hangs.

use std::path::Path;
use std::process::Command;
use std::time::{Duration, Instant};

fn sphrepro(args: &[&str]) -> (i32, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_sphrepro")).args(args).output().expect("binary runs");
    (out.status.code().unwrap_or(-1), String::from_utf8_lossy(&out.stderr).into_owned())
}

/// `DIR/summary.json`.
fn summary(dir: &Path) -> serde_json::Value {
    serde_json::from_slice(&std::fs::read(dir.join("summary.json")).unwrap()).unwrap()
}

fn simulate(dir: &Path, scene: &str, sets: &[&str]) -> (i32, String) {
    let mut args = vec!["simulate", scene, "--quiet", "--out", dir.to_str().unwrap()];
    for s in sets {
        args.push("--set");
        args.push(s);
    }
    sphrepro(&args)
}

#[test]
fn bad_input_is_refused_naming_key_and_value_and_writes_nothing() {
    let cases: &[(&str, &[&str], &[&str])] = &[
        ("taylor_green", &["nx=-5"], &["nx", "-5"]),
        ("taylor_green", &["nx=0"], &["nx", "0"]),
        ("taylor_green", &["nx=fifty"], &["nx", "fifty"]),
        ("taylor_green", &["tf=0"], &["tf", "0"]),
        ("taylor_green", &["hdx=0"], &["hdx", "0"]),
        ("taylor_green", &["hdx=-1.5"], &["hdx", "-1.5"]),
        ("taylor_green", &["re=0"], &["re", "0"]),
        ("taylor_green", &["re=-100"], &["re", "-100"]),
        ("taylor_green", &["frobnicate=3"], &["frobnicate", "3"]),
        ("taylor_green", &["scheme=warp9"], &["scheme", "warp9"]),
        ("taylor_green", &["pst=magic"], &["pst", "magic"]),
        ("taylor_green", &["kernel=box"], &["kernel", "box"]),
        ("taylor_green", &["corrections=some"], &["corrections", "some"]),
        ("taylor_green", &["cfl=nan"], &["cfl", "NaN"]),
        ("taylor_green", &["nx"], &["nx"]),
        // A box too small for the kernel support is a parameter error, not a panic.
        ("taylor_green", &["nx=4"], &["nx"]),
        // A support that does not reach the nearest particle (3 h or 2 h <= dx).
        ("taylor_green", &["hdx=0.3"], &["hdx", "0.3", "hdx > 0.3333"]),
        ("taylor_green", &["kernel=cubic_spline", "hdx=0.5"], &["hdx", "0.5"]),
        // A resolution that cannot run is refused before any particle is made: more
        // particles than 32-bit indices hold, or (3.6e9 particles, some 7 TB) more memory
        // than the machine has.
        ("taylor_green", &["nx=100000"], &["nx", "100000", "indexes"]),
        ("taylor_green", &["nx=60000"], &["nx", "60000", "GiB"]),
        ("dam_break", &["dx=0.00001"], &["dx", "0.00001"]),
        // A tank's geometry: the key that is off, not the spacing it is measured in.
        ("dam_break", &["column_height=0.07"], &["column_height", "0.07", "4 particle spacings"]),
        ("dam_break", &["tank_width=0.5"], &["tank_width", "0.5", "narrower"]),
        ("hydrostatic_tank", &["width=0.05"], &["width", "0.05", "4 particle spacings"]),
        ("taylor_green_3d", &["nz=4"], &["nz", "4"]),
        ("taylor_green_3d", &["nz=0"], &["nz", "0"]),
        ("no_such_scene", &[], &["no_such_scene"]),
        // Accepted as > 0, but its viscous time step would need 2.6e30 steps: refused at
        // once rather than stepping forever.
        ("taylor_green", &["re=1e-30", "tf=0.01"], &["re", "steps"]),
        ("taylor_green", &["nx=8", "nx=10"], &["nx=8", "nx=10", "twice"]),
        // An option the scheme does not read would be ignored without a word.
        ("taylor_green", &["scheme=edac", "pst=ipst"], &["pst", "ipst", "edac"]),
        ("taylor_green", &["scheme=edac", "corr_pressure=on"], &["corr_pressure", "on", "edac"]),
        ("taylor_green", &["scheme=tvf", "corr_momentum=on"], &["corr_momentum", "on", "tvf"]),
        ("taylor_green", &["pst=sun", "ipst_tol=0.1"], &["ipst_tol", "0.1", "sun"]),
        ("taylor_green", &["scheme=tvf", "edac_alpha=1"], &["edac_alpha", "1", "tvf"]),
    ];
    for (scene, sets, words) in cases {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("run");
        let (code, err) = simulate(&out, scene, sets);
        assert_eq!(code, 2, "{scene} {sets:?}: exit {code}, stderr: {err}");
        for w in *words {
            assert!(err.contains(w), "{scene} {sets:?}: message does not name `{w}`: {err}");
        }
        assert_eq!(err.trim().lines().count(), 1, "one-line error: {err}");
        assert!(!out.join("summary.json").exists(), "{scene} {sets:?} wrote a summary");
    }
}

#[test]
fn a_blow_up_ends_diverged_with_a_reason_and_a_non_zero_exit() {
    let dir = tempfile::tempdir().unwrap();
    let t0 = Instant::now();
    let (code, err) = simulate(dir.path(), "taylor_green", &["nx=16", "cfl=5", "tf=1.0"]);
    assert!(t0.elapsed() < Duration::from_secs(60), "took {:?}", t0.elapsed());
    assert_eq!(code, 3, "stderr: {err}");
    let s = summary(dir.path());
    assert_eq!(s["status"], "diverged");
    assert!(!s["reason"].as_str().unwrap().is_empty());
    assert!(s["step"].as_u64().unwrap() > 0);
    assert!(s["final_time"].as_f64().unwrap() < 1.0);
    assert!(s["metrics"].as_object().unwrap().is_empty(), "a diverged run reports no metrics");
    // The state the check stopped is the last snapshot of the ParaView series.
    let pvd = std::fs::read_to_string(dir.path().join("fluid.pvd")).unwrap();
    let last = pvd.lines().rfind(|l| l.contains("<DataSet")).expect("a snapshot");
    let t: f64 = last.split("timestep=\"").nth(1).unwrap().split('"').next().unwrap().parse().unwrap();
    assert_eq!(t, s["final_time"].as_f64().unwrap(), "{last}");
    let file = last.split("file=\"").nth(1).unwrap().split('"').next().unwrap();
    assert!(dir.path().join(file).exists(), "{file}");
}

/// `edac` at cfl = 5 on an 8x8 lattice stays finite and inside its periodic box, but its
/// speed grows to 30-45 U; a run at Mach > 1 has left the weakly compressible model and must
/// not report `completed`.
#[test]
fn a_run_that_grows_without_turning_nan_ends_diverged_at_mach_one() {
    let dir = tempfile::tempdir().unwrap();
    let (code, err) = simulate(dir.path(), "taylor_green", &["nx=8", "scheme=edac", "cfl=5", "tf=1.0"]);
    assert_eq!(code, 3, "stderr: {err}");
    let s = summary(dir.path());
    assert_eq!(s["status"], "diverged");
    let reason = s["reason"].as_str().unwrap();
    assert!(reason.contains("exceeds 1 c0"), "{reason}");
}

#[test]
fn a_finished_run_is_not_overwritten_without_force() {
    let dir = tempfile::tempdir().unwrap();
    let (code, err) = simulate(dir.path(), "taylor_green", &["nx=16", "tf=0.02"]);
    assert_eq!(code, 0, "{err}");
    let before = std::fs::read(dir.path().join("summary.json")).unwrap();
    let (code, err) = simulate(dir.path(), "taylor_green", &["nx=16", "tf=0.04"]);
    assert_eq!(code, 2);
    assert!(err.contains("--force"), "{err}");
    assert_eq!(std::fs::read(dir.path().join("summary.json")).unwrap(), before);
    let dir_s = dir.path().to_str().unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_sphrepro"))
        .args([
            "simulate",
            "taylor_green",
            "--quiet",
            "--force",
            "--set",
            "nx=16",
            "--set",
            "tf=0.04",
            "--out",
            dir_s,
        ])
        .status()
        .unwrap();
    assert!(out.success());
    let s = summary(dir.path());
    assert_eq!(s["params"]["tf"], 0.04);
}

/// A body of 65 536 particles makes tiles: the run times both orders of its passes on its
/// first steps (five each), and the summary counts the steps that ran as a wavefront.
#[test]
fn a_large_periodic_run_counts_its_wavefront_steps() {
    let dir = tempfile::tempdir().unwrap();
    let (code, err) = simulate(dir.path(), "taylor_green", &["nx=256", "tf=0.0015", "scheme=edac"]);
    assert_eq!(code, 0, "{err}");
    let s = summary(dir.path());
    let (steps, wave) = (s["steps"].as_u64().unwrap(), s["wavefront_steps"].as_u64().unwrap());
    assert!(steps >= 10, "{steps} steps: the test needs the tuning done");
    assert!((5..=steps).contains(&wave), "{wave} of {steps} steps as a wavefront");
}

#[test]
fn a_completed_run_writes_the_contracted_outputs() {
    let dir = tempfile::tempdir().unwrap();
    let (code, err) = simulate(dir.path(), "taylor_green", &["nx=16", "tf=0.05", "scheme=ctvf", "pst=ipst"]);
    assert_eq!(code, 0, "{err}");
    let s = summary(dir.path());
    for k in [
        "scene",
        "params",
        "particles",
        "steps",
        "final_time",
        "wall_seconds",
        "particle_steps_per_second",
        "threads",
        "status",
        "provenance",
    ] {
        assert!(s.get(k).is_some(), "summary lacks {k}");
    }
    assert_eq!(s["status"], "completed");
    assert_eq!(s["particles"], 256);
    // Too small a body for tiles: every step swept.
    assert_eq!(s["wavefront_steps"], 0);
    assert!((s["final_time"].as_f64().unwrap() - 0.05).abs() < 1e-12);
    for m in [
        "l1_velocity_final",
        "l1_velocity_max",
        "l1_velocity_mean",
        "umax_decay_rel_error",
        "p_l1_final",
        "kinetic_energy_rel_error",
    ] {
        assert!(s["metrics"][m].as_f64().unwrap().is_finite(), "metric {m}");
    }
    for k in ["version", "git_commit", "rustc", "host", "started", "finished"] {
        assert!(s["provenance"][k].is_string(), "provenance lacks {k}");
    }
    // The machine, so that wall times are read against the kind of host they ran on.
    for k in ["cpu_vendor", "cpu_brand", "compiled_simd", "distance_test"] {
        assert!(s["provenance"]["machine"][k].is_string(), "machine lacks {k}");
    }
    assert!(s["provenance"]["machine"]["logical_cpus"].as_u64().unwrap() >= 1);
    let ts = std::fs::read_to_string(dir.path().join("timeseries.csv")).unwrap();
    assert!(ts.lines().next().unwrap().starts_with("t,u_max,u_max_exact,l1_velocity"));
    assert!(ts.lines().count() > 10);
    // The mean L1 error is the trapezoidal time average of the series' L1 column.
    let rows: Vec<(f64, f64)> = ts
        .lines()
        .skip(1)
        .map(|l| {
            let v: Vec<f64> = l.split(',').map(|x| x.parse().unwrap()).collect();
            (v[0], v[3])
        })
        .collect();
    let integral: f64 = rows.windows(2).map(|w| 0.5 * (w[1].0 - w[0].0) * (w[0].1 + w[1].1)).sum();
    let (t_end, mean) = (rows.last().unwrap().0, s["metrics"]["l1_velocity_mean"].as_f64().unwrap());
    assert!((t_end - 0.05).abs() < 1e-12, "the series ends at tf");
    assert!(
        (mean - integral / t_end).abs() <= 1e-12 * mean.abs().max(1e-300),
        "{mean} vs {}",
        integral / t_end
    );
    let pvd = std::fs::read_to_string(dir.path().join("fluid.pvd")).unwrap();
    let n = pvd.matches("<DataSet").count();
    assert_eq!(n, 11, "snapshots at 0, tf/10, ..., tf");
    assert!(dir.path().join("vtu/fluid_00010.vtu").exists());
}

/// `bench --peer` runs the peer in the same rounds as ours for every size and thread count
/// and gives our ratio to it; a failing peer fails the bench, naming the script.
#[test]
fn bench_measures_a_peer_alongside() {
    use std::os::unix::fs::PermissionsExt;
    let dir = tempfile::tempdir().unwrap();
    let script = |name: &str, body: &str| {
        let p = dir.path().join(name);
        std::fs::write(&p, format!("#!/bin/sh\n{body}\n")).unwrap();
        std::fs::set_permissions(&p, std::fs::Permissions::from_mode(0o755)).unwrap();
        p
    };
    // A peer that reports 0.125 M particle-steps/s and echoes the time it was asked to run.
    let good = script(
        "peer.sh",
        r#"echo "{\"peer\": \"fake\", \"particle_steps_per_second\": 125000.0, \"args\": \"$*\"}""#,
    );
    let json = dir.path().join("bench.json");
    let bin = env!("CARGO_BIN_EXE_sphrepro");
    let out = Command::new(bin)
        .args(["bench", "--nx", "20", "--bench-threads", "1", "--variants", "edac", "--steps", "5"])
        .args(["--json", json.to_str().unwrap(), "--peer", good.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let table = String::from_utf8_lossy(&out.stdout);
    assert!(table.contains("ratio to peer"), "{table}");
    let v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let (ours, peer) = (&v["results"][0], &v["peers"][0]);
    assert_eq!(peer["nx"], 20);
    assert_eq!(peer["tf"], 2.0, "small sizes run to t = 2");
    let ratio = ours["particle_steps_per_second"].as_f64().unwrap() / 125000.0;
    assert!(table.contains(&format!("| 0.125 | {ratio:.1}x |")), "{table}");
    // A peer that fails.
    let bad = script("broken.sh", "echo 'no PySPH here' >&2; exit 3");
    let out = Command::new(bin)
        .args(["bench", "--nx", "20", "--bench-threads", "1", "--variants", "edac", "--steps", "5"])
        .args(["--json", json.to_str().unwrap(), "--peer", bad.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("broken.sh"));
    // Another kernel: every case and the accuracy run take it; an unknown one is refused.
    let out = Command::new(bin)
        .args(["bench", "--nx", "20", "--bench-threads", "1", "--variants", "edac", "--steps", "5"])
        .args([
            "--json",
            json.to_str().unwrap(),
            "--peer",
            good.to_str().unwrap(),
            "--kernel",
            "cubic_spline",
        ])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(v["results"][0]["kernel"], "cubic_spline");
    assert!(String::from_utf8_lossy(&out.stdout).contains("kernel cubic_spline"));
    let out = Command::new(bin).args(["bench", "--kernel", "spline9"]).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--kernel spline9"));
}

/// `bench --repeat 3`: each configuration once in the results, ours and the peer's, with
/// its three runs, and the reported run is the median of them; `--repeat 0` is refused.
#[test]
fn bench_repeats_every_case_and_reports_the_median_run() {
    use std::os::unix::fs::PermissionsExt;
    let dir = tempfile::tempdir().unwrap();
    // A peer whose k-th call reports k x 0.1 M particle-steps/s.
    let (count, peer) = (dir.path().join("calls"), dir.path().join("peer.sh"));
    let body = format!(
        "#!/bin/sh\necho x >> {c}\nk=$(wc -l < {c})\necho \"{{\\\"particle_steps_per_second\\\": ${{k}}00000.0}}\"\n",
        c = count.display()
    );
    std::fs::write(&peer, body).unwrap();
    std::fs::set_permissions(&peer, std::fs::Permissions::from_mode(0o755)).unwrap();
    let json = dir.path().join("bench.json");
    let bin = env!("CARGO_BIN_EXE_sphrepro");
    let out = Command::new(bin)
        .args(["bench", "--nx", "20", "--bench-threads", "1,2", "--variants", "edac", "--steps", "5"])
        .args(["--repeat", "3", "--json", json.to_str().unwrap(), "--peer", peer.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert_eq!(String::from_utf8_lossy(&out.stderr).matches("(run 3 of 3)").count(), 4);
    let v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let runs = |r: &serde_json::Value| -> Vec<f64> {
        r["runs"].as_array().unwrap().iter().map(|x| x.as_f64().unwrap()).collect()
    };
    let results = v["results"].as_array().unwrap();
    assert_eq!(results.len(), 2);
    for r in results {
        let mut runs = runs(r);
        assert_eq!(runs.len(), 3);
        runs.sort_by(f64::total_cmp);
        assert_eq!(r["particle_steps_per_second"].as_f64().unwrap(), runs[1]);
    }
    // The peer ran after our cases in each round: calls 1, 3, 5 on one thread, 2, 4, 6 on two.
    let peers = v["peers"].as_array().unwrap();
    assert_eq!(runs(&peers[0]), [1.0e5, 3.0e5, 5.0e5]);
    assert_eq!(runs(&peers[1]), [2.0e5, 4.0e5, 6.0e5]);
    assert_eq!(peers[0]["particle_steps_per_second"], 3.0e5);
    assert!(String::from_utf8_lossy(&out.stdout).contains("| 0.400 (0.200-0.600) |"));
    let out = Command::new(bin).args(["bench", "--repeat", "0"]).output().unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("--repeat"));
}

/// `bench --interleave 3`: the cases of a size side by side in one process, each
/// configuration once in the results with a run a round, so that the cost and the speed-up
/// are medians of the rounds' ratios; it does not go with `--repeat` or `--peer`, and needs
/// two rounds at least.
#[test]
fn bench_interleaves_the_cases_of_a_size() {
    let dir = tempfile::tempdir().unwrap();
    let json = dir.path().join("bench.json");
    let bin = env!("CARGO_BIN_EXE_sphrepro");
    let out = Command::new(bin)
        .args([
            "bench",
            "--nx",
            "16",
            "--bench-threads",
            "1,2",
            "--variants",
            "edac,ctvf+sun",
            "--steps",
            "6",
        ])
        .args(["--interleave", "3", "--json", json.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let rows: Vec<_> = v["results"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| {
            (
                r["variant"].as_str().unwrap(),
                r["threads"].as_u64().unwrap(),
                r["copies"].as_u64().unwrap(),
                r["runs"].as_array().unwrap().len(),
            )
        })
        .collect();
    // Each variant on one and two threads, then two copies on one thread each.
    assert_eq!(
        rows,
        [
            ("edac", 1, 1, 3),
            ("edac", 2, 1, 3),
            ("edac", 1, 2, 3),
            ("ctvf+sun", 1, 1, 3),
            ("ctvf+sun", 2, 1, 3),
            ("ctvf+sun", 1, 2, 3)
        ]
    );
    // Two copies did twice the steps of one in the same rounds.
    let steps = |i: usize| v["results"][i]["steps"].as_u64().unwrap();
    assert_eq!(steps(2), 2 * steps(0));
    // One shape with or without a peer: the provenance of the run (the build, and the
    // machine, named in the title too).
    let (build, host) = (&v["provenance"], &v["provenance"]["machine"]);
    assert_eq!(build["version"], env!("CARGO_PKG_VERSION"));
    assert!(host["logical_cpus"].as_u64().unwrap() >= 1);
    assert_eq!(v["peers"].as_array().map(Vec::len), Some(0));
    let table = String::from_utf8_lossy(&out.stdout);
    let test = host["distance_test"].as_str().unwrap();
    let title = format!("model {}", host["cpu_model"]);
    assert!(table.contains(&title) && table.contains(&format!("distance test {test}:")), "{table}");
    // The cost of ctvf+sun and the speed-up with their ranges over the rounds.
    let sun = table.lines().find(|l| l.starts_with("| ctvf+sun | 16 | 256 | 2 |")).unwrap();
    assert_eq!(sun.matches(") |").count(), 3, "{sun}");
    // The copies' row has its own speed-up against one thread, and the table says what it is.
    let pair = table.lines().find(|l| l.starts_with("| ctvf+sun | 16 | 256 | 2 x 1 |")).unwrap();
    assert_eq!(pair.matches(") |").count(), 3, "{pair}");
    assert!(table.contains("`2 x 1`: 2 copies"), "{table}");
    for bad in [
        &["--interleave", "3", "--repeat", "2"][..],
        &["--interleave", "1"],
        &["--interleave", "2", "--peer", "x"],
    ] {
        let out = Command::new(bin).arg("bench").args(bad).output().unwrap();
        assert_eq!(out.status.code(), Some(2), "{bad:?}");
        assert!(String::from_utf8_lossy(&out.stderr).contains("--interleave"), "{bad:?}");
    }
}

/// SIGTERM and SIGHUP stop a run as Ctrl-C does (a checkpoint, a `failed` summary), but a
/// SIGHUP ignored by whoever started it (`nohup`) stays ignored.
#[cfg(unix)]
#[test]
fn sigterm_and_sighup_stop_a_run_with_a_checkpoint_unless_hup_is_ignored() {
    use std::os::unix::process::CommandExt;
    let start = |dir: &Path, ignore_hup: bool| {
        let mut c = Command::new(env!("CARGO_BIN_EXE_sphrepro"));
        c.args(["simulate", "taylor_green", "--quiet", "--set", "nx=24", "--set", "tf=50"]);
        c.arg("--out").arg(dir).arg("--progress-file").arg(dir.join("progress"));
        // Set in both cases, so that the test does not depend on how it was started (under
        // `nohup`, the disposition every child inherits is "ignored").
        let hup = if ignore_hup { libc::SIG_IGN } else { libc::SIG_DFL };
        // SAFETY: only `signal` between fork and exec, async-signal-safe.
        unsafe {
            c.pre_exec(move || {
                libc::signal(libc::SIGHUP, hup);
                Ok(())
            });
        }
        let child = c.spawn().unwrap();
        let t0 = Instant::now();
        while !dir.join("progress").exists() {
            assert!(t0.elapsed() < Duration::from_secs(60), "no progress");
            std::thread::sleep(Duration::from_millis(20));
        }
        child
    };
    let signal = |child: &std::process::Child, sig: &str| {
        Command::new("kill").args([sig, &child.id().to_string()]).status().unwrap();
    };
    let stopped = |dir: &Path| {
        let s = summary(dir);
        s["status"] == "failed" && dir.join("checkpoint.json").exists()
    };
    for sig in ["-TERM", "-HUP"] {
        let dir = tempfile::tempdir().unwrap();
        let mut child = start(dir.path(), false);
        signal(&child, sig);
        assert_eq!(child.wait().unwrap().code(), Some(1), "{sig}");
        assert!(stopped(dir.path()), "{sig}");
    }
    let dir = tempfile::tempdir().unwrap();
    let mut child = start(dir.path(), true);
    signal(&child, "-HUP");
    std::thread::sleep(Duration::from_millis(500));
    assert!(child.try_wait().unwrap().is_none(), "an ignored SIGHUP stopped the run");
    signal(&child, "-TERM");
    assert_eq!(child.wait().unwrap().code(), Some(1));
    assert!(stopped(dir.path()));
}

/// The progress file a runner reads holds `time tf steps t0 seconds`: a fresh run starts
/// from t0 = 0, its simulated time and wall seconds grow, and so the runner can pace it.
#[test]
fn the_progress_file_gives_the_pace_of_the_run() {
    let dir = tempfile::tempdir().unwrap();
    let dir = dir.path();
    let mut child = Command::new(env!("CARGO_BIN_EXE_sphrepro"))
        .args(["simulate", "taylor_green", "--quiet", "--set", "nx=24", "--set", "tf=50"])
        .arg("--out")
        .arg(dir)
        .arg("--progress-file")
        .arg(dir.join("progress"))
        .spawn()
        .unwrap();
    let read = || -> Option<Vec<f64>> {
        let text = std::fs::read_to_string(dir.join("progress")).ok()?;
        let v: Vec<f64> = text.split_whitespace().filter_map(|x| x.parse().ok()).collect();
        (v.len() == 5).then_some(v)
    };
    let t0 = Instant::now();
    let mut seen: Vec<Vec<f64>> = Vec::new();
    while seen.len() < 2 && t0.elapsed() < Duration::from_secs(60) {
        if let Some(v) = read().filter(|v| seen.last().is_none_or(|l| l[4] < v[4])) {
            seen.push(v);
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    let _ = child.kill();
    let _ = child.wait();
    assert_eq!(seen.len(), 2, "two readings of the progress file: {seen:?}");
    let (a, b) = (&seen[0], &seen[1]);
    assert_eq!((a[1], a[3]), (50.0, 0.0), "tf and the run's start time: {a:?}");
    assert!(0.0 < a[0] && a[0] < b[0] && a[2] < b[2], "time and steps grow: {seen:?}");
    assert!(0.0 < a[4] && a[4] < b[4], "wall seconds grow: {seen:?}");
}
