//! `arlpcg generate`: levels from a trained Generator or from the rules, optionally verified by
//! the Solver, written as files named after game, seed and aux.

use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use anyhow::{Context, Result};
use rayon::prelude::*;

use crate::services::difficulty;
use crate::services::fsio;
use crate::services::generation::{Ask, GeneratorPolicy, LevelRequest};
use crate::services::level_files::{Format, LevelFiles, render};
use crate::services::making::{self, LevelSource, Proof, Redraw};
use crate::services::panel::{Judge, JudgePanel};
use crate::services::policies::{
    SOLVER_FILE, load_generator, load_judge, load_judges_under, load_panel, load_solver,
    policy_paths,
};
use crate::services::verify::{self, Solver, SolverPolicy};
use crate::services::wish::{self, Evidence, Reads, Want};
use crate::shells::cli::{GenerateArgs, default_solver};
use crate::shells::common::shipped_dir;
use arlpcg_core::game::Skill;
use arlpcg_core::level::Level;
use arlpcg_core::level::profile::Profile;

mod arguments;
mod asking;
use arguments::{check_arguments, stem, template};
use asking::{knob_values, wanted};

pub fn run(args: &GenerateArgs) -> Result<()> {
    let seeds = check_arguments(args)?;
    let want = wanted(args)?;
    let template = template(args)?;
    let ask = args.ask();
    let reads_runs = want.as_ref().is_some_and(|w| w.reads() > Reads::Pieces);
    let verify_trials = args
        .verify
        .or(ask.as_ref().and_then(Ask::success).map(|_| TARGET_TRIALS))
        .or(reads_runs.then_some(WANT_TRIALS));
    let generator = match &args.policies {
        Some(dir) => Some(load_generator(&policy_paths(dir).0, args.game)?.0),
        None => None,
    };
    let template = template.knobs(knob_values(args, generator.as_ref())?);
    let solver = chosen_solver(args, verify_trials, template.profile.as_ref())?;
    if let Some(policy) = &solver {
        crate::shells::common::check_fit(policy, template.profile.as_ref())?;
    }
    let panel = panel_of(args, template.profile.as_ref())?;
    let formats: Vec<Format> = args.format.iter().map(|&f| f.into()).collect();
    let plans: Vec<(u64, LevelFiles)> = seeds
        .iter()
        .map(|&seed| {
            (
                seed,
                LevelFiles::new(&args.out, &stem(args, seed), &formats).with_gltf(args.gltf.into()),
            )
        })
        .collect();
    // Ctrl-C stops generating; the levels finished so far are still written.
    let stop = Arc::new(AtomicBool::new(false));
    {
        let stop = stop.clone();
        let _ = ctrlc::set_handler(move || stop.store(true, Ordering::SeqCst));
    }
    // Every level is built (and verified) before the first file is written: a level that
    // cannot be built leaves the folder as it was, and --force replaces nothing. Several
    // levels are in flight at once; each depends only on its seed, so the files do not depend
    // on the number of threads.
    let skill = match args.judge {
        Some(Judge::Scripted(skill)) => skill,
        _ => Skill::Expert,
    };
    let who = solver
        .as_ref()
        .map_or(Solver::Scripted(skill), Solver::Policy);
    let curve = target_curve(
        args,
        generator.as_ref(),
        &who,
        template.profile.as_ref(),
        &stop,
    )?;
    let judges = match &want {
        Some(want) => load_judges_under(|| policies_dir(args), args.game, &want.judges())?,
        None => Vec::new(),
    };
    let players: Vec<(Judge, Solver)> = judges
        .iter()
        .map(|(judge, policy)| (*judge, judge.player(policy.as_ref())))
        .collect();
    let mut levels = build_levels(
        args,
        &plans,
        &template,
        generator.as_ref(),
        &who,
        curve.as_ref(),
        verify_trials,
        want.as_ref().map(|w| (w, players.as_slice())),
        &stop,
    )?;
    if let Some(panel) = &panel {
        let trials = verify_trials.unwrap_or(TARGET_TRIALS);
        play_panel(panel, &mut levels, trials, &stop);
    }
    // The folder is made only now, and removed again if the batch fails.
    let made_folder = !args.out.exists();
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("cannot create {}", args.out.display()))?;
    let written = write_batch(args, &levels, &plans);
    if written.is_err() && made_folder {
        let _ = std::fs::remove_dir(&args.out); // only if empty
    }
    let (staged, kept) = written?;
    let files = staged + kept;
    let unchanged = match kept {
        0 => String::new(),
        k => format!(", {k} of them already there and identical"),
    };
    if levels.len() < plans.len() {
        return Err(crate::shells::common::Interrupted(format!(
            "interrupted (Ctrl-C): wrote the {} of {} levels finished before it ({files} files{unchanged}) to {}; run the same command again to finish",
            levels.len(),
            plans.len(),
            args.out.display()
        ))
        .into());
    }
    let share = match args.shard {
        Some(shard) => format!(" (shard {}/{} of {})", shard.index, shard.count, args.count),
        None => String::new(),
    };
    crate::say!(
        "wrote {} levels{share} ({files} files{unchanged}) to {}",
        plans.len(),
        args.out.display()
    );
    report_verification(
        &levels,
        args.ask().as_ref().and_then(|ask| match ask {
            Ask::Aux(aux) => Some(*aux),
            _ => None,
        }),
    );
    apply_checks(args, &levels, &plans)
}

