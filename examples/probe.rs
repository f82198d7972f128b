use arlpcg::game::platform::{PlatformEnv, ScriptedController, SolverRewards};
fn main() {
    let level =
        arlpcg::level::yaml::load(std::path::Path::new(&std::env::args().nth(1).unwrap())).unwrap();
    let track = level.platform().unwrap();
    let mut env = PlatformEnv::new(track, level.goal, SolverRewards::default());
    env.reset(0);
    let mut c = ScriptedController::new(0, 0.3);
    for i in 0..400 {
        let a = c.act(&env);
        let s = env.step(a);
        let ch = env.character();
        if i % 10 == 0 || s.outcome.is_some() {
            println!(
                "{i} {:?} feet {:.2?} vel {:.2?} yaw {:.1} g {} fur {}",
                a,
                ch.feet,
                ch.velocity,
                ch.yaw.to_degrees(),
                ch.grounded,
                env.furthest()
            );
        }
        if s.outcome.is_some() {
            break;
        }
    }
}
