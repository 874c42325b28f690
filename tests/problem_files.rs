//! Every problem file in `problems/` validates (every preset, figures, tables, bounds and
//! the reference data they draw against), against the registered scenes.

use sphrepro::automation::registry;
use std::path::Path;

#[test]
fn every_problem_file_validates() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("problems");
    let mut paths: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    paths.sort();
    assert!(paths.len() >= 5, "{paths:?}");
    let mut errors = Vec::new();
    for p in &paths {
        let src = std::fs::read_to_string(p).unwrap();
        // `parse` expands and checks every preset whichever is asked for.
        match registry::parse(p, &src, "quick") {
            Ok(pr) => assert!(!pr.cases.is_empty()),
            Err(e) => errors.push(e),
        }
    }
    assert!(errors.is_empty(), "{}", errors.join("\n"));
}

/// The cavity problem: the resolutions and end time of each preset, and Ghia's points for
/// both Re.
#[test]
fn cavity_presets_and_reference_points() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("problems/cavity.toml");
    let src = std::fs::read_to_string(&path).unwrap();
    let quick = registry::parse(&path, &src, "quick").unwrap();
    let paper = registry::parse(&path, &src, "paper").unwrap();
    let res = |p: &registry::Problem, re: f64| {
        let mut v: Vec<i64> = p
            .cases
            .iter()
            .filter(|c| c.params.float("re") == re && c.params.str("corrections") == "all")
            .filter(|c| c.params.str("pst") == "sun")
            .map(|c| c.params.int("nx"))
            .collect();
        v.sort();
        v
    };
    assert_eq!(res(&quick, 100.0), [20, 30]);
    assert_eq!(res(&quick, 1000.0), [20, 30]);
    assert_eq!(res(&paper, 100.0), [50, 100, 150]);
    assert_eq!(res(&paper, 1000.0), [50, 100, 200]);
    assert!(paper
        .cases
        .iter()
        .filter(|c| c.params.float("re") == 100.0)
        .all(|c| c.params.float("tf") == 25.0));
    // The u profile is drawn with u horizontal and y vertical; Ghia's 17 points.
    let f = paper.figures.iter().find(|f| f.id == "fig14a_cavity_u_re100").unwrap();
    let registry::FigureKind::Profile { x, y, references, .. } = &f.kind else { panic!("{:?}", f.kind) };
    let r = &references[0];
    assert_eq!((x.as_str(), y.as_str()), ("u", "y"));
    assert_eq!(r.x.len(), 17);
    assert_eq!((r.x[16], r.y[16]), (1.0, 1.0)); // the lid
    let f = paper.figures.iter().find(|f| f.id == "fig15b_cavity_v_re1000").unwrap();
    let registry::FigureKind::Profile { references, .. } = &f.kind else { panic!() };
    assert_eq!(references[0].y_column, "Re1000");
    // Bounds measured on the quick preset guard the Re = 100 case in CI.
    assert_eq!(quick.bounds.len(), 3, "{:?}", quick.bounds);
}

/// Without results, every problem still lists every figure and table (not drawn, and why)
/// and judges every claim `not run`: the manuscript names what is missing rather than drop
/// it. (Nothing is drawn, so as not to overwrite a problem's last figures.)
#[test]
fn every_problem_reports_without_results() {
    use sphrepro::automation::report::Block;
    use sphrepro::automation::study;
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("problems");
    let tmp = tempfile::tempdir().unwrap();
    for name in
        ["cavity", "cavity_stability", "hydrostatic_tank", "dam_break", "dam_break_stability", "free_surface"]
    {
        // A copy outside the checkout, so that no committed result is read.
        let path = tmp.path().join(format!("problems/{name}.toml"));
        let src = std::fs::read_to_string(dir.join(format!("{name}.toml"))).unwrap();
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(&path, &src).unwrap();
        let p = registry::parse(&dir.join(format!("{name}.toml")), &src, "quick").unwrap();
        let p = registry::Problem { path: path.clone(), ..p };
        let r = study::regenerate(&p, &tmp.path().join("out"), &tmp.path().join("ms")).unwrap();
        assert!(!r.drawn, "{name}");
        assert_eq!(r.items.len(), p.figures.len() + p.tables.len(), "{name}");
        for it in &r.items {
            assert!(matches!(it.item.blocks[..], [Block::Missing { .. }]), "{name}/{}", it.id);
        }
        assert!(r.verdicts.iter().all(|v| v.own.verdict == study::Verdict::NotRun), "{name}");
    }
    assert!(!tmp.path().join("ms/figures").exists(), "nothing drawn");
}

