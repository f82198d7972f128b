//! The racing game as a user meets it: rule tracks the scripted driver clears, a cloned world
//! that replays a fresh one's run bit for bit, a car that stands on its four wheels, track files that round-trip and refuse
//! broken roads with the field and line, and glTF that reads back with the `gltf` crate.

use crate::common::import_glb;
use arlpcg::services::verify::{Solver, Summary, verify};
use arlpcg_core::game::SolverEnv;
use arlpcg_core::game::racing::car::CarAction;
use arlpcg_core::game::racing::feasibility::test_track;
use arlpcg_core::game::racing::{RacingEnv, RacingRewards, rules};
use arlpcg_core::level::racing::{RacingRulesConfig, RacingTrack, SegmentParams};
use arlpcg_core::level::scene::Scene;
use arlpcg_core::level::stats::Outcome;
use arlpcg_core::level::{Level, gltf as export, yaml};

fn rule_level(seed: u64, obstacles: u32) -> Level {
    let config = RacingRulesConfig {
        obstacles,
        ..RacingRulesConfig::default()
    };
    rules::racing_level(seed, None, None, &config, &Default::default()).unwrap()
}

fn track(level: &Level) -> &RacingTrack {
    level.racing().expect("a racing level")
}

/// A clone of an environment that has run replays the same run as a fresh one (the same seed
/// and actions in both games are checked in determinism.rs).
#[test]
fn a_cloned_environment_replays_a_fresh_ones_run() {
    let level = rule_level(5, 2);
    let mut env = RacingEnv::new(track(&level), level.goal, RacingRewards::default());
    for _ in 0..50 {
        env.step(CarAction {
            throttle: 1.0,
            steer: 0.2,
        });
    }
    let mut clone = env.clone();
    clone.reset(3);
    let mut again = RacingEnv::new(track(&level), level.goal, RacingRewards::default());
    again.reset(3);
    for _ in 0..100 {
        let action = CarAction {
            throttle: 0.8,
            steer: -0.1,
        };
        clone.step(action);
        again.step(action);
        assert_eq!(
            clone.world().position().to_array().map(f32::to_bits),
            again.world().position().to_array().map(f32::to_bits)
        );
    }
}

#[test]
fn the_car_stands_on_four_wheels_on_a_straight_and_drives_it() {
    let track = test_track(3, &[]);
    let goal = track.road().end().0;
    let mut env = RacingEnv::new(&track, goal, RacingRewards::default());
    for _ in 0..60 {
        env.step(CarAction::default());
    }
    assert_eq!(env.world().wheels_in_contact(), 4);
    let still = env.world().velocity().length();
    assert!(still < 0.2, "the car at rest moves at {still} m/s");
    let up = env.world().rotation() * rapier3d::math::Vector::Y;
    assert!(up.y > 0.99, "the car at rest tilts: up = {up:?}");
    let mut outcome = None;
    while outcome.is_none() {
        outcome = env
            .step(CarAction {
                throttle: 1.0,
                steer: 0.0,
            })
            .outcome;
    }
    assert_eq!(outcome, Some(Outcome::Success));
    assert_eq!(env.air_steps(), 0, "a flat straight gives no air time");
}

#[test]
fn rule_tracks_are_cleared_by_the_scripted_driver() {
    let stats: Vec<_> = (0..8)
        .map(|seed| {
            let level = rule_level(seed, (seed % 3) as u32);
            verify(
                &level,
                &Solver::Scripted(arlpcg_core::game::Skill::Expert),
                10,
                0,
                &|| {},
            )
            .unwrap()
        })
        .collect();
    let summary = Summary::of(&stats);
    assert!(
        summary.mean_success >= 0.9,
        "scripted success {} over rule tracks: {stats:?}",
        summary.mean_success
    );
    for s in &stats {
        assert!(
            s.mean_air_steps.is_some(),
            "racing statistics carry air time"
        );
        assert_eq!(s.successes + s.off_road + s.flipped + s.timed_out, s.trials);
    }
}

#[test]
fn random_actions_rarely_finish_and_their_failures_are_counted() {
    let level = rule_level(2, 0);
    let stats = verify(&level, &Solver::Random, 12, 0, &|| {}).unwrap();
    assert!(stats.success_ratio < 0.2, "{stats:?}");
    assert_eq!(
        stats.failures_by_piece.iter().sum::<u32>(),
        stats.trials - stats.successes
    );
}

#[test]
fn rule_tracks_reach_their_goal_and_avoid_their_obstacles() {
    for seed in 0..6 {
        let level = rule_level(seed, 4);
        let track = track(&level);
        assert!(!track.obstacles.is_empty());
        track.check_geometry().unwrap();
        level.validate().unwrap();
        // Same seed, same bytes.
        assert_eq!(
            yaml::to_string(&level),
            yaml::to_string(&rule_level(seed, 4))
        );
    }
}

