//! `arlpcg verify`: play each level many times and report the Solver's statistics, then a
//! summary over all the levels. Who plays: `players.rs`.

mod players;

use std::collections::hash_map::Entry;
use std::collections::{HashMap, HashSet};
use std::path::Path;

use anyhow::Result;
use serde_json::json;

use super::campaign::report_checks;
use crate::services::panel::{JudgePanel, rate};
use crate::services::policies::load_panel;
use crate::services::profile;
use crate::services::verify::{
    FailureConcentration, HalfwaySplit, Summary, Watch, passed_by_piece, verify,
};
use crate::services::wish::{Evidence, Reads, failures};
use crate::shells::cli::{Judges, VerifyArgs};
use crate::shells::common::{panel_fit, shipped_dir};
use arlpcg_core::game::facts::facts;
use arlpcg_core::level::profile::Profile;
use arlpcg_core::level::stats::{Outcome, PanelStats, SolverStats};
use arlpcg_core::level::yaml;
use arlpcg_core::level::{Game, Level};
use players::Solvers;

pub fn run(args: &VerifyArgs) -> Result<()> {
    if let Some(file) = &args.campaign {
        return super::campaign::replay(args, file);
    }
    check_arguments(args)?;
    if args.replay {
        return replay(args);
    }
    if let Some(judges) = &args.panel {
        return panel(args, judges);
    }
    if let Some(chart) = args.chart.as_ref().filter(|c| c.exists()) {
        anyhow::bail!(
            "--chart {} already exists: verify writes a new chart and replaces none; remove it \
             or name another file",
            chart.display()
        );
    }
    let profile = args.profile.as_deref().map(profile::load).transpose()?;
    let mut solvers = Solvers::default();
    let mut checked = Vec::new();
    let mut all = Vec::new();
    let mut halfway = HalfwaySplit::default();
    let mut concentration = FailureConcentration::default();
    let failed = each_level(
        &args.levels,
        |path| {
            load_under(path, profile.as_ref(), args.profile.as_deref()).and_then(|level| {
                let game = level.game();
                solvers.resolve(game, args)?;
                solvers.check_profile(&level, path)?;
                let solver = solvers.get(&level);
                let bar = crate::shells::common::progress_bar(
                    args.trials as u64,
                    &path.display().to_string(),
                );
                let stats = verify(&level, &solver, args.trials, args.seed, &|| bar.inc(1))?;
                bar.finish_and_clear();
                Ok((level, stats))
            })
        },
        |path, (level, stats)| {
            if args.json {
                crate::say!("{}", to_json(path, &level, &stats));
            } else {
                crate::say!("{}", describe(path, &level, &stats));
            }
            halfway.add(&level, &stats);
            concentration.add(&stats);
            checked.extend(failures(
                &args.checks,
                [(
                    path.display().to_string(),
                    &level,
                    Evidence {
                        stats: Some(&stats),
                        ..Evidence::default()
                    },
                )],
            ));
            if let Some(chart) = &args.chart {
                let name = path.file_stem().unwrap_or_default().to_string_lossy();
                let png = crate::services::verify::pacing_chart(&name, &level, &stats).to_png();
                crate::services::fsio::write_atomic(
                    chart,
                    &png,
                    crate::services::fsio::Overwrite::Never,
                )?;
                crate::warn!("wrote {}", chart.display());
            }
            all.push(stats);
            Ok(())
        },
    )?;
    if all.len() > 1 && !args.json {
        let s = Summary::of(&all);
        let steps = match s.completed_by_any > 0.0 {
            true => format!("{:.0}", s.mean_success_steps),
            false => "n/a".into(),
        };
        crate::say!(
            "{} levels: success ratio {:.3} ± {:.3} (mean ± std over levels), completed by at least one run {:.2}, mean progress {:.2}, mean steps of successful runs {steps}",
            s.levels,
            s.mean_success,
            s.std_success,
            s.completed_by_any,
            s.mean_progress
        );
        if let Some([last, worst]) = concentration.shares() {
            crate::say!(
                "of the {} failures, {last:.2} on each level's last piece and {worst:.2} on its most-failed piece; {:.1} pieces per level",
                concentration.failures,
                concentration.pieces_per_level()
            );
        }
        let [before, past] = halfway.per_piece();
        if halfway.failures.iter().sum::<u64>() > 0 {
            crate::say!(
                "failures per piece {before:.2} before the halfway point ({} pieces), {past:.2} past it ({} pieces): {:.0}% of the {} failures fall past it",
                halfway.pieces[0],
                halfway.pieces[1],
                100.0 * halfway.share_past(),
                halfway.failures.iter().sum::<u64>()
            );
        }
    }
    if failed > 0 {
        anyhow::bail!(
            "{failed} of {} level files could not be verified",
            args.levels.len()
        );
    }
    report_checks(&args.checks, checked, args.levels.len(), args.json)
}

