//! What a trained policy says about itself: its shape from the game and the configuration, its
//! card (game, role, inputs and outputs, how it was trained, from which commit), the files it is
//! saved as, and checkpoints read back for resuming.

use std::path::Path;

use super::config::TrainConfig;
use crate::services::fsio;
use crate::services::fsio::Overwrite;
use anyhow::{Context, Result, bail};
use arlpcg_core::game::facts::facts;
use arlpcg_core::game::generator::{GeneratorGame, KNOBS_PART};
use arlpcg_core::level::Game;
use arlpcg_core::level::profile::{ABILITIES_PART, ability_columns};
use arlpcg_core::rl::checkpoint;
use arlpcg_core::rl::checkpoint::{PolicyCard, Role, TrainMode, TrainingRecord, TrainingState};
use arlpcg_core::rl::normalizer::RunningNorm;
use arlpcg_core::rl::policy::{ActorCritic, PolicyShape};

/// What a game's agent (Solver or Generator) observes and does, as a policy card names it.
pub(super) struct AgentIo {
    observation: &'static [(&'static str, usize)],
    continuous: &'static [&'static str],
    binary: &'static [&'static str],
}

impl AgentIo {
    fn of(game: Game, role: Role) -> Self {
        fn io<G: GeneratorGame>(role: Role) -> AgentIo {
            match role {
                Role::Solver => AgentIo {
                    observation: G::OBSERVATION_LAYOUT,
                    continuous: G::CONTINUOUS_ACTIONS,
                    binary: G::BINARY_ACTIONS,
                },
                Role::Generator => AgentIo {
                    observation: G::GENERATOR_OBSERVATION_LAYOUT,
                    continuous: G::GENERATOR_ACTIONS,
                    binary: &[],
                },
            }
        }
        arlpcg_core::for_game!(game, G => io::<G>(role))
    }

    fn observation_size(&self) -> usize {
        self.observation.iter().map(|(_, k)| k).sum()
    }
}

/// The policy shape of `role`'s agent: the game's observation (and the abilities, for an
/// ability-aware run) in, its actions out.
pub(super) fn agent_shape(config: &TrainConfig, game: Game, role: Role) -> PolicyShape {
    let io = AgentIo::of(game, role);
    PolicyShape {
        observation: io.observation_size()
            + knob_columns(config, role)
            + ability_columns(config.ability_aware()),
        hidden: config.hidden.clone(),
        continuous: io.continuous.len(),
        binary: io.binary.len(),
    }
}

/// The knobs `role`'s agent observes: a Generator's, where its rewards weigh them.
fn knob_columns(config: &TrainConfig, role: Role) -> usize {
    match role {
        Role::Generator => config.generator.rewards.knobs.len(),
        Role::Solver => 0,
    }
}

/// The Solver's policy shape.
pub(super) fn solver_shape(config: &TrainConfig, game: Game) -> PolicyShape {
    agent_shape(config, game, Role::Solver)
}

/// The Generator's policy shape.
pub(super) fn generator_shape(config: &TrainConfig, game: Game) -> PolicyShape {
    agent_shape(config, game, Role::Generator)
}

/// Records the run's sessions in `card`: `commands[0]` started it, the others resumed it.
pub(super) fn record_commands(card: &mut PolicyCard, commands: &[String], commit: &str) {
    card.training.commit = commit.to_string();
    if let Some((first, later)) = commands.split_first() {
        card.training.command = first.clone();
        card.training.resumed_with = later.to_vec();
    }
}

/// The sessions a loaded card records, oldest first (a card from before `resumed_with` holds
/// only its last session's command).
pub(super) fn recorded_commands(card: &PolicyCard) -> Vec<String> {
    std::iter::once(card.training.command.clone())
        .filter(|command| !command.is_empty())
        .chain(card.training.resumed_with.iter().cloned())
        .collect()
}

/// A policy card for a policy trained by this run (its commands and commit are set by
/// [`record_commands`]).
pub(super) fn card(
    game: Game,
    role: Role,
    mode: TrainMode,
    config: &TrainConfig,
    normalizer: &RunningNorm,
    steps: u64,
    wall_time_s: f64,
) -> PolicyCard {
    let names = |list: &[&str]| list.iter().map(|s| s.to_string()).collect::<Vec<_>>();
    let layout = |list: &[(&str, usize)]| {
        list.iter()
            .map(|(n, k)| (n.to_string(), *k))
            .collect::<Vec<_>>()
    };
    let io = AgentIo::of(game, role);
    let mut observation = layout(io.observation);
    // A Generator with knobs observes their values after the game's observation...
    let knobs = knob_columns(config, role);
    if knobs > 0 {
        observation.push((KNOBS_PART.to_string(), knobs));
    }
    // ...and an ability-aware agent the main abilities after that.
    let abilities = ability_columns(config.ability_aware());
    if abilities > 0 {
        observation.push((ABILITIES_PART.to_string(), abilities));
    }
    PolicyCard {
        format: checkpoint::POLICY_FORMAT.into(),
        version: checkpoint::POLICY_VERSION,
        game,
        role,
        observation,
        continuous_actions: names(io.continuous),
        binary_actions: names(io.binary),
        network: agent_shape(config, game, role),
        normalizer: normalizer.clone(),
        training: TrainingRecord {
            mode,
            steps,
            wall_time_s: (wall_time_s * 10.0).round() / 10.0,
            seed: config.seed,
            commit: String::new(),
            command: String::new(),
            resumed_with: Vec::new(),
            population: Vec::new(),
            time_split: None,
            update_mfu: None,
        },
        results: Default::default(),
        max_pieces: (role == Role::Generator).then_some(config.generator.max_pieces),
        curve_offset: (role == Role::Generator && facts(game).curve_offset)
            .then_some(config.generator.curve_offset),
        // A Generator's is the reach of the Solver step it is saved at (`generator_card`).
        reach_runs: None,
        profile: config.profile.clone(),
        ability_spread: (config.ability_spread > 0.0).then_some(config.ability_spread),
        ability_ranges: config
            .trained_over(game)
            .ok()
            .flatten()
            .map(|ranges| ranges.named()),
    }
}

