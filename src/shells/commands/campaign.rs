//! `arlpcg campaign`: levels on a difficulty ramp, searched and verified, rated by the panel,
//! with a player population through them; and `verify --campaign`, which plays an existing
//! campaign again. The record and its report are [`crate::services::campaign`]'s.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use anyhow::{Context, Result};
use rayon::prelude::*;

use crate::services::campaign::{
    Campaign, CampaignAsk, CampaignLevel, PopulationAsk, REDRAWS, campaign_files, level_stem, rate,
    rate_and_mend, search_level,
};
use crate::services::difficulty;
use crate::services::fsio;
use crate::services::generation::GeneratorPolicy;
use crate::services::level_files::{Format, LevelFiles, render};
use crate::services::panel::Judge;
use crate::services::policies::{difficulty_curve, load_generator, load_panel, policy_paths};
use crate::services::profile;
use crate::services::verify::{self, Solver, Watch};
use crate::services::wish::{Constraint, Evidence, failures};
use crate::shells::cli::{CampaignArgs, VerifyArgs};
use crate::shells::common::{
    ChecksFailed, Interrupted, check_panel_fit, progress_bar, shipped_dir,
};
use arlpcg_core::level::profile::Profile;
use arlpcg_core::level::{Level, yaml};
use arlpcg_core::rl::checkpoint::TrainMode;
use arlpcg_core::statistics::population::Population;

pub fn run(args: &CampaignArgs) -> Result<()> {
    // Ctrl-C from the start stops the campaign at its next safe point: the levels finished
    // are written for --resume.
    let stop = Arc::new(AtomicBool::new(false));
    {
        let stop = stop.clone();
        let _ = ctrlc::set_handler(move || stop.store(true, Ordering::SeqCst));
    }
    if args.out.exists() && !args.out.is_dir() {
        anyhow::bail!("--out {} is not a folder", args.out.display());
    }
    crate::services::wish::fit_checks(&args.checks, args.game)
        .map_err(crate::shells::common::UsageError)?;
    let formats: Vec<Format> = args.format.iter().map(|&f| f.into()).collect();
    if !formats.contains(&Format::Yaml) {
        return Err(crate::shells::common::UsageError(
            "--format must include yaml: the campaign's record names its level files".into(),
        )
        .into());
    }
    let dir = match &args.policies {
        Some(dir) => dir.clone(),
        None => shipped_dir(args.game)?,
    };
    let profile = match &args.profile {
        Some(file) => Some(profile::for_game(profile::load(file)?, args.game, file)?),
        None => None,
    };
    let judge = campaign_judge(args, &dir, profile.as_ref())?;
    let ask = CampaignAsk {
        game: args.game,
        seed: args.seed,
        judge: judge.name(),
        trials: args.trials,
        ramp: args.ramp.clone(),
        pacing: args.pacing.clone(),
        profile,
        checks: args.checks.clone(),
        gltf: args.gltf.into(),
        population: match args.population {
            Some((theta_mean, theta_sd)) => PopulationAsk::Given(Population {
                theta_mean,
                theta_sd,
                retry: args.retry,
            }),
            None => PopulationAsk::ScriptedJudges { retry: args.retry },
        },
    };
    let n = args.levels as usize;
    let generator = load_generator(&policy_paths(&dir).0, args.game)?.0;
    let judged = load_panel(&dir, args.game, Some(&[judge]))?;
    let solver = judged.solver(0);
    if let Solver::Policy(policy) = &solver {
        crate::shells::common::check_fit(policy, ask.profile.as_ref())?;
    }
    let panel = load_panel(&dir, args.game, None)?;
    check_panel_fit(&panel, ask.profile.as_ref());
    let files: Vec<LevelFiles> = (0..n)
        .map(|k| LevelFiles::new(&args.out, &level_stem(k, n), &formats).with_gltf(ask.gltf))
        .collect();
    let resumed = match args.resume {
        true => resumed_levels(args, &ask, &files, &solver)?,
        false => vec![None; n],
    };
    let cache = crate::shells::common::cache_dir();
    let curve = difficulty_curve(
        (&dir, cache.as_deref()),
        &generator,
        &solver,
        ask.profile.as_ref(),
        || {
            crate::warn!(
                "measuring the policies' λ→success curve for {} ({} λ values × {} levels × {} runs), once",
                judge.name(),
                difficulty::CURVE_AUX.len(),
                difficulty::CURVE_LEVELS,
                difficulty::CURVE_TRIALS
            )
        },
        &|| stop.load(Ordering::SeqCst),
    )
    .map_err(|e| match e.downcast_ref::<difficulty::TargetError>() {
        Some(difficulty::TargetError::Stopped) => Interrupted(
            "interrupted (Ctrl-C) while the λ→success curve was measured; nothing was written"
                .into(),
        )
        .into(),
        _ => e,
    })?;
    let built = search_levels(args, &ask, &generator, &solver, &curve, resumed, &stop)?;
    if built.iter().any(Option::is_none) {
        return interrupted(args, &built, &files);
    }
    let mut levels: Vec<Level> = built.into_iter().flatten().collect();
    let search = |seed: u64, target: f64| {
        search_level((&generator, &solver), &curve, &ask, (seed, target), &|| {
            stop.load(Ordering::SeqCst)
        })
    };
    let Some(campaign) = rate_levels(&ask, &panel, &mut levels, &stop, Some(&search))? else {
        let searched: Vec<Option<Level>> = levels.into_iter().map(Some).collect();
        return interrupted(args, &searched, &files);
    };
    write_campaign(args, &campaign, &levels)?;
    report(&campaign);
    apply_checks(&campaign, &levels)
}

