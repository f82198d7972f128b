//! Loading trained policies from files: each pinned by the SHA-256 of its bytes (levels record
//! it), checked for game, role and shape, with errors that name the file.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};

use crate::services::generation::GeneratorPolicy;
use crate::services::panel::{Judge, JudgePanel};
use crate::services::verify::SolverPolicy;
use arlpcg_core::game::facts::facts;
use arlpcg_core::game::generator::DEFAULT_CURVE_OFFSET;
use arlpcg_core::game::generator::{BuildLimits, GeneratorGame, observation_size};
use arlpcg_core::game::{GameSpec, SolverEnv};
use arlpcg_core::level::profile::{ABILITIES_PART, Abilities, AbilityRanges, Profile};
use arlpcg_core::level::{Game, PolicyRef};
use arlpcg_core::rl::checkpoint::TrainMode;
use arlpcg_core::rl::checkpoint::{
    LoadedPolicy, MAX_POLICY_BYTES, PolicyCard, Role, load_policy, read_card,
};
use arlpcg_core::rl::policy::ActorCritic;

/// File names inside a policies folder.
pub const GENERATOR_FILE: &str = "generator.safetensors";
/// The Solver's file name inside a policies folder.
pub const SOLVER_FILE: &str = "solver.safetensors";

/// What a policy of one game and role must act with: `(continuous, binary)` action names.
type Actions = (&'static [&'static str], &'static [&'static str]);

fn load_pinned(
    path: &Path,
    (game, role): (Game, Role),
    observation: usize,
    (continuous, binary): Actions,
) -> Result<(LoadedPolicy, PolicyRef)> {
    let bytes =
        crate::services::fsio::read_limited(path, MAX_POLICY_BYTES, &format!("{role} policy"))?;
    let loaded = load_policy(&bytes, game, role, observation)
        .with_context(|| format!("{}", path.display()))?;
    let network = &loaded.card.network;
    if (network.continuous, network.binary) != (continuous.len(), binary.len()) {
        anyhow::bail!(
            "{}: card field network has {} continuous and {} binary actions, but the {game} {role} acts with {} ({}) and {} ({})",
            path.display(),
            network.continuous,
            network.binary,
            continuous.len(),
            continuous.join(", "),
            binary.len(),
            binary.join(", ")
        );
    }
    Ok((
        loaded,
        PolicyRef::pinned(path.display().to_string(), &bytes),
    ))
}

/// Loads a Solver policy of `game`.
pub fn load_solver(path: &Path, game: Game) -> Result<(SolverPolicy, PolicyCard)> {
    let (observation, actions): (usize, Actions) = arlpcg_core::for_game!(game, G => (
        <G as GameSpec>::Env::OBSERVATION_SIZE,
        (G::CONTINUOUS_ACTIONS, G::BINARY_ACTIONS),
    ));
    let (loaded, reference) = load_pinned(path, (game, Role::Solver), observation, actions)?;
    let card = loaded.card.clone();
    let profile = card
        .profile
        .as_ref()
        .map(|record| record.profile(game))
        .transpose()
        .map_err(|problem| anyhow::anyhow!("{}: card field profile.{problem}", path.display()))?;
    let reads_abilities = card
        .observation
        .last()
        .is_some_and(|(name, _)| name == ABILITIES_PART);
    // A card from before ranges gives only its share, around its profile's abilities.
    let trained_over = AbilityRanges::given(
        card.ability_ranges.as_ref(),
        card.ability_spread,
        &Abilities::of(profile.as_ref(), game),
    )
    .map_err(|problem| anyhow::anyhow!("{}: card field {problem}", path.display()))?;
    if reads_abilities != trained_over.is_some() {
        anyhow::bail!(
            "{}: card field ability_ranges (or ability_spread) must be given exactly when the observation ends with `{ABILITIES_PART}`",
            path.display()
        );
    }
    Ok((
        SolverPolicy {
            game,
            policy: loaded.policy,
            normalizer: loaded.card.normalizer,
            reference,
            profile,
            trained_over,
        },
        card,
    ))
}

