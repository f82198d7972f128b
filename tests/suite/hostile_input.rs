//! Fuzz-style properties of everything a user can feed in: arbitrary bytes and arbitrary YAML
//! trees (with the formats' own field names, and hostile numbers) into the level loader, the
//! training-configuration parser and the policy loader. Each must answer with an error or a
//! value, never a panic; the limits of `level::yaml_limits` and the file caps keep time and
//! memory bounded (a case that hung or aborted before would stall or kill this test).

use arlpcg::services::train::TrainConfig;
use arlpcg_core::game::platform::OBSERVATION_SIZE;
use arlpcg_core::level::{Game, yaml};
use arlpcg_core::rl::checkpoint::{Role, load_policy};
use proptest::prelude::*;
use serde_yaml::{Mapping, Value};

/// Field names of the level file and the training configuration, so that trees reach past
/// "unknown field" into the checks behind it.
const KEYS: &[&str] = &[
    "format", "version", "game", "seed", "aux", "start", "goal", "blocks", "segments", "source",
    "stats", "position", "heading", "size", "distance", "angle", "height", "length", "curve",
    "kind", "rules", "max_blocks", "angle_spread", "reach_margin", "solver", "trials", "successes",
    "fell", "timed_out", "success_ratio", "ci95", "mean_progress", "mean_success_steps",
    "failures_by_piece", "hidden", "checkpoint_minutes", "ppo", "generator", "num_envs",
    "num_steps", "num_minibatches", "update_epochs", "learning_rate", "clip_coef", "ent_coef",
    "vf_coef", "gamma", "gae_lambda", "max_grad_norm", "target_kl", "aux_values",
    "solver_phase_steps", "generator_phase_steps", "initial_log_std",
];

fn number() -> impl Strategy<Value = Value> {
    prop_oneof![
        prop::sample::select(vec![
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            1e308,
            -1e308,
            -0.0,
            0.0,
            0.5,
            1.0,
            -1.0,
            5.0,
            7.0,
            1e-320,
        ])
        .prop_map(Value::from),
        any::<i64>().prop_map(Value::from),
        any::<u64>().prop_map(Value::from),
        (-100.0f64..100.0).prop_map(Value::from),
    ]
}

fn leaf() -> impl Strategy<Value = Value> {
    prop_oneof![
        3 => number(),
        1 => prop::sample::select(vec![
            "arlpcg-level", "platform", "racing", "rules", "hand", "policy", "scripted", "0x7",
            "1e9", "", "~",
        ])
        .prop_map(Value::from),
        1 => any::<bool>().prop_map(Value::from),
        1 => Just(Value::Null),
    ]
}

fn tree() -> impl Strategy<Value = Value> {
    leaf().prop_recursive(6, 200, 8, |inner| {
        prop_oneof![
            prop::collection::vec(inner.clone(), 0..8).prop_map(Value::Sequence),
            prop::collection::vec((prop::sample::select(KEYS), inner), 0..8).prop_map(|pairs| {
                let mut map = Mapping::new();
                for (k, v) in pairs {
                    map.insert(Value::from(k), v);
                }
                Value::Mapping(map)
            }),
        ]
    })
}

/// A tree under a valid level header half of the time.
fn level_text() -> impl Strategy<Value = String> {
    (any::<bool>(), tree()).prop_map(|(header, tree)| {
        let body = serde_yaml::to_string(&tree).unwrap_or_default();
        if header {
            format!("format: arlpcg-level\nversion: 1\ngame: platform\n{body}")
        } else {
            body
        }
    })
}

/// Replaces the `n`-th node (pre-order, modulo the node count) of `value` with `with`.
fn replace_node(value: &mut Value, n: usize, with: Value) {
    fn count(v: &Value) -> usize {
        1 + match v {
            Value::Sequence(s) => s.iter().map(count).sum(),
            Value::Mapping(m) => m.values().map(count).sum(),
            _ => 0,
        }
    }
    fn visit(v: &mut Value, n: &mut usize, with: &mut Option<Value>) {
        if *n == 0 {
            if let Some(with) = with.take() {
                *v = with;
            }
            return;
        }
        *n -= 1;
        match v {
            Value::Sequence(s) => s.iter_mut().for_each(|x| visit(x, n, with)),
            Value::Mapping(m) => m.values_mut().for_each(|x| visit(x, n, with)),
            _ => {}
        }
    }
    let mut n = n % count(value);
    visit(value, &mut n, &mut Some(with));
}