/// Searches each level not resumed for its ramp point, several at once; `None` for those a
/// Ctrl-C left unsearched.
#[allow(clippy::too_many_arguments)]
fn search_levels(
    args: &CampaignArgs,
    ask: &CampaignAsk,
    generator: &GeneratorPolicy,
    solver: &Solver,
    curve: &difficulty::Curve,
    resumed: Vec<Option<Level>>,
    stop: &AtomicBool,
) -> Result<Vec<Option<Level>>> {
    let n = resumed.len();
    let bar = progress_bar(n as u64, "campaign levels searched");
    bar.inc(resumed.iter().flatten().count() as u64);
    let built: Vec<Option<Level>> = resumed
        .into_par_iter()
        .enumerate()
        .map(|(k, kept)| -> Result<Option<Level>> {
            if let Some(level) = kept {
                return Ok(Some(level));
            }
            if stop.load(Ordering::SeqCst) {
                return Ok(None);
            }
            let seed = level_seed(args.seed, k)?;
            let searched = search_level(
                (generator, solver),
                curve,
                ask,
                (seed, ask.target(k, n)),
                &|| stop.load(Ordering::SeqCst),
            );
            // A Ctrl-C during the search leaves the level unsearched.
            if is_search_stopped(&searched) {
                return Ok(None);
            }
            let level = searched.with_context(|| {
                format!(
                    "level {} of {n} (seed {seed}, success {:.2} asked); nothing was written",
                    k + 1,
                    ask.target(k, n)
                )
            })?;
            bar.inc(1);
            Ok(Some(level))
        })
        .collect::<Result<_>>()?;
    bar.finish_and_clear();
    Ok(built)
}

/// Whether `searched` is a search a Ctrl-C ended.
fn is_search_stopped<T>(searched: &Result<T>) -> bool {
    searched.as_ref().is_err_and(|e| {
        matches!(
            e.downcast_ref(),
            Some(difficulty::TargetError::SearchStopped)
        )
    })
}

/// Writes the levels, campaign.yaml, campaign.md and campaign.png, all or none, and says so.
fn write_campaign(args: &CampaignArgs, campaign: &Campaign, levels: &[Level]) -> Result<()> {
    let n = levels.len();
    let formats: Vec<Format> = args.format.iter().map(|&f| f.into()).collect();
    let files = campaign_files(&args.out, campaign, levels, &formats)?;
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("cannot create {}", args.out.display()))?;
    // A resumed campaign's own files (its levels, verified without the panel, and its
    // reports) are replaced; anything else of other contents is refused.
    let ours = |path: &Path| args.resume && is_campaign_file(path, n);
    let (written, kept) = fsio::write_batch(
        &args.out,
        files,
        &ours,
        "choose another --out, or remove it",
        || {
            crate::warn!(
                "waiting for another arlpcg run that is writing into {}",
                args.out.display()
            )
        },
    )?;
    let unchanged = match kept {
        0 => String::new(),
        k => format!(", {k} of them already there and identical"),
    };
    crate::say!(
        "wrote a campaign of {n} levels ({} files{unchanged}) to {}",
        written + kept,
        args.out.display()
    );
    Ok(())
}