/// Loads a Generator policy of `game`.
pub fn load_generator(path: &Path, game: Game) -> Result<(GeneratorPolicy, PolicyCard)> {
    let (observation, actions) =
        arlpcg_core::for_game!(game, G => (observation_size::<G>(), G::GENERATOR_ACTIONS));
    let (loaded, reference) =
        load_pinned(path, (game, Role::Generator), observation, (actions, &[]))?;
    let card = loaded.card.clone();
    let limits = generator_limits(path, &card)?;
    let knobs = arlpcg_core::rl::checkpoint::knob_part(&card);
    let game_knobs = arlpcg_core::for_game!(game, G => G::KNOBS.len());
    if knobs != 0 && knobs != game_knobs {
        anyhow::bail!(
            "{}: card field observation has {knobs} knobs, but the {game} Generator takes {game_knobs} (or none)",
            path.display()
        );
    }
    Ok((
        GeneratorPolicy {
            game,
            policy: loaded.policy,
            limits,
            knobs,
            normalizer: loaded.card.normalizer,
            reference,
        },
        card,
    ))
}

/// The piece budget, curve offset and reach a Generator's card (of the file at `path`) records,
/// each checked against its game's range, or the game's defaults where the card has none.
pub fn generator_limits(path: &Path, card: &PolicyCard) -> Result<BuildLimits> {
    let (default_max_pieces, most_pieces) =
        arlpcg_core::for_game!(card.game, G => (G::DEFAULT_MAX_PIECES, G::MAX_PIECES));
    let limits = BuildLimits {
        max_pieces: card.max_pieces.unwrap_or(default_max_pieces),
        curve_offset: card.curve_offset.unwrap_or(DEFAULT_CURVE_OFFSET),
        player: Default::default(),
        reach_runs: card.reach_runs,
    };
    if let Some(runs) = limits.reach_runs {
        match facts(card.game).reach_runs {
            None => anyhow::bail!(
                "{}: card field reach_runs is given, but the {} Generator's pieces are not cut \
                 to a reach",
                path.display(),
                card.game
            ),
            Some(most) if !(1..=most).contains(&runs) => anyhow::bail!(
                "{}: card field reach_runs is {runs}, outside [1, {most}]",
                path.display()
            ),
            Some(_) => {}
        }
    }
    if !(1..=most_pieces).contains(&limits.max_pieces) {
        anyhow::bail!(
            "{}: card field max_pieces is {}, outside [1, {most_pieces}]",
            path.display(),
            limits.max_pieces
        );
    }
    if !(0.0..=180.0).contains(&limits.curve_offset) {
        anyhow::bail!(
            "{}: card field curve_offset is {}, not a number of degrees in [0, 180]",
            path.display(),
            limits.curve_offset
        );
    }
    Ok(limits)
}

/// The file beside a policies folder's Generator that holds its λ→success curve with the
/// Solver beside it.
pub const CURVE_FILE: &str = "difficulty-curve.yaml";

/// Where the λ→success curve of the Generator in `dir` with the Solver at `solver_path` is kept:
/// [`CURVE_FILE`] for the folder's own Solver, else a file named after the other Solver and its
/// SHA-256, so that measuring with another Solver never replaces the folder's own curve.
pub fn curve_path(dir: &Path, solver_path: &Path, solver_sha256: &str) -> PathBuf {
    let own = dir.join(SOLVER_FILE);
    let same = match (own.canonicalize(), solver_path.canonicalize()) {
        (Ok(own), Ok(solver)) => own == solver,
        _ => own == solver_path,
    };
    if same {
        return dir.join(CURVE_FILE);
    }
    let stem = solver_path
        .file_stem()
        .and_then(|s| s.to_str())
        .filter(|s| {
            s.chars()
                .all(|c| c.is_ascii_alphanumeric() || c == '-' || c == '_')
        })
        .unwrap_or("solver");
    let short = solver_sha256.get(..12).unwrap_or(solver_sha256);
    dir.join(format!("difficulty-curve-{stem}-{short}.yaml"))
}