/// A valid document (parsed from `text`) with one to three of its nodes replaced by hostile
/// values or trees: past the syntax, into every range check.
fn mutated(text: &'static str) -> impl Strategy<Value = String> {
    let node = prop_oneof![6 => number(), 2 => leaf(), 1 => tree()];
    prop::collection::vec((any::<usize>(), node), 1..4).prop_map(move |edits| {
        let mut value: Value = serde_yaml::from_str(text).unwrap();
        for (n, with) in edits {
            replace_node(&mut value, n, with);
        }
        serde_yaml::to_string(&value).unwrap_or_default()
    })
}

const SHIPPED_LEVEL: &str = include_str!("../../levels/platform/platform_seed7_aux-0.50.yaml");

fn default_config() -> &'static str {
    static TEXT: std::sync::OnceLock<String> = std::sync::OnceLock::new();
    TEXT.get_or_init(|| serde_yaml::to_string(&TrainConfig::default()).unwrap())
}

fn shipped_solver() -> Vec<u8> {
    std::fs::read(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/policies/platform/solver.safetensors"
    ))
    .unwrap()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(400))]

    #[test]
    fn arbitrary_bytes_never_panic_the_level_loader(bytes in prop::collection::vec(any::<u8>(), 0..2000)) {
        let _ = yaml::parse(&String::from_utf8_lossy(&bytes));
    }

    #[test]
    fn arbitrary_yaml_trees_never_panic_the_level_loader(text in level_text()) {
        let _ = yaml::parse(&text);
    }

    #[test]
    fn damaged_levels_never_panic_the_level_loader(text in mutated(SHIPPED_LEVEL)) {
        let _ = yaml::parse(&text);
    }

    #[test]
    fn arbitrary_yaml_trees_never_panic_the_config_parser(tree in tree()) {
        let text = serde_yaml::to_string(&tree).unwrap_or_default();
        let _ = TrainConfig::parse(&text);
    }

    #[test]
    fn damaged_configs_are_refused_or_within_the_limits(text in mutated(default_config())) {
        if let Ok(c) = TrainConfig::parse(&text) {
            // What is accepted is within the documented limits (stated here independently of
            // the checks themselves).
            prop_assert!(!c.hidden.is_empty() && c.hidden.len() <= 8);
            prop_assert!(c.hidden.iter().all(|&h| (1..=4096).contains(&h)));
            prop_assert!((0.0..=1440.0).contains(&c.checkpoint_minutes));
            for p in [&c.solver, &c.generator.ppo] {
                prop_assert!((0.0..=1.0).contains(&p.learning_rate));
                prop_assert!((0.0..=1.0).contains(&p.gamma) && (0.0..=1.0).contains(&p.gae_lambda));
                prop_assert!(p.clip_coef > 0.0 && p.clip_coef <= 1.0);
                prop_assert!((0.0..=1.0).contains(&p.ent_coef) && (0.0..=100.0).contains(&p.vf_coef));
                prop_assert!(p.max_grad_norm.is_finite() && p.max_grad_norm > 0.0);
                prop_assert!(p.target_kl.is_none_or(|k| k.is_finite() && k > 0.0));
                prop_assert!(p.num_envs >= 1 && p.num_steps >= 1 && p.update_epochs >= 1);
                prop_assert!(p.num_envs * p.num_steps <= 1 << 20);
                prop_assert!(p.num_minibatches >= 1 && p.num_minibatches <= p.num_envs * p.num_steps);
            }
            prop_assert!(c.generator.aux_values.iter().all(|l| (-1.0..=1.0).contains(l)));
        }
    }

    #[test]
    fn arbitrary_bytes_never_panic_the_policy_loader(bytes in prop::collection::vec(any::<u8>(), 0..600)) {
        let _ = load_policy(&bytes, Game::Platform, Role::Solver, OBSERVATION_SIZE);
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(60))]

    /// Bytes of a real policy with some of its header bytes changed, or cut short.
    #[test]
    fn damaged_policy_files_are_refused_or_load_never_panic(
        edits in prop::collection::vec((0usize..4000, any::<u8>()), 1..6),
        cut in prop::option::of(0usize..3_000_000),
    ) {
        let mut bytes = shipped_solver();
        for (at, value) in edits {
            if at < bytes.len() {
                bytes[at] = value;
            }
        }
        if let Some(cut) = cut {
            bytes.truncate(cut);
        }
        let _ = load_policy(&bytes, Game::Platform, Role::Solver, OBSERVATION_SIZE);
    }
}

