//! A damaged result is named as damaged, with the command that computes it again.

use crate::common::*;

/// A damaged `summary.json` is named as damaged, with the command that computes the case
/// again: by `status`, by `run` (which does not take it for a crash to rerun) and by
/// `--plot-only` (exit 1); the command it names repairs it.
#[test]
fn a_damaged_summary_is_named_with_the_command_that_recomputes_it() {
    let p = Problem::new(THREE_CASES);
    assert_eq!(p.run(&["run", "tiny"]).code, Some(0));
    let path = p.case_dir("b").join("summary.json");
    let text = std::fs::read_to_string(&path).unwrap();
    std::fs::write(&path, &text[..text.len() / 2]).unwrap();
    let command = "`sphrepro run tiny --match b --force`";
    for args in [&["status"][..], &["run", "tiny"], &["run", "tiny", "--plot-only"], &["check"]] {
        let o = p.run(args);
        let t = o.text();
        assert_eq!(o.code, Some(1), "{args:?}: {t}");
        assert!(t.contains("damaged") && t.contains(command), "{args:?}: {t}");
        assert!(!t.contains("killed or crashed"), "{args:?}: {t}");
    }
    assert_eq!(std::fs::read_to_string(&path).unwrap(), text[..text.len() / 2], "nothing reran it");
    let o = p.run(&["run", "tiny", "--match", "b", "--force"]);
    assert_eq!(o.code, Some(0), "{}", o.text());
    assert!(p.run(&["status"]).stdout.contains("3 done, 0 failed"));
}