/// Writes a policy and its YAML card (`<name>.safetensors`, `<name>.yaml`) into `out`.
pub(super) fn save_policy_files(
    out: &Path,
    name: &str,
    policy: &ActorCritic,
    card: &PolicyCard,
) -> Result<()> {
    fsio::write_atomic(
        &out.join(format!("{name}.safetensors")),
        &checkpoint::policy_bytes(policy, card),
        Overwrite::Allowed,
    )?;
    fsio::write_atomic(
        &out.join(format!("{name}.yaml")),
        serde_yaml::to_string(card)?.as_bytes(),
        Overwrite::Allowed,
    )
}

/// The game and mode of the run whose checkpoint is `path`: what `--resume` continues when
/// `--game` or `--mode` is not given.
pub(super) fn checkpoint_identity(path: &Path) -> Result<(Game, TrainMode)> {
    let bytes =
        crate::services::fsio::read_limited(path, checkpoint::MAX_POLICY_BYTES, "checkpoint")
            .context("cannot resume")?;
    let card = checkpoint::read_card(&bytes).with_context(|| format!("{}", path.display()))?;
    Ok((card.game, card.training.mode))
}

/// The policies and cards a run writes into its folder, which a resumed session replaces.
const RUN_POLICY_FILES: [&str; 5] = [
    "solver.yaml",
    "solver.safetensors",
    "generator.yaml",
    "generator.safetensors",
    super::BEST_CHECK_GENERATOR,
];

/// Refuses to resume from the checkpoint `checkpoint` of the run folder `out` when a policy or
/// card in the folder, or its Generator's checkpoint, is of another game, or of the same role
/// with another observation or other actions: the folder then holds files of two runs, and
/// resuming would replace the other run's policies. Files that do not read as policy cards are
/// left to the run that wrote them.
pub(super) fn check_folder_policies(
    out: &Path,
    checkpoint: &Path,
    generator_checkpoint: &Path,
) -> Result<()> {
    let read = |path: &Path| -> Option<PolicyCard> {
        let bytes = fsio::read_limited(path, checkpoint::MAX_POLICY_BYTES, "policy").ok()?;
        match path.extension().is_some_and(|e| e == "yaml") {
            true => serde_yaml::from_slice(&bytes).ok(),
            false => checkpoint::read_card(&bytes).ok(),
        }
    };
    let Some(run) = read(checkpoint) else {
        return Ok(()); // reading the checkpoint names what is wrong with it
    };
    let generator = read(generator_checkpoint);
    let others = RUN_POLICY_FILES.iter().map(|name| out.join(name));
    for path in std::iter::once(generator_checkpoint.to_path_buf()).chain(others) {
        let Some(card) = read(&path) else {
            continue;
        };
        let two_runs = "the folder holds files of two different runs, and resuming would \
                        replace its policies; resume a folder that one run wrote";
        if card.game != run.game {
            bail!(
                "{}: a {} {}, and {} is a {} run's: {two_runs}",
                path.display(),
                card.game,
                card.role,
                checkpoint.display(),
                run.game
            );
        }
        let same_role = match card.role {
            Role::Solver => Some(&run),
            Role::Generator => generator.as_ref().filter(|_| path != generator_checkpoint),
        };
        if let Some(own) = same_role.filter(|own| !same_layout(own, &card)) {
            bail!(
                "{}: a {} of {}, and the run's checkpoint plays {}: {two_runs}",
                path.display(),
                card.role,
                layout(&card),
                layout(own)
            );
        }
    }
    Ok(())
}

/// Whether two cards observe and act alike.
fn same_layout(a: &PolicyCard, b: &PolicyCard) -> bool {
    a.role == b.role
        && a.observation == b.observation
        && a.continuous_actions == b.continuous_actions
        && a.binary_actions == b.binary_actions
}

/// A card's observation size and actions, for a message.
fn layout(card: &PolicyCard) -> String {
    let size: usize = card.observation.iter().map(|(_, k)| k).sum();
    let actions: Vec<&str> = (card.continuous_actions.iter())
        .chain(&card.binary_actions)
        .map(String::as_str)
        .collect();
    format!("{size} observations and actions {}", actions.join(", "))
}

/// Reads a checkpoint of `role`, checking that it was trained in `mode`.
pub(super) fn read_checkpoint(
    path: &Path,
    game: Game,
    role: Role,
    mode: TrainMode,
) -> Result<(checkpoint::LoadedPolicy, TrainingState)> {
    let bytes =
        crate::services::fsio::read_limited(path, checkpoint::MAX_POLICY_BYTES, "checkpoint")
            .context("cannot resume")?;
    let observation = AgentIo::of(game, role).observation_size();
    let loaded = checkpoint::load_policy(&bytes, game, role, observation)
        .with_context(|| format!("{}", path.display()))?;
    let state = loaded
        .training_state()
        .with_context(|| format!("{}", path.display()))?;
    if loaded.card.training.mode != mode {
        bail!(
            "{} was trained with --mode {}, not {}",
            path.display(),
            loaded.card.training.mode,
            mode.name()
        );
    }
    Ok((loaded, state))
}