/// A policy file whose card says `edit`'s lie: written with the weights `shape` asks for.
fn policy_with_card(
    dir: &std::path::Path,
    name: &str,
    shape: Option<arlpcg_core::rl::policy::PolicyShape>,
    edit: impl FnOnce(&mut arlpcg_core::rl::checkpoint::PolicyCard),
) -> String {
    let loaded = load_policy(
        &shipped_solver(),
        Game::Platform,
        Role::Solver,
        OBSERVATION_SIZE,
    )
    .unwrap();
    let mut card = loaded.card.clone();
    edit(&mut card);
    let policy = match shape {
        Some(shape) => {
            card.network = shape.clone();
            arlpcg_core::rl::policy::ActorCritic::new(shape, 1).unwrap()
        }
        None => loaded.policy,
    };
    let path = dir.join(name);
    std::fs::write(
        &path,
        arlpcg_core::rl::checkpoint::policy_bytes(&policy, &card),
    )
    .unwrap();
    path.display().to_string()
}

#[test]
fn a_card_that_disagrees_with_its_weights_or_its_game_is_refused_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let level = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/levels/platform/platform_seed7_aux+0.50.yaml"
    );
    // The shipped Solver observes the game's values and the character's abilities after them.
    let observation = load_policy(
        &shipped_solver(),
        Game::Platform,
        Role::Solver,
        OBSERVATION_SIZE,
    )
    .unwrap()
    .card
    .network
    .observation;
    let solver_shape = |continuous, binary| arlpcg_core::rl::policy::PolicyShape {
        observation,
        hidden: vec![8],
        continuous,
        binary,
    };
    let cases = [
        (
            policy_with_card(dir.path(), "five.safetensors", None, |c| {
                c.continuous_actions = (0..5).map(|k| format!("a{k}")).collect();
            }),
            "continuous_actions names 5",
        ),
        (
            policy_with_card(dir.path(), "wide.safetensors", None, |c| {
                c.observation = vec![("everything".into(), 2500)];
            }),
            "observation names 2500",
        ),
        (
            policy_with_card(
                dir.path(),
                "none.safetensors",
                Some(solver_shape(0, 0)),
                |c| {
                    c.continuous_actions.clear();
                    c.binary_actions.clear();
                },
            ),
            "0 continuous and 0 binary actions",
        ),
        (
            policy_with_card(
                dir.path(),
                "swapped.safetensors",
                Some(solver_shape(1, 2)),
                |c| {
                    c.continuous_actions = vec!["forward".into()];
                    c.binary_actions = vec!["turn".into(), "jump".into()];
                },
            ),
            "1 continuous and 2 binary actions",
        ),
    ];
    for (policy, expected) in &cases {
        for args in [
            vec!["verify", "--trials", "1", "--policy", policy, level],
            vec!["export-policy", policy, "--out", "/nonexistent-dir/x.onnx"],
        ] {
            let output = crate::common::arlpcg(&args);
            let err = crate::common::stderr(&output);
            assert_eq!(output.status.code(), Some(1), "{args:?}: {err}");
            assert!(
                err.contains(expected) && err.contains(policy.as_str()),
                "{args:?}: {err}"
            );
        }
    }
}

