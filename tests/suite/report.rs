//! docs/results.md is what `arlpcg report` writes from the committed results and cards; the
//! check fails on a page that differs, naming the line; curves are drawn from a run's metrics.

use crate::common::{arlpcg, arlpcg_ok, stderr, words};

#[test]
fn the_committed_results_page_is_what_report_writes() {
    // Integration tests run in the package's root, where the committed files are.
    arlpcg_ok(["report", "--check"]);
    let page = std::fs::read_to_string("docs/results.md").unwrap();
    // Short enough to read: two games, each with its knob tables (the page grew to 229 lines
    // when the platform Generator took its two style knobs).
    assert!(page.lines().count() <= 250, "the page stays short");
    // Its figures are the JSON's: the shipped platform Solver's validation success.
    assert!(page.contains("| arlpcg | 0.944 ± 0.112 |"), "{page}");
}

#[test]
fn a_page_that_differs_fails_the_check_naming_the_line() {
    let dir = tempfile::tempdir().unwrap();
    let page = dir.path().join("results.md");
    let page_arg = page.to_str().unwrap();
    arlpcg_ok(words("report --out {}", &[&page_arg]));
    arlpcg_ok(words("report --check --out {}", &[&page_arg]));
    let written = std::fs::read_to_string(&page).unwrap();
    let edited = written.replacen("0.944 ± 0.112", "0.990 ± 0.200", 1);
    assert_ne!(edited, written);
    std::fs::write(&page, &edited).unwrap();
    let output = arlpcg(words("report --check --out {}", &[&page_arg]));
    assert_eq!(output.status.code(), Some(1));
    let line = 1 + written
        .lines()
        .position(|l| l.contains("0.944 ± 0.112"))
        .unwrap();
    assert!(
        stderr(&output).contains(&format!("line {line} ")),
        "{}",
        stderr(&output)
    );
    // The check wrote nothing.
    assert_eq!(std::fs::read_to_string(&page).unwrap(), edited);
}

#[test]
fn curves_are_drawn_from_a_runs_metrics() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::copy(
        "runs/platform-rule-pcg-s0/metrics.csv",
        dir.path().join("metrics.csv"),
    )
    .unwrap();
    arlpcg_ok(words("report --curves {}", &[&dir.path()]));
    let png = std::fs::read(dir.path().join("learning-curve.png")).unwrap();
    assert!(
        png.starts_with(b"\x89PNG") && png.len() > 10_000,
        "{}",
        png.len()
    );
    // A folder without metrics is refused by name.
    let empty = tempfile::tempdir().unwrap();
    let output = arlpcg(words("report --curves {}", &[&empty.path()]));
    assert!(!output.status.success());
}