/// Every figure the CTVF paper numbers for its fluid benchmarks (figs. 1-17) is drawn by
/// exactly one problem, under the paper's number, with the paper's caption.
#[test]
fn the_ctvf_papers_figures_1_to_17_each_have_one_item() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("problems");
    let all = registry::load_dir(&dir, "quick").unwrap();
    let mut numbers: Vec<String> = all
        .iter()
        .filter(|p| p.paper == "ctvf")
        .flat_map(|p| p.figures.iter().filter_map(|f| f.info.number.clone()))
        .collect();
    numbers.sort_by_key(|n| sphrepro::automation::papers::number_key(n));
    let figures: Vec<String> = numbers.iter().map(|n| sphrepro::automation::papers::figure_of(n)).collect();
    for k in 1..=17 {
        assert!(figures.contains(&format!("Fig. {k}")), "no item for Fig. {k}: {numbers:?}");
    }
    let mut unique = numbers.clone();
    unique.dedup();
    assert_eq!(unique, numbers, "a number drawn twice");
    for p in &all {
        for f in p.figures.iter().filter(|f| f.info.number.is_some()) {
            assert!(!f.info.paper_caption.is_empty(), "{}/{}", p.name, f.id);
        }
    }
}

/// The dam-break problems: the resolutions and end time of each preset, the fig. 17 times
/// inside every preset's end time, normals drawn as arrows, the trade along dx as a spacing.
#[test]
fn dam_break_presets_figures_and_stability_sweep() {
    let load = |name: &str, preset: &str| {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("problems/{name}.toml"));
        let src = std::fs::read_to_string(&path).unwrap();
        registry::parse(&path, &src, preset).unwrap()
    };
    let dxs = |p: &registry::Problem| {
        let mut v: Vec<f64> = p.cases.iter().map(|c| c.params.float("dx")).collect();
        v.sort_by(f64::total_cmp);
        v.dedup();
        v
    };
    let (quick, paper) = (load("dam_break", "quick"), load("dam_break", "paper"));
    for (p, dx, tf) in [(&quick, 0.05, 2.0), (&paper, 0.01, 2.5)] {
        assert!(p.cases.iter().all(|c| c.params.float("tf") == tf));
        assert!(dxs(p).contains(&dx));
        let fig = |id: &str| p.figures.iter().find(|f| f.id == id).unwrap_or_else(|| panic!("{id}"));
        for (id, t) in [
            ("fig17a_dam_break_speed_t0.6", 0.6),
            ("fig17b_dam_break_speed_t1.1", 1.1),
            ("fig17c_dam_break_speed_t2.0", 2.0),
        ] {
            let registry::FigureKind::Particles { field, time, arrows: None, view } = &fig(id).kind else {
                panic!()
            };
            assert_eq!((field.as_str(), *time), ("speed", Some(t)));
            // The tank, as the paper frames it: the spray above it is counted, not drawn.
            assert_eq!(*view, Some([-0.1, 4.1, -0.1, 4.1]));
            assert!(fig(id).select.pick(&p.cases).iter().all(|c| c.params.float("dx") == dx));
        }
        let registry::FigureKind::Particles { field, arrows, .. } = &fig("fig03_dam_break_normals").kind
        else {
            panic!()
        };
        assert_eq!((field.as_str(), arrows.as_deref()), ("free_surface", Some("normal")));
        assert!(matches!(fig("trade_dam_break").kind, registry::FigureKind::Trade { spacing: true, .. }));
        let registry::FigureKind::Profile { references, clip_to_reference: true, .. } =
            &fig("fig16_dam_break_toe").kind
        else {
            panic!()
        };
        // The MPS computation the paper compares with, and the experiment.
        assert_eq!((references[0].x.len(), references[1].x.len()), (18, 9));
        // ctvf sun (with and without corrections) and ipst at the main resolution, with the
        // paper's equations and with the surface at p = 0 and the walls clamped; with the
        // latter, ipst also on every fifth step (the authors' code's default).
        let at: Vec<_> = p.cases.iter().filter(|c| c.params.float("dx") == dx).collect();
        assert_eq!(at.len(), 7, "{at:?}");
        let clamped: Vec<_> = at.iter().filter(|c| c.params.str("wall_pressure") == "non_negative").collect();
        assert_eq!(clamped.len(), 4);
        assert!(clamped.iter().all(|c| c.params.str("surface_pressure") == "zero"));
        let every5: Vec<_> = at.iter().filter(|c| c.params.int("ipst_interval") == 5).collect();
        assert_eq!(every5.len(), 1);
        assert_eq!(every5[0].params.str("pst"), "ipst");
        assert_eq!(every5[0].params.str("wall_pressure"), "non_negative");
    }
    assert_eq!(dxs(&quick), [0.05, 0.1]);
    let (sq, sp) = (load("dam_break_stability", "quick"), load("dam_break_stability", "paper"));
    // The quick sweep stops at dx = 0.05 to keep `reproduce` within minutes; the paper preset
    // goes to the dam break's own spacing.
    assert_eq!(dxs(&sq), [0.05, 0.1, 0.2]);
    assert_eq!(dxs(&sp), [0.01, 0.0125, 0.02, 0.025, 0.05, 0.1, 0.2]);
    assert_eq!((sq.cases.len(), sp.cases.len()), (42, 63));
    // The spacing map runs to t = 1 s, the end-time map up to 4 s at one coarse spacing.
    let tfs = |p: &registry::Problem| {
        let mut v: Vec<f64> = p.cases.iter().map(|c| c.params.float("tf")).collect();
        v.sort_by(f64::total_cmp);
        v.dedup();
        v
    };
    assert_eq!(tfs(&sq), [1.0, 2.0, 3.0, 4.0]);
    assert!(sq.cases.iter().filter(|c| c.params.float("tf") > 1.0).all(|c| c.params.float("dx") == 0.1));
    let fs = load("free_surface", "quick");
    let shapes: Vec<_> = fs.cases.iter().map(|c| c.params.str("shape").to_string()).collect();
    assert_eq!(shapes, ["ring", "patch", "column"]);
}

