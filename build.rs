//! Records the provenance the binary reports in every `summary.json`: the git commit it was
//! built from (and whether the tree had uncommitted changes) and the rustc version.
use std::process::Command;

fn run(cmd: &str, args: &[&str]) -> Option<String> {
    let out = Command::new(cmd).args(args).output().ok()?;
    out.status.success().then(|| String::from_utf8_lossy(&out.stdout).trim().to_string())
}

fn main() {
    let commit = run("git", &["rev-parse", "HEAD"]).unwrap_or_else(|| "unknown".into());
    // Without optional locks, `git status` does not write the index it refreshes, which
    // would change `.git/index` and rebuild the binary at the next cargo command.
    let dirty = run("git", &["--no-optional-locks", "status", "--porcelain", "--untracked-files=no"])
        .map(|s| !s.is_empty())
        .unwrap_or(false);
    let rustc = std::env::var("RUSTC").unwrap_or_else(|_| "rustc".into());
    let rustc_version = run(&rustc, &["--version"]).unwrap_or_else(|| "unknown".into());
    println!("cargo:rustc-env=SPHREPRO_GIT_COMMIT={commit}");
    println!("cargo:rustc-env=SPHREPRO_GIT_DIRTY={dirty}");
    println!("cargo:rustc-env=SPHREPRO_RUSTC={rustc_version}");
    // Rebuild the stamp when HEAD moves or the index changes.
    for f in [".git/HEAD", ".git/index", ".git/refs/heads"] {
        if std::path::Path::new(f).exists() {
            println!("cargo:rerun-if-changed={f}");
        }
    }
    println!("cargo:rerun-if-changed=src");
}
