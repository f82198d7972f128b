//! Property tests of the level file: any valid level writes and reads back to itself, and the
//! text is stable (writing what was read gives the same bytes).

use arlpcg_core::level::platform::{BlockParams, PlatformTrack, Start};
use arlpcg_core::level::{Level, Source, Track, params, yaml};
use proptest::prelude::*;

fn block() -> impl Strategy<Value = BlockParams> {
    let r = |p: params::ParamRange| p.min..=p.max;
    (
        r(params::BLOCK_DISTANCE),
        r(params::BLOCK_ANGLE),
        r(params::BLOCK_SIZE),
        r(params::BLOCK_HEIGHT),
    )
        .prop_map(|(distance, angle, size, height)| {
            BlockParams::new(distance, angle, size, height).unwrap()
        })
}

/// A level of arbitrary full-precision parameters, keeping only blocks that place validly.
fn level() -> impl Strategy<Value = Level> {
    (
        prop::collection::vec(block(), 1..30),
        -180.0..=180.0f64,
        any::<Option<u64>>(),
        prop::option::of(-1.0..=1.0f64),
    )
        .prop_filter_map(
            "needs at least one valid block",
            |(blocks, heading, seed, aux)| {
                let mut track = PlatformTrack::new(Start {
                    heading,
                    ..Start::default()
                });
                for b in blocks {
                    let _ = track.push(b);
                }
                (track.block_count() > 0).then(|| Level {
                    seed,
                    aux,
                    goal: track.last().position,
                    track: Track::Platform(track),
                    source: Source::Hand,
                    stats: None,
                    pacing: None,
                    profile: None,
                    knobs: Default::default(),
                    want: None,
                })
            },
        )
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    #[test]
    fn any_valid_level_round_trips(level in level()) {
        let text = yaml::to_string(&level);
        let read = yaml::parse(&text).map_err(|e| TestCaseError::fail(format!("{e}\n{text}")))?;
        prop_assert_eq!(&read, &level);
        prop_assert_eq!(yaml::to_string(&read), text);
    }

    #[test]
    fn arbitrary_text_never_panics(text in "\\PC{0,200}") {
        let _ = yaml::parse(&text);
    }
}