/// The policy in `path`, whichever game and role its card names, loaded and checked as that
/// game's Solver or Generator: its network, card and pinned reference.
pub fn load_any(path: &Path) -> Result<(ActorCritic, PolicyCard, PolicyRef)> {
    let bytes = crate::services::fsio::read_limited(path, MAX_POLICY_BYTES, "policy")?;
    let card = read_card(&bytes).with_context(|| format!("{}", path.display()))?;
    Ok(match card.role {
        Role::Solver => {
            let (solver, card) = load_solver(path, card.game)?;
            (solver.policy, card, solver.reference)
        }
        Role::Generator => {
            let (generator, card) = load_generator(path, card.game)?;
            (generator.policy, card, generator.reference)
        }
    })
}

/// The λ→success curve of `generator` with `solver` on levels made for `profile` (none, or the
/// default: the built-in game): read from the policies folder `dir` (see [`curve_path`]; the
/// shipped curves) or from the cache folder `cache` when it was measured with these two
/// policies and this profile (by SHA-256), else measured (`on_measure` is told first: it takes
/// a while; `stopped` can end it) and kept in `cache` ([`cached_curve_path`]). Nothing is
/// written into `dir`: it is an input, perhaps read-only or under version control.
pub fn difficulty_curve(
    (dir, cache): (&Path, Option<&Path>),
    generator: &GeneratorPolicy,
    solver: &crate::services::verify::Solver,
    profile: Option<&Profile>,
    on_measure: impl FnOnce(),
    stopped: &dyn Fn() -> bool,
) -> Result<crate::services::difficulty::Curve> {
    use crate::services::verify::Solver;
    // A Solver is known by its SHA-256; the scripted player (no file) by its judge name.
    let (path, identity) = match solver {
        Solver::Policy(p) => (
            curve_path(dir, Path::new(&p.reference.path), &p.reference.sha256),
            p.reference.sha256.clone(),
        ),
        Solver::Scripted(skill) => {
            let name = Judge::Scripted(*skill).name();
            (dir.join(format!("difficulty-curve-{name}.yaml")), name)
        }
        Solver::Random => anyhow::bail!("random actions have no difficulty curve to aim with"),
    };
    let profile = profile.filter(|p| !p.is_default());
    let profile_sha256 = profile.map(Profile::sha256);
    // Another profile's curve is kept beside the built-in game's, as
    // `….profile-<its SHA-256's first 12 digits>.yaml`.
    let path = match &profile_sha256 {
        Some(sha) => path.with_extension(format!("profile-{}.yaml", &sha[..12])),
        None => path,
    };
    let current = |c: &crate::services::difficulty::Curve| {
        c.generator_sha256 == generator.reference.sha256
            && c.solver_sha256 == identity
            && c.profile_sha256 == profile_sha256
    };
    let cached = cache.map(|cache| {
        cached_curve_path(
            cache,
            &generator.reference.sha256,
            &identity,
            profile_sha256.as_deref(),
        )
    });
    for path in std::iter::once(&path).chain(&cached) {
        if let Ok(bytes) = crate::services::fsio::read_limited(path, 1 << 20, "difficulty curve")
            && let Ok(curve) = serde_yaml::from_slice::<crate::services::difficulty::Curve>(&bytes)
            && current(&curve)
        {
            // The curve of these very policies, damaged: say so rather than aim with it.
            curve.check().map_err(|problem| {
                anyhow::anyhow!(
                    "{}: {problem} (delete the file and it is measured again)",
                    path.display()
                )
            })?;
            return Ok(curve);
        }
    }
    on_measure();
    let curve =
        crate::services::difficulty::measure(generator, solver, &identity, profile, stopped)?;
    // A cache that cannot be written only costs a new measurement next time.
    if let Some(cached) = &cached
        && let Some(folder) = cached.parent()
        && std::fs::create_dir_all(folder).is_ok()
    {
        let _ = crate::services::fsio::write_atomic(
            cached,
            serde_yaml::to_string(&curve)?.as_bytes(),
            crate::services::fsio::Overwrite::Allowed,
        );
    }
    Ok(curve)
}