/// `--check` on the batch's levels: exit code 3, naming each level and check, on a failure.
fn apply_checks(args: &GenerateArgs, levels: &[Level], plans: &[(u64, LevelFiles)]) -> Result<()> {
    let named = levels.iter().zip(plans).map(|(level, (seed, _))| {
        (
            format!("{} (seed {seed})", stem(args, *seed)),
            level,
            Evidence::of(level),
        )
    });
    let failed = wish::failures(&args.checks, named);
    super::campaign::report_checks(&args.checks, failed, levels.len(), false)
}

/// The panel's runs on every level, rated together, with a progress bar; Ctrl-C in `stop`
/// cuts them short.
fn play_panel(panel: &JudgePanel, levels: &mut Vec<Level>, trials: u32, stop: &AtomicBool) {
    let runs = (levels.len() * panel.judges.len()) as u64 * trials as u64;
    let bar = crate::shells::common::progress_bar(runs, "panel runs");
    let watch = verify::Watch {
        on_trial: &|_| bar.inc(1),
        stop: &|| stop.load(Ordering::SeqCst),
    };
    crate::services::panel::play_and_rate(panel, levels, trials, &watch);
    bar.finish_and_clear();
}

/// What verification did across the batch: redrawn, unsolved and uncertified levels.
/// What the batch's runs measured, a line per player: the Solver's (or verifying judge's) mean
/// success over the levels and their range, how many levels were built at a λ other than the
/// one asked for (`asked`), and each judge's mean with --panel.
fn report_verification(levels: &[Level], asked: Option<f64>) {
    let stats: Vec<_> = levels.iter().filter_map(|l| l.stats.as_ref()).collect();
    if let Some(summary) = mean_and_range(stats.iter().map(|s| s.success_ratio)) {
        let eased = asked.map_or(0, |asked| {
            levels
                .iter()
                .filter(|l| l.aux.is_some_and(|aux| (aux - asked).abs() > 1e-9))
                .count()
        });
        let eased = match eased {
            0 => String::new(),
            n => format!("; {n} of them built at an eased λ"),
        };
        crate::say!(
            "success of the runs that verified: {summary} over {} levels{eased}",
            stats.len()
        );
    }
    let panels: Vec<_> = stats.iter().filter_map(|s| s.panel.as_ref()).collect();
    if let Some(first) = panels.first() {
        let judges: Vec<String> = first
            .judges
            .iter()
            .enumerate()
            .filter_map(|(k, judge)| {
                let ratios = panels.iter().filter_map(|p| p.judges.get(k));
                Some(format!(
                    "{} {}",
                    judge.judge,
                    mean_and_range(ratios.map(|j| j.success_ratio))?
                ))
            })
            .collect();
        crate::say!("panel, each judge's success: {}", judges.join(", "));
    }
    let redrawn: Vec<u32> = stats.iter().map(|s| s.redraws).filter(|&r| r > 0).collect();
    if !redrawn.is_empty() {
        crate::say!(
            "redrew {} levels that no run completed ({} draws replaced)",
            redrawn.len(),
            redrawn.iter().sum::<u32>()
        );
    }
    let unsolved = stats.iter().filter(|s| s.successes == 0).count();
    if unsolved > 0 {
        crate::say!("kept {unsolved} levels that no run completed (--allow-unsolved)");
    }
    let uncertified = stats
        .iter()
        .filter(|s| s.successes > 0 && s.certificate.is_none())
        .count();
    if uncertified > 0 {
        crate::say!(
            "{uncertified} levels have no certificate: no single run succeeded within the search (their success ratio is tiny)"
        );
    }
}

/// "mean (lowest-highest)" of `ratios`, none when there are none.
fn mean_and_range(ratios: impl Iterator<Item = f64>) -> Option<String> {
    let ratios: Vec<f64> = ratios.collect();
    let (lowest, highest) = ratios
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &r| {
            (lo.min(r), hi.max(r))
        });
    let mean = ratios.iter().sum::<f64>() / ratios.len().max(1) as f64;
    (!ratios.is_empty()).then(|| format!("{mean:.3} ({lowest:.2}-{highest:.2})"))
}

