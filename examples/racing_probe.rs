use arlpcg::game::racing::{RacingEnv, ScriptedDriver, SolverRewards, rules};
use arlpcg::level::Track;
use arlpcg::level::racing::RacingRulesConfig;
fn main() {
    let t0 = std::time::Instant::now();
    let mut total_steps = 0u64;
    let mut succ = 0;
    let n: u64 = std::env::args().nth(1).map(|s| s.parse().unwrap()).unwrap_or(10);
    for seed in 0..n {
        let level = rules::racing_level(seed, None, None, &RacingRulesConfig::default()).unwrap();
        let Track::Racing(track) = &level.track else { panic!() };
        let mut env = RacingEnv::new(track, level.goal, SolverRewards::default());
        env.reset(seed);
        let mut driver = ScriptedDriver::new(seed, 0.1);
        let mut maxv: f32 = 0.0;
        loop {
            let a = driver.act(&env);
            let s = env.step(a);
            maxv = maxv.max(env.world().velocity().length());
            if let Some(o) = s.outcome {
                total_steps += env.steps() as u64;
                if o == arlpcg::level::stats::Outcome::Success { succ += 1; }
                println!("seed {seed}: {} segs, len {:.0} m, {:?} at {:.0} m after {} steps, air {}, vmax {:.1}", track.segments.len(), env.road().length(), o, env.along(), env.steps(), env.air_steps(), maxv);
                break;
            }
        }
    }
    let dt = t0.elapsed().as_secs_f64();
    println!("{succ}/{n} success; {} steps in {:.2}s = {:.0} steps/s (1 thread, incl. generation)", total_steps, dt, total_steps as f64 / dt);
}