/// The seed level `k` is searched from.
fn level_seed(seed: u64, k: usize) -> Result<u64> {
    seed.checked_add(k as u64).ok_or_else(|| {
        crate::shells::common::UsageError(format!(
            "--seed {seed} plus the levels overflows a 64-bit seed"
        ))
        .into()
    })
}

/// Whether `path` is one of the files a campaign of `n` levels writes.
fn is_campaign_file(path: &Path, n: usize) -> bool {
    let Some(name) = path.file_name().and_then(|n| n.to_str()) else {
        return false;
    };
    let stem = name.split('.').next().unwrap_or_default();
    ["campaign.yaml", "campaign.md", "campaign.png"].contains(&name)
        || (0..n).any(|k| level_stem(k, n) == stem)
}

/// With --resume, the levels an earlier run of this campaign left in --out, each in the slot of
/// the seed it was searched from (a finished campaign's files are in the panel's order): each
/// checked to be this campaign's, its game and profile, verified by the judge from one of its
/// seeds.
fn resumed_levels(
    args: &CampaignArgs,
    ask: &CampaignAsk,
    files: &[LevelFiles],
    solver: &Solver,
) -> Result<Vec<Option<Level>>> {
    let n = files.len();
    let mut levels: Vec<Option<Level>> = vec![None; n];
    for files in files {
        let path = files
            .paths()
            .into_iter()
            .find(|p| p.extension().is_some_and(|e| e == "yaml"))
            .expect("a campaign writes YAML");
        if !path.exists() {
            continue;
        }
        let mut level = yaml::load(&path)?;
        let drawn = level
            .stats
            .as_ref()
            .filter(|s| level.game() == args.game && s.solver == solver.reference())
            .filter(|_| level.profile == ask.profile)
            .and_then(|s| s.seed.checked_sub(args.seed));
        // A level drawn anew where b stepped down is drawn again once the panel has rated
        // the campaign: the draws are seeded, so it comes back the same.
        if drawn.is_some_and(|j| (n..n + REDRAWS).contains(&(j as usize))) {
            continue;
        }
        let slot = drawn.filter(|&j| j < n as u64).map(|j| j as usize);
        let Some(slot) = slot.filter(|&j| levels[j].is_none()) else {
            anyhow::bail!(
                "{}: not a level of this campaign (a {} level{} verified by {} from one of seeds {}..{}, each once); remove it or choose another --out",
                path.display(),
                args.game,
                ask.profile
                    .as_ref()
                    .map_or(String::new(), |p| format!(" for profile `{}`", p.name)),
                solver.reference().describe(),
                args.seed,
                args.seed.saturating_add(n as u64 - 1),
            );
        };
        // A level searched for another ramp or with other trials is not this campaign's level.
        check_resumed(&level, &path, ask.target(slot, n), args.trials)?;
        // The panel plays the whole campaign again: its rating is of all the levels together.
        if let Some(stats) = &mut level.stats {
            stats.panel = None;
        }
        levels[slot] = Some(level);
    }
    Ok(levels)
}

/// Refuses a resumed level that the campaign asked for now would not have kept: one whose
/// judge's success lies off its ramp point (it was searched for another `--ramp`), or that
/// was verified with another `--trials`.
fn check_resumed(level: &Level, path: &Path, target: f64, trials: u32) -> Result<()> {
    let Some(stats) = &level.stats else {
        return Ok(());
    };
    let again = "resume with the arguments it was made with, or choose another --out";
    if stats.trials != trials {
        anyhow::bail!(
            "{}: verified with {} runs, and --trials asks {trials}: {again}",
            path.display(),
            stats.trials
        );
    }
    if (stats.success_ratio - target).abs() > difficulty::BAND + 1e-9 {
        anyhow::bail!(
            "{}: measured success {:.2}, and --ramp asks {target:.2} ± {} of this level: it was searched for another ramp; {again}",
            path.display(),
            stats.success_ratio,
            difficulty::BAND
        );
    }
    Ok(())
}