/// Rates the levels of each game together (the judges' abilities come from all of them),
/// saying each judge's ability unless `json`.
fn rate_each_game(rated: &mut [(&Path, Level, PanelStats)], json: bool) {
    for game in Game::ALL {
        let mut of_game: Vec<&mut PanelStats> = rated
            .iter_mut()
            .filter(|(_, level, _)| level.game() == game)
            .map(|(_, _, s)| s)
            .collect();
        if of_game.is_empty() {
            continue;
        }
        let abilities = rate(&mut of_game);
        if !json {
            let shown: Vec<String> = abilities
                .iter()
                .map(|(name, theta)| format!("{name} {theta:+.2}"))
                .collect();
            crate::say!("{game} judges' ability θ (logits): {}", shown.join(", "));
        }
    }
}

/// The checks on the arguments alone (exit 2 on a misfit).
fn check_arguments(args: &VerifyArgs) -> Result<()> {
    let usage = |message: &str| Err(crate::shells::common::UsageError(message.into()).into());
    if args.policies.is_some() && args.panel.is_none() {
        return usage("--policies names where the panel's Solvers come from: give --panel too");
    }
    if args.replay && !args.checks.is_empty() {
        return usage("--check reads new trials; --replay plays none");
    }
    let one_players = |c: &&crate::services::wish::Constraint| {
        c.attribute.reads() == Reads::Runs && !c.needs_panel()
    };
    if args.panel.is_some()
        && let Some(check) = args.checks.iter().find(one_players)
    {
        return usage(&format!(
            "with --panel, `{check}` has no one player's runs to read: a check reads the pieces, `b LO..HI` or `success LO..HI for JUDGE` (or verify without --panel)"
        ));
    }
    if args.panel.is_none()
        && let Some(check) = args.checks.iter().find(|c| c.needs_panel())
    {
        return usage(&format!(
            "--check {check} reads the panel's runs: give --panel too"
        ));
    }
    if args.chart.is_some() && args.levels.len() != 1 {
        return usage("--chart draws one level: give one level file");
    }
    if let Some(chart) = &args.chart
        && chart.extension().is_none_or(|e| e != "png")
    {
        return usage(&format!(
            "--chart {}: the file name must end in .png",
            chart.display()
        ));
    }
    Ok(())
}

/// The level file `path`, to be played under `profile` (read from `file`) when one is given:
/// a level recording another profile is played under this one, and says so.
fn load_under(path: &Path, profile: Option<&Profile>, file: Option<&Path>) -> Result<Level> {
    let mut level = yaml::load(path)?;
    let (Some(profile), Some(file)) = (profile, file) else {
        return Ok(level);
    };
    let profile = profile::for_game(profile.clone(), level.game(), file)?;
    let sha = profile.sha256();
    let recorded = level.profile.as_ref().map(|p| (p.name.clone(), p.sha256()));
    if recorded.as_ref().map(|(_, recorded)| recorded) != Some(&sha) {
        let was = recorded.map_or("the built-in profile".into(), |(name, sha)| {
            format!("profile `{name}` ({})", &sha[..12])
        });
        crate::warn!(
            "{}: made under {was}; playing it under `{}` ({})",
            path.display(),
            profile.name,
            &sha[..12]
        );
    }
    level.profile = Some(profile);
    Ok(level)
}

/// `verify --replay`: each level's certificate run, again, with the Solver that recorded it.
fn replay(args: &VerifyArgs) -> Result<()> {
    let failed = each_level(
        &args.levels,
        |path| replay_one(&yaml::load(path)?),
        |path, said| {
            crate::say!("{}: {said}", path.display());
            Ok(())
        },
    )?;
    if failed > 0 {
        anyhow::bail!(
            "{failed} of {} certificates did not replay",
            args.levels.len()
        );
    }
    Ok(())
}

