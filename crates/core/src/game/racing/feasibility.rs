//! What the car can do, measured in the real simulation with the scripted driver: top speed, the
//! fastest constant speed through the tightest curve, and the air time crests give at speed.
//! `docs/racing-physics.md` prints these figures; a test re-measures them.

use super::car::{Car, CarAction, DECISION_DT};
use super::env::{RacingEnv, RacingRewards};
use super::scripted::ScriptedDriver;
use crate::game::SolverEnv;
use crate::level::racing::{RacingTrack, RoadShape, SegmentParams};
use crate::level::stats::Outcome;

/// The tightest curve the ranges allow: 30 degrees over 20 m (radius 38 m, banked 15 degrees).
pub const TIGHTEST: SegmentParams = SegmentParams {
    length: 20.0,
    curve: 30.0,
    height: 0.0,
};

/// A track of `lead` straight 30 m segments, then `middle`, then two straight 30 m segments.
pub fn test_track(lead: usize, middle: &[SegmentParams]) -> RacingTrack {
    let straight = SegmentParams {
        length: 30.0,
        curve: 0.0,
        height: 0.0,
    };
    let mut track = RacingTrack::new([0.0; 3], 0.0);
    track.segments = std::iter::repeat_n(straight, lead)
        .chain(middle.iter().copied())
        .chain([straight; 2])
        .collect();
    track
}

/// How one measured run went.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DriveOutcome {
    /// How the run ended.
    pub outcome: Outcome,
    /// Seconds in the air.
    pub air_s: f32,
    /// Fastest speed reached, m/s.
    pub top_speed: f32,
}

/// Drives `track` in `car` with `driver` until the run ends.
pub fn drive(
    track: &RacingTrack,
    car: Car,
    driver: &mut ScriptedDriver,
    seed: u64,
) -> DriveOutcome {
    let goal = track.road().end().0;
    let mut env = RacingEnv::new(track, goal, RacingRewards::default()).with_car(car);
    env.reset(seed);
    let mut top_speed: f32 = 0.0;
    loop {
        let action = driver.act(&env);
        let step = env.step(action);
        top_speed = top_speed.max(env.world().velocity().length());
        if let Some(outcome) = step.outcome {
            return DriveOutcome {
                outcome,
                air_s: env.air_steps() as f32 * DECISION_DT,
                top_speed,
            };
        }
    }
}

/// Top speed of `car` at full throttle on a long straight, m/s.
pub fn top_speed(car: Car) -> f32 {
    let track = test_track(12, &[]);
    let goal = track.road().end().0;
    let mut env = RacingEnv::new(&track, goal, RacingRewards::default()).with_car(car);
    let mut top: f32 = 0.0;
    while env
        .step(CarAction {
            throttle: 1.0,
            steer: 0.0,
        })
        .outcome
        .is_none()
    {
        top = top.max(env.world().velocity().length());
    }
    top
}

/// The fastest speed (to 1 m/s) that `car` holds through `curves` tightest curves in a row
/// of a road of `road`'s width and banking without leaving it, over `seeds` seeded starts.
pub fn cornering_speed(car: Car, curves: usize, seeds: u64, road: RoadShape) -> f32 {
    let mut track = test_track(12, &vec![TIGHTEST; curves]);
    track.road = road;
    (8..=40)
        .map(|v| v as f32)
        .take_while(|&v| {
            (0..seeds).all(|seed| {
                drive(&track, car, &mut ScriptedDriver::holding(v), seed).outcome
                    == Outcome::Success
            })
        })
        .last()
        .unwrap_or(0.0)
}

/// Air time (s) and outcome of a crest: `height` m up over one 20 m segment and down over the
/// next, driven in `car` at a held `speed`.
pub fn crest(car: Car, height: f64, speed: f32) -> DriveOutcome {
    let up = SegmentParams {
        length: 20.0,
        curve: 0.0,
        height,
    };
    let down = SegmentParams {
        height: -height,
        ..up
    };
    drive(
        &test_track(12, &[up, down]),
        car,
        &mut ScriptedDriver::holding(speed),
        0,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    #[ignore = "prints the figures of docs/racing-physics.md"]
    fn print_figures() {
        println!("top speed {:.1} m/s", top_speed(Car::default()));
        for curves in [1, 2, 3, 4, 6] {
            println!(
                "{curves} tightest curves: held at {} m/s",
                cornering_speed(Car::default(), curves, 3, RoadShape::default())
            );
        }
        for h in [1.0, 2.0, 3.0, 4.0, 5.0] {
            let row: Vec<String> = [15.0, 20.0, 25.0, 28.0]
                .iter()
                .map(|&v| {
                    let r = crest(Car::default(), h, v);
                    format!("{:.2} s {:?}", r.air_s, r.outcome)
                })
                .collect();
            println!("crest {h} m: {}", row.join(" | "));
        }
        for v in [15.0, 18.0, 20.0, 25.0] {
            for h in [3.0, 5.0] {
                let up = SegmentParams {
                    length: 20.0,
                    curve: 0.0,
                    height: h,
                };
                let down = SegmentParams {
                    length: 20.0,
                    curve: 30.0,
                    height: -h,
                };
                let run = drive(
                    &test_track(12, &[up, down, TIGHTEST]),
                    Car::default(),
                    &mut ScriptedDriver::holding(v),
                    0,
                );
                println!(
                    "crest {h} m into the tightest curve at {v}: {:.2} s {:?}",
                    run.air_s, run.outcome
                );
            }
        }
    }

    /// Re-measures the figures docs/racing-physics.md states.
    #[test]
    fn the_documented_feasibility_figures_hold() {
        let top = top_speed(Car::default());
        assert!((27.0..=29.0).contains(&top), "top speed {top} m/s");
        // One tightest curve at top speed; four in a row need braking to about 22 m/s.
        let road = RoadShape::default();
        assert!(cornering_speed(Car::default(), 1, 2, road) >= 28.0);
        let four = cornering_speed(Car::default(), 4, 2, road);
        assert!(
            (20.0..=24.0).contains(&four),
            "four tightest curves held at {four} m/s"
        );
        // A narrower road without banking must be taken slower.
        let flat = RoadShape {
            width: 7.0,
            banking: 0.0,
        };
        let on_flat = cornering_speed(Car::default(), 4, 2, flat);
        assert!(on_flat < four, "held at {on_flat} m/s on the flat road");
        let track = test_track(12, &[TIGHTEST; 4]);
        let braking = drive(&track, Car::default(), &mut ScriptedDriver::new(0, 0.0), 0);
        assert_eq!(braking.outcome, Outcome::Success, "{braking:?}");
        // Crests: none at 15 m/s, air at speed, more the higher the crest.
        assert_eq!(crest(Car::default(), 5.0, 15.0).air_s, 0.0);
        let low = crest(Car::default(), 3.0, 25.0);
        let high = crest(Car::default(), 5.0, 25.0);
        assert!(
            low.air_s > 0.5 && high.air_s > low.air_s + 0.3,
            "{low:?} {high:?}"
        );
        assert_eq!(high.outcome, Outcome::Success);
        // What the car cannot do: a 5 m crest into the tightest curve at 20 m/s.
        let up = SegmentParams {
            length: 20.0,
            curve: 0.0,
            height: 5.0,
        };
        let down = SegmentParams {
            length: 20.0,
            curve: 30.0,
            height: -5.0,
        };
        let jump = drive(
            &test_track(12, &[up, down, TIGHTEST]),
            Car::default(),
            &mut ScriptedDriver::holding(20.0),
            0,
        );
        assert_eq!(jump.outcome, Outcome::OffRoad, "{jump:?}");
    }
}
