//! Campaigns and acceptance checks: `campaign` follows its ramp, resumes to the same bytes and
//! refuses a folder of other files; `verify --campaign` re-reports; `--check` fails a batch
//! with exit code 3 and bad checks are usage errors.

use crate::common::{arlpcg, arlpcg_ok, fails_with, files_of, small_campaign, stderr};

const LEVEL: &str = "levels/platform/platform_seed7_aux-1.00.yaml";

#[test]
fn a_campaign_follows_its_ramp_and_resumes_to_the_same_bytes() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("first");
    let done = small_campaign(&out, &["--check", "completed"]);
    assert!(done.status.success(), "{}", stderr(&done));
    let record: serde_yaml::Value =
        serde_yaml::from_slice(&std::fs::read(out.join("campaign.yaml")).unwrap()).unwrap();
    assert_eq!(record["format"].as_str(), Some("arlpcg-campaign"));
    let levels = record["levels"].as_sequence().unwrap();
    assert_eq!(levels.len(), 3);
    let mut reach = 1.0 + 1e-9;
    for (k, level) in levels.iter().enumerate() {
        let asked = level["asked"].as_f64().unwrap();
        let measured = level["measured"].as_f64().unwrap();
        assert!(
            (asked - [0.9, 0.7, 0.5][k]).abs() < 1e-9 && (measured - asked).abs() <= 0.1 + 1e-9,
            "level {k}: asked {asked}, measured {measured}"
        );
        assert!(level["b"].as_f64().unwrap().is_finite());
        let now = level["players"]["reach"].as_f64().unwrap();
        assert!(now <= reach, "the funnel only narrows: {now} after {reach}");
        reach = now;
    }
    let page = std::fs::read_to_string(out.join("campaign.md")).unwrap();
    assert!(page.contains("| 3 | level03.yaml | 0.50 |"), "{page}");
    let png = std::fs::read(out.join("campaign.png")).unwrap();
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    let first = files_of(&out);

    // The same command again finds every file identical.
    let again = small_campaign(&out, &["--check", "completed"]);
    assert!(String::from_utf8_lossy(&again.stdout).contains("already there and identical"));

    // Interrupted after two levels (as a Ctrl-C leaves it): --resume finishes it, the same bytes.
    let resumed = dir.path().join("resumed");
    std::fs::create_dir(&resumed).unwrap();
    for name in ["level01.yaml", "level03.yaml"] {
        std::fs::copy(out.join(name), resumed.join(name)).unwrap();
    }
    let done = small_campaign(&resumed, &["--check", "completed", "--resume"]);
    assert!(done.status.success(), "{}", stderr(&done));
    assert_eq!(files_of(&resumed), first);

    // A level of another campaign is not taken for this one's.
    let other = dir.path().join("other");
    std::fs::create_dir(&other).unwrap();
    std::fs::copy(LEVEL, other.join("level02.yaml")).unwrap();
    fails_with(
        &small_campaign(&other, &["--resume"]),
        1,
        "level02.yaml: not a level of this campaign",
    );
    // Without --resume it is not replaced.
    fails_with(
        &small_campaign(&other, &[]),
        1,
        "level02.yaml already exists with other contents",
    );

    // verify --campaign plays it again and applies the campaign's checks and more.
    let record = out.join("campaign.yaml");
    let replayed = arlpcg_ok(&["verify", "--campaign", record.to_str().unwrap()]);
    let report = String::from_utf8_lossy(&replayed.stdout);
    assert!(report.contains("| 1 | level01.yaml | 0.90 |"), "{report}");
    let strict = arlpcg(&[
        "verify",
        "--campaign",
        record.to_str().unwrap(),
        "--check",
        "success 0.99..1",
    ]);
    assert_eq!(strict.status.code(), Some(3), "{}", stderr(&strict));
    assert!(
        String::from_utf8_lossy(&strict.stdout)
            .contains("check failed: level03.yaml: success 0.99..1"),
        "{}",
        String::from_utf8_lossy(&strict.stdout)
    );
}

#[test]
fn checks_fail_a_batch_with_exit_code_3_and_bad_checks_are_usage_errors() {
    let verify = |checks: &[&str]| {
        let mut args = vec![
            "verify", LEVEL, "--trials", "10", "--solver", "scripted-expert",
        ];
        for check in checks {
            args.extend_from_slice(&["--check", check]);
        }
        arlpcg(&args)
    };
    assert!(verify(&["completed", "success 0..1"]).status.success());
    let failed = verify(&["success 0..0.05"]);
    fails_with(&failed, 3, "1 of 1 levels failed their checks");
    assert!(
        String::from_utf8_lossy(&failed.stdout)
            .contains(&format!("check failed: {LEVEL}: success 0..0.05: success")),
        "{}",
        String::from_utf8_lossy(&failed.stdout)
    );
    fails_with(&verify(&["speed 1..2"]), 2, "`speed` is not a check");
    fails_with(&verify(&["success 0.6..0.4"]), 2, "LO ≤ HI");
    fails_with(
        &verify(&["b -1..1"]),
        2,
        "--check b reads the panel's rating",
    );
    let panel = arlpcg(&["verify", LEVEL, "--panel", "--check", "completed"]);
    fails_with(&panel, 2, "with --panel, a check is `b LO..HI`");

    // generate writes its files, then fails the batch.
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().to_str().unwrap();
    let generated = arlpcg(&[
        "generate", "--rules", "--count", "2", "--verify", "10", "--judge", "scripted-expert",
        "--format", "yaml", "--check", "success 0..0.05", "--out", out,
    ]);
    fails_with(&generated, 3, "2 of 2 levels failed their checks");
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 2);
    let unverified = arlpcg(&["generate", "--rules", "--check", "completed", "--out", out]);
    fails_with(&unverified, 2, "--check reads the levels' statistics");
}
