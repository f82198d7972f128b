//! The panel of judges: the scripted player's skills apart on rule levels, `verify --panel`,
//! `generate --panel` and `--judge`; campaigns, which the panel rates (`campaign` follows its
//! ramp, resumes to the same bytes and refuses a folder of other files; `verify --campaign`
//! re-reports); and `--check`, which fails a batch with exit code 3.

use arlpcg::services::verify::{Solver, verify};
use arlpcg_core::game::{GameSpec, PlatformGame, RacingGame, Skill};

use crate::common::{arlpcg, arlpcg_ok, fails_with, files_of, small_campaign, stderr, words};

/// Mean success of each skill, weakest first, on `levels` rule levels of `G`, `trials` runs each.
fn skill_success<G: GameSpec>(levels: u64, trials: u32) -> Vec<f64> {
    let levels: Vec<_> = (0..levels)
        .filter_map(|k| G::rule_level(9_000 + k, &Default::default()))
        .collect();
    assert!(levels.len() >= 4, "the rules build most seeds");
    Skill::ALL
        .iter()
        .map(|&skill| {
            let total: f64 = levels
                .iter()
                .map(|level| {
                    verify(level, &Solver::Scripted(skill), trials, 0, &|| {})
                        .unwrap()
                        .success_ratio
                })
                .sum();
            total / levels.len() as f64
        })
        .collect()
}

#[test]
fn scripted_skills_are_clearly_apart_on_rule_levels() {
    // Calibrated on 40 rule levels × 20 runs (measured at 93fa40a): platform 0.46 / 0.91 / 1.00,
    // racing 0.59 / 0.87 / 1.00.
    for (game, success) in [
        ("platform", skill_success::<PlatformGame>(6, 16)),
        ("racing", skill_success::<RacingGame>(5, 8)),
    ] {
        let [novice, median, expert] = success[..] else {
            unreachable!()
        };
        assert!(expert >= 0.95, "{game}: expert {expert:.2}");
        assert!(
            novice + 0.15 < median && median < expert,
            "{game}: novice {novice:.2}, median {median:.2}, expert {expert:.2}"
        );
        assert!(
            novice < 0.8,
            "{game}: a novice below the trained Solvers, {novice:.2}"
        );
    }
}

#[test]
fn verify_panel_reports_every_judge_and_rates_the_levels_together() {
    let levels = [
        "levels/platform/platform_seed7_aux+1.00.yaml",
        "levels/platform/platform_seed7_aux-1.00.yaml",
    ];
    let mut args = vec!["verify", "--panel", "--trials", "12", "--json"];
    args.extend(levels);
    let out = arlpcg_ok(&args);
    let rows: Vec<serde_json::Value> = String::from_utf8(out.stdout)
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(rows.len(), 2);
    for row in &rows {
        let panel = row["panel"].as_object().unwrap();
        assert_eq!(
            panel.len(),
            7,
            "every shipped Solver and three skills: {panel:?}"
        );
        assert!(panel.contains_key("rule-pcg") && panel.contains_key("scripted-novice"));
        assert_eq!(row["rating"]["levels"], 2);
        let ci = row["rating"]["ci95"].as_array().unwrap();
        let b = row["rating"]["b"].as_f64().unwrap();
        assert!(
            ci[0].as_f64().unwrap() < b && b < ci[1].as_f64().unwrap(),
            "{row}"
        );
    }
    let b = |k: usize| rows[k]["rating"]["b"].as_f64().unwrap();
    assert!(
        b(0) < b(1),
        "the λ = 1 level rates easier than the λ = -1 one"
    );

    let some = arlpcg_ok(words(
        "verify {} --panel scripted-median,arlpcg --trials 4 --json",
        &[&levels[0]],
    ));
    let row: serde_json::Value = serde_json::from_slice(&some.stdout).unwrap();
    let names: Vec<&String> = row["panel"].as_object().unwrap().keys().collect();
    assert_eq!(names, ["arlpcg", "scripted-median"]);

    let bad = arlpcg(words("verify {} --panel scripted-wizard", &[&levels[0]]));
    fails_with(&bad, 2, "scripted-expert");

    // Under --profile the panel plays the profile's character: a low jumper cannot climb the
    // hand-made staircase the built-in character climbs.
    let dir = tempfile::tempdir().unwrap();
    let low = dir.path().join("low.yaml");
    let init = arlpcg_ok(words("profile init --game platform", &[]));
    let text = String::from_utf8(init.stdout).unwrap();
    std::fs::write(
        &low,
        text.replace("name: default", "name: low")
            .replace("jump_speed: 9.25", "jump_speed: 5.0"),
    )
    .unwrap();
    let staircase = concat!(env!("CARGO_MANIFEST_DIR"), "/levels/hand/staircase.yaml");
    let expert = |profile: &[&str]| {
        let mut args = vec![
            staircase, "--panel", "scripted-expert", "--trials", "4", "--json",
        ];
        args.extend_from_slice(profile);
        let out = arlpcg_ok([&["verify"], args.as_slice()].concat());
        let row: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        row["panel"]["scripted-expert"].clone()
    };
    let low = low.to_str().unwrap();
    assert_ne!(
        expert(&[]),
        expert(&["--profile", low]),
        "--profile plays the low jumper"
    );
}