#[test]
fn track_files_round_trip_and_broken_roads_are_named() {
    let level = rule_level(7, 3);
    let text = yaml::to_string(&level);
    let back = yaml::parse(&text).unwrap();
    assert_eq!(back, level);
    assert_eq!(yaml::to_string(&back), text);

    let hand = "\
format: arlpcg-level
version: 1
game: racing
start: {position: [0, 0, 0], heading: 0}
segments:
- {length: 30, curve: 30, height: 0}
";
    let level = yaml::parse(hand).unwrap();
    assert_eq!(
        level.goal,
        track(&level)
            .road()
            .end()
            .0
            .map(arlpcg_core::level::params::quantize)
    );
    let problem = |text: &str| yaml::parse(text).unwrap_err().to_string();
    let looping = hand.to_string() + &"- {length: 30, curve: 30, height: 0}\n".repeat(12);
    let msg = problem(&looping);
    assert!(
        msg.contains("segments[") && msg.contains("crosses segment"),
        "{msg}"
    );
    assert!(msg.contains("(line "), "{msg}");
    let blocked = format!(
        "{hand}obstacles:\n- {{kind: cylinder, position: [15, 0, -2], radius: 2, height: 4}}\n"
    );
    let msg = problem(&blocked);
    assert!(
        msg.contains("segments[0]: segment 0 runs into obstacle 0"),
        "{msg}"
    );
    let far = format!("{hand}goal: [300, 0, 0]\n");
    assert!(problem(&far).contains("does not reach the goal"));
    let nan = format!(
        "{hand}obstacles:\n- {{kind: cylinder, position: [100, .nan, 0], radius: 2, height: 4}}\n"
    );
    let msg = problem(&nan);
    assert!(
        msg.contains("obstacles[0].position: coordinate must be a number"),
        "{msg}"
    );
    let odd = format!(
        "{hand}obstacles:\n- {{kind: pyramid, position: [100, 0, 0], radius: 2, height: 4}}\n"
    );
    assert!(problem(&odd).contains("unknown variant `pyramid`"));
    let steep = hand.replace("height: 0}", "height: 7}");
    assert!(problem(&steep).contains("height 7 is out of range [-5, 5] m"));
    let rules_mixup = format!(
        "{hand}source: {{kind: rules, rules: {{max_blocks: 5, angle_spread: 5, reach_margin: 1}}}}\n"
    );
    assert!(problem(&rules_mixup).contains("racing-rules"));
}

#[test]
fn racing_gltf_reads_back_with_a_mesh_per_segment_facing_up() {
    let level = rule_level(3, 3);
    let track = track(&level);
    let glb = export::to_glb(&Scene::of_level(&level));
    // Left for `.ci/run` to pass through the Khronos validator.
    let exports = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("gltf-exports");
    std::fs::create_dir_all(&exports).unwrap();
    std::fs::write(exports.join("racing_rules_seed3.glb"), &glb).unwrap();
    let (document, buffers) = import_glb(&glb);
    let segments: Vec<gltf::Node> = document
        .nodes()
        .filter(|n| {
            n.name()
                .is_some_and(|name| name.starts_with("segment_") && !name.ends_with("_collider"))
        })
        .collect();
    assert_eq!(segments.len(), track.segments.len());
    let obstacles = document
        .nodes()
        .filter(|n| {
            n.name()
                .is_some_and(|name| name.starts_with("obstacle_") && !name.ends_with("_collider"))
        })
        .count();
    assert_eq!(obstacles, track.obstacles.len());
    let extras: serde_json::Value =
        serde_json::from_str(segments[2].extras().as_ref().unwrap().get()).unwrap();
    assert_eq!(extras["curve"], track.segments[2].curve);
    for node in &segments {
        let mesh = node.mesh().unwrap();
        let surface = mesh.primitives().next().unwrap();
        assert_eq!(surface.material().name(), Some("road"));
        let reader = surface.reader(|b| Some(&buffers[b.index()]));
        let positions: Vec<[f32; 3]> = reader.read_positions().unwrap().collect();
        let uvs = reader.read_tex_coords(0).unwrap().into_f32().count();
        assert_eq!(uvs, positions.len());
        let indices: Vec<u32> = reader.read_indices().unwrap().into_u32().collect();
        for t in indices.chunks(3) {
            let [a, b, c] = [t[0], t[1], t[2]].map(|i| positions[i as usize]);
            let e1 = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
            let e2 = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
            let up = e1[2] * e2[0] - e1[0] * e2[2];
            assert!(up > 0.0, "{:?}: a road triangle faces down", node.name());
        }
    }
    // The road's end is where the track file says the road ends.
    let last = segments.last().unwrap().mesh().unwrap();
    let bounds = last.primitives().next().unwrap().bounding_box();
    let (end, _) = track.road().end();
    assert!(end[0] as f32 >= bounds.min[0] - 1e-3 && end[0] as f32 <= bounds.max[0] + 1e-3);
}

#[test]
fn a_segment_can_be_built_from_the_generator_ranges_only() {
    assert!(SegmentParams::new(31.0, 0.0, 0.0).is_err());
    assert!(SegmentParams::new(25.0, f64::NAN, 0.0).is_err());
    assert!(SegmentParams::new(25.0, -30.0, 5.0).is_ok());
    // The environment's observation has the size its layout says, and finite values.
    let level = rule_level(1, 2);
    let env = RacingEnv::new(track(&level), level.goal, RacingRewards::default());
    let mut observation = vec![f32::NAN; RacingEnv::OBSERVATION_SIZE];
    env.observe(&mut observation);
    assert!(observation.iter().all(|x| x.is_finite()), "{observation:?}");
}