/// With `--panel`, the panel of judges, having said which of its Solvers never trained with
/// `profile`'s abilities.
fn panel_of(args: &GenerateArgs, profile: Option<&Profile>) -> Result<Option<JudgePanel>> {
    if !args.panel {
        return Ok(None);
    }
    let panel = load_panel(&policies_dir(args)?, args.game, None)?;
    crate::shells::common::check_panel_fit(&panel, profile);
    Ok(Some(panel))
}

/// The folder the judges come from: --policies, else the shipped policies of the game.
fn policies_dir(args: &GenerateArgs) -> Result<PathBuf> {
    match &args.policies {
        Some(dir) => Ok(dir.clone()),
        None => shipped_dir(args.game),
    }
}

/// With `--target-success`: the policies' λ→success curve on levels made for `profile`, read
/// from beside them or measured once (Ctrl-C in `stop` ends the measurement: exit 130, nothing
/// written).
fn target_curve(
    args: &GenerateArgs,
    generator: Option<&GeneratorPolicy>,
    solver: &Solver,
    profile: Option<&Profile>,
    stop: &AtomicBool,
) -> Result<Option<difficulty::Curve>> {
    let (Some(Ask::Success(target)), Some(generator), Some(dir)) =
        (args.ask(), generator, &args.policies)
    else {
        return Ok(None);
    };
    let announce = || {
        crate::warn!(
            "measuring the policies' λ→success curve ({} λ values × {} levels × {} runs), once",
            difficulty::CURVE_AUX.len(),
            difficulty::CURVE_LEVELS,
            difficulty::CURVE_TRIALS
        )
    };
    let cache = crate::shells::common::cache_dir();
    crate::services::policies::difficulty_curve(
        (dir, cache.as_deref()),
        generator,
        solver,
        profile,
        announce,
        &|| stop.load(Ordering::SeqCst),
    )
    .inspect(|curve| {
        if let Some(span) = curve.beyond(target) {
            crate::warn!(
                "success {target} lies beyond the span of this pair's λ→success curve for that judge ({span}): seeds whose levels cannot reach it fail the batch; a weaker judge (--judge scripted-median) spans more"
            );
        }
    })
    .map(Some)
    .map_err(|e| match e.downcast_ref::<difficulty::TargetError>() {
        Some(difficulty::TargetError::Stopped) => crate::shells::common::Interrupted(
            "interrupted (Ctrl-C) while the λ→success curve was measured; nothing was written"
                .into(),
        )
        .into(),
        _ => e,
    })
}

/// Writes the files of `levels`, all or none ([`fsio::write_batch`]); files of other contents
/// are replaced only with --force. Returns (files written, files left as they were).
fn write_batch(
    args: &GenerateArgs,
    levels: &[Level],
    plans: &[(u64, LevelFiles)],
) -> Result<(usize, usize)> {
    // A .gltf after the .bin it names.
    let files = levels
        .iter()
        .zip(plans)
        .flat_map(|(level, (_, files))| render(level, files).into_iter().rev());
    fsio::write_batch(
        &args.out,
        files,
        &|_| args.force,
        "use --force to overwrite it",
        || {
            crate::warn!(
                "waiting for another arlpcg run that is writing into {}",
                args.out.display()
            )
        },
    )
}

/// Runs per candidate of `--target-success` without `--verify`.
const TARGET_TRIALS: u32 = 100;

/// Runs per played candidate of a wish list that reads runs, without `--verify`.
const WANT_TRIALS: u32 = 20;

/// The Solver that plays `--verify` and `--target-success`: the judge asked for, the file asked
/// for, the one beside the Generator, or the shipped one; none for the scripted player (the
/// expert where a folder's Solver cannot play `profile`'s character) or when nothing is verified.
fn chosen_solver(
    args: &GenerateArgs,
    verify_trials: Option<u32>,
    profile: Option<&Profile>,
) -> Result<Option<SolverPolicy>> {
    let shipped = default_solver(args.game);
    Ok(match (verify_trials, args.judge, &args.solver_policy) {
        (None, _, _) => None,
        // A Solver judge's policy; none for the scripted player.
        (Some(_), Some(judge), _) => {
            load_judge(&policies_dir(args)?, args.game, judge)?.map(|(policy, _)| policy)
        }
        (Some(_), None, Some(path)) => Some(load_solver(path, args.game)?.0),
        (Some(_), None, None) => {
            let folder = match (&args.policies, &shipped) {
                (Some(dir), _) => dir.as_path(),
                (None, Ok(solver)) if solver.exists() => solver
                    .parent()
                    .expect("the Solver file of a policies folder"),
                (None, Err(e)) => {
                    crate::warn!("{e:#}: the scripted expert verifies");
                    return Ok(None);
                }
                (None, Ok(solver)) => {
                    crate::warn!(
                        "{}: no such Solver policy: the scripted expert verifies",
                        solver.display()
                    );
                    return Ok(None);
                }
            };
            let policy = load_solver(&folder.join(SOLVER_FILE), args.game)?.0;
            // A folder's Solver that cannot play the character gives way to the scripted expert.
            match policy.stand_in(profile) {
                None => Some(policy),
                Some((_, why)) => {
                    crate::warn!("{why}");
                    None
                }
            }
        }
    })
}