/// After a Ctrl-C: writes the levels finished so far (without the panel's rating, which is of
/// the whole campaign) for `--resume` to keep, and says so (exit 130).
fn interrupted(args: &CampaignArgs, built: &[Option<Level>], files: &[LevelFiles]) -> Result<()> {
    let finished: Vec<(&Level, &LevelFiles)> = built
        .iter()
        .zip(files)
        .filter_map(|(level, files)| level.as_ref().map(|l| (l, files)))
        .collect();
    if !finished.is_empty() {
        std::fs::create_dir_all(&args.out)
            .with_context(|| format!("cannot create {}", args.out.display()))?;
        let level_files = finished
            .iter()
            .flat_map(|(level, files)| render(level, files).into_iter().rev());
        fsio::write_batch(
            &args.out,
            level_files,
            &|path| args.resume && is_campaign_file(path, files.len()),
            "choose another --out, or remove it",
            || {},
        )?;
    }
    Err(Interrupted(format!(
        "interrupted (Ctrl-C): {} of {} levels were finished and written to {}; the same command with --resume finishes the campaign",
        finished.len(),
        files.len(),
        args.out.display()
    ))
    .into())
}

/// The panel plays every level (a progress bar), the levels are rated together and recorded;
/// with `mend`, reordered and mended where b steps down ([`rate_and_mend`], drawing with
/// `mend`'s search). `None` after a Ctrl-C.
fn rate_levels(
    ask: &CampaignAsk,
    panel: &crate::services::panel::JudgePanel,
    levels: &mut Vec<Level>,
    stop: &AtomicBool,
    mend: Option<&dyn Fn(u64, f64) -> Result<Level>>,
) -> Result<Option<Campaign>> {
    let level_runs = panel.judges.len() as u64 * ask.trials as u64;
    let bar = progress_bar(levels.len() as u64 * level_runs, "panel runs");
    let watch = Watch {
        on_trial: &|_| bar.inc(1),
        stop: &|| stop.load(Ordering::SeqCst),
    };
    let campaign = match mend {
        None => rate(ask, panel, levels, &watch)?,
        Some(search) => {
            let draw = |seed: u64, target: f64| {
                bar.inc_length(level_runs);
                search(seed, target)
            };
            let mended = rate_and_mend(ask, panel, levels, &watch, &draw);
            // A Ctrl-C while a level was drawn anew stops the campaign as one during the panel.
            if is_search_stopped(&mended) {
                bar.finish_and_clear();
                return Ok(None);
            }
            mended?.map(|(campaign, kept)| {
                for seed in kept {
                    crate::say!(
                        "drew a level anew from seed {seed} where the panel's b stepped down"
                    );
                }
                campaign
            })
        }
    };
    bar.finish_and_clear();
    Ok(campaign)
}

/// One line per level, then the funnel's end.
fn report(campaign: &Campaign) {
    for level in &campaign.levels {
        crate::say!(
            "{}: asked {:.2}, measured {:.2} ({:.2} to {:.2}), b {:+.2}; {:.1}% of players reach it, {:.1}% quit on it",
            level.file,
            level.asked,
            level.measured,
            level.ci95[0],
            level.ci95[1],
            level.b,
            100.0 * level.players.reach,
            100.0 * level.players.quit
        );
    }
    if !campaign.steps_down().is_empty() {
        crate::say!("the panel's {}", campaign.b_trend());
    }
    crate::say!(
        "{:.1}% of players finish the campaign (θ ~ Normal({:+.2}, {:.2}), retry {:.2})",
        100.0 * campaign.finishers(),
        campaign.population.theta_mean,
        campaign.population.theta_sd,
        campaign.population.retry
    );
}