fn replay_one(level: &arlpcg_core::level::Level) -> Result<String> {
    let (seed, run) = crate::services::certificate::run(level)?;
    let solver = level.stats.as_ref().map(|s| s.solver.describe());
    let solver = solver.unwrap_or_default();
    if run.result.outcome != Outcome::Success {
        anyhow::bail!(
            "the certificate run (seed {seed}) did not succeed with the {solver}: it {}",
            run.result.outcome.describe()
        );
    }
    Ok(format!(
        "the certificate run (seed {seed}) succeeds again with the {solver} in {} decisions",
        run.result.steps
    ))
}

/// Says what [`panel_fit`] says of `panel` on `level` that this run has not said yet (once a
/// run, as [`Solvers::check_profile`] says it of the Solver); nothing with `json`.
fn say_panel_fit(panel: &JudgePanel, level: &Level, json: bool, said: &mut HashSet<String>) {
    for line in panel_fit(panel, level.profile.as_ref()) {
        if !json && said.insert(line.clone()) {
            crate::warn!("{line}");
        }
    }
}

/// `verify --panel`: every level played by every judge, then rated over judges × levels (the
/// levels of each game together).
fn panel(args: &VerifyArgs, chosen: &Judges) -> Result<()> {
    let mut panels: HashMap<Game, JudgePanel> = HashMap::new();
    let mut rated: Vec<(&Path, Level, PanelStats)> = Vec::new();
    let mut said = HashSet::new();
    let profile = args.profile.as_deref().map(profile::load).transpose()?;
    let failed = each_level(
        &args.levels,
        |path| {
            load_under(path, profile.as_ref(), args.profile.as_deref()).and_then(|level| {
                let game = level.game();
                let panel = match panels.entry(game) {
                    Entry::Occupied(known) => known.into_mut(),
                    Entry::Vacant(new) => {
                        let dir = args
                            .policies
                            .clone()
                            .map_or_else(|| shipped_dir(game), Ok)?;
                        let chosen = (!chosen.0.is_empty()).then_some(chosen.0.as_slice());
                        let panel = load_panel(&dir, game, chosen)?;
                        if !args.json {
                            crate::warn!("{game} panel: {}", panel.names().join(", "));
                        }
                        new.insert(panel)
                    }
                };
                say_panel_fit(panel, &level, args.json, &mut said);
                let runs = args.trials as u64 * panel.judges.len() as u64;
                let bar = crate::shells::common::progress_bar(runs, &path.display().to_string());
                let watch = Watch {
                    on_trial: &|_| bar.inc(1),
                    stop: &|| false,
                };
                let played = crate::services::panel::play(
                    panel,
                    &level,
                    args.trials,
                    args.seed,
                    &watch,
                    &|_, _| {},
                )?
                .expect("a panel without a stop condition plays to the end");
                bar.finish_and_clear();
                Ok((level, played))
            })
        },
        |path, (level, stats)| {
            rated.push((path, level, stats));
            Ok(())
        },
    )?;
    rate_each_game(&mut rated, args.json);
    let checked = failures(
        &args.checks,
        rated.iter().map(|(path, level, stats)| {
            let evidence = Evidence {
                panel: Some(stats),
                ..Evidence::default()
            };
            (path.display().to_string(), level, evidence)
        }),
    );
    for (path, _, stats) in &rated {
        let rating = stats.rating.expect("rated above");
        if args.json {
            let ratios: serde_json::Map<String, serde_json::Value> = stats
                .judges
                .iter()
                .map(|j| (j.judge.clone(), json!(j.success_ratio)))
                .collect();
            crate::say!(
                "{}",
                json!({
                    "level": path.display().to_string(),
                    "seed": stats.seed,
                    "trials": stats.trials,
                    "panel": ratios,
                    "panel_ci95": stats.judges.iter().map(|j| (j.judge.clone(), json!(j.ci95))).collect::<serde_json::Map<_, _>>(),
                    "rating": {"b": rating.b, "ci95": rating.ci95, "levels": rating.levels},
                })
            );
        } else {
            let judges: Vec<String> = stats
                .judges
                .iter()
                .map(|j| format!("{} {:.2}", j.judge, j.success_ratio))
                .collect();
            crate::say!(
                "{}: difficulty b {:+.2} (95% CI {:+.2} to {:+.2}); {}",
                path.display(),
                rating.b,
                rating.ci95[0],
                rating.ci95[1],
                judges.join(", ")
            );
        }
    }
    if failed > 0 {
        anyhow::bail!(
            "{failed} of {} level files could not be verified",
            args.levels.len()
        );
    }
    report_checks(&args.checks, checked, args.levels.len(), args.json)
}