/// Files are held to the limits of the arguments that would make them: a population beyond
/// `--population`'s limits is refused as an argument (exit 2), and in a campaign.yaml, as are
/// more runs than `campaign --trials` allows and a number out of its range, by file and field,
/// before anything is played.
#[test]
fn files_meet_the_limits_of_the_arguments_that_make_them() {
    use crate::common::{arlpcg, arlpcg_within, fails_with, stderr, words};
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("campaign");
    let asked = arlpcg(words(
        "campaign --ramp 0:0.5 --population 0,1e308 --out {}",
        &[&out],
    ));
    fails_with(&asked, 2, "theta_sd 1e308 must be a number within [0, 50]");
    assert!(!out.exists());
    let shipped = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/results/platform/campaign/campaign.yaml"
    ))
    .unwrap();
    let file = dir.path().join("campaign.yaml");
    let theta_sd = shipped
        .lines()
        .find(|line| line.trim_start().starts_with("theta_sd: "))
        .unwrap()
        .trim_start();
    for (from, to, expected) in [
        (
            "trials: 100\n",
            "trials: 4000000000\n",
            "trials: 4000000000 is not within [10, 100000]",
        ),
        (
            theta_sd, "theta_sd: 1.0e308", "population.theta_sd 1e308 must be",
        ),
        (
            "  measured: 1.0\n",
            "  measured: 1.0e308\n",
            "].measured: 1e308 is not a number within [0, 1]",
        ),
    ] {
        assert!(shipped.contains(from), "{from}");
        std::fs::write(&file, shipped.replacen(from, to, 1)).unwrap();
        let args = ["verify", "--campaign", file.to_str().unwrap()];
        let refused = arlpcg_within(&args, std::time::Duration::from_secs(60));
        fails_with(&refused, 1, expected);
        assert!(stderr(&refused).contains(file.to_str().unwrap()));
    }
}

/// `report` reads files of both games: a results.json, a campaign or a card of the other game
/// where one game's belongs is refused in one line naming the file (it once panicked on the
/// results, and quoted the campaign and listed the card), as is a number out of its range (it
/// once wrote a 309-digit success ratio); the page is left as it was.
#[test]
fn report_refuses_the_other_games_files_and_numbers_out_of_range() {
    use crate::common::{arlpcg, arlpcg_ok, fails_with, stderr, words};
    let dir = tempfile::tempdir().unwrap();
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let (results, policies) = (dir.path().join("results"), dir.path().join("policies"));
    copy_tree(&root.join("results"), &results, &|_| true);
    copy_tree(&root.join("policies"), &policies, &|p| {
        p.extension().is_none_or(|e| e == "yaml")
    });
    let page = dir.path().join("results.md");
    let report = |extra: &str| {
        arlpcg(words(
            &format!("report --results {{}} --policies {{}} --out {{}}{extra}"),
            &[&results, &policies, &page],
        ))
    };
    arlpcg_ok(words(
        "report --results {} --policies {} --out {}",
        &[&results, &policies, &page],
    ));
    let written = std::fs::read(&page).unwrap();
    let platform = results.join("platform");
    let swap = |target: &std::path::Path, from: &std::path::Path, expected: &str| {
        let own = std::fs::read(target).unwrap();
        std::fs::copy(from, target).unwrap();
        for extra in ["", " --check"] {
            let refused = report(extra);
            fails_with(&refused, 1, expected);
            let said = stderr(&refused);
            assert_eq!(said.lines().count(), 1, "{said}");
            assert!(said.contains(target.to_str().unwrap()), "{said}");
        }
        std::fs::write(target, own).unwrap();
    };
    swap(
        &platform.join("results.json"),
        &results.join("racing/results.json"),
        "its columns are not the platform game's",
    );
    swap(
        &platform.join("campaign/campaign.yaml"),
        &results.join("racing/campaign/campaign.yaml"),
        "a racing campaign in the platform results",
    );
    swap(
        &policies.join("platform/solver.yaml"),
        &policies.join("racing/solver.yaml"),
        "the card of a racing policy",
    );
    let mut json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(platform.join("results.json")).unwrap()).unwrap();
    json["controllability"][0]["success_ratio"] = serde_json::json!(1e308);
    let huge = dir.path().join("huge.json");
    std::fs::write(&huge, serde_json::to_vec(&json).unwrap()).unwrap();
    swap(
        &platform.join("results.json"),
        &huge,
        "controllability[0].success_ratio: 1e308 is not a number within [0, 1]",
    );
    assert_eq!(
        std::fs::read(&page).unwrap(),
        written,
        "the page was rewritten"
    );
}

