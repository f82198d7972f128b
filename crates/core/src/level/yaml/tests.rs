use super::*;
use crate::level::{Source, params};

const HAND_MADE: &str = "\
format: arlpcg-level
version: 1
game: platform
start: {position: [0, 0, 0], heading: 0}
blocks:
- {distance: 7, angle: 0, size: 5, height: 1}
- {distance: 6, angle: 30, size: 4, height: -1}
";

#[test]
fn a_hand_made_level_needs_only_relative_parameters() {
    let level = parse(HAND_MADE).unwrap();
    let track = level.platform().unwrap();
    assert_eq!(track.block_count(), 2);
    assert_eq!(
        level.goal,
        track.last().position.map(params::quantize),
        "the goal defaults to the last block"
    );
    assert_eq!(level.source, Source::Hand);
    // Written back, it reads back to the same level, byte for byte on a second round.
    let text = to_string(&level);
    let again = parse(&text).unwrap();
    assert_eq!(again, level);
    assert_eq!(to_string(&again), text);
}

fn problem(text: &str) -> String {
    parse(text).unwrap_err().to_string()
}

#[test]
fn out_of_range_values_name_field_and_line() {
    let msg = problem(&HAND_MADE.replace("size: 4,", "size: 12,"));
    assert!(
        msg.contains("blocks[1]") && msg.contains("size 12 is out of range [4, 6] m"),
        "{msg}"
    );
    assert!(msg.contains("line 7"), "{msg}");
    let msg = problem(&HAND_MADE.replace("height: 1}", "height: .nan}"));
    assert!(
        msg.contains("blocks[0]: height must be a number, not NaN"),
        "{msg}"
    );
    // In block style too, the item and its line are named.
    let block_style = to_string(&parse(HAND_MADE).unwrap()).replacen("size: 5.0", "size: 5.5e3", 1);
    let msg = problem(&block_style);
    assert!(
        msg.contains("blocks[0]: size 5500 is out of range") && msg.contains("line 16"),
        "{msg}"
    );
}

#[test]
fn header_problems_come_first() {
    assert!(problem("").contains("empty"));
    assert!(
        problem(&HAND_MADE.replace("version: 1", "version: 2"))
            .contains("format version 2 is not supported")
    );
    assert!(problem(&HAND_MADE.replace("arlpcg-level", "gltf")).contains("format is gltf"));
    assert!(problem("just some words").contains("not an arlpcg level"));
    assert!(problem("- a\n- list").contains("not an arlpcg level"));
}

#[test]
fn unknown_missing_and_misplaced_fields_are_named() {
    let msg = problem(&HAND_MADE.replace("game: platform", "game: platform\ncolour: red"));
    assert!(msg.contains("unknown field `colour`"), "{msg}");
    let msg = problem(&HAND_MADE.replace("game: platform", "game: chess"));
    assert!(msg.contains("unknown variant `chess`"), "{msg}");
    let msg = problem(&HAND_MADE.replace("size: 5, ", ""));
    assert!(msg.contains("blocks[0]: missing field `size`"), "{msg}");
    let msg = problem(&HAND_MADE.replace("blocks:", "segments:"));
    assert!(msg.contains("segments"), "{msg}");
}

#[test]
fn overlaps_moved_transforms_and_unreached_goals_are_caught() {
    let overlap = HAND_MADE.replace(
        "{distance: 6, angle: 30, size: 4, height: -1}",
        "{distance: 7, angle: 180, size: 4, height: -1}",
    );
    let msg = problem(&overlap);
    assert!(
        msg.contains("blocks[1]: block 1 overlaps the start block (line 7)"),
        "{msg}"
    );
    let moved = HAND_MADE.replace("height: 1}", "height: 1, position: [7, 1, 3]}");
    assert!(problem(&moved).contains("blocks[0].position"));
    let far_goal = format!("{HAND_MADE}goal: [100, 0, 0]\n");
    assert!(problem(&far_goal).contains("does not reach the goal"));
}

#[test]
fn line_of_item_finds_block_style_items() {
    let text = "a: 1\nblocks:\n  - x: 1\n    y: 2\n  - x: 3\nsource:\n  kind: hand\n";
    assert_eq!(line_of_item(text, "blocks", 0), Some(3));
    assert_eq!(line_of_item(text, "blocks", 1), Some(5));
    assert_eq!(line_of_item(text, "blocks", 2), None);
}

#[test]
fn a_racing_level_keeps_its_road_and_a_bad_one_is_named() {
    let hand_made = "\
format: arlpcg-level
version: 1
game: racing
start: {position: [0, 0, 0], heading: 0}
segments:
- {length: 30, curve: 20, height: 0}
- {length: 30, curve: 0, height: 1}
";
    // Without `road:`, the built-in road, and none is written back.
    let built_in = parse(hand_made).unwrap();
    assert!(built_in.racing().unwrap().road.is_default());
    assert!(!to_string(&built_in).contains("road:"));
    let narrow = format!("{hand_made}road: {{width: 7, banking: 0}}\n");
    let level = parse(&narrow).unwrap();
    let road = level.racing().unwrap().road();
    assert_eq!(road.shape().width, 7.0);
    assert!(road.samples().iter().all(|p| p.bank == 0.0));
    assert!(built_in.racing().unwrap().road().samples()[5].bank > 0.0);
    assert_eq!(parse(&to_string(&level)).unwrap(), level);
    let msg = problem(&narrow.replace("width: 7", "width: 20"));
    assert!(
        msg.contains("road") && msg.contains("road width 20 is out of range [6, 14] m"),
        "{msg}"
    );
    let msg = problem(&format!("{HAND_MADE}road: {{width: 7, banking: 0}}\n"));
    assert!(msg.contains("a platform level has no road"), "{msg}");
}

#[test]
fn a_level_keeps_the_headroom_of_the_character_it_was_made_for() {
    // Out, then back over the start block 3.1 m up: room for the built-in 1.8 m character...
    let over_the_start = "\
format: arlpcg-level
version: 1
game: platform
start: {position: [0, 0, 0], heading: 0, size: 6}
blocks:
- {distance: 5, angle: 0, size: 6, height: 1.5}
- {distance: 5, angle: 180, size: 6, height: 1.6}
";
    assert!(parse(over_the_start).is_ok());
    // ...but not for a 2 m one, whose profile the level records.
    let tall = crate::level::profile::Profile::default_of(crate::level::Game::Platform)
        .with_value("character.height", 2.0)
        .unwrap();
    let record = serde_yaml::to_string(&serde_yaml::Mapping::from_iter([(
        "profile".into(),
        serde_yaml::to_value(tall.record()).unwrap(),
    )]))
    .unwrap();
    let msg = problem(&format!("{over_the_start}{record}"));
    assert!(
        msg.contains("blocks[1]: block 1 overlaps the start block"),
        "{msg}"
    );
}

#[test]
fn a_level_records_only_its_games_knobs() {
    let knobs = |names: &str| format!("{HAND_MADE}knobs: {{{names}}}\n");
    let level = parse(&knobs("stride: 1, steps: -0.5")).unwrap();
    assert_eq!(level.knobs["steps"], -0.5);
    let msg = problem(&knobs("stride: 1, curviness: 0.5"));
    assert!(
        msg.contains("knobs")
            && msg.contains(
                "`curviness` is not a knob of a platform level (its knobs: stride, steps)"
            ),
        "{msg}"
    );
}
