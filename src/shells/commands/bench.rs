//! `arlpcg bench`: an ask set scored as the PCG Benchmark scores a generator
//! ([`crate::services::wish::score`]): each ask searched for on a few seeds with the policies
//! (`generate --want`'s search), then quality, controllability per ask and per attribute,
//! diversity against plain levels, and the time per level.

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use anyhow::Result;
use arlpcg_core::level::Level;
use rayon::prelude::*;

use crate::services::fsio::{self, Overwrite};
use crate::services::generation::LevelRequest;
use crate::services::making::wanted::{Search, Unmet};
use crate::services::making::{self, LevelSource, Proof};
use crate::services::panel::Judge;
use crate::services::policies::{load_generator, load_judges_under, load_solver, policy_paths};
use crate::services::verify::{self, Solver, Watch};
use crate::services::wish::score::{AskSet, Outcome, Score, score};
use crate::shells::cli::BenchArgs;
use crate::shells::common::{UsageError, shipped_dir};

/// Plain levels the diversity of the searched ones is held against, at most.
const MAX_PLAIN: u64 = 100;

pub fn run(args: &BenchArgs) -> Result<()> {
    let asks = AskSet::load(&args.asks, args.game).map_err(UsageError)?;
    if let Some(out) = &args.out {
        fsio::check_writable(out, overwrite(args))?;
    }
    let dir = match &args.policies {
        Some(dir) => dir.clone(),
        None => shipped_dir(args.game)?,
    };
    let generator = load_generator(&policy_paths(&dir).0, args.game)?.0;
    let solver = load_solver(&policy_paths(&dir).1, args.game)?.0;
    let who = Solver::Policy(&solver);
    let mut asked: Vec<Judge> = Vec::new();
    for judge in asks.iter().flat_map(|(_, want, _)| want.judges()) {
        if !asked.contains(&judge) {
            asked.push(judge);
        }
    }
    let judges = load_judges_under(|| Ok(dir.clone()), args.game, &asked)?;
    let stop = AtomicBool::new(false);
    let jobs: Vec<(usize, u64)> = (0..asks.len())
        .flat_map(|a| (0..u64::from(args.levels)).map(move |seed| (a, seed)))
        .collect();
    let bar = crate::shells::common::progress_bar(jobs.len() as u64, "asks × seeds");
    let watch = Watch {
        on_trial: &|_| {},
        stop: &|| stop.load(Ordering::SeqCst),
    };
    // Each search's outcome, and for a search that met nothing why (the closest it came).
    let searched: Vec<(Outcome, Option<String>)> = jobs
        .par_iter()
        .map(|&(ask, seed)| {
            let want = &asks[ask].1;
            let players: Vec<(Judge, Solver)> = judges
                .iter()
                .filter(|(judge, _)| want.judges().contains(judge))
                .map(|(judge, policy)| (*judge, judge.player(policy.as_ref())))
                .collect();
            let search = Search {
                want,
                solver: Some(&who),
                judges: &players,
                trials: args.trials,
            };
            let started = Instant::now();
            let made = making::verified_level(
                LevelSource::Generator(&generator),
                &LevelRequest::new(seed, None),
                &Proof::Wanted(search),
                &watch,
                &|_| {},
            );
            bar.inc(1);
            let seconds = started.elapsed().as_secs_f64();
            let outcome = match made {
                Ok(level) => Outcome {
                    met: level.is_some(),
                    level,
                    missed: Vec::new(),
                    seconds,
                },
                Err(e) => match e.downcast::<Unmet>() {
                    Ok(unmet) => {
                        let why = format!("ask {}, seed {seed}: {unmet}", ask + 1);
                        let level = unmet
                            .closest_level
                            .map(|closest| {
                                closest_certified(*closest, &who, args.trials, seed, &watch)
                            })
                            .transpose()?
                            .flatten();
                        let outcome = Outcome {
                            level,
                            met: false,
                            missed: unmet.missed,
                            seconds,
                        };
                        return Ok((outcome, Some(why)));
                    }
                    Err(e) => return Err(e.context(format!("ask {}, seed {seed}", ask + 1))),
                },
            };
            Ok((outcome, None))
        })
        .collect::<Result<_>>()?;
    bar.finish_and_clear();
    for why in searched.iter().filter_map(|(_, why)| why.as_ref()) {
        crate::warn!("{why}");
    }
    let outcomes: Vec<Outcome> = searched.into_iter().map(|(outcome, _)| outcome).collect();
    let plain: Vec<_> = (0..(jobs.len() as u64).min(MAX_PLAIN))
        .map(|seed| LevelSource::Generator(&generator).level(&LevelRequest::new(seed, Some(0.0))))
        .collect::<Result<_>>()?;
    let scored = score(args.game, &asks, args.levels, &outcomes, &plain);
    crate::say!("{}", describe(&scored));
    if let Some(out) = &args.out {
        let json = serde_json::to_string_pretty(&scored)? + "\n";
        fsio::write_atomic(out, json.as_bytes(), overwrite(args))?;
        crate::warn!("wrote {}", out.display());
    }
    Ok(())
}

/// The closest candidate of a search that met nothing, played (when the search had not) and
/// certified as a kept level would be: the level a benchmark scores that search by.
fn closest_certified(
    mut closest: Level,
    who: &Solver,
    trials: u32,
    seed: u64,
    watch: &Watch,
) -> Result<Option<Level>> {
    if closest.stats.is_none() {
        match verify::verify_watched(&closest, who, trials, seed, watch)? {
            Some(stats) => closest.stats = Some(stats),
            None => return Ok(None),
        }
    }
    Ok(Some(verify::certified(closest, who, seed)?))
}

fn overwrite(args: &BenchArgs) -> Overwrite {
    match args.force {
        true => Overwrite::Allowed,
        false => Overwrite::Never,
    }
}

/// The score as a few lines of text.
fn describe(s: &Score) -> String {
    let attributes: Vec<String> = s
        .by_attribute
        .iter()
        .map(|(name, share)| format!("{name} {:.0}%", 100.0 * share))
        .collect();
    format!(
        "{} asks ({} sentences) × {} seeds = {} levels: quality {:.0}% certified, controllability {:.0}% meet every constraint (per attribute: {}), diversity {:.3} (plain levels at λ = 0: {:.3}), median {:.1} s per level",
        s.asks,
        s.sentences,
        s.levels_per_ask,
        s.searched,
        100.0 * s.quality,
        100.0 * s.controllability,
        attributes.join(", "),
        s.diversity,
        s.plain_diversity,
        s.median_seconds
    )
}