/// Copies the files of `from` that `keep` keeps into `to`, folders and all.
fn copy_tree(
    from: &std::path::Path,
    to: &std::path::Path,
    keep: &dyn Fn(&std::path::Path) -> bool,
) {
    std::fs::create_dir_all(to).unwrap();
    for entry in std::fs::read_dir(from).unwrap() {
        let path = entry.unwrap().path();
        let target = to.join(path.file_name().unwrap());
        if path.is_dir() {
            copy_tree(&path, &target, keep);
        } else if keep(&path) {
            std::fs::copy(&path, &target).unwrap();
        }
    }
}

/// Text from files is made safe before it reaches a terminal: a profile name with a line break
/// or escape codes is refused, and what a file says is echoed with its control characters
/// escaped (a profile's format here); `-0.0` in a profile reads as 0, the same level as `0.0`.
#[test]
fn file_text_is_safe_for_a_terminal_and_minus_zero_is_zero() {
    use crate::common::{arlpcg, arlpcg_ok, fails_with, stderr, words};
    let dir = tempfile::tempdir().unwrap();
    let init = arlpcg_ok(words("profile init --game platform", &[]));
    let profile = String::from_utf8(init.stdout).unwrap();
    let named = dir.path().join("named.yaml");
    let name = "name: \"evil\\n\\e[2J\\e[31mred\"";
    std::fs::write(&named, profile.replacen("name: default", name, 1)).unwrap();
    let refused = arlpcg(words("profile check {}", &[&named]));
    fails_with(
        &refused,
        1,
        "name: a line of text without control characters",
    );
    assert!(!refused.stderr.contains(&0x1b), "{}", stderr(&refused));

    // What a file says, quoted back in a message, has its control characters escaped.
    let format = dir.path().join("format.yaml");
    let forged = "format: \"\\e[2Jwho\\rforged\"";
    std::fs::write(
        &format,
        profile.replacen("format: arlpcg-profile", forged, 1),
    )
    .unwrap();
    let refused = arlpcg(words("profile check {}", &[&format]));
    assert_eq!(refused.status.code(), Some(1), "{}", stderr(&refused));
    assert!(
        !refused.stderr.contains(&0x1b) && !refused.stderr.contains(&b'\r'),
        "{:?}",
        stderr(&refused)
    );
    assert!(
        stderr(&refused).contains("`\\u{1b}[2Jwho forged`"),
        "{}",
        stderr(&refused)
    );

    // -0.0 and 0.0: one profile, one SHA-256, one level.
    let level = |drop: &str| {
        let path = dir.path().join(format!("drop{drop}.yaml"));
        let text = profile.replacen("min_height: ", &format!("min_height: {drop} #"), 1);
        std::fs::write(&path, text).unwrap();
        let out = dir.path().join(format!("levels{drop}"));
        arlpcg_ok(words(
            "generate --rules --profile {} --seed 3 --format yaml --out {}",
            &[&path, &out],
        ));
        std::fs::read(out.join("platform_seed3.yaml")).unwrap()
    };
    assert_eq!(level("-0.0"), level("0.0"));
}

/// A run trained for a profile is not one more seed of the built-in game: `eval --runs`
/// refuses it by its card, naming the file and the profile.
#[test]
fn a_run_trained_for_a_profile_is_not_a_seed_of_the_built_in_game() {
    use arlpcg_core::level::profile::Profile;
    let dir = tempfile::tempdir().unwrap();
    let run = dir.path().join("run");
    std::fs::create_dir(&run).unwrap();
    let solver = policy_with_card(&run, "solver.safetensors", None, |card| {
        let profile = Profile::default_of(Game::Platform)
            .with_value("character.jump_speed", 8.0)
            .unwrap();
        card.profile = Some(
            Profile {
                name: "jumpy".into(),
                ..profile
            }
            .record(),
        );
    });
    let out = dir.path().join("out");
    let args = [
        "eval",
        "--runs",
        run.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ];
    let refused = crate::common::arlpcg(args);
    crate::common::fails_with(&refused, 1, "was trained for profile `jumpy`");
    assert!(crate::common::stderr(&refused).contains(&solver));
    assert!(!out.exists());
}