/// Builds (and verifies) the level of every plan, several at once ([`making::verified_level`]);
/// after a Ctrl-C, the levels finished before it, a prefix of the batch, so that a re-run
/// resumes it.
#[allow(clippy::too_many_arguments)]
fn build_levels(
    args: &GenerateArgs,
    plans: &[(u64, LevelFiles)],
    template: &LevelRequest,
    generator: Option<&GeneratorPolicy>,
    who: &Solver,
    curve: Option<&difficulty::Curve>,
    verify_trials: Option<u32>,
    want: Option<(&Want, &[(Judge, Solver)])>,
    stop: &AtomicBool,
) -> Result<Vec<Level>> {
    let source = generator.map_or(LevelSource::Rules(args.game), LevelSource::Generator);
    let target = args.ask().as_ref().and_then(Ask::success);
    let proof = match (want, target, curve, verify_trials) {
        (Some((want, judges)), ..) => Proof::Wanted(making::wanted::Search {
            want,
            solver: verify_trials.map(|_| who),
            judges,
            trials: verify_trials.unwrap_or(WANT_TRIALS),
        }),
        (None, Some(target), Some(curve), _) => Proof::Target {
            solver: who,
            curve,
            target,
            trials: verify_trials.unwrap_or(TARGET_TRIALS),
            checks: &args.checks,
        },
        (None, _, _, Some(trials)) if args.verify.is_some() => Proof::Played {
            solver: who,
            trials,
            redraw: Redraw {
                keep_unsolved: args.allow_unsolved,
                ..Redraw::default()
            },
        },
        _ => Proof::Unplayed,
    };
    // Ctrl-C abandons the trials under way within a tick: the level is not finished.
    let watch = verify::Watch {
        on_trial: &|_| {},
        stop: &|| stop.load(Ordering::SeqCst),
    };
    // A seed whose level cannot be built at any λ fails the batch before any level is played:
    // each seed's first draw is built, unplayed, first (milliseconds beside the runs); a seed
    // the Generator builds only at a lower λ is eased when it is played.
    if let Proof::Played { redraw, .. } = proof {
        plans.par_iter().try_for_each(|(seed, _)| {
            let request = LevelRequest {
                seed: *seed,
                ..template.clone()
            };
            making::buildable(source, &request, redraw.ease_step)
                .map(drop)
                .with_context(|| format!("seed {seed} (nothing was played or written)"))
        })?;
    }
    // The first seed that fails ends the batch: the seeds not yet started are not played.
    let failed = AtomicBool::new(false);
    let bar = crate::shells::common::progress_bar(plans.len() as u64, "generating");
    let mut built: Vec<Option<Result<Level>>> = plans
        .par_iter()
        .map(|(seed, _)| {
            if stop.load(Ordering::SeqCst) || failed.load(Ordering::SeqCst) {
                return None;
            }
            // A success target searches its own draws, λ and (without a goal) seeds.
            let request = match proof {
                Proof::Target { .. } => LevelRequest::new(*seed, None)
                    .goal(args.goal)
                    .profile(template.profile.clone())
                    .knobs(template.knobs.clone()),
                _ => LevelRequest {
                    seed: *seed,
                    ..template.clone()
                },
            };
            let level = making::verified_level(source, &request, &proof, &watch, &|eased| {
                crate::warn!("{eased}")
            });
            bar.inc(1);
            if level.is_err() {
                failed.store(true, Ordering::SeqCst);
            }
            level
                .with_context(|| format!("seed {seed} (nothing was written)"))
                .transpose()
        })
        .collect();
    bar.finish_and_clear();
    let first_error = built.iter_mut().find_map(|level| match level {
        Some(Err(_)) => level.take()?.err(),
        _ => None,
    });
    if let Some(error) = first_error {
        return Err(error);
    }
    // The levels finished before a Ctrl-C: a prefix of the batch, so that a re-run resumes it.
    let mut levels = Vec::with_capacity(plans.len());
    for level in built {
        match level {
            Some(level) => levels.push(level?),
            None => break,
        }
    }
    Ok(levels)
}