/// Where the cache folder `cache` keeps a measured λ→success curve: `curves/` and a name made
/// of the Generator's SHA-256, the Solver's (or the scripted player's judge name) and the
/// profile's, each cut to 12 digits, so that policies of the same file names in other folders
/// never share a curve.
pub fn cached_curve_path(
    cache: &Path,
    generator_sha256: &str,
    solver: &str,
    profile_sha256: Option<&str>,
) -> PathBuf {
    // A SHA-256 is cut to 12 hex digits; a judge name is kept whole.
    let short = |id: &str| match id.len() {
        64 => id[..12].to_string(),
        _ => id.to_string(),
    };
    let profile = profile_sha256.map_or(String::new(), |sha| format!("-profile-{}", short(sha)));
    cache.join("curves").join(format!(
        "difficulty-curve-{}-{}{profile}.yaml",
        short(generator_sha256),
        short(solver)
    ))
}

/// The Solver file of `judge` in a policies folder (`solver.safetensors` is the ARLPCG
/// Solver, `solver-<mode>.safetensors` the others); `None` for the scripted player.
pub fn judge_file(dir: &Path, judge: Judge) -> Option<PathBuf> {
    match judge {
        Judge::Solver(TrainMode::Arlpcg) => Some(dir.join(SOLVER_FILE)),
        Judge::Solver(mode) => Some(dir.join(format!("solver-{}.safetensors", mode.name()))),
        Judge::Scripted(_) => None,
    }
}

/// The panel of judges `chosen` from the policies folder `dir` (by default every Solver judge
/// whose file is there, and the scripted player at its three skills). A chosen Solver judge
/// whose file is missing is an error naming it.
pub fn load_panel(dir: &Path, game: Game, chosen: Option<&[Judge]>) -> Result<JudgePanel> {
    if !dir.is_dir() {
        anyhow::bail!(
            "{}: no such policies folder (the panel's Solvers are read from it)",
            dir.display()
        );
    }
    let judges: Vec<Judge> = match chosen {
        Some(chosen) => chosen.to_vec(),
        None => Judge::ALL
            .into_iter()
            .filter(|&j| judge_file(dir, j).is_none_or(|p| p.exists()))
            .collect(),
    };
    let mut panel = JudgePanel { judges: Vec::new() };
    for judge in judges {
        let policy = load_judge(dir, game, judge)?.map(|(policy, _)| policy);
        panel.judges.push((judge, policy));
    }
    Ok(panel)
}

/// The Solver of `judge` in the policies folder `dir`, checked to be trained in the judge's
/// mode; `None` for the scripted player.
pub fn load_judge(
    dir: &Path,
    game: Game,
    judge: Judge,
) -> Result<Option<(SolverPolicy, PolicyCard)>> {
    let Some(path) = judge_file(dir, judge) else {
        return Ok(None);
    };
    let (policy, card) =
        load_solver(&path, game).with_context(|| format!("judge {}", judge.name()))?;
    if Judge::Solver(card.training.mode) != judge {
        anyhow::bail!(
            "judge {}: {} was trained in mode {}, not {}",
            judge.name(),
            path.display(),
            card.training.mode,
            judge.name()
        );
    }
    Ok(Some((policy, card)))
}

/// Each of `judges` with its Solver policy ([`load_judge`]: none for the scripted player, whose
/// folder is never read).
pub fn load_judges_under(
    dir: impl Fn() -> Result<PathBuf>,
    game: Game,
    judges: &[Judge],
) -> Result<Vec<(Judge, Option<SolverPolicy>)>> {
    judges
        .iter()
        .map(|&judge| match judge {
            Judge::Scripted(_) => Ok((judge, None)),
            Judge::Solver(_) => Ok((
                judge,
                load_judge(&dir()?, game, judge)?.map(|(policy, _)| policy),
            )),
        })
        .collect()
}

/// The paths of the Generator and the Solver in a policies folder.
pub fn policy_paths(dir: &Path) -> (PathBuf, PathBuf) {
    (dir.join(GENERATOR_FILE), dir.join(SOLVER_FILE))
}

#[cfg(test)]
mod tests;