fn to_json(path: &Path, level: &Level, s: &SolverStats) -> serde_json::Value {
    let game = level.game();
    let mut value = json!({
        "level": path.display().to_string(),
        "solver": s.solver.describe(),
        "seed": s.seed,
        "trials": s.trials,
        "successes": s.successes,
        "success_ratio": s.success_ratio,
        "ci95": s.ci95,
        "mean_progress": s.mean_progress,
        "mean_success_steps": s.mean_success_steps,
        "fell": s.fell,
        "timed_out": s.timed_out,
    });
    let facts = facts(game);
    for (ending, _) in facts.endings {
        value[*ending] = json!(s.ending_count(ending));
    }
    if facts.air_time_step.is_some() {
        value["mean_air_steps"] = json!(s.mean_air_steps);
    }
    value[format!("failures_by_{}", facts.piece)] = json!(s.failures_by_piece);
    if let Some(pacing) = &level.pacing {
        value["aux_curve"] = json!(pacing.curve.to_string());
        value["aux_by_piece"] = json!(pacing.piece_aux);
        value["passed_by_piece"] = json!(
            passed_by_piece(s)
                .iter()
                .map(|p| round2(*p))
                .collect::<Vec<_>>()
        );
    }
    value
}

fn round2(x: f64) -> f64 {
    (x * 100.0).round() / 100.0
}

fn describe(path: &Path, level: &Level, s: &SolverStats) -> String {
    let game = level.game();
    let mut text = format!(
        "{}: {}/{} succeeded, success ratio {:.2} (95% CI {:.2}-{:.2}), mean progress {:.2}",
        path.display(),
        s.successes,
        s.trials,
        s.success_ratio,
        s.ci95[0],
        s.ci95[1],
        s.mean_progress
    );
    let failures: Vec<String> = s
        .failures_by_piece
        .iter()
        .enumerate()
        .filter(|(_, n)| **n > 0)
        .map(|(i, n)| format!("{} {i}: {n}", facts(game).piece))
        .collect();
    if let (Some(air), Some(dt)) = (s.mean_air_steps, facts(game).air_time_step) {
        text += &format!(", mean air time {:.2} s", air * dt);
    }
    if let Some(profile) = &level.profile {
        text += &format!(", under profile `{}`", profile.name);
    }
    if !failures.is_empty() {
        let causes = facts(game)
            .endings
            .iter()
            .map(|(ending, words)| format!("{words} {}", s.ending_count(ending).unwrap_or(0)))
            .collect::<Vec<_>>()
            .join(", ");
        text += &format!(
            "\n  failed {} {} ({causes})",
            facts(game).failed_at,
            failures.join(", ")
        );
    }
    if let Some(pacing) = &level.pacing {
        let passed: Vec<String> = passed_by_piece(s)
            .iter()
            .zip(&pacing.piece_aux)
            .map(|(p, aux)| match aux {
                Some(aux) => format!("{p:.2} (λ {aux:+.2})"),
                None => format!("{p:.2} (kept)"),
            })
            .collect();
        text += &format!(
            "\n  aux curve {}; runs past each {}: {}",
            pacing.curve,
            facts(game).piece,
            passed.join(", ")
        );
    }
    text
}

/// Plays each level file in turn (`play`), hands what it found to `done`, and prints each file's
/// error on one line: how many failed. It stops when nobody reads stdout any more; an error of
/// `done` (writing a chart) ends it.
fn each_level<'a, T>(
    levels: &'a [std::path::PathBuf],
    mut play: impl FnMut(&'a Path) -> Result<T>,
    mut done: impl FnMut(&'a Path, T) -> Result<()>,
) -> Result<usize> {
    let mut failed = 0;
    for path in levels {
        if crate::shells::common::stdout_closed() {
            break; // nobody reads the rest
        }
        match play(path) {
            Ok(found) => done(path, found)?,
            Err(err) => {
                failed += 1;
                report_error(path, &err);
            }
        }
    }
    Ok(failed)
}

/// Prints a level file's error on one line, naming the file once.
fn report_error(path: &Path, err: &anyhow::Error) {
    let message = one_line(&format!("{err:#}"));
    let file = path.display().to_string();
    match message.starts_with(&file) {
        true => crate::warn!("error: {message}"),
        false => crate::warn!("error: {file}: {message}"),
    }
}

/// Folds a multi-line error message onto one line.
pub fn one_line(message: &str) -> String {
    message.split_whitespace().collect::<Vec<_>>().join(" ")
}
