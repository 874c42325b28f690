//! Problem files no one should write.

use crate::common::*;
use std::time::{Duration, Instant};

/// Problem files no one should write: each is refused (exit 2) naming the file, without a
/// panic, within the time limit, and nothing is written.
#[test]
fn malformed_problem_files_are_refused_naming_the_file() {
    let good = THREE_CASES;
    let nested = format!("{}{}", "[".repeat(100_000), "]".repeat(100_000));
    // Seven parameters at ten values each: ten million cases.
    let ten = |f: &dyn Fn(usize) -> String| (0..10).map(f).collect::<Vec<_>>().join(", ");
    let grid = format!(
        "nx = [{}], re = [{}], cfl = [{}], hdx = [{}], perturb = [{}], seed = [{}], tf = [{}]",
        ten(&|i| format!("{}", 12 + i)),
        ten(&|i| format!("{}.0", 100 + i)),
        ten(&|i| format!("0.{}", 10 + i)),
        ten(&|i| format!("1.{i}")),
        ten(&|i| format!("0.0{i}")),
        ten(&|i| format!("{}", 1 + i)),
        ten(&|i| format!("0.0{}", 1 + i)),
    );
    let bad: Vec<(&str, Vec<u8>)> = vec![
        ("empty", Vec::new()),
        ("blank", b"\n\n   \n".to_vec()),
        ("binary", (0..=255u8).cycle().take(4096).collect()),
        ("not UTF-8", [good.as_bytes(), b"\n# \xff\xfe\n"].concat()),
        ("truncated", good.as_bytes()[..good.len() / 2].to_vec()),
        ("no scene", good.replace("scene = \"taylor_green\"\n", "").into_bytes()),
        ("scene not a string", good.replace("\"taylor_green\"", "42").into_bytes()),
        ("no cases", good.split("[[cases]]").next().unwrap().as_bytes().to_vec()),
        ("no quick preset", good.replace("[presets.quick]", "[presets.slow]").into_bytes()),
        ("NaN", good.replace("tf = 0.02", "tf = nan").into_bytes()),
        ("infinite", good.replace("tf = 0.02", "tf = inf").into_bytes()),
        ("negative zero", good.replace("tf = 0.02", "tf = -0.0").into_bytes()),
        ("beyond i64", good.replace("nx = 12", "nx = 99999999999999999999").into_bytes()),
        ("huge nx", good.replace("nx = 12", "nx = 9223372036854775807").into_bytes()),
        ("deep nesting", good.replace("nx = 12", &format!("nx = {nested}")).into_bytes()),
        ("a key twice", good.replace("tf = 0.02", "tf = 0.02\ntf = 0.03").into_bytes()),
        ("a table twice", format!("{good}[params]\nnx = 3\n").into_bytes()),
        ("a name with a slash", good.replace("name = \"a\"", "name = \"../../a\"").into_bytes()),
        ("an empty name", good.replace("name = \"a\"", "name = \"\"").into_bytes()),
        (
            "ten million cases",
            good.replace("params = { nx = 12 }", &format!("grid = {{ {grid} }}"))
                .replace("tf = 0.02\n", "")
                .into_bytes(),
        ),
        ("tiny tf", good.replace("tf = 0.02", "tf = 1e-300").into_bytes()),
        ("tiny output interval", good.replace("tf = 0.02", "tf = 0.02\noutput_dt = 1e-300").into_bytes()),
        ("huge perturbation", good.replace("nx = 12", "nx = 12, perturb = 1e20").into_bytes()),
    ];
    for (what, bytes) in bad {
        let p = Problem::new("");
        std::fs::write(p.root.join("problems/tiny.toml"), &bytes).unwrap();
        for args in [&["run", "tiny"][..], &["status"], &["list"]] {
            let t0 = Instant::now();
            let o = p.run(args);
            let t = o.text();
            assert!(t0.elapsed() < Duration::from_secs(30), "{what} {args:?}: took {:?}", t0.elapsed());
            assert_eq!(o.code, Some(2), "{what} {args:?}: {t}");
            assert!(o.stderr.contains("tiny.toml"), "{what} {args:?}: the file is not named: {t}");
            assert!(!o.panicked(), "{what} {args:?}: {t}");
            assert!(!p.root.join("output").exists(), "{what} {args:?}: wrote output");
        }
    }
    // A folder, a dangling link or an unreadable file where a problem file should be.
    #[cfg(unix)]
    {
        let p = Problem::new(good);
        std::fs::create_dir(p.root.join("problems/dir.toml")).unwrap();
        let o = p.run(&["run", "tiny"]);
        assert_eq!(o.code, Some(2), "{}", o.text());
        assert!(o.stderr.contains("dir.toml") && !o.panicked(), "{}", o.text());
        std::fs::remove_dir(p.root.join("problems/dir.toml")).unwrap();
        std::os::unix::fs::symlink("nowhere.toml", p.root.join("problems/link.toml")).unwrap();
        let o = p.run(&["run", "tiny"]);
        assert_eq!(o.code, Some(2), "{}", o.text());
        assert!(o.stderr.contains("link.toml") && !o.panicked(), "{}", o.text());
    }
}