#[test]
fn generate_records_the_panel_and_the_rating_and_verifies_with_a_judge() {
    let dir = tempfile::tempdir().unwrap();
    let out_dir = dir.path().join("rated");
    arlpcg_ok(words(
        "generate --game platform --policies policies/platform --aux=-1 --seed 100 --count 2 --verify 6 --panel --judge scripted-median --format yaml --out {}",
        &[&out_dir],
    ));
    let path = out_dir.join("platform_seed100_aux-1.00.yaml");
    let level = arlpcg_core::level::yaml::load(&path).unwrap();
    let stats = level.stats.unwrap();
    assert_eq!(
        stats.solver,
        arlpcg_core::level::SolverRef::Scripted {
            skill: Skill::Median
        }
    );
    let panel = stats.panel.expect("--panel records the panel");
    assert_eq!(panel.judges.len(), 7);
    assert_eq!(panel.trials, 6);
    let arlpcg = &panel.judges[0];
    assert_eq!(arlpcg.judge, "arlpcg");
    let played = &arlpcg
        .policy
        .as_ref()
        .expect("a Solver judge's policy")
        .path;
    assert!(played.ends_with("platform/solver.safetensors"), "{played}");
    let rating = panel.rating.expect("and the rating");
    assert_eq!(rating.levels, 2);
    assert!(rating.ci95[0] < rating.b && rating.b < rating.ci95[1]);
}

const LEVEL: &str = "levels/platform/platform_seed7_aux-1.00.yaml";

#[test]
fn a_campaign_follows_its_ramp_and_resumes_to_the_same_bytes() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("first");
    let done = small_campaign(&out, &["--check", "completed"]);
    assert!(done.status.success(), "{}", stderr(&done));
    // Under the built-in abilities every Solver of the panel trained with them.
    assert!(
        !stderr(&done).contains("never trained"),
        "{}",
        stderr(&done)
    );
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

    // Interrupted after two levels (as a Ctrl-C leaves it): --resume finishes it, the same bytes,
    // on one worker thread where the first run had every core.
    let resumed = dir.path().join("resumed");
    std::fs::create_dir(&resumed).unwrap();
    for name in ["level01.yaml", "level03.yaml"] {
        std::fs::copy(out.join(name), resumed.join(name)).unwrap();
    }
    let done = small_campaign(
        &resumed,
        &["--check", "completed", "--resume", "--threads", "1"],
    );
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
    let replayed = arlpcg_ok(words("verify --campaign {}", &[&record]));
    let report = String::from_utf8_lossy(&replayed.stdout);
    assert!(report.contains("| 1 | level01.yaml | 0.90 |"), "{report}");
    let strict = arlpcg(words(
        "verify --campaign {} --check {}",
        &[&record, &"success 0.99..1"],
    ));
    assert_eq!(strict.status.code(), Some(3), "{}", stderr(&strict));
    assert!(
        String::from_utf8_lossy(&strict.stdout)
            .contains("check failed: level03.yaml: success 0.99..1"),
        "{}",
        String::from_utf8_lossy(&strict.stdout)
    );
}

