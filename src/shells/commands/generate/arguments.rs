//! What `generate`'s arguments ask, before anything is made: the checks on them alone, the
//! request every level of the batch shares, and the levels' file names.

use std::sync::Arc;

use anyhow::Result;

use super::asking::{knob_suffix, want_suffix};
use crate::services::generation::{Ask, KeptPrefix, LevelRequest};
use crate::services::level_files::file_stem;
use crate::services::profile;
use crate::services::wish::{self, Reads};
use crate::shells::cli::{GenerateArgs, KeepArg};
use arlpcg_core::game::facts::facts;
use arlpcg_core::level::Game;

/// The checks on the arguments alone, before any file is read (exit 2 on a misfit); returns
/// the seeds of the levels to make (this shard's).
pub(super) fn check_arguments(args: &GenerateArgs) -> Result<Vec<u64>> {
    let usage = |message: &str| Err(crate::shells::common::UsageError(message.into()).into());
    let ask = args.ask();
    let success = ask.as_ref().and_then(Ask::success);
    if success.is_some() && args.policies.is_none() {
        return usage("--target-success needs --policies: a Generator that λ steers");
    }
    if args.obstacles > 0 && facts(args.game).max_obstacles == 0 {
        let with: Vec<&str> = Game::ALL
            .into_iter()
            .filter(|g| facts(*g).max_obstacles > 0)
            .map(Game::name)
            .collect();
        return usage(&format!(
            "--obstacles is for {} levels: {} levels have none",
            with.join(" or "),
            args.game
        ));
    }
    if ask.as_ref().and_then(Ask::curve).is_some() && args.policies.is_none() {
        return usage("--aux-curve needs --policies: the rules know no λ, a Generator follows it");
    }
    if args.keep.is_some() && args.obstacles > 0 {
        return usage(
            "--obstacles with --keep: the kept level's scene (start, goal, obstacles) stays",
        );
    }
    let wants = args.want.is_some() || args.want_file.is_some() || args.sentence.is_some();
    if args.policies.is_some() && ask.is_none() && !wants {
        return usage(
            "--policies needs --aux λ in [-1, 1] (+1 easy, -1 hard), --aux-curve CURVE, --target-success P or a wish list (--want, --want-file, --ask)",
        );
    }
    if let Some(want) = &args.want {
        want.fit_search(args.game)
            .map_err(crate::shells::common::UsageError)?;
    }
    wish::fit_checks(&args.checks, args.game).map_err(crate::shells::common::UsageError)?;
    if args.solver_policy.is_some() && args.verify.is_none() && success.is_none() {
        return usage("--solver-policy plays --verify N or --target-success P; give one of them");
    }
    if let Some(check) = args
        .checks
        .iter()
        .find(|c| c.attribute.reads() > Reads::Pieces)
        && args.verify.is_none()
        && success.is_none()
        && !wants
    {
        return usage(&format!(
            "--check {check} reads the levels' runs: give --verify N, --target-success P or a wish list"
        ));
    }
    if let Some(check) = args.checks.iter().find(|c| c.needs_panel())
        && !args.panel
    {
        return usage(&format!(
            "--check {check} reads the panel's runs: give --panel too"
        ));
    }
    if args.judge.is_some() && args.verify.is_none() && success.is_none() {
        return usage("--judge plays --verify N or --target-success P; give one of them");
    }
    if args.keep.is_some() && args.policies.is_none() {
        return usage("--keep needs --policies: a Generator continues the kept pieces");
    }
    if args.out.exists() && !args.out.is_dir() {
        anyhow::bail!("--out {} is not a folder", args.out.display());
    }
    (0..args.count as u64)
        .filter(|&i| args.shard.is_none_or(|shard| shard.owns(i)))
        .map(|i| args.seed.checked_add(i))
        .collect::<Option<_>>()
        .ok_or_else(|| {
            crate::shells::common::UsageError(format!(
                "--seed {} plus --count {} overflows a 64-bit seed",
                args.seed, args.count
            ))
            .into()
        })
}

/// The level `--keep` names, read and checked, and the pieces to keep of it.
fn kept_prefix(keep: &KeepArg, game: Game) -> Result<KeptPrefix> {
    let (level, from) = arlpcg_core::level::yaml::load_pinned(&keep.level)?;
    if level.game() != game {
        anyhow::bail!(
            "{}: a {} level, but this run generates {game} levels (--game {})",
            keep.level.display(),
            level.game(),
            level.game()
        );
    }
    if keep.pieces > level.piece_count() {
        anyhow::bail!(
            "{}: --keep asks for {} pieces, but the level has {}",
            keep.level.display(),
            keep.pieces,
            level.piece_count()
        );
    }
    Ok(KeptPrefix {
        level: Arc::new(level),
        pieces: keep.pieces,
        from,
    })
}

/// A level's file name: game, seed and λ, or the success rate asked for, or `curve` and a
/// short hash of the aux curve (its text is in the file); `_keepK` when K pieces were kept.
pub(super) fn stem(args: &GenerateArgs, seed: u64) -> String {
    let kept = match &args.keep {
        Some(keep) => format!("_keep{}", keep.pieces),
        None => String::new(),
    };
    stem_of_lambda(args, seed) + &knob_suffix(args) + &want_suffix(args) + &kept
}

fn stem_of_lambda(args: &GenerateArgs, seed: u64) -> String {
    match args.ask() {
        Some(Ask::Success(target)) => format!("{}_seed{seed}_success{target:.2}", args.game),
        Some(Ask::Curve(curve)) => {
            let hash = arlpcg_core::level::sha256_hex(curve.to_string().as_bytes());
            format!("{}_seed{seed}_curve-{}", args.game, &hash[..8])
        }
        Some(Ask::Aux(aux)) => file_stem(args.game, seed, Some(aux)),
        None => file_stem(args.game, seed, None),
    }
}

/// What every level of the batch asks, bar its seed and draw: goal, obstacles, λ or curve, the
/// kept prefix and the profile.
pub(super) fn template(args: &GenerateArgs) -> Result<LevelRequest> {
    let profile = match &args.profile {
        Some(file) => Some(profile::for_game(profile::load(file)?, args.game, file)?),
        None => None,
    };
    let mut template = LevelRequest::new(0, None)
        .goal(args.goal)
        .obstacles(args.obstacles)
        .profile(profile);
    if let Some(aux) = args.ask().as_ref().and_then(Ask::aux) {
        template = template.aux(aux);
    }
    if let Some(keep) = &args.keep {
        template = template.keep(kept_prefix(keep, args.game)?);
    }
    Ok(template)
}