/// The campaign's checks on its levels (named by their files), exit code 3 on a failure.
fn apply_checks(campaign: &Campaign, levels: &[Level]) -> Result<()> {
    let evidence = campaign
        .levels
        .iter()
        .zip(levels)
        .map(|(entry, level)| (entry.file.clone(), level, Evidence::of(level)));
    let failed = failures(&campaign.checks, evidence);
    report_checks(&campaign.checks, failed, levels.len(), false)
}

/// Exit code 3, naming each level and check that failed, when any did. The verdict goes to
/// standard output, or with `json` to standard error (standard output then carries only JSON).
pub fn report_checks(
    checks: &[Constraint],
    failed: Vec<(String, String)>,
    levels: usize,
    json: bool,
) -> Result<()> {
    let tell = |line: String| match json {
        true => crate::warn!("{line}"),
        false => crate::say!("{line}"),
    };
    if failed.is_empty() {
        if !checks.is_empty() {
            tell(format!("every level passed its checks ({})", checks.len()));
        }
        return Ok(());
    }
    for (level, why) in &failed {
        tell(format!("check failed: {level}: {why}"));
    }
    let levels_failed = {
        let mut names: Vec<&String> = failed.iter().map(|(n, _)| n).collect();
        names.dedup();
        names.len()
    };
    Err(ChecksFailed(format!(
        "{levels_failed} of {levels} levels failed their checks ({} failures)",
        failed.len()
    ))
    .into())
}

/// The judge `--judge` names, else the folder's Solver where it trained with the abilities of
/// `profile` (or its ability-aware Solver where that one did), else the scripted expert, who
/// plays with any abilities ([`crate::services::verify::default_player`]; the campaign records the judge that played).
fn campaign_judge(args: &CampaignArgs, dir: &Path, profile: Option<&Profile>) -> Result<Judge> {
    if let Some(judge) = args.judge {
        return Ok(judge);
    }
    let solver = Judge::Solver(TrainMode::Arlpcg);
    let panel = load_panel(dir, args.game, Some(&[solver]))?;
    let Solver::Policy(policy) = panel.solver(0) else {
        return Ok(solver);
    };
    Ok(match policy.stand_in(profile) {
        None => solver,
        Some((skill, why)) => {
            crate::warn!("{why}");
            Judge::Scripted(skill)
        }
    })
}

/// `verify --campaign FILE`: the judge and the panel play every level of the campaign again
/// (the levels as they are now, from the seeds the campaign gives them); the report goes to
/// standard output; the campaign's checks and --check are applied.
pub fn replay(args: &VerifyArgs, file: &Path) -> Result<()> {
    let (_, campaign, mut levels) = crate::services::campaign::open(file)?;
    let judge = Judge::parse(&campaign.judge)
        .map_err(|e| anyhow::anyhow!("{}: judge: {e}", file.display()))?;
    let dir: PathBuf = match &args.policies {
        Some(dir) => dir.clone(),
        None => shipped_dir(campaign.game)?,
    };
    let judged = load_panel(&dir, campaign.game, Some(&[judge]))?;
    let profile = campaign.ask().profile;
    let solver = judged.solver(0);
    if let Solver::Policy(policy) = &solver {
        crate::shells::common::check_fit(policy, profile.as_ref())?;
    }
    let panel = load_panel(&dir, campaign.game, None)?;
    check_panel_fit(&panel, profile.as_ref());
    for (level, entry) in levels.iter_mut().zip(&campaign.levels) {
        level.stats = Some(verify::verify(
            level,
            &solver,
            campaign.trials,
            entry.seed,
            &|| {},
        )?);
    }
    let mut ask = campaign.ask();
    ask.checks.extend(args.checks.iter().copied());
    let replayed = rate_levels(&ask, &panel, &mut levels, &AtomicBool::new(false), None)?
        .expect("a panel without a stop condition plays to the end");
    // The levels keep the files the campaign gives them.
    let replayed = Campaign {
        levels: campaign
            .levels
            .iter()
            .zip(replayed.levels)
            .map(|(entry, again)| CampaignLevel {
                file: entry.file.clone(),
                ..again
            })
            .collect(),
        ..replayed
    };
    crate::say!("{}", replayed.to_markdown());
    apply_checks(&replayed, &levels)
}