/// With --pacing, every level follows the curve's shape, moved as a whole to its ramp point;
/// with --profile, every level is made for it and the record says so.
#[test]
fn a_paced_campaign_moves_one_shape_per_level() {
    let dir = tempfile::tempdir().unwrap();
    let init = arlpcg_ok(words("profile init --game platform", &[]));
    let profile = String::from_utf8(init.stdout)
        .unwrap()
        .replace("name: default", "name: quick")
        .replace("run_speed: 8.0", "run_speed: 8.5");
    let profile_file = dir.path().join("quick.yaml");
    std::fs::write(&profile_file, profile).unwrap();
    let out = dir.path().join("campaign");
    let profile_arg = profile_file.to_str().unwrap();
    let done = small_campaign(
        &out,
        &[
            "--pacing", "0:0.4, 1:-0.4", "--profile", profile_arg, "--physics", "khr", "--format",
            "glb",
        ],
    );
    assert!(done.status.success(), "{}", stderr(&done));
    // Every Solver of the shipped panel trained over ranges that hold 8.5 m/s, so the campaign
    // warns of none (one beyond them is named, as `verify` does).
    let said = stderr(&done);
    assert!(
        !said.contains("never trained") && !said.contains("lies beyond"),
        "{said}"
    );
    let level01 = std::fs::read_to_string(out.join("level01.yaml")).unwrap();
    assert!(level01.contains("profile:\n  name: quick"), "{level01}");
    let record: serde_yaml::Value =
        serde_yaml::from_slice(&std::fs::read(out.join("campaign.yaml")).unwrap()).unwrap();
    assert_eq!(record["pacing"].as_str(), Some("0:0.4, 1:-0.4"));
    assert_eq!(record["profile"]["name"].as_str(), Some("quick"));
    // --physics khr: the record keeps it (a level searched anew is written the same way) and
    // the levels' glTF carries the Khronos drafts, not OMI.
    assert_eq!(record["gltf"]["physics"].as_str(), Some("khr"));
    let glb =
        String::from_utf8_lossy(&std::fs::read(out.join("level01.glb")).unwrap()).into_owned();
    assert!(glb.contains("KHR_physics_rigid_bodies") && !glb.contains("OMI_physics_body"));
    for level in record["levels"].as_sequence().unwrap() {
        assert!(level.get("aux").is_none(), "{level:?}");
        let curve = level["aux_curve"].as_str().unwrap();
        let points: Vec<f64> = curve
            .split(", ")
            .map(|p| p.split(':').nth(1).unwrap().parse().unwrap())
            .collect();
        let [start, end] = points[..] else {
            panic!("{curve}")
        };
        let clamped = start == 1.0 || end == -1.0;
        assert!(clamped || ((start - end) - 0.8).abs() < 2e-3, "{curve}");
        assert!(start > end, "{curve}");
    }
    let page = std::fs::read_to_string(out.join("campaign.md")).unwrap();
    let said = "each level paced by `0:0.4, 1:-0.4` moved as a whole, made for profile `quick`";
    assert!(page.contains(said), "{page}");
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
    fails_with(&verify(&["speed 1..2"]), 2, "`speed` is not an attribute");
    fails_with(&verify(&["success 0.6..0.4"]), 2, "is empty");
    fails_with(
        &verify(&["b -1..1"]),
        2,
        "--check b -1..1 reads the panel's runs",
    );
    let panel = arlpcg(words("verify {} --panel --check completed", &[&LEVEL]));
    fails_with(
        &panel,
        2,
        "with --panel, `completed` has no one player's runs",
    );
    // A check on the pieces reads the same level file: the shipped level has 5 blocks.
    assert!(verify(&["pieces 5", "jump 5..10"]).status.success());
    let pieces = verify(&["pieces >= 20"]);
    fails_with(&pieces, 3, "1 of 1 levels failed their checks");
    assert!(
        String::from_utf8_lossy(&pieces.stdout).contains("pieces >= 20: measured 5"),
        "{}",
        String::from_utf8_lossy(&pieces.stdout)
    );

    // generate writes its files, then fails the batch.
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().to_str().unwrap();
    let generated = arlpcg(words(
        "generate --rules --count 2 --verify 10 --judge scripted-expert --format yaml --check {} --out {}",
        &[&"success 0..0.05", &out],
    ));
    fails_with(&generated, 3, "2 of 2 levels failed their checks");
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 2);
    let unverified = arlpcg(words(
        "generate --rules --check completed --out {}",
        &[&out],
    ));
    fails_with(&unverified, 2, "--check completed reads the levels' runs");
    // A check on the pieces needs no runs; one of the other game's is refused before any.
    let racing = arlpcg(words(
        "generate --rules --check {} --out {}",
        &[&"curve <= 30", &out],
    ));
    fails_with(&racing, 2, "`curve` is not an attribute of these levels");
}

/// A campaign's checks on the pieces are met by search, not only checked: the three levels of
/// this campaign have 7, 3 and 9 blocks when searched for their ramp point alone.
#[test]
fn a_campaign_searches_for_its_checks_on_the_pieces() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("campaign");
    let done = small_campaign(&out, &["--check", "pieces 5..6"]);
    assert!(done.status.success(), "{}", stderr(&done));
    for k in 1..=3 {
        let level = arlpcg_core::level::yaml::load(&out.join(format!("level0{k}.yaml"))).unwrap();
        let blocks = level.platform().unwrap().block_count();
        assert!((5..=6).contains(&blocks), "level {k}: {blocks} blocks");
    }
}