/// The committed results hold what the figures read: for every problem, at both presets,
/// every committed case (a whole finished run in `results/`) holds what each figure and
/// table drawing from it reads (its files; the snapshots a particle figure draws). A case
/// lacking any of it is not done for the cache, so a fresh clone's `reproduce` would run it
/// again: this test says which, in seconds, without a simulation.
#[test]
fn every_committed_case_holds_what_its_figures_read() {
    use sphrepro::automation::cache;
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let empty = tempfile::tempdir().unwrap(); // an output folder with nothing: a fresh clone
    let mut paths: Vec<_> = std::fs::read_dir(root.join("problems"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    paths.sort();
    let (mut bad, mut committed) = (Vec::new(), 0);
    for path in &paths {
        let src = std::fs::read_to_string(path).unwrap();
        for preset in ["quick", "paper"] {
            let p = registry::parse(path, &src, preset).unwrap();
            for e in cache::entries(empty.path(), &p) {
                if e.is_committed() {
                    committed += 1;
                }
                if let cache::State::Incomplete(why) = e.state() {
                    bad.push(format!("{}/{} ({preset}): {why}", p.name, e.case.name));
                }
            }
        }
    }
    assert!(committed > 100, "only {committed} committed case(s) found");
    bad.dedup();
    assert!(bad.is_empty(), "{} committed case(s) lack what figures read:\n{}", bad.len(), bad.join("\n"));
}

/// Every problem has a committed baseline of its quick preset whose cases are the preset's,
/// with the same inputs: a new case, a changed parameter or a new solver version is blessed
/// (`sphrepro bless PROBLEM`) in the change that makes it. Static: no simulation.
#[test]
fn every_problem_has_a_baseline_of_its_current_cases() {
    use sphrepro::automation::{baseline, cache::CaseRecord};
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut paths: Vec<_> = std::fs::read_dir(root.join("problems"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    paths.sort();
    let mut bad = Vec::new();
    for path in &paths {
        let p = registry::parse(path, &std::fs::read_to_string(path).unwrap(), baseline::PRESET).unwrap();
        let Some(b) = baseline::read(&p).unwrap() else {
            bad.push(format!("{}: no baseline ({})", p.name, baseline::path(&p).display()));
            continue;
        };
        let now: Vec<(String, String)> =
            p.cases.iter().map(|c| (c.name.clone(), CaseRecord::new(&p.name, c).key)).collect();
        let then: Vec<(String, String)> = b.cases.iter().map(|(n, o)| (n.clone(), o.key.clone())).collect();
        let mut now_sorted = now.clone();
        now_sorted.sort();
        if now_sorted != then {
            bad.push(format!(
                "{}: the baseline's cases or their inputs differ from the quick preset's",
                p.name
            ));
        }
    }
    assert!(bad.is_empty(), "{}", bad.join("\n"));
}
